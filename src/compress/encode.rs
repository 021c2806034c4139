//! Encoding the dense part into block textures: per-channel maps, strips of four rows in
//! parallel, optional error feedback along each block row (see `dense.rs` for the layout).

use super::decode::decode_block_at;
use super::dense::{DenseEncoding, DenseTexture, EncodeOptions};
use super::logmap::LogMap;
use super::{bc1, bc4, bc6h, Sidecar};
use crate::error::{Error, Result};
use crate::radiosity::TransportMatrix;
use rayon::prelude::*;

/// Per-channel maps for the dense part `m` (scale = the channel's largest value), the entries
/// in `holes` counting as zero.
pub fn channel_maps(
    m: &TransportMatrix,
    opts: &EncodeOptions,
    holes: Option<&Sidecar>,
) -> Vec<LogMap> {
    (0..m.channels)
        .map(|c| {
            let max = (0..m.n)
                .into_par_iter()
                .fold(
                    || 0.0f32,
                    |a, i| {
                        // The row's values between its holes, in order.
                        let row = m.row(c, i);
                        let holes = holes.map_or(&[][..], |h| h.row_cols(i));
                        let mut start = 0;
                        let mut a = a;
                        for &j in holes {
                            a = row[start..j as usize].iter().fold(a, |a, &b| a.max(b));
                            start = j as usize + 1;
                        }
                        row[start..].iter().fold(a, |a, &b| a.max(b))
                    },
                )
                .reduce(|| 0.0f32, f32::max);
            match opts.encoding {
                DenseEncoding::F32 => LogMap {
                    scale: 1.0,
                    range: opts.log_range,
                },
                _ => {
                    let mut map = LogMap::seed(max);
                    map.range = opts.log_range;
                    map
                }
            }
        })
        .collect()
}

/// Encode the dense part `m` (entries already split off are zero, or listed in `holes`).
/// Parallel over block rows; the output does not depend on the thread count.
///
/// `holes` (optional) marks entries whose dense value does not matter (they were moved to the
/// sidecar, which will hold the residual): they count as zero, are filled like padding and are
/// ignored by the error feedback. So `m` may be the whole matrix: the result is that of its
/// dense part with the holes zeroed, without that copy.
pub fn encode_dense(
    m: &TransportMatrix,
    opts: &EncodeOptions,
    holes: Option<&Sidecar>,
) -> Result<DenseTexture> {
    if !(opts.log_range.is_finite() && opts.log_range > 0.0) {
        return Err(Error::knob(format!(
            "log range {} must be a positive number",
            opts.log_range
        )));
    }
    let (n, ch) = (m.n, m.channels);
    let padded = 4 * n.div_ceil(4);
    let bw = padded / 4;
    let maps = channel_maps(m, opts, holes);
    let luts: Vec<[f32; 256]> = maps.iter().map(LogMap::lut).collect();
    let nl = DenseTexture::layer_count(opts.encoding, ch);
    let row_bytes = bw * opts.encoding.block_bytes();
    let rows: Vec<Vec<Vec<u8>>> = (0..bw)
        .into_par_iter()
        .map(|by| {
            let strip = Strip::gather(m, by, padded, holes);
            if opts.feedback {
                encode_row_feedback(&strip, opts.encoding, &maps, &luts, nl)
            } else {
                encode_strip(&strip.values, padded, ch, opts.encoding, &maps, nl)
            }
        })
        .collect();
    let mut layers = vec![Vec::with_capacity(row_bytes * bw); nl];
    for row in rows {
        for (l, part) in layers.iter_mut().zip(row) {
            l.extend_from_slice(&part);
        }
    }
    Ok(DenseTexture {
        encoding: opts.encoding,
        n,
        channels: ch,
        padded,
        maps,
        layers,
    })
}

/// Four rows of the matrix: `values[c][y·width + x]`, with a mask of the texels that matter.
/// Texels that do not matter — padding beyond `n`, and (with hole filling) the entries moved to
/// the sidecar — copy their nearest mattering neighbour in the row (or the row above), so they
/// never widen a block's range.
struct Strip {
    values: Vec<Vec<f32>>,
    care: Vec<bool>,
    width: usize,
    channels: usize,
}

impl Strip {
    fn gather(m: &TransportMatrix, by: usize, padded: usize, holes: Option<&Sidecar>) -> Strip {
        let (n, ch) = (m.n, m.channels);
        let mut care = vec![false; 4 * padded];
        for y in 0..4 {
            let i = 4 * by + y;
            if i < n {
                care[y * padded..y * padded + n].fill(true);
                if let Some(h) = holes {
                    for k in h.row_ptr[i] as usize..h.row_ptr[i + 1] as usize {
                        care[y * padded + h.cols[k] as usize] = false;
                    }
                }
            }
        }
        let values = (0..ch)
            .map(|c| {
                let mut v = vec![0.0f32; 4 * padded];
                for y in 0..4 {
                    let i = 4 * by + y;
                    if i < n {
                        v[y * padded..y * padded + n].copy_from_slice(m.row(c, i));
                        if let Some(h) = holes {
                            for &j in h.row_cols(i) {
                                v[y * padded + j as usize] = 0.0;
                            }
                        }
                    }
                    fill_row(
                        &mut v[y * padded..(y + 1) * padded],
                        &care[y * padded..(y + 1) * padded],
                    );
                    if y > 0 && !care[y * padded..(y + 1) * padded].iter().any(|&b| b) {
                        v.copy_within((y - 1) * padded..y * padded, y * padded);
                    }
                }
                v
            })
            .collect();
        Strip {
            values,
            care,
            width: padded,
            channels: ch,
        }
    }
}

