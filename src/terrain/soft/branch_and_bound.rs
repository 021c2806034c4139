//! Soft shadows, exact and fast: branch-and-bound over the min/max mipmap (beyond the soft-shadow paper).
//!
//! The traversal of [`crate::terrain::hard::accelerated_traversal`] with a continuous criterion: the
//! state is the exact traversal's texel and entry time plus a level; a block is skipped when the
//! upper bound of the slope of anything it holds ([`slope_upper_bound`] from its max/min height
//! and the distances at the current entry and the block's exit) is at most the best slope found
//! so far — starting from max(0, tan(e_P − α)), so blocks that could only dim a disc that is
//! already fully visible are skipped too; otherwise it descends; at the texel level it takes
//! the exhaustive method's sample. It stops when the disc is fully hidden or nothing left can
//! beat `best` ([`beyond_reach`]). Skipped blocks hold no sample above `best`, so the maximum —
//! and the lit fraction — equals the exhaustive one (up to the rounding of the bounds, far below
//! 1e-9 in lit fraction). No recursion, no allocation; the loop is bounded like A2's.

use crate::heightmap::HeightMap;
use crate::terrain::hard::accelerated_traversal::{block_exit_time, texel_after_block};
use crate::terrain::hard::exact_traversal::texel_sample;
use crate::terrain::minmax_mipmap::MinMaxMipmap;
use crate::terrain::soft::model::{beyond_reach, slope, slope_upper_bound, PixelSun};
use crate::terrain::sun::Track;

/// Lit fraction of the pixel at (col, row) over `mip` (built from `map`).
pub fn lit_branch_and_bound(
    map: &HeightMap,
    mip: &MinMaxMipmap,
    track: &Track,
    ps: &PixelSun,
    col: usize,
    row: usize,
) -> f32 {
    if let Some(v) = ps.settled() {
        return v;
    }
    let (w, h) = (map.width as i64, map.height as i64);
    let (sx, sy) = (track.step_x, track.step_y);
    let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
    let (hmax, hmin) = (mip.max_height as f64, mip.min_height as f64);
    let m = track.metres_per_t;
    let top = mip.levels.len() as i64 - 1;
    let mut level = -1i64;
    let (mut ix, mut iy) = (col as i64, row as i64);
    let mut t_in = 0.0f64;
    let mut best = ps.best_init;
    let max_iterations = (w + h + 1) * (top + 3);
    for _ in 0..max_iterations {
        if level < 0 {
            let tx = Track::exit_time(px, ix, sx, track.inv_ux);
            let ty = Track::exit_time(py, iy, sy, track.inv_uy);
            let t_out = tx.min(ty);
            let (t_mid, hq) = texel_sample(map, track, [px, py], [ix, iy], t_in, t_out);
            let s = slope(hq, ps.zp, m * t_mid, ps.radius);
            if s > best {
                best = s;
                if best >= ps.slope_dark {
                    return 0.0;
                }
            }
            if tx <= ty {
                ix += sx;
            }
            if ty <= tx {
                iy += sy;
            }
            t_in = t_out;
            level = 0;
        } else {
            let shift = level + 1;
            let (bx, by) = (ix >> shift, iy >> shift);
            let (bmax, bmin) = mip.texel(level as usize, bx as usize, by as usize);
            let txb = block_exit_time(px, bx, shift, sx, track.inv_ux);
            let tyb = block_exit_time(py, by, shift, sy, track.inv_uy);
            let t_exit = txb.min(tyb);
            let ub = slope_upper_bound(
                bmax as f64,
                bmin as f64,
                ps.zp,
                m * t_in,
                m * t_exit,
                ps.radius,
            );
            if ub > best {
                level -= 1;
                continue;
            }
            [ix, iy] = texel_after_block(track, [px, py], [ix, iy], [bx, by], shift, [txb, tyb]);
            t_in = t_exit;
            if level < top {
                level += 1;
            }
        }
        if ix < 0
            || iy < 0
            || ix >= w
            || iy >= h
            || beyond_reach(hmax, hmin, ps.zp, m * t_in, ps.radius, best)
        {
            break;
        }
    }
    ps.lit_fraction(best)
}
