//! Soft shadows by the soft-shadow paper's dynamic programming over the max mipmap (Jung et al. 2020,
//! §3.2–3.3, Algorithm 1), adapted to relume's min/max mipmap and texel samples.
//!
//! The track is cut into intervals of length ℓ = B_s / max(|u_x|, |u_y|) — one texel of the
//! start level s (side B_s = 2^(s+1) height-map texels) along the dominant axis — laid end to end
//! from P ("long shadows by concatenating intervals"). In each interval the method descends from
//! level s to the texels: at every level it looks at the (up to three) blocks the interval's
//! footprint touches — all of them, not only the canonical DDA's — bounds the occluder slope in
//! each from the block's max height and its distance range, keeps the block with the largest
//! bound and narrows the interval to it; at the texel level it takes the exhaustive method's
//! samples of the touched texels. The best slope over all intervals gives the lit fraction. Cost
//! O(levels) per interval, so O(1) per pixel with a capped interval count. The greedy choice can
//! miss the true maximum (the paper's 1-D terrain assumption); the samples are a subset of the
//! exhaustive method's, so the answer is never darker than the exhaustive one. One pruning
//! that cannot change the answer is added: a descent stops when no block's bound beats the
//! best slope found so far.
//!
//! Knobs: `start_level` (clamped to the mipmap's top; −1 = texels) and `intervals` (0 = as many
//! as reach the map's border or where nothing can matter any more).

use crate::heightmap::HeightMap;
use crate::terrain::hard::exact_traversal::texel_sample;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::soft::model::{beyond_reach, slope, slope_upper_bound, PixelSun};
use crate::terrain::soft::uniform::map_exit_time;
use crate::terrain::sun::Track;

/// Entry and exit times of block `b` (side 1 << shift) on one axis.
#[inline]
fn block_times(p: f64, b: i64, shift: i64, step: i64, inv_u: f64) -> (f64, f64) {
    let lo = Track::crossing(p, b << shift, inv_u);
    let hi = Track::crossing(p, (b + 1) << shift, inv_u);
    match step {
        1 => (lo, hi),
        -1 => (hi, lo),
        _ => (f64::NEG_INFINITY, f64::INFINITY),
    }
}

/// floor(x) as an integer, without a libm call.
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    t - ((x < t as f64) as i64)
}

/// Lit fraction of the pixel at (col, row) by dynamic programming from `start_level`.
#[allow(clippy::too_many_arguments)]
pub fn lit_dynamic_programming(
    map: &HeightMap,
    mip: &MinMaxMipmap,
    track: &Track,
    ps: &PixelSun,
    col: usize,
    row: usize,
    start_level: i64,
    intervals: u32,
) -> f32 {
    if let Some(v) = ps.settled() {
        return v;
    }
    let (w, h) = (map.width as i64, map.height as i64);
    let (sx, sy) = (track.step_x, track.step_y);
    let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
    let (hmax, hmin) = (mip.max_height as f64, mip.min_height as f64);
    let m = track.metres_per_t;
    let start = start_level.clamp(-1, mip.levels.len() as i64 - 1);
    let ell = (1i64 << (start + 1)) as f64 / track.ux.abs().max(track.uy.abs());
    let t_end = map_exit_time(track, px, py, map.width, map.height);
    let needed = (t_end / ell).ceil().min(1e9) as u64;
    let count = if intervals == 0 {
        needed
    } else {
        needed.min(intervals as u64)
    };
    let mut best = ps.best_init;
    for k in 0..count {
        let a = k as f64 * ell;
        if beyond_reach(hmax, hmin, ps.zp, m * a, ps.radius, best) {
            break;
        }
        let (mut lo, mut hi) = (a, (a + ell).min(t_end));
        let mut level = start;
        while level >= -1 {
            let shift = level + 1;
            let (lw, lh) = if level >= 0 {
                let l = &mip.levels[level as usize];
                (l.width as i64, l.height as i64)
            } else {
                (w, h)
            };
            // The block the interval starts in (just inside it, so that a start on a grid line
            // picks the block ahead), then up to three more along the track.
            let t0 = lo + 1e-9 * (hi - lo);
            let mut bx = floor_i64(px + track.ux * t0) >> shift;
            let mut by = floor_i64(py + track.uy * t0) >> shift;
            // (bound, lo, hi) of the chosen block, and the largest bound of all blocks.
            let mut chosen = (f64::NEG_INFINITY, lo, hi);
            let mut bound = f64::NEG_INFINITY;
            for _ in 0..4 {
                if bx < 0 || by < 0 || bx >= lw || by >= lh {
                    break;
                }
                let (x_in, x_out) = block_times(px, bx, shift, sx, track.inv_ux);
                let (y_in, y_out) = block_times(py, by, shift, sy, track.inv_uy);
                let (b_in, b_out) = (lo.max(x_in).max(y_in), hi.min(x_out).min(y_out));
                // Blocks: any contact. Texels: a transit of positive length, exactly the texels
                // the exhaustive traversal visits (a track through a corner touches the side
                // texels in one point and does not visit them).
                if b_out > b_in || (level >= 0 && b_out == b_in) {
                    if level >= 0 {
                        let (bmax, bmin) = mip.texel(level as usize, bx as usize, by as usize);
                        let (hi_f, lo_f) = (bmax as f64, bmin as f64);
                        let ub =
                            slope_upper_bound(hi_f, lo_f, ps.zp, m * b_in, m * b_out, ps.radius);
                        bound = bound.max(ub);
                        // Keep the block whose bound is largest (the paper's "smallest cost";
                        // evaluating the max height at the middle of the block's stretch
                        // instead measured slightly worse on Puget Sound).
                        if ub > chosen.0 {
                            chosen = (ub, b_in, b_out);
                        }
                    } else {
                        // Texel level: the exhaustive sample of this texel (its whole transit).
                        let t_in = x_in.max(y_in).max(0.0);
                        let t_out = x_out.min(y_out);
                        let (t_mid, hq) = texel_sample(map, track, [px, py], [bx, by], t_in, t_out);
                        best = best.max(slope(hq, ps.zp, m * t_mid, ps.radius));
                    }
                }
                if x_out.min(y_out) >= hi {
                    break;
                }
                let (step_x, step_y) = (x_out <= y_out, y_out <= x_out);
                if step_x {
                    bx += sx;
                }
                if step_y {
                    by += sy;
                }
            }
            if level >= 0 {
                if chosen.0 == f64::NEG_INFINITY || bound <= best {
                    break; // nothing here can beat what we have
                }
                lo = chosen.1;
                hi = chosen.2;
            }
            level -= 1;
        }
        if best >= ps.slope_dark {
            return 0.0;
        }
    }
    ps.lit_fraction(best)
}
