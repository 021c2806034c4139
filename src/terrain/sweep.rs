//! Hard shadows by a certified sweep (docs/algorithms.md §4.3): a running maximum along bands
//! parallel to the sun's track bounds most pixels; short exact walks and witness texels decide
//! the rest with the exact test, so the mask equals [`shadowed_exact`] on every pixel.
//!
//! **The bound.** Pixel P (centre p, height z_P) is shadowed when some texel T on its track has
//! `h(Q_T) − z_P > rise·t_T` ([`shadowed_exact`]), with t_T = (Q_T − p)·u. So with
//! F(q) = h(q) − rise·(q − c_T)·u (c_T the centre of T):
//!
//! `h(Q_T) − rise·t_T = F(Q_T) − rise·(c_T − p)·u ≤ D(T) − rise·c_T·u + rise·p·u`,
//!
//! where D(T) is the maximum of F over T's square. F is the bilinear surface minus a linear
//! function, bilinear on each quarter of the square, so D(T) is F's largest value at nine
//! points — the centre, the edge midpoints and the corners ([`directional_bound`], with the
//! border clamping of [`sample_bilinear`]). Hence
//! `U(P) = rise·p·u + max_{T ∈ S} (D(T) − rise·c_T·u) ≤ z_P − ε` proves that no texel of S
//! shadows P, for any set S of texels.
//!
//! **The sweep.** In a frame whose rows are the track's major axis (the map transposed when
//! |u_x| > |u_y|) the track crosses one row per step and drifts m = u_x/u_y columns per row
//! (|m| ≤ 1). Band j holds the tracks whose intercept b = p_x − p_y·m lies in
//! [j/K, (j + 1)/K) (K = 2 bands per texel); in row y′ they cover the columns
//! `⌊j/K + min(y′m, (y′+1)m) − δ⌋ ..= ⌊(j+1)/K + max(y′m, (y′+1)m) + δ⌋` (1 to 3 texels).
//! Rows are visited from the sun's side; each band keeps the running maximum of
//! D − rise·c·u over its window for the rows beyond the next one and beyond the current one.
//!
//! **Per pixel, in order.** (1) Walk P's track exactly through its own row (the start texel,
//! where t ≈ 0, defeats any bound): a texel above the ray means shadow. (2) The bound over the
//! rows beyond: lit. (3) Walk on through the next row. (4) The bound over the rows beyond that:
//! lit. (5) The texels of P's track in the row where its band's maximum lies, each with its
//! exact transit — t_in = max(entry_x, entry_y), t_out = min(exit_x, exit_y), by the same
//! [`Track::crossing`] expressions as the walk, so bit for bit its values; a texel passing the
//! exact test is a witness: shadow. (6) The accelerated traversal.
//!
//! Every "shadow" is an exact test the walking traversal also makes, every "lit" a bound with
//! margin ε (1e-9 of the largest magnitude compared, for f64 rounding; D is rounded up to f32).
//! The answer of every pixel is exact, so it does not depend on the order or the threads.

use super::accelerated_traversal::shadowed_accelerated;
use super::exact_traversal::{shadowed_exact, texel_sample, TrackWalk};
use super::minmax_mipmap::MinMaxMipmap;
use super::sun::{Track, TrackKind};
use super::sweep_bound::{directional_bound, transpose};
use crate::heightmap::HeightMap;
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::atomic::{AtomicU8, Ordering};

/// How the sweep decided the pixels (for the study and the benchmark).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SweepStats {
    /// Proved lit by a band bound.
    pub lit_by_bound: u64,
    /// Shadowed by a texel of the short exact walk.
    pub shadowed_near: u64,
    /// Shadowed by a witness texel in the row of the band's maximum.
    pub shadowed_by_witness: u64,
    /// Left to the exact (accelerated) traversal.
    pub traversed: u64,
}

impl SweepStats {
    fn add(self, o: SweepStats) -> SweepStats {
        SweepStats {
            lit_by_bound: self.lit_by_bound + o.lit_by_bound,
            shadowed_near: self.shadowed_near + o.shadowed_near,
            shadowed_by_witness: self.shadowed_by_witness + o.shadowed_by_witness,
            traversed: self.traversed + o.traversed,
        }
    }
}

/// Bands per texel of intercept.
const K: i64 = 2;
/// Bands per parallel work item.
const CHUNK: i64 = 1024;

/// The shadow mask (row-major, `true` = shadowed), equal to the exact traversal's on every
/// pixel. `mip` speeds up the traversal of undecided pixels (the plain exact traversal without).
pub fn shadow_mask_sweep(
    map: &HeightMap,
    mip: Option<&MinMaxMipmap>,
    track: &Track,
) -> (Vec<bool>, SweepStats) {
    let n = map.width * map.height;
    match track.kind {
        TrackKind::Zenith => return (vec![false; n], SweepStats::default()),
        TrackKind::BelowHorizon => return (vec![true; n], SweepStats::default()),
        TrackKind::Ray => {}
    }
    let frame = Frame::new(map, track);
    let mask: Vec<AtomicU8> = (0..n).map(|_| AtomicU8::new(0)).collect();
    let (jmin, jmax) = frame.band_range();
    let starts: Vec<i64> = (jmin..=jmax).step_by(CHUNK as usize).collect();
    let stats = starts
        .par_iter()
        .map(|&j0| frame.sweep_bands(map, mip, j0, (j0 + CHUNK).min(jmax + 1), &mask))
        .reduce(SweepStats::default, SweepStats::add);
    let mask = mask.into_iter().map(|v| v.into_inner() != 0).collect();
    (mask, stats)
}

