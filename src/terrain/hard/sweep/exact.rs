//! The certified sweep's exact per-pixel pieces ([`crate::terrain::hard::sweep`]): the walk of a track one
//! major-axis line at a time (the traversal's own stepping) and the witness test of one line's
//! texels with their exact transits. Both make only tests [`shadowed_exact`] makes, with its
//! numbers, so a `true` from either is the traversal's `true`.
//!
//! [`shadowed_exact`]: crate::terrain::hard::exact_traversal::shadowed_exact

use crate::heightmap::HeightMap;
use crate::terrain::hard::exact_traversal::{texel_sample, TrackWalk};
use crate::terrain::sun::Track;

/// The exact traversal's walk ([`TrackWalk`]: [`shadowed_exact`](crate::terrain::hard::exact_traversal::shadowed_exact)'s stepping), run one
/// major-axis line at a time.
pub struct Walk<'a> {
    map: &'a HeightMap,
    track: &'a Track,
    walk: TrackWalk<'a>,
    zp: f64,
    transposed: bool,
}

impl<'a> Walk<'a> {
    pub fn new(
        map: &'a HeightMap,
        track: &'a Track,
        col: usize,
        row: usize,
        transposed: bool,
    ) -> Self {
        Walk {
            map,
            track,
            walk: TrackWalk::new(map, track, col, row),
            zp: map.heights[row * map.width + col] as f64,
            transposed,
        }
    }

    /// Test the texels of the current major-axis line; `true` when one is above the ray.
    /// Afterwards the walk stands at the first texel of the next line (or has left the map).
    pub fn through_line(&mut self) -> bool {
        let major = |(x, y): (i64, i64)| if self.transposed { x } else { y };
        let line = major(self.walk.current());
        let p = self.walk.start();
        while major(self.walk.current()) == line {
            let Some(t) = self.walk.next() else {
                break;
            };
            let (t_mid, hq) = texel_sample(self.map, self.track, p, [t.ix, t.iy], t.t_in, t.t_out);
            if hq - self.zp > self.track.rise_per_t * t_mid {
                return true;
            }
        }
        false
    }
}

/// Does a texel of (col, row)'s track in the original row `line` (or column, `transposed`)
/// pass the exact test? Only texels the walking traversal visits are tested, with its exact
/// transit times, so `true` means [`shadowed_exact`](crate::terrain::hard::exact_traversal::shadowed_exact) is `true`.
pub fn witness(
    map: &HeightMap,
    track: &Track,
    col: usize,
    row: usize,
    line: i64,
    transposed: bool,
) -> bool {
    let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
    let zp = map.heights[row * map.width + col] as f64;
    // Major axis (the one `line` indexes) and minor axis, as (p, step, inv_u, u, start, size).
    let y_axis = (
        py,
        track.step_y,
        track.inv_uy,
        track.uy,
        row as i64,
        map.height as i64,
    );
    let x_axis = (
        px,
        track.step_x,
        track.inv_ux,
        track.ux,
        col as i64,
        map.width as i64,
    );
    let (major, minor) = if transposed {
        (x_axis, y_axis)
    } else {
        (y_axis, x_axis)
    };
    let entry = |a: (f64, i64, f64, f64, i64, i64), c: i64| {
        if c == a.4 {
            0.0
        } else {
            Track::entry_time(a.0, c, a.1, a.2)
        }
    };
    let exit = |a: (f64, i64, f64, f64, i64, i64), c: i64| Track::exit_time(a.0, c, a.1, a.2);
    let (ta, tb) = (entry(major, line), exit(major, line));
    if ta >= tb && line != major.4 {
        return false;
    }
    let (from, to) = if minor.1 == 0 {
        (minor.4, minor.4)
    } else {
        let (qa, qb) = (minor.0 + minor.3 * ta, minor.0 + minor.3 * tb);
        (
            (qa.min(qb).floor() as i64 - 1).max(0),
            (qa.max(qb).floor() as i64 + 1).min(minor.5 - 1),
        )
    };
    for c in from..=to {
        let t_in = entry(minor, c).max(ta).max(0.0);
        let t_out = exit(minor, c).min(tb);
        let start = c == minor.4 && line == major.4;
        if t_in >= t_out && !start {
            continue;
        }
        let texel = if transposed { [line, c] } else { [c, line] };
        let (t_mid, hq) = texel_sample(map, track, [px, py], texel, t_in, t_out);
        if hq - zp > track.rise_per_t * t_mid {
            return true;
        }
    }
    false
}
