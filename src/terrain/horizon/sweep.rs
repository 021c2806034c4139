//! The horizon line sweep: the horizon angle of every pixel along one direction, equal to the
//! exact per-pixel horizon ([`crate::terrain::horizon`] has the geometry: rational directions, periods,
//! stencils, and the hull argument; docs/algorithms.md §4.4). Lines of pixels are walked from
//! their far ends with an upper convex hull per line ([`crate::terrain::horizon::hull`]), on bundles of
//! [`LANES`] adjacent lines in lock-step.
//!
//! **Precondition of the bundles:** a direction (a, b) with |b| ≥ |a| (so b ≠ 0); [`Sweeper`]
//! transposes the map (once) for the others and the answer back.
//!
//! **Why bundles.** The line through pixel (c + 1, r) is the line through (c, r) moved one
//! column: the same periods and stencils, one texel to the right. [`LANES`] such lines walked
//! from their far ends at once visit the same rows at adjacent columns, so one contiguous load
//! per stencil tap serves every lane (AVX2: four f64 lanes per instruction, bit for bit the
//! scalar stencil's operations), and each cache line of the map is fetched once per bundle
//! rather than once per line. Each lane keeps its own hull; the answer of every pixel is the
//! one-line sweep's, operation for operation.
//!
//! **Virtual lines.** Pixel n of lane j is (x₀ + j + n·a, r₀ + n·b), r₀ one of the first |b|
//! rows on the side the walk ends at, n from the far end down to 0. x₀ runs over every column
//! whose line meets the map (also columns left or right of it, for slanted lines), so every
//! pixel is on exactly one lane; a lane is active while its pixel is on the map, which happens
//! over one interval of n, so a lane's hull starts empty and is never reset.

use crate::heightmap::HeightMap;
pub use crate::terrain::horizon::hull::LANES;
use crate::terrain::horizon::hull::{atan_degrees, Hulls};
use crate::terrain::horizon::{
    border_walk, bundle_list, period, Direction, PeriodTexel, Stencil, Stencils,
};
use crate::terrain::sun::Track;
use crate::terrain::transpose::{transpose, transpose_map};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU16, AtomicU32, Ordering};

/// Horizon angles (degrees, row-major) of every pixel along `dir`, by the line sweep; on a
/// planet of radius `planet_radius` metres when given (a sample d metres away drops by
/// d²/(2R), the parabolic approximation of the sphere: see the module notes).
pub fn horizon_sweep(map: &HeightMap, dir: &Direction, planet_radius: Option<f64>) -> Vec<f32> {
    Sweeper::new(map).sweep(dir, planet_radius)
}

/// The line sweep of one map for any number of directions: it keeps the map's transpose, made
/// once on first need, for the directions nearer the x axis than the y axis (the bundles
/// below need |b| ≥ |a|: their lanes are adjacent columns).
pub struct Sweeper<'a> {
    map: &'a HeightMap,
    transposed: std::sync::OnceLock<HeightMap>,
    /// For the f32 sweep: the map less its mid-range height, and that map's transpose.
    centred: std::sync::OnceLock<(HeightMap, HeightMap)>,
}

impl<'a> Sweeper<'a> {
    pub fn new(map: &'a HeightMap) -> Self {
        Sweeper {
            map,
            transposed: std::sync::OnceLock::new(),
            centred: std::sync::OnceLock::new(),
        }
    }

    /// The map's transpose, made on first need.
    fn transposed(&self) -> &HeightMap {
        self.transposed.get_or_init(|| transposed(self.map))
    }

    /// [`horizon_sweep`] along `dir`.
    pub fn sweep(&self, dir: &Direction, planet_radius: Option<f64>) -> Vec<f32> {
        self.sweep_map(dir, planet_radius, &mut Vec::new(), |&a| a)
    }