/// The sweep frame: canonical rows along the track's major axis.
struct Frame<'a> {
    track: &'a Track,
    transposed: bool,
    /// Canonical width and height.
    w: usize,
    h: usize,
    /// Canonical heights and the bound D, row-major in the canonical frame.
    z: Cow<'a, [f32]>,
    d: Vec<f32>,
    /// u in canonical axes; m = ucx / ucy.
    ucx: f64,
    ucy: f64,
    m: f64,
    rise: f64,
    eps: f64,
    /// The map's largest height (the plain traversal's early stop).
    max_height: f32,
}

impl<'a> Frame<'a> {
    fn new(map: &'a HeightMap, track: &'a Track) -> Frame<'a> {
        let transposed = track.ux.abs() > track.uy.abs();
        let (w, h, z, ucx, ucy) = if transposed {
            let z = transpose(&map.heights, map.width, map.height);
            (map.height, map.width, Cow::Owned(z), track.uy, track.ux)
        } else {
            let z = Cow::Borrowed(&map.heights[..]);
            (map.width, map.height, z, track.ux, track.uy)
        };
        // The canonical grid's bilinear surface is the map's, transposed: D is the same bound.
        let d = directional_bound(&z, w, h, track.rise_per_t * ucx, track.rise_per_t * ucy);
        let rise = track.rise_per_t;
        let (lo, hi) = map.min_max();
        let span = (map.width + map.height) as f64 + 2.0;
        let eps = 1e-9 * ((lo as f64).abs().max((hi as f64).abs()) + rise * span) + 1e-12;
        Frame {
            track,
            transposed,
            w,
            h,
            z,
            d,
            ucx,
            ucy,
            m: ucx / ucy,
            rise,
            eps,
            max_height: hi,
        }
    }

    /// Band of the pixels of canonical row y: j = K·x + k(y).
    fn band_offset(&self, y: usize) -> i64 {
        (K as f64 * (0.5 - (y as f64 + 0.5) * self.m)).floor() as i64
    }

    fn band_range(&self) -> (i64, i64) {
        let (k0, k1) = (self.band_offset(0), self.band_offset(self.h - 1));
        // Start at a multiple of K so that chunks hold whole groups of K bands.
        (
            k0.min(k1).div_euclid(K) * K,
            K * (self.w as i64 - 1) + k0.max(k1),
        )
    }

    /// For band j = K·q + s, the columns its tracks cover in row y are
    /// q + lo[s] ..= q + hi[s].
    fn window(&self, y: usize) -> ([i64; K as usize], [i64; K as usize]) {
        const DELTA: f64 = 1e-6;
        let (m0, m1) = (y as f64 * self.m, (y + 1) as f64 * self.m);
        let (a, b) = (m0.min(m1), m0.max(m1));
        let mut lo = [0; K as usize];
        let mut hi = [0; K as usize];
        for s in 0..K as usize {
            lo[s] = (s as f64 / K as f64 + a - DELTA).floor() as i64;
            hi[s] = ((s + 1) as f64 / K as f64 + b + DELTA).floor() as i64;
        }
        (lo, hi)
    }

    /// Sweep bands [j0, j1) over every row from the sun's side, deciding their pixels.
    fn sweep_bands(
        &self,
        map: &HeightMap,
        mip: Option<&MinMaxMipmap>,
        j0: i64,
        j1: i64,
        mask: &[AtomicU8],
    ) -> SweepStats {
        let nb = (j1 - j0) as usize;
        // Maxima over the rows beyond the current one (best1) and beyond the next (best2),
        // the row of best2's maximum, and the last row's window values.
        let mut best1 = vec![f64::NEG_INFINITY; nb];
        let mut best2 = vec![f64::NEG_INFINITY; nb];
        let mut row2 = vec![usize::MAX; nb];
        let mut prev = vec![f64::NEG_INFINITY; nb];
        let mut prev_row = usize::MAX;
        let mut g = vec![0.0f64; self.w];
        let mut stats = SweepStats::default();
        let max_height = self.max_height;
        let up = self.ucy > 0.0;
        let kx = self.rise * self.ucx;
        for step in 0..self.h {
            let y = if up { self.h - 1 - step } else { step };
            self.decide_row(
                map,
                mip,
                max_height,
                y,
                j0,
                j1,
                [&best1, &best2],
                &row2,
                mask,
                &mut stats,
            );
            // The previous row is beyond the next row of the rows still to come.
            if prev_row != usize::MAX {
                for i in 0..nb {
                    if prev[i] > best2[i] {
                        best2[i] = prev[i];
                        row2[i] = prev_row;
                    }
                }
            }
            // This row's window values: for band j = K·q + s the maximum of g over
            // q + lo[s] ..= q + hi[s], from a sliding maximum per window length.
            let row_term = self.rise * (y as f64 + 0.5) * self.ucy;
            let (lo, hi) = self.window(y);
            let (q0, q1) = (j0.div_euclid(K), (j1 - 1).div_euclid(K));
            let xa = (q0 + lo[0]).max(0);
            let xb = (q1 + hi[K as usize - 1]).min(self.w as i64 - 1);
            let drow = &self.d[y * self.w..(y + 1) * self.w];
            for x in xa.max(0) as usize..=(xb.max(-1) + 1) as usize {
                if x < self.w {
                    g[x] = drow[x] as f64 - kx * (x as f64 + 0.5);
                }
            }
            for (s, (&l, &r)) in lo.iter().zip(&hi).enumerate() {
                for q in q0..=q1 {
                    let j = K * q + s as i64;
                    if j < j0 || j >= j1 {
                        continue;
                    }
                    let (a, b) = ((q + l).max(xa), (q + r).min(xb));
                    let mut v = f64::NEG_INFINITY;
                    for x in a..=b {
                        v = v.max(g[x as usize]);
                    }
                    let v = v - row_term;
                    let i = (j - j0) as usize;
                    prev[i] = v;
                    if v > best1[i] {
                        best1[i] = v;
                    }
                }
            }
            prev_row = y;
        }
        stats
    }

    /// Decide the pixels of canonical row y whose band is in [j0, j1).
    #[allow(clippy::too_many_arguments)]
    fn decide_row(
        &self,
        map: &HeightMap,
        mip: Option<&MinMaxMipmap>,
        max_height: f32,
        y: usize,
        j0: i64,
        j1: i64,
        [best1, best2]: [&[f64]; 2],
        row2: &[usize],
        mask: &[AtomicU8],
        stats: &mut SweepStats,
    ) {
        let k = self.band_offset(y);
        let x0 = (j0 - k).div_euclid(K) + ((j0 - k).rem_euclid(K) != 0) as i64;
        let x1 = (j1 - 1 - k).div_euclid(K);
        let zrow = &self.z[y * self.w..(y + 1) * self.w];
        for x in x0.max(0)..=x1.min(self.w as i64 - 1) {
            let i = (K * x + k - j0) as usize;
            let zp = zrow[x as usize] as f64;
            let pu = (x as f64 + 0.5) * self.ucx + (y as f64 + 0.5) * self.ucy;
            let (col, row) = if self.transposed {
                (y, x as usize)
            } else {
                (x as usize, y)
            };
            let mut walk = Walk::new(map, self.track, col, row, self.transposed);
            let shadowed = if walk.through_line() {
                stats.shadowed_near += 1;
                true
            } else if best1[i] + self.rise * pu <= zp - self.eps {
                stats.lit_by_bound += 1;
                false
            } else if walk.through_line() {
                stats.shadowed_near += 1;
                true
            } else if best2[i] + self.rise * pu <= zp - self.eps {
                stats.lit_by_bound += 1;
                false
            } else if row2[i] != usize::MAX
                && witness(map, self.track, col, row, row2[i] as i64, self.transposed)
            {
                stats.shadowed_by_witness += 1;
                true
            } else {
                stats.traversed += 1;
                match mip {
                    Some(mip) => shadowed_accelerated(map, mip, self.track, col, row),
                    None => shadowed_exact(map, self.track, col, row, max_height),
                }
            };
            if shadowed {
                mask[row * map.width + col].store(1, Ordering::Relaxed);
            }
        }
    }
}

