//! BC1 (DXT1) blocks: encoding with intel_tex_2 (ISPC kernels) and a CPU decoder.
//!
//! A BC1 block is 8 bytes for 4x4 texels: two RGB 5:6:5 endpoints `c0`, `c1` (little-endian
//! u16: red in bits 11..16, green 5..11, blue 0..5) and sixteen 2-bit palette indices (texel
//! `t = 4·y + x` in bits `2t..2t+2` of the little-endian u32 at byte 4).
//!
//! Decoding ([`decode_block`]) follows the D3D/Vulkan definition with the integer arithmetic of
//! common software decoders (and Pillow's `BcnDecode.c`, which a test compares with exactly):
//! endpoints expand to 8 bits by bit replication (`r8 = r5 << 3 | r5 >> 2`,
//! `g8 = g6 << 2 | g6 >> 4`); if `c0 > c1` the palette is `c0, c1, (2·c0 + c1)/3, (c0 + 2·c1)/3`,
//! else `c0, c1, (c0 + c1)/2, black`, each division truncating, per channel on the 8-bit
//! values. GPUs may round the interpolated colours differently (the spec allows it); the WGSL
//! port of this function must use exactly this arithmetic to match the CPU gather.

use rayon::prelude::*;

/// Bytes per BC1 block.
pub const BLOCK_BYTES: usize = 8;

/// Expand a 5:6:5 colour to 8 bits per channel by bit replication.
#[inline]
pub fn expand_565(c: u16) -> [u8; 3] {
    let r = ((c >> 11) & 31) as u8;
    let g = ((c >> 5) & 63) as u8;
    let b = (c & 31) as u8;
    [
        (r << 3) | (r >> 2),
        (g << 2) | (g >> 4),
        (b << 3) | (b >> 2),
    ]
}

/// The four palette colours of a block (index 3 of a three-colour block is black).
#[inline]
pub fn palette(block: &[u8]) -> [[u8; 3]; 4] {
    let c0 = u16::from_le_bytes([block[0], block[1]]);
    let c1 = u16::from_le_bytes([block[2], block[3]]);
    let (a, b) = (expand_565(c0), expand_565(c1));
    let mut p = [a, b, [0; 3], [0; 3]];
    for ch in 0..3 {
        let (x, y) = (a[ch] as u32, b[ch] as u32);
        if c0 > c1 {
            p[2][ch] = ((2 * x + y) / 3) as u8;
            p[3][ch] = ((x + 2 * y) / 3) as u8;
        } else {
            p[2][ch] = ((x + y) / 2) as u8;
        }
    }
    p
}

/// Decode one block to 16 RGB texels, row-major (`t = 4·y + x`).
#[inline]
pub fn decode_block(block: &[u8]) -> [[u8; 3]; 16] {
    let p = palette(block);
    let bits = u32::from_le_bytes([block[4], block[5], block[6], block[7]]);
    let mut out = [[0u8; 3]; 16];
    for (t, o) in out.iter_mut().enumerate() {
        *o = p[((bits >> (2 * t)) & 3) as usize];
    }
    out
}

/// Encode a `width`x`height` image (both multiples of 4) whose texel (x, y) is `texel(y, x)`
/// into BC1 blocks in row-major block order. Block rows are encoded in parallel; the output
/// does not depend on the thread count (each block is encoded independently).
pub fn encode_image(
    width: usize,
    height: usize,
    texel: impl Fn(usize, usize) -> [u8; 3] + Sync,
) -> Vec<u8> {
    assert!(
        width.is_multiple_of(4) && height.is_multiple_of(4),
        "BC1 image size must be a multiple of 4"
    );
    let bw = width / 4;
    let mut out = vec![0u8; bw * (height / 4) * BLOCK_BYTES];
    if out.is_empty() {
        return out;
    }
    out.par_chunks_mut(bw * BLOCK_BYTES)
        .enumerate()
        .for_each_init(
            || vec![0u8; width * 4 * 4],
            |rgba, (by, dst)| {
                for y in 0..4 {
                    for x in 0..width {
                        let [r, g, b] = texel(4 * by + y, x);
                        let o = (y * width + x) * 4;
                        rgba[o..o + 4].copy_from_slice(&[r, g, b, 255]);
                    }
                }
                encode_strip(rgba, width, dst);
            },
        );
    out
}