/// Give every don't-care texel the value of the nearest texel that matters to its left (or,
/// at the start of the row, to its right).
fn fill_row(v: &mut [f32], care: &[bool]) {
    let Some(first) = care.iter().position(|&b| b) else {
        return;
    };
    let mut last = v[first];
    for x in 0..v.len() {
        if care[x] {
            last = v[x];
        } else {
            v[x] = last;
        }
    }
    let head = v[first];
    v[..first].fill(head);
}

/// Encode 4 rows of linear values (`values[c][y·width + x]`) into each layer's bytes.
fn encode_strip(
    values: &[Vec<f32>],
    width: usize,
    channels: usize,
    encoding: DenseEncoding,
    maps: &[LogMap],
    nl: usize,
) -> Vec<Vec<u8>> {
    let blocks_w = width / 4;
    let mut out: Vec<Vec<u8>> = vec![vec![0u8; blocks_w * encoding.block_bytes()]; nl];
    let src = |c: usize| if channels == 1 { 0 } else { c };
    match encoding {
        DenseEncoding::Bc1Log => {
            let mut rgba = vec![0u8; 4 * width * 4];
            for t in 0..4 * width {
                for c in 0..3 {
                    rgba[4 * t + c] = maps[src(c)].encode(values[src(c)][t]);
                }
                rgba[4 * t + 3] = 255;
            }
            bc1::encode_strip(&rgba, width, &mut out[0]);
        }
        DenseEncoding::Bc4Log => {
            for c in 0..channels {
                let r8: Vec<u8> = values[c].iter().map(|&v| maps[c].encode(v)).collect();
                bc4::bc4_encode_strip(&r8, width, &mut out[c]);
            }
        }
        DenseEncoding::Bc6h => {
            let mut rgba = vec![0u8; 4 * width * 8];
            for t in 0..4 * width {
                for c in 0..3 {
                    let map = &maps[src(c)];
                    let v = if map.scale > 0.0 {
                        (values[src(c)][t] / map.scale).max(0.0)
                    } else {
                        0.0
                    };
                    let h = half::f16::from_f32(v).to_le_bytes();
                    rgba[8 * t + 2 * c..8 * t + 2 * c + 2].copy_from_slice(&h);
                }
                let one = half::f16::ONE.to_le_bytes();
                rgba[8 * t + 6..8 * t + 8].copy_from_slice(&one);
            }
            bc6h::bc6h_encode_strip(&rgba, width, &mut out[0]);
        }
        DenseEncoding::F16 => {
            for c in 0..channels {
                let s = maps[c].scale;
                for (t, v) in values[c].iter().enumerate() {
                    let x = if s > 0.0 { v / s } else { 0.0 };
                    out[c][2 * t..2 * t + 2].copy_from_slice(&half::f16::from_f32(x).to_le_bytes());
                }
            }
        }
        DenseEncoding::F32 => {
            for c in 0..channels {
                for (t, v) in values[c].iter().enumerate() {
                    out[c][4 * t..4 * t + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
        }
    }
    out
}

/// Encode one block row left to right with error feedback (module doc).
fn encode_row_feedback(
    strip: &Strip,
    encoding: DenseEncoding,
    maps: &[LogMap],
    luts: &[[f32; 256]],
    nl: usize,
) -> Vec<Vec<u8>> {
    let (width, ch) = (strip.width, strip.channels);
    let bb = encoding.block_bytes();
    let mut out: Vec<Vec<u8>> = vec![Vec::with_capacity(width / 4 * bb); nl];
    let mut carry = [[0.0f64; 4]; 3];
    let mut target: Vec<Vec<f32>> = vec![vec![0.0; 16]; ch];
    let mut dec = [[0.0f32; 16]; 3];
    for bx in 0..width / 4 {
        for c in 0..ch {
            for y in 0..4 {
                let row = &strip.values[c][y * width + 4 * bx..y * width + 4 * bx + 4];
                let sum: f64 = row.iter().map(|&v| v.max(0.0) as f64).sum();
                let factor = if sum > 0.0 {
                    (1.0 + carry[c][y] / sum).clamp(0.5, 2.0)
                } else {
                    1.0
                };
                for x in 0..4 {
                    target[c][4 * y + x] = (row[x].max(0.0) as f64 * factor) as f32;
                }
            }
        }
        let enc = encode_strip(&target, 4, ch, encoding, maps, nl);
        let layers: Vec<&[u8]> = enc.iter().map(Vec::as_slice).collect();
        decode_block_at(encoding, ch, maps, luts, &layers, 1, 0, 0, &mut dec);
        for c in 0..ch {
            for y in 0..4 {
                for x in 0..4 {
                    let t = y * width + 4 * bx + x;
                    if strip.care[t] {
                        carry[c][y] += strip.values[c][t] as f64 - dec[c][4 * y + x] as f64;
                    }
                }
            }
        }
        for (o, e) in out.iter_mut().zip(&enc) {
            o.extend_from_slice(e);
        }
    }
    // F16/F32 store texels row-major: the per-block bytes above are 4x4 row-major blocks;
    // reorder them into 4 texel rows.
    if !encoding.is_block_compressed() {
        let size = bb / 16;
        for layer in out.iter_mut() {
            let mut rows = vec![0u8; layer.len()];
            for bx in 0..width / 4 {
                for y in 0..4 {
                    let src = bx * bb + y * 4 * size;
                    let dst = (y * width + 4 * bx) * size;
                    rows[dst..dst + 4 * size].copy_from_slice(&layer[src..src + 4 * size]);
                }
            }
            *layer = rows;
        }
    }
    out
}
