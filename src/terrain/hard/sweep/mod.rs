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
//! points — the centre, the edge midpoints and the corners ([`bound_row`], with the border
//! clamping of [`sample_bilinear`]; computed row by row where the bands need it). Hence
//! `U(P) = rise·p·u + max_{T ∈ S} (D(T) − rise·c_T·u) ≤ z_P − ε` proves that no texel of S
//! shadows P, for any set S of texels.
//!
//! **The sweep.** In a frame whose rows are the track's major axis (the map transposed when
//! |u_x| > |u_y|) the track crosses one row per step and drifts m = u_x/u_y columns per row
//! (|m| ≤ 1). Band j holds the tracks whose intercept b = p_x − p_y·m lies in
//! [j/K, (j + 1)/K) (K = 1 band per texel); in row y′ they cover the columns
//! `⌊j/K + min(y′m, (y′+1)m) − δ⌋ ..= ⌊(j+1)/K + max(y′m, (y′+1)m) + δ⌋` (2 to 4 texels).
//! Rows are visited from the sun's side; each band keeps the running maximum of
//! D − rise·c·u over its window for the rows at least L ahead of the current one (a ring of
//! the last L − 1 rows' values delays them), and the row where that maximum lies. L = 8 lines
//! for a sun below 20° (the ray rises little per line, so near texels defeat the bound), else
//! 2. Band windows are computed only where they meet the map.
//!
//! **Per pixel, in order.** (1) The texels of P's track in its first L lines (the start texel,
//! where t ≈ 0, defeats any bound) by the near stencil ([`crate::terrain::hard::sweep::near`]): every track
//! is an integer translate of every other, so their transits and bilinear weights are the same
//! constants for all pixels and the exact test is a fixed stencil, evaluated in f32 for a
//! whole row with a certified margin: above the margin, a texel passes the exact test
//! (shadow); below −margin none does; between (near ties) and where a tap leaves the map, the
//! scalar walk of those L lines ([`crate::terrain::hard::sweep::exact::Walk`]) decides. (2) The bound over the
//! rows at least L ahead: lit. (3) The texels of P's track in the row where its band's maximum
//! lies, each with its exact transit — t_in = max(entry_x, entry_y), t_out = min(exit_x,
//! exit_y), by the same [`Track::crossing`] expressions as the walk, so bit for bit its values;
//! a texel passing the exact test is a witness: shadow ([`crate::terrain::hard::sweep::exact::witness`]).
//! (4) Line by line ([`crate::terrain::hard::sweep::bands`]): each band also keeps the maximum of each block
//! of 16 lines, and of each super-block of 16 blocks; a block or super-block whose maximum
//! passes the bound test holds no texel above the ray (the super-blocks are scanned first, so a
//! pixel 4096 lines long reads about 16 + 16 maxima instead of 256), and every line of the
//! other blocks gets the exact test of P's texels in it — the per-line
//! stencil ([`NearStencil::line_max`], same constants and margin argument as the near one),
//! or the witness walk of that line where a tap leaves the map or the value is within the
//! margin. So every line beyond the first L is bounded or tested: no traversal, no mipmap.
//!
//! Every "shadow" is an exact test the walking traversal also makes (or the stencil's value
//! beyond its error bound), every "lit" a bound with margin ε (1e-9 of the largest magnitude compared, for f64 rounding; D and the band values are rounded up to f32).
//! The answer of every pixel is exact, so it does not depend on the order or the threads.

pub mod bands;
pub mod bound;
pub mod exact;
pub mod near;

use crate::heightmap::HeightMap;
#[cfg(doc)]
use crate::terrain::hard::exact_traversal::shadowed_exact;
use crate::terrain::hard::sweep::bands::{up_f32, Bands, BLOCK, SUPER};
use crate::terrain::hard::sweep::bound::{bound_row, height_range, BoundSun};
use crate::terrain::hard::sweep::exact::{witness, Walk};
use crate::terrain::hard::sweep::near::{decide, Axes, NearStencil};
use crate::terrain::sun::{Track, TrackKind};
use crate::terrain::transpose::transpose;
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
    /// Of those, shadowed.
    pub traversed_shadowed: u64,
}