    /// [`Sweeper::sweep`] with `f` applied to every angle on the way into the returned plane
    /// (row-major), the sweep itself writing into `scratch`. A build over many directions
    /// passes the same scratch every time: the sweep's own plane (4 bytes a texel, the map's
    /// size) is then allocated once, not faulted in afresh for every direction, and a
    /// transposed direction's answer is transposed and mapped in one pass.
    pub fn sweep_map<T: Copy + Default + Send>(
        &self,
        dir: &Direction,
        planet_radius: Option<f64>,
        scratch: &mut Vec<AtomicU32>,
        f: impl Fn(&f32) -> T + Sync,
    ) -> Vec<T> {
        let map = self.map;
        let n = map.width * map.height;
        scratch.truncate(n);
        scratch.resize_with(n, || AtomicU32::new(0));
        // Every texel is on exactly one lane and written once; NaN marks any that were not
        // (the tests compare every texel with the exact horizon) rather than leaving the
        // previous direction's angle there.
        scratch
            .par_iter()
            .for_each(|v| v.store(f32::NAN.to_bits(), Ordering::Relaxed));
        let read = |v: &AtomicU32| f(&f32::from_bits(v.load(Ordering::Relaxed)));
        if dir.a.abs() <= dir.b.abs() {
            sweep_steep(map, dir, planet_radius, scratch);
            return scratch.par_iter().map(read).collect();
        }
        let t = self.transposed();
        // The mirrored direction on the mirrored map: the same tracks, x and y swapped.
        let mirrored = Direction {
            a: dir.b,
            b: dir.a,
            azimuth_deg: dir.azimuth_deg,
        };
        sweep_steep(t, &mirrored, planet_radius, scratch);
        transpose_map(scratch, t.width, t.height, read)
    }
}

impl Sweeper<'_> {
    /// The horizon map's quantised angles (u16, row-major; [`crate::terrain::horizon::map::encode`]'s
    /// steps) along `dir` by the f32 sweep ([`crate::terrain::horizon::sweep_f32`]: within f32 rounding of
    /// [`Sweeper::sweep`]). `scratch` serves the transposed directions as in
    /// [`Sweeper::sweep_map`].
    pub fn sweep_u16(
        &self,
        dir: &Direction,
        planet_radius: Option<f64>,
        scratch: &mut Vec<u16>,
    ) -> Vec<u16> {
        // Heights less their mid-range: f32 keeps a sample's height to half an ulp of the
        // relief's half-range, not of the altitude (a 50 m relief at 3,000 m altitude).
        let (map, t) = self.centred.get_or_init(|| {
            let (lo, hi) = self.map.min_max();
            let mid = (0.5 * (lo as f64 + hi as f64)) as f32;
            let m = self.map;
            let map = HeightMap {
                width: m.width,
                height: m.height,
                heights: crate::cpu::huge_vec(m.heights.len(), |v| {
                    v.extend(m.heights.iter().map(|&h| h - mid))
                }),
                cell_size: m.cell_size,
                height_scale: m.height_scale,
            };
            let t = transposed(&map);
            (map, t)
        });
        let n = map.width * map.height;
        let simd = crate::cpu::Simd::detect();
        if dir.a.abs() <= dir.b.abs() {
            let mut plane = vec![0u16; n];
            crate::terrain::horizon::sweep_f32::sweep_steep_u16(
                map,
                dir,
                planet_radius,
                simd,
                atomics(&mut plane),
            );
            return plane;
        }
        let mirrored = Direction {
            a: dir.b,
            b: dir.a,
            azimuth_deg: dir.azimuth_deg,
        };
        scratch.clear();
        scratch.resize(n, 0);
        crate::terrain::horizon::sweep_f32::sweep_steep_u16(
            t,
            &mirrored,
            planet_radius,
            simd,
            atomics(scratch),
        );
        transpose_map(scratch, t.width, t.height, |&v| v)
    }
}

/// The map with x and y swapped.
fn transposed(map: &HeightMap) -> HeightMap {
    HeightMap {
        width: map.height,
        height: map.width,
        heights: crate::cpu::huge_vec(map.heights.len(), |v| {
            v.extend(transpose(&map.heights, map.width, map.height))
        }),
        cell_size: [map.cell_size[1], map.cell_size[0]],
        height_scale: map.height_scale,
    }
}

