//! Exact relief-shadow traversal: algorithm A1 of the relief-shadow paper (Timokhin & Mikhaylyuk 2021, §4),
//! the reference every faster method is compared with.
//!
//! A pixel P (texel centre p = (col + ½, row + ½), height z_P = its texel's height) is in shadow
//! when some texel T on the sun's track from p has a sample height above the sun ray:
//!
//! ```text
//!     h(Q_T) − z_P  >  rise_per_t · t_T          (strict: touching the ray is lit)
//! ```
//!
//! where t_T = (t_in + t_out)/2 is the midpoint of the track's transit through T (the relief-shadow paper's
//! "two transit points") and Q_T = p + u·t_T, clamped into T's square, is sampled bilinearly
//! ([`sample_bilinear`]). The start texel (P's own) is tested too, so a plane facing away from
//! the sun more steeply than the sun's elevation shadows itself.
//!
//! Stepping is by integers: from texel (ix, iy) the track leaves through the x grid line at
//! time `tx` or the y grid line at `ty` ([`Track::exit_time`]); the smaller wins, a tie steps
//! diagonally (the track passes exactly through the corner, touching the side texels in a
//! single point only). Every step moves ix or iy one texel forward, so a track leaves a W×H map
//! after at most W + H steps, whatever the floating point does; the loop is also bounded by
//! that count explicitly. Event times are computed from the fixed texel-centre start
//! (`(boundary − p)·(1/u)`), never accumulated, so the accelerated traversal can reproduce them
//! bit for bit.
//!
//! Special suns ([`TrackKind`]): at the zenith nothing shadows; at or below the horizon
//! everything is shadowed.
//!
//! Precision: positions, times and the comparison are f64 (heights are f32 converted exactly).
//! An f32 port (the GPU) runs the same comparisons in f32; it agrees except for pixels whose
//! deciding sample lies within rounding error of the sun ray.

use crate::heightmap::HeightMap;
use crate::terrain::sun::{Track, TrackKind};

/// Bilinear height at texel-space (qx, qy) from flat row-major `heights[row * width + col]`
/// (texel centres at half-integers, clamped at the border, as [`HeightMap::bilinear`]), with
/// the result clamped to [min, max] of its four texels so that rounding can never leave that
/// range (the min/max mipmap relies on it).
#[inline]
pub fn sample_bilinear(heights: &[f32], width: usize, height: usize, qx: f64, qy: f64) -> f64 {
    let fx = (qx - 0.5).clamp(0.0, (width - 1) as f64);
    let fy = (qy - 0.5).clamp(0.0, (height - 1) as f64);
    let x0 = (fx as usize).min(width - 1);
    let y0 = (fy as usize).min(height - 1);
    let x1 = (x0 + 1).min(width - 1);
    let y1 = (y0 + 1).min(height - 1);
    let tx = fx - x0 as f64;
    let ty = fy - y0 as f64;
    let a = heights[y0 * width + x0] as f64;
    let b = heights[y0 * width + x1] as f64;
    let c = heights[y1 * width + x0] as f64;
    let d = heights[y1 * width + x1] as f64;
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
    let v = top + (bottom - top) * ty;
    let lo = a.min(b).min(c.min(d));
    let hi = a.max(b).max(c.max(d));
    v.clamp(lo, hi)
}

/// The sample of texel [ix, iy] on the track from [px, py] between times t_in and t_out:
/// returns (t_mid, height at Q clamped into the texel's square).
#[inline]
pub fn texel_sample(
    map: &HeightMap,
    track: &Track,
    [px, py]: [f64; 2],
    [ix, iy]: [i64; 2],
    t_in: f64,
    t_out: f64,
) -> (f64, f64) {
    let t_mid = 0.5 * (t_in + t_out);
    let qx = (px + track.ux * t_mid).clamp(ix as f64, (ix + 1) as f64);
    let qy = (py + track.uy * t_mid).clamp(iy as f64, (iy + 1) as f64);
    let h = sample_bilinear(&map.heights, map.width, map.height, qx, qy);
    (t_mid, h)
}

