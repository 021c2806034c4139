//! The per-sun bound of the certified sweep ([`super::sweep`]): D(T), the maximum over each
//! texel's square of the bilinear surface minus the sun ray's linear rise, and the transpose
//! that puts the track's major axis along rows.

use rayon::prelude::*;

/// D(T): the maximum over T's square of F(q) = h(q) − rise·(q − c_T)·u at the nine points
/// where it can lie (module docs), border-clamped like [`sample_bilinear`], for a w×h grid
/// and the sun's rise per texel along x and y (`rise·u_x`, `rise·u_y`); `peak` is at least
/// every |height| ([`height_range`]). Evaluated in f32 (it vectorises) and then raised by 2e-6
/// of the largest magnitude, which covers f32 rounding of the nine sums (about 8 ulps) with a
/// margin of 30.
///
/// [`sample_bilinear`]: super::exact_traversal::sample_bilinear
pub fn directional_bound(
    heights: &[f32],
    w: usize,
    h: usize,
    rise_x: f64,
    rise_y: f64,
    peak: f32,
) -> Vec<f32> {
    let (ex, ey) = ((0.5 * rise_x) as f32, (0.5 * rise_y) as f32);
    let raise = 2e-6 * (peak + ex.abs() + ey.abs());
    let mut d = vec![0.0f32; w * h];
    let max = |a: f32, b: f32| if b > a { b } else { a };
    d.par_chunks_mut(w).enumerate().for_each_init(
        || {
            [
                vec![0.0f32; w + 2],
                vec![0.0f32; w + 2],
                vec![0.0f32; w + 2],
            ]
        },
        |[rn, rc, rs], (y, out)| {
            let (n, s) = (y.saturating_sub(1), (y + 1).min(h - 1));
            // Rows padded by one clamped texel on each side, so the inner loop has no branches.
            for (r, v) in [(n, &mut *rn), (y, &mut *rc), (s, &mut *rs)] {
                let row = &heights[r * w..(r + 1) * w];
                v[0] = row[0];
                v[1..=w].copy_from_slice(row);
                v[w + 1] = row[w - 1];
            }
            for (x, o) in out.iter_mut().enumerate() {
                let (l, c, r) = (rc[x], rc[x + 1], rc[x + 2]);
                let (nl, nc, nr) = (rn[x], rn[x + 1], rn[x + 2]);
                let (sl, sc, sr) = (rs[x], rs[x + 1], rs[x + 2]);
                // Offsets in texels: west (−½, 0), east, north (0, −½), south, and the corners.
                let mut v = max(c, 0.5 * (c + l) + ex);
                v = max(v, 0.5 * (c + r) - ex);
                v = max(v, 0.5 * (c + nc) + ey);
                v = max(v, 0.5 * (c + sc) - ey);
                v = max(v, 0.25 * (c + l + nc + nl) + ex + ey);
                v = max(v, 0.25 * (c + r + nc + nr) - ex + ey);
                v = max(v, 0.25 * (c + l + sc + sl) + ex - ey);
                v = max(v, 0.25 * (c + r + sc + sr) - ex - ey);
                *o = v + raise;
            }
        },
    );
    d
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

/// Transpose a w×h row-major grid (blocked for the cache).
pub fn transpose(src: &[f32], w: usize, h: usize) -> Vec<f32> {
    const B: usize = 32;
    let mut dst = vec![0.0f32; w * h];
    // dst is h wide and w tall: dst[x * h + y] = src[y * w + x].
    dst.par_chunks_mut(h * B).enumerate().for_each(|(bx, out)| {
        let x0 = bx * B;
        let xs = out.len() / h;
        for y0 in (0..h).step_by(B) {
            for x in x0..x0 + xs {
                for y in y0..(y0 + B).min(h) {
                    out[(x - x0) * h + y] = src[y * w + x];
                }
            }
        }
    });
    dst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::heightmap::HeightMap;
    use crate::terrain::exact_traversal::sample_bilinear;
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
            let d = directional_bound(
                &map.heights,
                w,
                h,
                track.rise_per_t * track.ux,
                track.rise_per_t * track.uy,
                7.5 * 1.5,
            );
            for y in 0..h {
                for x in 0..w {
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
                    let dv = d[y * w + x] as f64;
                    // An upper bound, and tight: the peak is at one of the 9 grid points.
                    assert!(
                        peak <= dv && dv - peak < 1e-3,
                        "az {az} ({x}, {y}): {peak} vs {dv}"
                    );
                }
            }
        }
    }

    #[test]
    fn transpose_swaps_axes() {
        let src: Vec<f32> = (0..35).map(|i| i as f32).collect();
        let t = transpose(&src, 7, 5);
        for y in 0..5 {
            for x in 0..7 {
                assert_eq!(t[x * 5 + y], src[y * 7 + x]);
            }
        }
    }
}