/// A plane of u16 seen as atomics, for the sweep's workers to write their texels into (each
/// texel by one lane).
fn atomics(v: &mut [u16]) -> &[AtomicU16] {
    // SAFETY: AtomicU16 has the size, alignment and bit validity of u16, and the exclusive
    // borrow means no other access for the returned lifetime.
    unsafe { &*(v as *mut [u16] as *const [AtomicU16]) }
}

/// The sweep for |b| ≥ |a| on `map` itself, into `out` (the angles' bits, row-major).
fn sweep_steep(map: &HeightMap, dir: &Direction, planet_radius: Option<f64>, out: &[AtomicU32]) {
    let track = dir.track(map.cell_size);
    let per = period(&track, dir);
    // The drop of a sample Δt away: κ·Δt² (t units: metres_per_t metres).
    let kappa = planet_radius.map_or(0.0, |r| track.metres_per_t.powi(2) / (2.0 * r));
    let stencils = Stencils::new(&track, dir, &per);
    sweep_bundles(map, (dir, &track), &per, &stencils, kappa, out)
}

/// What every bundle of one direction shares.
struct Plan<'a> {
    map: &'a HeightMap,
    track: Track,
    dir: Direction,
    per: &'a [PeriodTexel],
    stencils: &'a Stencils,
    /// The period stencils' t from the pixel.
    ts: Vec<f64>,
    period_t: f64,
    kappa: f64,
    avx2: bool,
}

/// How a lane's samples were found at the current pixel.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// Off the map: no pixel.
    Off,
    /// The stencils (every tap on the map): heights in `Lanes::heights`.
    Stencil,
    /// Near the border: the walk's own samples in `Lanes::border`.
    Border,
}

/// One worker's scratch: a hull per lane and the samples of the current pixel.
struct Lanes {
    hulls: Hulls,
    mode: [Mode; LANES],
    /// Stencil mode: the period's heights, [stencil][lane], and the own texel's half and full
    /// transits.
    heights: Vec<[f64; LANES]>,
    own: [f64; LANES],
    full: [f64; LANES],
    /// Border mode, per lane: (t from the pixel, height) of the period's samples on the map
    /// in push order (decreasing t), the own half transit and the full one.
    border: [Vec<(f64, f64)>; LANES],
    border_own: [(f64, f64); LANES],
    border_full: [(f64, f64); LANES],
}

impl Lanes {
    fn new(period: usize) -> Lanes {
        Lanes {
            hulls: Hulls::new(),
            mode: [Mode::Off; LANES],
            heights: vec![[0.0; LANES]; period],
            own: [0.0; LANES],
            full: [0.0; LANES],
            border: std::array::from_fn(|_| Vec::new()),
            border_own: [(0.0, 0.0); LANES],
            border_full: [(0.0, 0.0); LANES],
        }
    }
}

/// Horizon angles (degrees, row-major, as f32 bits) of every pixel of `map` along `dir`
/// (|b| ≥ |a|) into `out`: the per-line sweep of [`crate::terrain::horizon`], on bundles.
pub(super) fn sweep_bundles(
    map: &HeightMap,
    dir: (&Direction, &Track),
    per: &[PeriodTexel],
    stencils: &Stencils,
    kappa: f64,
    out: &[AtomicU32],
) {
    sweep_bundles_with(map, dir, per, stencils, kappa, crate::cpu::has_avx2(), out)
}

/// [`sweep_bundles`] with the AVX2 kernels on or off (they give the same bits).
fn sweep_bundles_with(
    map: &HeightMap,
    (dir, track): (&Direction, &Track),
    per: &[PeriodTexel],
    stencils: &Stencils,
    kappa: f64,
    avx2: bool,
    out: &[AtomicU32],
) {
    assert!(dir.b != 0 && dir.a.abs() <= dir.b.abs());
    let (w, h) = (map.width as i64, map.height as i64);
    let plan = Plan {
        map,
        track: *track,
        dir: *dir,
        per,
        stencils,
        ts: stencils.period.iter().map(|s| s.t).collect(),
        period_t: (dir.a as f64).hypot(dir.b as f64),
        kappa,
        avx2,
    };
    let bundles = bundle_list(map, dir, LANES);
    assert_eq!(out.len(), (w * h) as usize);
    let k = per.len() - 1;
    bundles.par_chunks(8).for_each_init(
        || Lanes::new(k - 1),
        |lanes, chunk| {
            for &(r0, x0, n0, n1) in chunk {
                bundle(&plan, lanes, (r0, x0), (n0, n1), out);
            }
        },
    );
}

