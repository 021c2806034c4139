//! Soft shadows by uniform stepping (the soft-shadow paper's baseline, Jung et al. 2020 §2/§6.3: 100 fixed
//! steps): `steps` bilinear samples at t_i = (i + ½)·L/steps along the track, where L is the
//! distance to the map's border or, when shorter, to where a flat ray at e_P − α clears the
//! map's highest point (beyond it nothing can dim the disc: "the ray leaves the terrain
//! volume"). Samples between texels can miss thin features — that is the baseline's error.

use crate::heightmap::HeightMap;
use crate::terrain::hard::exact_traversal::sample_bilinear;
use crate::terrain::soft::model::{slope, PixelSun};
use crate::terrain::sun::Track;

/// The t at which the track from (px, py) leaves the map.
#[inline]
pub fn map_exit_time(track: &Track, px: f64, py: f64, width: usize, height: usize) -> f64 {
    let tx = match track.step_x {
        1 => Track::crossing(px, width as i64, track.inv_ux),
        -1 => Track::crossing(px, 0, track.inv_ux),
        _ => f64::INFINITY,
    };
    let ty = match track.step_y {
        1 => Track::crossing(py, height as i64, track.inv_uy),
        -1 => Track::crossing(py, 0, track.inv_uy),
        _ => f64::INFINITY,
    };
    tx.min(ty)
}

/// Lit fraction of the pixel at (col, row) with `steps` uniform samples; `hmax` = the map's
/// maximum height.
pub fn lit_uniform(
    map: &HeightMap,
    track: &Track,
    ps: &PixelSun,
    col: usize,
    row: usize,
    steps: u32,
    hmax: f32,
) -> f32 {
    if let Some(v) = ps.settled() {
        return v;
    }
    let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
    let m = track.metres_per_t;
    let mut len = map_exit_time(track, px, py, map.width, map.height);
    if ps.slope_lit > 0.0 {
        len = len.min((hmax as f64 - ps.zp).max(0.0) / ps.slope_lit / m);
    }
    let dt = len / steps.max(1) as f64;
    let mut best = ps.best_init;
    for i in 0..steps {
        let t = (i as f64 + 0.5) * dt;
        let hq = sample_bilinear(
            &map.heights,
            map.width,
            map.height,
            px + track.ux * t,
            py + track.uy * t,
        );
        let s = slope(hq, ps.zp, m * t, ps.radius);
        if s > best {
            best = s;
            if best >= ps.slope_dark {
                return 0.0;
            }
        }
    }
    ps.lit_fraction(best)
}