/// Is the pixel at (col, row) in shadow? Exact traversal A1.
///
/// `stop_height` is an upper bound of every height in the map (its maximum, or +∞ to disable):
/// once the sun ray at the current texel's entry is at or above it (`rise·t_in ≥ stop − z_P`),
/// no later sample can be above the ray and the traversal stops early. The answer does not
/// depend on it.
pub fn shadowed_exact(
    map: &HeightMap,
    track: &Track,
    col: usize,
    row: usize,
    stop_height: f32,
) -> bool {
    match track.kind {
        TrackKind::Zenith => return false,
        TrackKind::BelowHorizon => return true,
        TrackKind::Ray => {}
    }
    let (w, h) = (map.width as i64, map.height as i64);
    let px = col as f64 + 0.5;
    let py = row as f64 + 0.5;
    let zp = map.heights[row * map.width + col] as f64;
    let headroom = stop_height as f64 - zp;
    let (mut ix, mut iy) = (col as i64, row as i64);
    let mut t_in = 0.0f64;
    // Exit times of the current column and row, recomputed (same expression) when they change.
    let mut tx = Track::exit_time(px, ix, track.step_x, track.inv_ux);
    let mut ty = Track::exit_time(py, iy, track.step_y, track.inv_uy);
    for _ in 0..(w + h) {
        let t_out = tx.min(ty);
        let (t_mid, hq) = texel_sample(map, track, [px, py], [ix, iy], t_in, t_out);
        if hq - zp > track.rise_per_t * t_mid {
            return true;
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
        if ix < 0 || iy < 0 || ix >= w || iy >= h || track.rise_per_t * t_in >= headroom {
            return false;
        }
    }
    false
}

/// One texel of a track with its transit times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transit {
    pub ix: i64,
    pub iy: i64,
    pub t_in: f64,
    pub t_out: f64,
}

/// The texels the exact traversal visits from (col, row), in order, with their transits:
/// [`shadowed_exact`]'s stepping (the same expressions, the same W + H bound), as an iterator
/// that allocates nothing, whatever the sun's elevation (the soft-shadow reference walks below
/// the horizon too) — for the kernels that keep more than a yes/no along the track
/// (horizons, the soft-shadow reference, the sweep's near walks).
#[derive(Clone, Debug)]
pub struct TrackWalk<'a> {
    track: &'a Track,
    p: [f64; 2],
    size: [i64; 2],
    ix: i64,
    iy: i64,
    t_in: f64,
    tx: f64,
    ty: f64,
    left: i64,
}

impl<'a> TrackWalk<'a> {
    pub fn new(map: &HeightMap, track: &'a Track, col: usize, row: usize) -> TrackWalk<'a> {
        let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
        let (ix, iy) = (col as i64, row as i64);
        let size = [map.width as i64, map.height as i64];
        TrackWalk {
            track,
            p: [px, py],
            size,
            ix,
            iy,
            t_in: 0.0,
            tx: Track::exit_time(px, ix, track.step_x, track.inv_ux),
            ty: Track::exit_time(py, iy, track.step_y, track.inv_uy),
            left: if track.kind == TrackKind::Ray {
                size[0] + size[1]
            } else {
                0
            },
        }
    }

    /// The pixel centre the track starts from.
    pub fn start(&self) -> [f64; 2] {
        self.p
    }

    /// The texel the walk stands at (the next one it yields).
    pub fn current(&self) -> (i64, i64) {
        (self.ix, self.iy)
    }
}

impl Iterator for TrackWalk<'_> {
    type Item = Transit;

    #[inline]
    fn next(&mut self) -> Option<Transit> {
        let inside =
            self.ix >= 0 && self.iy >= 0 && self.ix < self.size[0] && self.iy < self.size[1];
        if self.left <= 0 || !inside {
            return None;
        }
        self.left -= 1;
        let t = self.track;
        let t_out = self.tx.min(self.ty);
        let out = Transit {
            ix: self.ix,
            iy: self.iy,
            t_in: self.t_in,
            t_out,
        };
        let (step_x, step_y) = (self.tx <= self.ty, self.ty <= self.tx);
        if step_x {
            self.ix += t.step_x;
            self.tx = Track::exit_time(self.p[0], self.ix, t.step_x, t.inv_ux);
        }
        if step_y {
            self.iy += t.step_y;
            self.ty = Track::exit_time(self.p[1], self.iy, t.step_y, t.inv_uy);
        }
        self.t_in = t_out;
        Some(out)
    }
}