/// Walk one bundle from step n1 down to n0: samples for every lane (all lanes' stencils at
/// once where they all fit), then each lane's hull query, as the one-line sweep does.
fn bundle(
    plan: &Plan,
    lanes: &mut Lanes,
    (r0, x0): (i64, i64),
    (n0, n1): (i64, i64),
    out: &[AtomicU32],
) {
    let map = plan.map;
    let (w, h) = (map.width as i64, map.height as i64);
    let (st, hs, kappa) = (plan.stencils, &map.heights, plan.kappa);
    // Every step pushes at most the period's samples and the full transit.
    lanes
        .hulls
        .reset((n1 - n0 + 1) as usize * (plan.per.len() - 1) + 1);
    // Heights on the line's parabola: f(τ) = h − κτ² (module notes of `horizon`).
    let f = |ts: f64, hq: f64| (ts, hq - kappa * ts * ts);
    for n in (n0..=n1).rev() {
        let r = r0 + n * plan.dir.b;
        let c0 = x0 + n * plan.dir.a;
        let tau = n as f64 * plan.period_t;
        let rows_fit = r + st.lo[1] >= 0 && r + st.hi[1] < h;
        let all_fit = rows_fit && c0 + st.lo[0] >= 0 && c0 + LANES as i64 - 1 + st.hi[0] < w;
        // The own texel's half transit, then the tangent to everything beyond it: the
        // horizon's tangent for lane j, in `slopes[j]`.
        let mut slopes = [f64::NAN; LANES];
        let mut finish = |j: usize, own: (f64, f64), s: f64| {
            let zp = hs[(r * w + c0 + j as i64) as usize] as f64;
            let mut best = (own.1 - kappa * own.0 * own.0 - zp) / own.0;
            if s > f64::NEG_INFINITY {
                best = best.max(s + 2.0 * kappa * tau);
            }
            slopes[j] = best / plan.track.metres_per_t;
        };
        if all_fit {
            let first = (r * w + c0) as usize;
            eval_lanes(plan, first, lanes);
            #[cfg(target_arch = "x86_64")]
            if plan.avx2 {
                for g in 0..LANES / 4 {
                    let z =
                        std::array::from_fn(|l| hs[first + 4 * g + l] as f64 - kappa * tau * tau);
                    let full = (st.full.t, &lanes.full);
                    // SAFETY: AVX2 was detected; `reset` left room for every push.
                    let s = unsafe {
                        lanes
                            .hulls
                            .step_avx2(g, &plan.ts, &lanes.heights, full, tau, kappa, z)
                    };
                    for (l, &s) in s.iter().enumerate() {
                        finish(4 * g + l, (st.own.t, lanes.own[4 * g + l]), s);
                    }
                }
                store(
                    &slopes,
                    first as i64,
                    &[Mode::Stencil; LANES],
                    out,
                    plan.avx2,
                );
                continue;
            }
            lanes.mode = [Mode::Stencil; LANES];
        } else {
            for j in 0..LANES {
                let c = c0 + j as i64;
                lanes.mode[j] = if c < 0 || c >= w {
                    Mode::Off
                } else if rows_fit && c + st.lo[0] >= 0 && c + st.hi[0] < w {
                    eval_lane(plan, (r * w + c) as usize, j, lanes);
                    Mode::Stencil
                } else {
                    border_samples(plan, (c, r), j, lanes);
                    Mode::Border
                };
            }
        }
        // One lane at a time: push the period's samples (decreasing τ) before P's query, the
        // own texel crossed in full (≈ P itself) after it.
        for j in 0..LANES {
            let (own, full) = match lanes.mode[j] {
                Mode::Off => continue,
                Mode::Stencil => {
                    for (s, &t) in plan.ts.iter().enumerate().rev() {
                        lanes.hulls.push(j, f(tau + t, lanes.heights[s][j]));
                    }
                    ((st.own.t, lanes.own[j]), f(tau + st.full.t, lanes.full[j]))
                }
                Mode::Border => {
                    for &(t, hq) in &lanes.border[j] {
                        lanes.hulls.push(j, f(tau + t, hq));
                    }
                    let (t, hq) = lanes.border_full[j];
                    (lanes.border_own[j], f(tau + t, hq))
                }
            };
            let zp = hs[(r * w + c0 + j as i64) as usize] as f64;
            let s = lanes.hulls.tangent(j, tau, zp - kappa * tau * tau);
            finish(j, own, s.unwrap_or(f64::NEG_INFINITY));
            lanes.hulls.push(j, full);
        }
        // The bundle's first lane may lie left of the map (c0 < 0 in row 0): index in i64.
        store(&slopes, r * w + c0, &lanes.mode, out, plan.avx2);
    }
}

