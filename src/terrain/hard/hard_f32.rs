//! f32 twins of the hard-shadow kernels: [`shadowed_exact`] and [`shadowed_accelerated`] line
//! for line in single precision, as a GPU (WGSL) port evaluates them. They show that the f32
//! evaluation is well-defined — the integer stepping, the loop bounds and the monotonicity
//! argument that makes A2 equal A1 do not depend on the precision (tests: the two f32 kernels
//! agree on every pixel) — and measure how far f32 moves from the f64 reference: only pixels
//! whose deciding sample is within f32 rounding of the sun ray flip. f32 positions near x ≈ 1000
//! carry ~6e-5 texel of error, millimetres of height on steep slopes: measured 3 pixels in
//! 10,000 on the half-size SRTM map and fewer on Puget Sound (`tests/terrain/f32.rs`). A WGSL
//! port should match these twins up to its own rounding of division and conversions.
//!
//! Inputs: the f64 [`Track`] rounded to f32 ([`TrackF32`]), the same flat arrays.
//!
//! [`shadowed_exact`]: crate::terrain::hard::exact_traversal::shadowed_exact
//! [`shadowed_accelerated`]: crate::terrain::hard::accelerated_traversal::shadowed_accelerated

use crate::heightmap::HeightMap;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::sun::{Track, TrackKind};

/// The per-sun uniforms in f32 (what the GPU receives).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackF32 {
    pub kind: TrackKind,
    pub ux: f32,
    pub uy: f32,
    pub step_x: i32,
    pub step_y: i32,
    pub inv_ux: f32,
    pub inv_uy: f32,
    pub rise_per_t: f32,
}

impl From<&Track> for TrackF32 {
    fn from(t: &Track) -> Self {
        TrackF32 {
            kind: t.kind,
            ux: t.ux as f32,
            uy: t.uy as f32,
            step_x: t.step_x as i32,
            step_y: t.step_y as i32,
            inv_ux: t.inv_ux as f32,
            inv_uy: t.inv_uy as f32,
            rise_per_t: t.rise_per_t as f32,
        }
    }
}

#[inline]
fn exit_time(p: f32, c: i32, step: i32, inv_u: f32) -> f32 {
    if step > 0 {
        ((c + 1) as f32 - p) * inv_u
    } else if step < 0 {
        (c as f32 - p) * inv_u
    } else {
        f32::INFINITY
    }
}

#[inline]
fn entry_time(p: f32, c: i32, step: i32, inv_u: f32) -> f32 {
    if step > 0 {
        (c as f32 - p) * inv_u
    } else if step < 0 {
        ((c + 1) as f32 - p) * inv_u
    } else {
        f32::NEG_INFINITY
    }
}

#[inline]
fn block_exit_time(p: f32, b: i32, shift: i32, step: i32, inv_u: f32) -> f32 {
    if step > 0 {
        (((b + 1) << shift) as f32 - p) * inv_u
    } else if step < 0 {
        ((b << shift) as f32 - p) * inv_u
    } else {
        f32::INFINITY
    }
}

/// Bilinear height, clamped to its four texels' range (f32 twin of `sample_bilinear`).
#[inline]
pub fn sample_bilinear_f32(heights: &[f32], width: usize, height: usize, qx: f32, qy: f32) -> f32 {
    let fx = (qx - 0.5).clamp(0.0, (width - 1) as f32);
    let fy = (qy - 0.5).clamp(0.0, (height - 1) as f32);
    let x0 = (fx as usize).min(width - 1);
    let y0 = (fy as usize).min(height - 1);
    let x1 = (x0 + 1).min(width - 1);
    let y1 = (y0 + 1).min(height - 1);
    let tx = fx - x0 as f32;
    let ty = fy - y0 as f32;
    let a = heights[y0 * width + x0];
    let b = heights[y0 * width + x1];
    let c = heights[y1 * width + x0];
    let d = heights[y1 * width + x1];
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    let v = top + (bottom - top) * ty;
    v.clamp(a.min(b).min(c.min(d)), a.max(b).max(c.max(d)))
}

#[inline]
fn texel_sample(
    map: &HeightMap,
    tr: &TrackF32,
    p: [f32; 2],
    c: [i32; 2],
    t_in: f32,
    t_out: f32,
) -> (f32, f32) {
    let t_mid = 0.5 * (t_in + t_out);
    let qx = (p[0] + tr.ux * t_mid).clamp(c[0] as f32, (c[0] + 1) as f32);
    let qy = (p[1] + tr.uy * t_mid).clamp(c[1] as f32, (c[1] + 1) as f32);
    (
        t_mid,
        sample_bilinear_f32(&map.heights, map.width, map.height, qx, qy),
    )
}

