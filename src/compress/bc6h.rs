//! BC6H (unsigned half-float RGB, 16 bytes per block): encoded by intel_tex_2, decoded by
//! `bcdec_rs` (a port of the public-domain bcdec).

/// Encode a strip of 4 rows of RGBA f16 texels (8 bytes each) into BC6H blocks.
pub fn bc6h_encode_strip(rgba16: &[u8], width: usize, dst: &mut [u8]) {
    let surface = intel_tex_2::RgbaSurface {
        data: rgba16,
        width: width as u32,
        height: 4,
        stride: width as u32 * 8,
    };
    let settings = intel_tex_2::bc6h::basic_settings();
    intel_tex_2::bc6h::compress_blocks_into(&settings, &surface, dst);
}

/// Decode a BC6H (unsigned) block to 16 RGB f32 texels.
#[inline]
pub fn bc6h_decode_block(block: &[u8]) -> [[f32; 3]; 16] {
    let mut tmp = [0.0f32; 48];
    bcdec_rs::bc6h_float(block, &mut tmp, 12, false);
    let mut out = [[0.0f32; 3]; 16];
    for t in 0..16 {
        out[t] = [tmp[3 * t], tmp[3 * t + 1], tmp[3 * t + 2]];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bc6h_round_trips_half_floats() {
        let mut rgba = vec![0u8; 16 * 8];
        for t in 0..16 {
            for c in 0..3 {
                let v = half::f16::from_f32(0.01 * (1.0 + 0.02 * t as f32) * (c + 1) as f32);
                rgba[t * 8 + 2 * c..t * 8 + 2 * c + 2].copy_from_slice(&v.to_le_bytes());
            }
        }
        let mut blk = [0u8; 16];
        bc6h_encode_strip(&rgba, 4, &mut blk);
        let d = bc6h_decode_block(&blk);
        for t in 0..16 {
            for c in 0..3 {
                let want = 0.01 * (1.0 + 0.02 * t as f32) * (c + 1) as f32;
                assert!((d[t][c] - want).abs() / want < 0.02, "{t} {c}: {}", d[t][c]);
            }
        }
    }
}