/// The texels the exact traversal visits from (col, row), in order, with their transit
/// times (t_in, t_out) — for tests and diagnostics (allocates; not a kernel).
pub fn track_texels(
    map: &HeightMap,
    track: &Track,
    col: usize,
    row: usize,
) -> Vec<(i64, i64, f64, f64)> {
    if track.kind != TrackKind::Ray {
        return Vec::new();
    }
    TrackWalk::new(map, track, col, row)
        .map(|t| (t.ix, t.iy, t.t_in, t.t_out))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::sun::Sun;

    fn flat(w: usize, h: usize) -> HeightMap {
        HeightMap::new(w, h, vec![0.0; w * h], [1.0, 1.0])
    }

    #[test]
    fn a_diagonal_track_steps_through_corners() {
        let map = flat(5, 5);
        // An exactly diagonal track (+1, +1)/√2 passes through the corners: diagonal steps.
        let mut track = Track::new(&Sun::new(135.0, 10.0).unwrap(), [1.0, 1.0]);
        track.uy = track.ux;
        track.inv_uy = track.inv_ux;
        let texels: Vec<(i64, i64)> = track_texels(&map, &track, 0, 0)
            .iter()
            .map(|t| (t.0, t.1))
            .collect();
        assert_eq!(texels, vec![(0, 0), (1, 1), (2, 2), (3, 3), (4, 4)]);
        // sin/cos make azimuth 135° one ulp off the diagonal: the track then touches the side
        // texels for a zero-length transit, and still ends in the corner.
        let track = Track::new(&Sun::new(135.0, 10.0).unwrap(), [1.0, 1.0]);
        let texels = track_texels(&map, &track, 0, 0);
        assert!(texels.iter().all(|t| (t.0 - t.1).abs() <= 1));
        assert_eq!((texels.last().unwrap().0, texels.last().unwrap().1), (4, 4));
    }

    #[test]
    fn a_shallow_track_visits_every_touched_texel() {
        let map = flat(8, 3);
        let track = Track::new(&Sun::new(70.0, 10.0).unwrap(), [1.0, 1.0]);
        let texels = track_texels(&map, &track, 0, 2);
        // Leaves through the top, consecutive texels are 4-neighbours, times are ordered.
        for w in texels.windows(2) {
            let (a, b) = (w[0], w[1]);
            assert_eq!((b.0 - a.0).abs() + (b.1 - a.1).abs(), 1);
            assert_eq!(a.3, b.2);
            assert!(a.2 < a.3);
        }
        assert_eq!(texels.last().unwrap().1, 0);
    }

    #[test]
    fn special_suns() {
        let map = flat(3, 3);
        let zenith = Track::new(&Sun::new(0.0, 90.0).unwrap(), [1.0, 1.0]);
        let below = Track::new(&Sun::new(0.0, 0.0).unwrap(), [1.0, 1.0]);
        assert!(!shadowed_exact(&map, &zenith, 1, 1, f32::INFINITY));
        assert!(shadowed_exact(&map, &below, 1, 1, f32::INFINITY));
    }

    #[test]
    fn a_wall_shadows_the_flat_ground_in_front() {
        // A 10 m wall at column 0; sun in the west (azimuth 270) at 45°: shadow 10 m long.
        let (w, h) = (30, 3);
        let mut heights = vec![0.0; w * h];
        for r in 0..h {
            heights[r * w] = 10.0;
        }
        let map = HeightMap::new(w, h, heights, [1.0, 1.0]);
        let track = Track::new(&Sun::new(270.0, 45.0).unwrap(), [1.0, 1.0]);
        let shadowed: Vec<bool> = (0..w)
            .map(|c| shadowed_exact(&map, &track, c, 1, 10.0))
            .collect();
        let last = shadowed.iter().rposition(|s| *s).unwrap();
        assert!((9..=10).contains(&last), "{shadowed:?}");
        assert!(!shadowed[0]);
    }
}