/// f32 twin of `shadowed_exact` (`stop_height` = the map's maximum or +∞).
pub fn shadowed_exact_f32(
    map: &HeightMap,
    tr: &TrackF32,
    col: usize,
    row: usize,
    stop_height: f32,
) -> bool {
    match tr.kind {
        TrackKind::Zenith => return false,
        TrackKind::BelowHorizon => return true,
        TrackKind::Ray => {}
    }
    let (w, h) = (map.width as i32, map.height as i32);
    let p = [col as f32 + 0.5, row as f32 + 0.5];
    let zp = map.heights[row * map.width + col];
    let headroom = stop_height - zp;
    let (mut ix, mut iy) = (col as i32, row as i32);
    let mut t_in = 0.0f32;
    let mut tx = exit_time(p[0], ix, tr.step_x, tr.inv_ux);
    let mut ty = exit_time(p[1], iy, tr.step_y, tr.inv_uy);
    for _ in 0..(w + h) {
        let t_out = tx.min(ty);
        let (t_mid, hq) = texel_sample(map, tr, p, [ix, iy], t_in, t_out);
        if hq - zp > tr.rise_per_t * t_mid {
            return true;
        }
        let (step_x, step_y) = (tx <= ty, ty <= tx);
        if step_x {
            ix += tr.step_x;
            tx = exit_time(p[0], ix, tr.step_x, tr.inv_ux);
        }
        if step_y {
            iy += tr.step_y;
            ty = exit_time(p[1], iy, tr.step_y, tr.inv_uy);
        }
        t_in = t_out;
        if ix < 0 || iy < 0 || ix >= w || iy >= h || tr.rise_per_t * t_in >= headroom {
            return false;
        }
    }
    false
}

#[inline]
fn coordinate_after(p: f32, u: f32, step: i32, inv_u: f32, t: f32, from: i32, last: i32) -> i32 {
    if step == 0 {
        return from;
    }
    let x = p + u * t;
    let estimate = x.floor() as i32;
    let mut c = if step > 0 {
        estimate.clamp(from, last)
    } else {
        estimate.clamp(last, from)
    };
    while c != last && exit_time(p, c, step, inv_u) <= t {
        c += step;
    }
    while c != from && entry_time(p, c, step, inv_u) > t {
        c -= step;
    }
    c
}

/// f32 twin of `shadowed_accelerated`.
pub fn shadowed_accelerated_f32(
    map: &HeightMap,
    mip: &MinMaxMipmap,
    tr: &TrackF32,
    col: usize,
    row: usize,
) -> bool {
    match tr.kind {
        TrackKind::Zenith => return false,
        TrackKind::BelowHorizon => return true,
        TrackKind::Ray => {}
    }
    let (w, h) = (map.width as i32, map.height as i32);
    let (sx, sy) = (tr.step_x, tr.step_y);
    let p = [col as f32 + 0.5, row as f32 + 0.5];
    let zp = map.heights[row * map.width + col];
    let rise = tr.rise_per_t;
    let top = mip.levels.len() as i32 - 1;
    let headroom = mip.max_height - zp;
    let mut level = -1i32;
    let (mut ix, mut iy) = (col as i32, row as i32);
    let mut t_in = 0.0f32;
    for _ in 0..(w + h + 1) * (top + 3) {
        if level < 0 {
            let tx = exit_time(p[0], ix, sx, tr.inv_ux);
            let ty = exit_time(p[1], iy, sy, tr.inv_uy);
            let t_out = tx.min(ty);
            let (t_mid, hq) = texel_sample(map, tr, p, [ix, iy], t_in, t_out);
            if hq - zp > rise * t_mid {
                return true;
            }
            if tx <= ty {
                ix += sx;
            }
            if ty <= tx {
                iy += sy;
            }
            t_in = t_out;
            if ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom {
                return false;
            }
            level = 0;
            continue;
        }
        let shift = level + 1;
        let (bx, by) = (ix >> shift, iy >> shift);
        let (bmax, bmin) = mip.texel(level as usize, bx as usize, by as usize);
        let txb = block_exit_time(p[0], bx, shift, sx, tr.inv_ux);
        let tyb = block_exit_time(p[1], by, shift, sy, tr.inv_uy);
        let t_exit = txb.min(tyb);
        if bmax - zp <= rise * t_in {
            let last_x = if sx > 0 {
                ((bx + 1) << shift) - 1
            } else {
                bx << shift
            };
            let last_y = if sy > 0 {
                ((by + 1) << shift) - 1
            } else {
                by << shift
            };
            let nx = if txb <= tyb {
                last_x + sx
            } else {
                coordinate_after(p[0], tr.ux, sx, tr.inv_ux, t_exit, ix, last_x)
            };
            let ny = if tyb <= txb {
                last_y + sy
            } else {
                coordinate_after(p[1], tr.uy, sy, tr.inv_uy, t_exit, iy, last_y)
            };
            ix = nx;
            iy = ny;
            t_in = t_exit;
            if ix < 0 || iy < 0 || ix >= w || iy >= h || rise * t_in >= headroom {
                return false;
            }
            if level < top {
                level += 1;
            }
        } else if bmin - zp > rise * t_exit {
            return true;
        } else {
            level -= 1;
        }
    }
    false
}
