//! Per-block decoding of the dense texture: the CPU twin of the WGSL decoders in
//! `shaders/gather_compressed.wgsl` (BC1, BC4, BC6H, F16, F32).

use super::dense::{BlockValues, DenseEncoding, DenseTexture};
use super::logmap::LogMap;
use super::{bc1, bc4, bc6h};

/// Decoding tables of a texture (built once per gather).
pub struct Decoder<'a> {
    tex: &'a DenseTexture,
    layers: Vec<&'a [u8]>,
    luts: Vec<[f32; 256]>,
}

impl DenseTexture {
    /// Decoding tables for [`Decoder::block`].
    pub fn decoder(&self) -> Decoder<'_> {
        Decoder {
            tex: self,
            layers: self.layers.iter().map(Vec::as_slice).collect(),
            luts: self.maps.iter().map(LogMap::lut).collect(),
        }
    }
}

impl Decoder<'_> {
    /// Linear values of block (by, bx), channels beyond `channels` left zero.
    #[inline]
    pub fn block(&self, by: usize, bx: usize, out: &mut BlockValues) {
        let t = self.tex;
        let bw = t.padded / 4;
        decode_block_at(
            t.encoding,
            t.channels,
            &t.maps,
            &self.luts,
            &self.layers,
            bw,
            by,
            bx,
            out,
        );
    }
}

/// Decode block (by, bx) of layers whose rows are `bw` blocks wide (block encodings) or
/// `4·bw` texels wide (F16, F32). A plain function: the WGSL gather ports this.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn decode_block_at(
    encoding: DenseEncoding,
    channels: usize,
    maps: &[LogMap],
    luts: &[[f32; 256]],
    layers: &[&[u8]],
    bw: usize,
    by: usize,
    bx: usize,
    out: &mut BlockValues,
) {
    let bb = encoding.block_bytes();
    let k = (by * bw + bx) * bb;
    match encoding {
        DenseEncoding::Bc1Log => {
            let texels = bc1::decode_block(&layers[0][k..k + bb]);
            if channels == 1 {
                for t in 0..16 {
                    out[0][t] = luts[0][texels[t][1] as usize];
                }
            } else {
                for t in 0..16 {
                    for c in 0..3 {
                        out[c][t] = luts[c][texels[t][c] as usize];
                    }
                }
            }
        }
        DenseEncoding::Bc4Log => {
            for c in 0..channels {
                let blk = &layers[c][k..k + bb];
                let pal = bc4::bc4_palette(blk);
                let mut vals = [0.0f32; 8];
                for (v, p) in vals.iter_mut().zip(pal) {
                    *v = maps[c].decode_real(p);
                }
                let idx = bc4::bc4_indices(blk);
                for t in 0..16 {
                    out[c][t] = vals[idx[t] as usize];
                }
            }
        }
        DenseEncoding::Bc6h => {
            let texels = bc6h::bc6h_decode_block(&layers[0][k..k + bb]);
            let src = if channels == 1 { 1 } else { 0 };
            for c in 0..channels {
                for t in 0..16 {
                    out[c][t] = texels[t][if channels == 1 { src } else { c }] * maps[c].scale;
                }
            }
        }
        DenseEncoding::F16 | DenseEncoding::F32 => {
            let w = 4 * bw;
            let size = if encoding == DenseEncoding::F16 { 2 } else { 4 };
            for c in 0..channels {
                for y in 0..4 {
                    let o = ((4 * by + y) * w + 4 * bx) * size;
                    let row = &layers[c][o..o + 4 * size];
                    for x in 0..4 {
                        let v = if size == 2 {
                            half::f16::from_le_bytes([row[2 * x], row[2 * x + 1]]).to_f32()
                        } else {
                            f32::from_le_bytes(row[4 * x..4 * x + 4].try_into().unwrap())
                        };
                        out[c][4 * y + x] = v * maps[c].scale;
                    }
                }
            }
        }
    }
}
