//! Soft shadows, the reference: every texel on the track (the exact traversal's texels and
//! samples, see [`crate::terrain::hard::exact_traversal`]), the largest occluder slope over all of
//! them.
//!
//! Stops early only when the answer cannot change any more: the disc is fully hidden
//! (best ≥ slope_dark) or, with `early_stop`, no height of the map can exceed `best` from the
//! current distance on ([`beyond_reach`] with the map's maximum and minimum).

use crate::heightmap::HeightMap;
use crate::terrain::hard::exact_traversal::texel_sample;
use crate::terrain::soft::model::{beyond_reach, slope, PixelSun};
use crate::terrain::sun::Track;

/// Lit fraction of the pixel at (col, row). `range` = (max, min) height of the map.
pub fn lit_exhaustive(
    map: &HeightMap,
    track: &Track,
    ps: &PixelSun,
    col: usize,
    row: usize,
    range: (f32, f32),
    early_stop: bool,
) -> f32 {
    if let Some(v) = ps.settled() {
        return v;
    }
    let (w, h) = (map.width as i64, map.height as i64);
    let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
    let (hmax, hmin) = (range.0 as f64, range.1 as f64);
    let m = track.metres_per_t;
    let (mut ix, mut iy) = (col as i64, row as i64);
    let mut t_in = 0.0f64;
    let mut tx = Track::exit_time(px, ix, track.step_x, track.inv_ux);
    let mut ty = Track::exit_time(py, iy, track.step_y, track.inv_uy);
    let mut best = ps.best_init;
    for _ in 0..(w + h) {
        let t_out = tx.min(ty);
        let (t_mid, hq) = texel_sample(map, track, [px, py], [ix, iy], t_in, t_out);
        let s = slope(hq, ps.zp, m * t_mid, ps.radius);
        if s > best {
            best = s;
            if best >= ps.slope_dark {
                return 0.0;
            }
        }
        let (step_x, step_y) = (tx <= ty, ty <= tx);
        if step_x {
            ix += track.step_x;
            tx = Track::exit_time(px, ix, track.step_x, track.inv_ux);
        }
        if step_y {
            iy += track.step_y;
            ty = Track::exit_time(py, iy, track.step_y, track.inv_uy);
        }
        t_in = t_out;
        if ix < 0 || iy < 0 || ix >= w || iy >= h {
            break;
        }
        if early_stop && beyond_reach(hmax, hmin, ps.zp, m * t_in, ps.radius, best) {
            break;
        }
    }
    ps.lit_fraction(best)
}