impl SweepStats {
    fn add(self, o: SweepStats) -> SweepStats {
        SweepStats {
            lit_by_bound: self.lit_by_bound + o.lit_by_bound,
            shadowed_near: self.shadowed_near + o.shadowed_near,
            shadowed_by_witness: self.shadowed_by_witness + o.shadowed_by_witness,
            traversed: self.traversed + o.traversed,
            traversed_shadowed: self.traversed_shadowed + o.traversed_shadowed,
        }
    }
}

/// Bands per texel of intercept. Two give tighter windows (0.73 % of the pixels left to the
/// line-by-line tests at 4K, 300°/5°, against 0.93 % with one) but twice the band updates;
/// since those tests are cheap, one measured faster at 2K and 4K (docs/terrain.md).
const K: i64 = 1;
/// Bands per parallel work item (512 texels of intercept, as 1024 bands did with K = 2: fewer,
/// wider items balance worse on two threads).
const CHUNK: i64 = 512;
/// Major-axis lines (the own one and those after it) tested exactly before the bound: for a
/// sun below LOW_SUN (tan 20°) LINES_LOW, where the bound is weak near the pixel (the ray
/// rises little per line), else LINES (Puget Sound, benches/terrain_sweep.rs).
const LINES: i64 = 2;
const LINES_LOW: i64 = 8;
const LOW_SUN: f64 = 0.364;

/// The shadow mask (row-major, `true` = shadowed), equal to the exact traversal's on every
/// pixel. Needs no mipmap: undecided pixels are settled line by line from the bands' history.
pub fn shadow_mask_sweep(map: &HeightMap, track: &Track) -> (Vec<bool>, SweepStats) {
    let n = map.width * map.height;
    match track.kind {
        TrackKind::Zenith => return (vec![false; n], SweepStats::default()),
        TrackKind::BelowHorizon => return (vec![true; n], SweepStats::default()),
        TrackKind::Ray => {}
    }
    let frame = Frame::new(map, track);
    // Zeroed by the allocator: only the pages of shadowed pixels are ever written.
    let mut mask = vec![0u8; n];
    // SAFETY: AtomicU8 has the size, alignment and bit validity of u8, and `mask` is not
    // otherwise touched while the view lives.
    let view: &[AtomicU8] = unsafe { &*(mask.as_mut_slice() as *mut [u8] as *const [AtomicU8]) };
    let (jmin, jmax) = frame.band_range();
    let starts: Vec<i64> = (jmin..=jmax).step_by(CHUNK as usize).collect();
    let stats = starts
        .par_iter()
        .map(|&j0| frame.sweep_bands(map, j0, (j0 + CHUNK).min(jmax + 1), view))
        .reduce(SweepStats::default, SweepStats::add);
    // In place: the same allocation becomes the Vec<bool>.
    let mask = mask.into_iter().map(|v| v != 0).collect();
    (mask, stats)
}

