//! The per-sun bound of the certified sweep ([`crate::terrain::hard::sweep`]): D(T), the maximum over each
//! texel's square of the bilinear surface minus the sun ray's linear rise, and the transpose
//! that puts the track's major axis along rows.

use rayon::prelude::*;

/// The sun's half-texel rises and the raise that makes [`bound_row`] an upper bound.
#[derive(Clone, Copy, Debug)]
pub struct BoundSun {
    /// ½·rise·u_x and ½·rise·u_y in the grid's axes.
    pub ex: f32,
    pub ey: f32,
    /// 2e-6 of the largest magnitude summed (module docs of [`bound_row`]).
    pub raise: f32,
}

impl BoundSun {
    /// For the sun's rise per texel along x and y (`rise·u_x`, `rise·u_y`) over heights whose
    /// magnitude is at most `peak` ([`height_range`]).
    pub fn new(rise_x: f64, rise_y: f64, peak: f32) -> BoundSun {
        let (ex, ey) = ((0.5 * rise_x) as f32, (0.5 * rise_y) as f32);
        BoundSun {
            ex,
            ey,
            raise: 2e-6 * (peak + ex.abs() + ey.abs()),
        }
    }
}

/// D(T) for the texels (xa + i, y), i < out.len(), of a w×h row-major grid: the maximum over
/// T's square of F(q) = h(q) − rise·(q − c_T)·u at the nine points where it can lie (the
/// centre, the edge midpoints, the corners: F is bilinear on each quarter of the square),
/// border-clamped like [`sample_bilinear`]. Evaluated in f32 (it vectorises) and then raised by
/// 2e-6 of the largest magnitude, which covers f32 rounding of the nine sums (about 8 ulps)
/// with a margin of 30. Computed row by row where the sweep needs it, so the bound of the whole
/// map is never stored (a 4096² map's would be 64 MiB of fresh pages per sun).
///
/// [`sample_bilinear`]: crate::terrain::hard::exact_traversal::sample_bilinear
#[allow(clippy::too_many_arguments)]
pub fn bound_row(
    z: &[f32],
    w: usize,
    h: usize,
    y: usize,
    xa: usize,
    sun: BoundSun,
    out: &mut [f32],
) {
    let n = out.len();
    debug_assert!(xa + n <= w);
    let (n_row, s_row) = (y.saturating_sub(1), (y + 1).min(h - 1));
    let rows = [
        &z[n_row * w..(n_row + 1) * w],
        &z[y * w..(y + 1) * w],
        &z[s_row * w..(s_row + 1) * w],
    ];
    let BoundSun { ex, ey, raise } = sun;
    let max = |a: f32, b: f32| if b > a { b } else { a };
    // Offsets in texels: west (−½, 0), east, north (0, −½), south, and the corners.
    let nine = |[nl, nc, nr]: [f32; 3], [l, c, r]: [f32; 3], [sl, sc, sr]: [f32; 3]| {
        let mut v = max(c, 0.5 * (c + l) + ex);
        v = max(v, 0.5 * (c + r) - ex);
        v = max(v, 0.5 * (c + nc) + ey);
        v = max(v, 0.5 * (c + sc) - ey);
        v = max(v, 0.25 * (c + l + nc + nl) + ex + ey);
        v = max(v, 0.25 * (c + r + nc + nr) - ex + ey);
        v = max(v, 0.25 * (c + l + sc + sl) + ex - ey);
        v = max(v, 0.25 * (c + r + sc + sr) - ex - ey);
        v + raise
    };
    // A texel and its clamped neighbours in one row.
    let three = |row: &[f32], x: usize| [row[x.saturating_sub(1)], row[x], row[(x + 1).min(w - 1)]];
    let edge = |x: usize| nine(three(rows[0], x), three(rows[1], x), three(rows[2], x));
    // Interior columns 1..w−1 without clamps (they vectorise), the border ones clamped.
    let (ia, ib) = (xa.max(1), (xa + n).min(w - 1).max(xa.max(1)));
    for x in (xa..ia).chain(ib..xa + n) {
        out[x - xa] = edge(x);
    }
    if ia < ib {
        let m = ib - ia;
        let [rn, rc, rs] = rows.map(|r| &r[ia - 1..ib + 1]);
        for (i, o) in out[ia - xa..][..m].iter_mut().enumerate() {
            *o = nine(
                [rn[i], rn[i + 1], rn[i + 2]],
                [rc[i], rc[i + 1], rc[i + 2]],
                [rs[i], rs[i + 1], rs[i + 2]],
            );
        }
    }
}

/// The smallest and largest height (one parallel pass; the heights must not be NaN).
pub fn height_range(heights: &[f32]) -> (f32, f32) {
    heights
        .par_chunks(1 << 16)
        .map(|c| {
            c.iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                    (if v < lo { v } else { lo }, if v > hi { v } else { hi })
                })
        })
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::heightmap::HeightMap;
    use crate::terrain::hard::exact_traversal::sample_bilinear;
    use crate::terrain::sun::{Sun, Track};

    #[test]
    fn the_directional_bound_covers_the_square() {
        let (w, h) = (7, 5);
        let heights: Vec<f32> = (0..w * h)
            .map(|i| ((i * 37 % 11) as f32 - 5.0) * 1.5)
            .collect();
        let map = HeightMap::new(w, h, heights, [1.0, 1.0]);
        for az in [0.0, 37.0, 90.0, 200.0, 300.0] {
            let track = Track::new(&Sun::new(az, 25.0).unwrap(), [1.0, 2.0]);
            let sun = BoundSun::new(
                track.rise_per_t * track.ux,
                track.rise_per_t * track.uy,
                7.5 * 1.5,
            );
            for y in 0..h {
                // Whole rows and pieces of rows (the sweep asks for windows).
                let mut d = vec![0.0f32; w];
                bound_row(&map.heights, w, h, y, 0, sun, &mut d);
                for (xa, n) in [(0, 1), (1, 3), (4, 3), (6, 1), (2, 5)] {
                    let mut part = vec![0.0f32; n];
                    bound_row(&map.heights, w, h, y, xa, sun, &mut part);
                    assert_eq!(part[..], d[xa..xa + n], "row {y} from {xa}");
                }
                for (x, &dv) in d.iter().enumerate() {
                    let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
                    let mut peak = f64::NEG_INFINITY;
                    for i in 0..=16 {
                        for k in 0..=16 {
                            let (qx, qy) = (x as f64 + i as f64 / 16.0, y as f64 + k as f64 / 16.0);
                            let f = sample_bilinear(&map.heights, w, h, qx, qy)
                                - track.rise_per_t * ((qx - cx) * track.ux + (qy - cy) * track.uy);
                            peak = peak.max(f);
                        }
                    }
                    let dv = dv as f64;
                    // An upper bound, and tight: the peak is at one of the 9 grid points.
                    assert!(
                        peak <= dv && dv - peak < 1e-3,
                        "az {az} ({x}, {y}): {peak} vs {dv}"
                    );
                }
            }
        }
    }
}