/// The angles (degrees) of the lanes' horizon tangents into `out` from `first` on (lane j at
/// `first + j`), for the lanes on the map (`first` may be negative when lane 0 is not).
fn store(slopes: &[f64; LANES], first: i64, mode: &[Mode; LANES], out: &[AtomicU32], avx2: bool) {
    let degrees = atan_degrees(slopes, avx2);
    for (j, (&deg, &m)) in degrees.iter().zip(mode).enumerate() {
        if m != Mode::Off {
            out[(first + j as i64) as usize].store((deg as f32).to_bits(), Ordering::Relaxed);
        }
    }
}

/// The walk's own samples of pixel (c, r) near the border, where some stencil tap is off the
/// map: the period's texels up to the edge (the walk stops there), its own texel's half
/// transit, and its full transit as the previous pixel's track crosses it.
fn border_samples(plan: &Plan, (c, r): (i64, i64), j: usize, lanes: &mut Lanes) {
    let border = &mut lanes.border[j];
    let (own, full) = border_walk(plan.map, (&plan.dir, &plan.track), plan.per, (c, r), border);
    lanes.border_own[j] = own;
    lanes.border_full[j] = full;
}

/// Every stencil of the lanes' pixels, lane j at `base + j` (all taps on the map).
fn eval_lanes(plan: &Plan, base: usize, lanes: &mut Lanes) {
    let (hs, w, st) = (&plan.map.heights[..], plan.map.width, plan.stencils);
    #[cfg(target_arch = "x86_64")]
    if plan.avx2 {
        // SAFETY: AVX2 was detected; every tap of every lane is on the map (the caller's test),
        // which is what `eval_avx2` reads.
        unsafe {
            for (s, stencil) in st.period.iter().enumerate() {
                eval_avx2(stencil, hs, base, w, &mut lanes.heights[s]);
            }
            eval_avx2(&st.own, hs, base, w, &mut lanes.own);
            eval_avx2(&st.full, hs, base, w, &mut lanes.full);
        }
        return;
    }
    for j in 0..LANES {
        eval_lane(plan, base + j, j, lanes);
    }
}

/// Every stencil of lane j's pixel at `pixel` (all its taps on the map), by [`Stencil::eval`].
fn eval_lane(plan: &Plan, pixel: usize, j: usize, lanes: &mut Lanes) {
    let (hs, w, st) = (
        &plan.map.heights[..],
        plan.map.width as isize,
        plan.stencils,
    );
    let base = pixel as isize;
    for (s, stencil) in st.period.iter().enumerate() {
        lanes.heights[s][j] = stencil.eval(hs, base, w);
    }
    lanes.own[j] = st.own.eval(hs, base, w);
    lanes.full[j] = st.full.eval(hs, base, w);
}