/// Encode one strip of 4 rows (`rgba` is 4·width RGBA8 texels) into `width/4` blocks.
pub fn encode_strip(rgba: &[u8], width: usize, dst: &mut [u8]) {
    let surface = intel_tex_2::RgbaSurface {
        data: rgba,
        width: width as u32,
        height: 4,
        stride: width as u32 * 4,
    };
    intel_tex_2::bc1::compress_blocks_into(&surface, dst);
}

/// Decode a whole BC1 image to RGB8 (row-major, 3 bytes per texel).
pub fn decode_image(width: usize, height: usize, blocks: &[u8]) -> Vec<u8> {
    let bw = width / 4;
    let mut out = vec![0u8; width * height * 3];
    for by in 0..height / 4 {
        for bx in 0..bw {
            let k = (by * bw + bx) * BLOCK_BYTES;
            let texels = decode_block(&blocks[k..k + BLOCK_BYTES]);
            for (t, rgb) in texels.iter().enumerate() {
                let (y, x) = (4 * by + t / 4, 4 * bx + t % 4);
                out[(y * width + x) * 3..(y * width + x) * 3 + 3].copy_from_slice(rgb);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_colour_block_decodes_by_the_spec() {
        // c0 = pure red (31,0,0) = 0xF800, c1 = blue (0,0,31) = 0x001F; c0 > c1: four colours.
        let mut b = [0u8; 8];
        b[0..2].copy_from_slice(&0xF800u16.to_le_bytes());
        b[2..4].copy_from_slice(&0x001Fu16.to_le_bytes());
        // texel t gets index t % 4.
        let bits: u32 = (0..16).map(|t| ((t % 4) as u32) << (2 * t)).sum();
        b[4..8].copy_from_slice(&bits.to_le_bytes());
        let d = decode_block(&b);
        assert_eq!(d[0], [255, 0, 0]);
        assert_eq!(d[1], [0, 0, 255]);
        assert_eq!(d[2], [170, 0, 85]);
        assert_eq!(d[3], [85, 0, 170]);
    }

    #[test]
    fn three_colour_block_has_black() {
        let mut b = [0u8; 8];
        b[0..2].copy_from_slice(&0x0010u16.to_le_bytes());
        b[2..4].copy_from_slice(&0x0011u16.to_le_bytes());
        b[4..8].copy_from_slice(&0xFFFF_FFFFu32.to_le_bytes());
        assert_eq!(decode_block(&b)[5], [0, 0, 0]);
        b[4..8].copy_from_slice(&0xAAAA_AAAAu32.to_le_bytes());
        // (16·8+4, ...) mean of blue 16 → 132 and 17 → 140: 136.
        assert_eq!(decode_block(&b)[0], [0, 0, 136]);
    }

    #[test]
    fn flat_colour_round_trips_within_endpoint_precision() {
        let img = encode_image(8, 4, |_, _| [200, 100, 50]);
        let dec = decode_image(8, 4, &img);
        for t in dec.chunks(3) {
            assert!((t[0] as i32 - 200).abs() <= 4, "{t:?}");
            assert!((t[1] as i32 - 100).abs() <= 2, "{t:?}");
            assert!((t[2] as i32 - 50).abs() <= 4, "{t:?}");
        }
    }

    #[test]
    fn zero_image_decodes_to_zero() {
        let img = encode_image(12, 8, |_, _| [0, 0, 0]);
        assert!(decode_image(12, 8, &img).iter().all(|&v| v == 0));
    }
}
