//! Soft shadows, the reference: every texel on the track (the exact traversal's texels and
//! samples, see [`crate::terrain::exact_traversal`]), the largest occluder slope over all of
//! them.
//!
//! Stops early only when the answer cannot change any more: the disc is fully hidden
//! (best ≥ slope_dark) or, with `early_stop`, no height of the map can exceed `best` from the
//! current distance on ([`beyond_reach`] with the map's maximum and minimum).

use super::model::{beyond_reach, slope, PixelSun};
use crate::heightmap::HeightMap;
use crate::terrain::exact_traversal::{texel_sample, TrackWalk};
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
    let (hmax, hmin) = (range.0 as f64, range.1 as f64);
    let m = track.metres_per_t;
    let walk = TrackWalk::new(map, track, col, row);
    let p = walk.start();
    let mut best = ps.best_init;
    for t in walk {
        if t.t_in > 0.0
            && early_stop
            && beyond_reach(hmax, hmin, ps.zp, m * t.t_in, ps.radius, best)
        {
            break;
        }
        let (t_mid, hq) = texel_sample(map, track, p, [t.ix, t.iy], t.t_in, t.t_out);
        let s = slope(hq, ps.zp, m * t_mid, ps.radius);
        if s > best {
            best = s;
            if best >= ps.slope_dark {
                return 0.0;
            }
        }
    }
    ps.lit_fraction(best)
}