/// [`Stencil::eval`] of lanes `base + j`, four at a time: the same operations (no FMA), so the
/// same bits.
///
/// # Safety
/// AVX2 must be available, and the taps of lanes 0..LANES (texels `base + j + dy·w + dx` up to
/// one row and one column further) must lie in `hs`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn eval_avx2(st: &Stencil, hs: &[f32], base: usize, w: usize, out: &mut [f64; LANES]) {
    use std::arch::x86_64::*;
    let i = (base as isize + st.dy as isize * w as isize + st.dx as isize) as usize;
    assert!(i + w + LANES < hs.len());
    let (tx, ty) = (_mm256_set1_pd(st.tx), _mm256_set1_pd(st.ty));
    for half in 0..LANES / 4 {
        let p = hs.as_ptr().add(i + 4 * half);
        let a = _mm256_cvtps_pd(_mm_loadu_ps(p));
        let b = _mm256_cvtps_pd(_mm_loadu_ps(p.add(1)));
        let c = _mm256_cvtps_pd(_mm_loadu_ps(p.add(w)));
        let d = _mm256_cvtps_pd(_mm_loadu_ps(p.add(w + 1)));
        let top = _mm256_add_pd(a, _mm256_mul_pd(_mm256_sub_pd(b, a), tx));
        let bottom = _mm256_add_pd(c, _mm256_mul_pd(_mm256_sub_pd(d, c), tx));
        let v = _mm256_add_pd(top, _mm256_mul_pd(_mm256_sub_pd(bottom, top), ty));
        let lo = _mm256_min_pd(_mm256_min_pd(a, b), _mm256_min_pd(c, d));
        let hi = _mm256_max_pd(_mm256_max_pd(a, b), _mm256_max_pd(c, d));
        _mm256_storeu_pd(
            out.as_mut_ptr().add(4 * half),
            _mm256_min_pd(_mm256_max_pd(v, lo), hi),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::horizon::directions;
    use crate::terrain::horizon::test_maps::{map, steep};
    use proptest::prelude::*;

    fn sweep(map: &HeightMap, dir: &Direction, kappa: f64, avx2: bool) -> Vec<f32> {
        let track = dir.track(map.cell_size);
        let per = period(&track, dir);
        let stencils = Stencils::new(&track, dir, &per);
        let out: Vec<AtomicU32> = (0..map.width * map.height)
            .map(|_| AtomicU32::new(f32::NAN.to_bits()))
            .collect();
        sweep_bundles_with(map, (dir, &track), &per, &stencils, kappa, avx2, &out);
        out.into_iter()
            .map(|v| f32::from_bits(v.into_inner()))
            .collect()
    }

    /// Found by the proptest below: in row 0 of an 8-wide map a bundle's first lanes lie left
    /// of the map, and its output index went below zero (an overflow panic where overflow is
    /// checked, as in tests). Both paths, the same bits.
    #[test]
    fn bundles_starting_left_of_a_narrow_map() {
        let m = map(8, 56, 0);
        let d = directions(64, m.cell_size)[17];
        let d = steep(d);
        let slow = sweep(&m, &d, 0.0, false);
        assert!(slow.iter().all(|v| v.is_finite()));
        if crate::cpu::has_avx2() {
            let fast = sweep(&m, &d, 0.0, true);
            assert!(fast
                .iter()
                .zip(&slow)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The AVX2 stencils and hulls give the portable path's bits on every pixel.
        #[test]
        fn avx2_bundles_equal_the_portable_ones(
            w in 8usize..90, h in 8usize..90, seed in any::<u64>(), k in 0usize..64,
            kappa in prop::sample::select(vec![0.0, 1e-6, 0.05]),
        ) {
            // CI machines have AVX2 (x86-64-v3): there the comparison must run.
            if !crate::cpu::has_avx2() {
                prop_assert!(std::env::var_os("CI").is_none(), "no AVX2 on this CI machine");
                return Ok(());
            }
            let m = map(w, h, seed);
            let dirs = directions(64, m.cell_size);
            let d = steep(dirs[k]);
            let fast = sweep(&m, &d, kappa, true);
            let slow = sweep(&m, &d, kappa, false);
            let same = fast.iter().zip(&slow).filter(|(a, b)| a.to_bits() == b.to_bits()).count();
            prop_assert_eq!(same, w * h, "{}x{} {:?}", w, h, d);
        }
    }
}
