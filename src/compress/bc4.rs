//! BC4: one channel, 8 bytes per block.
//!
//! BC4 ([`bc4_palette`]): endpoints `r0`, `r1` are bytes 0 and 1; sixteen 3-bit indices follow
//! (texel `t` in bits `3t..3t+3` of the 48-bit little-endian integer at bytes 2..8). If
//! `r0 > r1` the palette is `r0, r1, ((7−k)·r0 + k·r1)/7` for k = 1..6, else
//! `r0, r1, ((5−k)·r0 + k·r1)/5` for k = 1..4, then 0 and 255. Values are kept as real numbers
//! (the D3D/Vulkan UNORM decode interpolates in float), not rounded to 8 bits.
//!

/// The eight palette values of a BC4 block as real codes in [0, 255].
#[inline]
pub fn bc4_palette(block: &[u8]) -> [f32; 8] {
    let (r0, r1) = (block[0] as f32, block[1] as f32);
    let mut p = [0.0f32; 8];
    p[0] = r0;
    p[1] = r1;
    if block[0] > block[1] {
        for k in 1..7 {
            p[k + 1] = ((7 - k) as f32 * r0 + k as f32 * r1) / 7.0;
        }
    } else {
        for k in 1..5 {
            p[k + 1] = ((5 - k) as f32 * r0 + k as f32 * r1) / 5.0;
        }
        p[6] = 0.0;
        p[7] = 255.0;
    }
    p
}

/// The sixteen 3-bit palette indices of a BC4 block (row-major texels).
#[inline]
pub fn bc4_indices(block: &[u8]) -> [u8; 16] {
    let mut bits = 0u64;
    for (k, &b) in block[2..8].iter().enumerate() {
        bits |= (b as u64) << (8 * k);
    }
    let mut out = [0u8; 16];
    for (t, o) in out.iter_mut().enumerate() {
        *o = ((bits >> (3 * t)) & 7) as u8;
    }
    out
}

/// Decode a BC4 block to 16 real codes.
#[inline]
pub fn bc4_decode_block(block: &[u8]) -> [f32; 16] {
    let p = bc4_palette(block);
    let idx = bc4_indices(block);
    let mut out = [0.0f32; 16];
    for t in 0..16 {
        out[t] = p[idx[t] as usize];
    }
    out
}

/// Encode a strip of 4 rows of one-byte texels (`width` a multiple of 4) into BC4 blocks.
pub fn bc4_encode_strip(r8: &[u8], width: usize, dst: &mut [u8]) {
    let surface = intel_tex_2::RSurface {
        data: r8,
        width: width as u32,
        height: 4,
        stride: width as u32,
    };
    intel_tex_2::bc4::compress_blocks_into(&surface, dst);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bc4_palettes_follow_the_spec() {
        let p = bc4_palette(&[210, 140, 0, 0, 0, 0, 0, 0]);
        assert_eq!(p[0], 210.0);
        assert_eq!(p[1], 140.0);
        assert!((p[2] - 200.0).abs() < 1e-4);
        assert!((p[7] - 150.0).abs() < 1e-4);
        let q = bc4_palette(&[10, 60, 0, 0, 0, 0, 0, 0]);
        assert_eq!((q[2], q[6], q[7]), (20.0, 0.0, 255.0));
    }

    #[test]
    fn bc4_round_trips_a_gradient_closely() {
        let mut r8 = vec![0u8; 16];
        for (t, v) in r8.iter_mut().enumerate() {
            *v = 100 + 3 * t as u8;
        }
        let mut blk = [0u8; 8];
        bc4_encode_strip(&r8, 4, &mut blk);
        let d = bc4_decode_block(&blk);
        for t in 0..16 {
            // 16 values over a range of 45 with 8 palette levels: at most half a step off.
            assert!(
                (d[t] - r8[t] as f32).abs() <= 45.0 / 7.0 / 2.0 + 1e-3,
                "{t}: {} vs {}",
                d[t],
                r8[t]
            );
        }
    }
}