/// The sweep frame: canonical rows along the track's major axis.
struct Frame<'a> {
    track: &'a Track,
    transposed: bool,
    /// Canonical width and height.
    w: usize,
    h: usize,
    /// Canonical heights, row-major in the canonical frame, and the sun for their bound D.
    z: Cow<'a, [f32]>,
    bound: BoundSun,
    /// u in canonical axes; m = ucx / ucy.
    ucx: f64,
    ucy: f64,
    m: f64,
    rise: f64,
    eps: f64,
    /// The exact test of the texels of the first `lines` lines, for whole rows; and of the
    /// texels of any one line, for one pixel.
    near: NearStencil,
    far_lines: NearStencil,
    lines: i64,
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
        let (lo, hi) = height_range(&map.heights);
        let peak = lo.abs().max(hi.abs());
        let (rx, ry) = (track.rise_per_t * ucx, track.rise_per_t * ucy);
        let bound = BoundSun::new(rx, ry, peak);
        let rise = track.rise_per_t;
        let span = (map.width + map.height) as f64 + 2.0;
        let eps = 1e-9 * ((lo as f64).abs().max((hi as f64).abs()) + rise * span) + 1e-12;
        let (sx, sy) = (track.step_x, track.step_y);
        let axes = if transposed {
            Axes {
                x: (track.uy, sy, track.inv_uy),
                y: (track.ux, sx, track.inv_ux),
            }
        } else {
            Axes {
                x: (track.ux, sx, track.inv_ux),
                y: (track.uy, sy, track.inv_uy),
            }
        };
        let lines = if track.tan_elevation < LOW_SUN {
            LINES_LOW
        } else {
            LINES
        };
        let near = NearStencil::new(axes, rise, lines, hi as f64 - lo as f64);
        let far_lines = NearStencil::new(axes, rise, h as i64, hi as f64 - lo as f64);
        Frame {
            track,
            transposed,
            w,
            h,
            z,
            bound,
            ucx,
            ucy,
            m: ucx / ucy,
            rise,
            eps,
            near,
            far_lines,
            lines,
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
    fn sweep_bands(&self, map: &HeightMap, j0: i64, j1: i64, mask: &[AtomicU8]) -> SweepStats {
        let q0 = j0.div_euclid(K);
        let nq = (j1 - j0 + K - 1) as usize / K as usize;
        let slots = (self.lines - 1) as usize;
        let mut bands = Bands::new(q0, nq, K as usize, slots, self.h);
        // Scratch: the row's g = D − rise·x·u_x (padded), one window's maxima, the stencil.
        let mut gp = vec![f32::NEG_INFINITY; nq + 8];
        let mut wmax = vec![f32::NEG_INFINITY; nq];
        let mut near = vec![0.0f32; nq + 2];
        let mut lit = vec![0u8; nq + 2];
        let mut drow = vec![0.0f32; nq + 8];
        let mut stats = SweepStats::default();
        for step in 0..self.h {
            let y = self.line(step);
            let scratch = (&mut near[..], &mut lit[..]);
            self.decide_row(map, (y, step), (j0, j1), &bands, scratch, mask, &mut stats);
            // This row's window values: for band j = K·q + s the maximum of g over
            // q + lo[s] ..= q + hi[s] (−∞ off the map).
            let (lo, hi) = self.window(y);
            let omin = lo[0];
            let len = nq + (hi[K as usize - 1] - omin) as usize;
            if gp.len() < len {
                gp.resize(len, f32::NEG_INFINITY);
            }
            let x_first = q0 + omin;
            // Columns x_first + t for t in ta..tb lie on the map.
            let ta = (-x_first).clamp(0, len as i64) as usize;
            let tb = (self.w as i64 - x_first).clamp(ta as i64, len as i64) as usize;
            gp[..ta].fill(f32::NEG_INFINITY);
            gp[tb..len].fill(f32::NEG_INFINITY);
            if ta < tb {
                let xa = (x_first + ta as i64) as usize;
                if drow.len() < tb - ta {
                    drow.resize(tb - ta, 0.0);
                }
                let drow = &mut drow[..tb - ta];
                self.g_row(y, xa, drow, &mut gp[ta..tb]);
            }
            // Only bands ra..rb have a window on the map in this row.
            let ra = (-hi[K as usize - 1] - q0).clamp(0, nq as i64) as usize;
            let rb = (self.w as i64 - lo[0] - q0).clamp(ra as i64, nq as i64) as usize;
            for s in 0..K as usize {
                wmax.fill(f32::NEG_INFINITY);
                for o in lo[s]..=hi[s] {
                    let g = &gp[(o - omin) as usize + ra..][..rb - ra];
                    for (m, &g) in wmax[ra..rb].iter_mut().zip(g) {
                        *m = if g > *m { g } else { *m };
                    }
                }
                bands.push(step, s, &wmax);
            }
            bands.end_step(step, y);
        }
        stats
    }

    /// The canonical line visited at `step` (rows from the sun's side).
    fn line(&self, step: usize) -> usize {
        if self.ucy > 0.0 {
            self.h - 1 - step
        } else {
            step
        }
    }

    /// g = D − rise·c·u for the texels (xa + t, y), t < g.len(), computed in f64 and stored as
    /// an f32 no smaller ([`up_f32`]); `d` (as long) is scratch for the bound.
    fn g_row(&self, y: usize, xa: usize, d: &mut [f32], g: &mut [f32]) {
        bound_row(&self.z, self.w, self.h, y, xa, self.bound, d);
        let kx = self.rise * self.ucx;
        // rise·(y + ½)·u_y, the line's share of rise·c·u.
        let row_term = self.rise * (y as f64 + 0.5) * self.ucy;
        for (t, (g, &dv)) in g.iter_mut().zip(&*d).enumerate() {
            // i32 → f64 converts in one vector instruction; the map is under 2³¹ wide.
            *g = up_f32(dv as f64 - kx * ((xa as i32 + t as i32) as f64 + 0.5) - row_term);
        }
    }

    /// Decide the pixels of canonical row y whose band is in [j0, j1).
    #[allow(clippy::too_many_arguments)]
    fn decide_row(
        &self,
        map: &HeightMap,
        (y, step): (usize, usize),
        (j0, j1): (i64, i64),
        bands: &Bands,
        (near, lit): (&mut [f32], &mut [u8]),
        mask: &[AtomicU8],
        stats: &mut SweepStats,
    ) {
        let k = self.band_offset(y);
        let x0 = ((j0 - k).div_euclid(K) + ((j0 - k).rem_euclid(K) != 0) as i64).max(0);
        let x1 = (j1 - 1 - k).div_euclid(K).min(self.w as i64 - 1);
        if x0 > x1 {
            return;
        }
        // Pixel x's band is j = K·(x + kq) + s: entry s·nq + x + kq − q0.
        let (kq, s) = (k.div_euclid(K), k.rem_euclid(K) as usize);
        let band_base = s as i64 * bands.nq as i64 + kq - bands.q0;
        // The stencil's pixels: xs..=xe.
        let (mut xs, mut xe) = (1, 0);
        if self.near.row_inside(y, self.h) {
            let (a, b) = self.near.x_range(self.w);
            (xs, xe) = (x0.max(a), x1.min(b));
            if xs <= xe {
                let n = (xe - xs + 1) as usize;
                self.near
                    .row_max(&self.z, self.w, y, xs as usize, &mut near[..n]);
            }
        }
        let zrow = &self.z[y * self.w..(y + 1) * self.w];
        let margin = self.near.margin;
        let (rise, eps, ucx, ycy) = (self.rise, self.eps, self.ucx, (y as f64 + 0.5) * self.ucy);
        // The common case for a whole run of pixels at once (it vectorises): no texel of the
        // first lines above the ray, and the bound below.
        if xs <= xe {
            let n = (xe - xs + 1) as usize;
            let best = &bands.best2[(band_base + xs) as usize..][..n];
            let z = &zrow[xs as usize..][..n];
            let pixels = lit[..n].iter_mut().zip(&near[..n]).zip(best.iter().zip(z));
            for (k, ((l, &v), (&b, &zp))) in pixels.enumerate() {
                let b = b as f64;
                // i32 → f64 converts in one vector instruction; the map is under 2³¹ wide.
                let pu = ((xs as i32 + k as i32) as f64 + 0.5) * ucx + ycy;
                *l = ((v < -margin) & (b + rise * pu <= zp as f64 - eps)) as u8;
            }
        }
        const ALL_LIT: u64 = 0x0101_0101_0101_0101;
        let mut x = x0;
        while x <= x1 {
            if xs <= x && x <= xe {
                let k = (x - xs) as usize;
                if x + 7 <= xe && u64::from_le_bytes(lit[k..k + 8].try_into().unwrap()) == ALL_LIT {
                    stats.lit_by_bound += 8;
                    x += 8;
                    continue;
                }
                if lit[k] != 0 {
                    stats.lit_by_bound += 1;
                    x += 1;
                    continue;
                }
            }
            let (col, row) = if self.transposed {
                (y, x as usize)
            } else {
                (x as usize, y)
            };
            let pixel = Pixel {
                x,
                y,
                step,
                col,
                row,
                z: zrow[x as usize],
                i: (band_base + x) as usize,
            };
            let stencil = if xs <= x && x <= xe {
                decide(near[(x - xs) as usize], margin)
            } else {
                None
            };
            let shadowed = match stencil {
                Some(true) => {
                    stats.shadowed_near += 1;
                    true
                }
                Some(false) => self.far(map, pixel, bands, stats),
                None => {
                    let mut walk = Walk::new(map, self.track, col, row, self.transposed);
                    if (0..self.lines).any(|_| walk.through_line()) {
                        stats.shadowed_near += 1;
                        true
                    } else {
                        self.far(map, pixel, bands, stats)
                    }
                }
            };
            if shadowed {
                mask[row * map.width + col].store(1, Ordering::Relaxed);
            }
            x += 1;
        }
    }

    /// Decide a pixel whose first `lines` lines hold no texel above the ray: the bound over
    /// the lines beyond, a witness in the line of the band's maximum, else line by line
    /// ([`crate::terrain::hard::sweep::bands`]): blocks of lines whose maximum clears the bound are lit; in the
    /// others each line's window value is recomputed, and the lines it does not clear are
    /// tested exactly.
    fn far(&self, map: &HeightMap, p: Pixel, bands: &Bands, stats: &mut SweepStats) -> bool {
        let pu = (p.x as f64 + 0.5) * self.ucx + (p.y as f64 + 0.5) * self.ucy;
        let (rise, bar) = (self.rise, p.z as f64 - self.eps);
        // The bound's test, NaN-free values: `clears(v)` proves v's lines lit.
        let clears = |v: f64| v + rise * pu <= bar;
        if clears(bands.best2[p.i] as f64) {
            stats.lit_by_bound += 1;
            return false;
        }
        // The exact test of the track's texels in line y (a line ahead of the near ones): the
        // line's stencil where its taps lie on the map and it decides, else the witness.
        let shadows = |y: usize| {
            let k = y.abs_diff(p.y);
            let v = self
                .far_lines
                .line_max(&self.z, (self.w, self.h), (p.x, p.y as i64), k);
            match v.and_then(|v| decide(v, self.far_lines.margin)) {
                Some(shadowed) => shadowed,
                None => witness(map, self.track, p.col, p.row, y as i64, self.transposed),
            }
        };
        let line = bands.row2[p.i];
        if line != u32::MAX && shadows(line as usize) {
            stats.shadowed_by_witness += 1;
            return true;
        }
        stats.traversed += 1;
        // The steps whose lines joined the bound: 0 ..= p.step − lines.
        let Some(last) = p.step.checked_sub(self.lines as usize) else {
            return false;
        };
        let finished = (last + 1) / BLOCK;
        let blocks = bands.blocks(p.i, finished);
        let supers = bands.supers(p.i, finished / SUPER);
        // The blocks of `range` that the bound does not clear, line by line.
        let in_blocks = |range: std::ops::Range<usize>| {
            range
                .filter(|&b| !clears(blocks[b] as f64))
                .any(|b| (b * BLOCK..(b + 1) * BLOCK).any(|st| shadows(self.line(st))))
        };
        let shadowed = supers
            .iter()
            .enumerate()
            .filter(|&(_, &v)| !clears(v as f64))
            .any(|(s, _)| in_blocks(s * SUPER..(s + 1) * SUPER))
            || in_blocks(supers.len() * SUPER..finished)
            || (finished * BLOCK..=last).any(|st| shadows(self.line(st)));
        stats.traversed_shadowed += shadowed as u64;
        shadowed
    }
}

/// A pixel of the canonical frame handed to [`Frame::far`]: its column x in line y (visited at
/// `step`), its place in the map, its height and its band's entry i.
#[derive(Clone, Copy)]
struct Pixel {
    x: i64,
    y: usize,
    step: usize,
    col: usize,
    row: usize,
    z: f32,
    i: usize,
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
            let (mask, _) = shadow_mask_sweep(&map, &track);
            for row in 0..h {
                for col in 0..w {
                    let exact = crate::terrain::hard::exact_traversal::shadowed_exact(
                        &map, &track, col, row, 10.0,
                    );
                    assert_eq!(mask[row * w + col], exact, "az {az} ({col}, {row})");
                }
            }
        }
    }
}