/// The exact traversal's walk ([`TrackWalk`]: [`shadowed_exact`]'s stepping), run one
/// major-axis line at a time.
struct Walk<'a> {
    map: &'a HeightMap,
    track: &'a Track,
    walk: TrackWalk<'a>,
    zp: f64,
    transposed: bool,
}

impl<'a> Walk<'a> {
    fn new(map: &'a HeightMap, track: &'a Track, col: usize, row: usize, transposed: bool) -> Self {
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
    fn through_line(&mut self) -> bool {
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
/// transit times, so `true` means [`shadowed_exact`] is `true`.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::sun::Sun;

    #[test]
    fn a_wall_is_swept_like_it_is_traversed() {
        let (w, h) = (40, 9);
        let mut heights = vec![0.0; w * h];
        for r in 0..h {
            heights[r * w + 3] = 10.0;
        }
        let map = HeightMap::new(w, h, heights, [1.0, 1.0]);
        for az in [270.0, 250.0, 290.0, 90.0, 0.0, 180.0] {
            let track = Track::new(&Sun::new(az, 30.0).unwrap(), [1.0, 1.0]);
            let (mask, _) = shadow_mask_sweep(&map, None, &track);
            for row in 0..h {
                for col in 0..w {
                    let exact = shadowed_exact(&map, &track, col, row, 10.0);
                    assert_eq!(mask[row * w + col], exact, "az {az} ({col}, {row})");
                }
            }
        }
    }
}
