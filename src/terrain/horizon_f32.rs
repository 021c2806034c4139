//! The horizon line sweep in f32 (docs/algorithms.md §4.4): the bundles of
//! [`super::horizon_sweep`] — the same lines, periods, stencils and walk order — with f32
//! samples, hulls over fixed-point coordinates, eight lanes per AVX2 instruction
//! ([`super::horizon_hull_f32`]), and the angles quantised to the horizon map's u16 on the way
//! out ([`super::horizon_quantise`]). The f64 sweep is the exact reference (bit for bit the
//! per-pixel walk up to rounding); this one is what [`super::horizon_map::HorizonMap::build`]
//! runs. Its error against the exact horizon is measured in `tests/terrain_horizon.rs` and
//! docs/terrain.md: f32 rounding of the samples and of the slopes, 3e-5° on Puget Sound 4096²
//! (the u16 step is 0.0027°), up to 2e-3° next to a synthetic 178 m cliff between half-metre
//! texels.
//!
//! **Precondition:** a direction (a, b) with |b| ≥ |a| (b ≠ 0), as for the f64 bundles;
//! [`super::horizon_sweep::Sweeper`] transposes the map for the others.

use super::horizon::{border_walk, bundle_list};
use super::horizon::{period, Direction, Stencils};
use super::horizon_hull::LANES;
use super::horizon_hull_f32::{HullsF32, LaneInput, Step};
use super::horizon_quantise::quantise_lanes;
use crate::cpu::Simd;
use crate::heightmap::HeightMap;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU16, Ordering};

/// Quantised horizon angles (the horizon map's u16, row-major) of every pixel of `map` along
/// `dir` (|b| ≥ |a|) into `out`, on a planet of radius `planet_radius` metres when given.
pub(super) fn sweep_steep_u16(
    map: &HeightMap,
    dir: &Direction,
    planet_radius: Option<f64>,
    simd: Simd,
    out: &[AtomicU16],
) {
    assert!(dir.b != 0 && dir.a.abs() <= dir.b.abs());
    assert_eq!(out.len(), map.width * map.height);
    let plan = Plan::new(map, dir, planet_radius, simd);
    let bundles = bundle_list(map, dir);
    bundles.par_chunks(8).for_each_init(
        || Scratch::new(plan.ts.len()),
        |scratch, chunk| {
            for &(r0, x0, n0, n1) in chunk {
                bundle(&plan, scratch, (r0, x0), (n0, n1), out);
            }
        },
    );
}

/// What every bundle of one direction shares.
struct Plan<'a> {
    map: &'a HeightMap,
    dir: Direction,
    track: super::sun::Track,
    per: Vec<super::horizon::PeriodTexel>,
    stencils: Stencils,
    /// The period samples' t from the pixel, nearest first.
    ts: Vec<f64>,
    near_drop: Vec<f32>,
    near_inv: Vec<f32>,
    period_t: f64,
    kappa: f64,
    /// Fixed-point units per t (2^F), and each period sample's t in them (exact i32, and as
    /// f32: a sample's τ less P's).
    units: f64,
    offsets: Vec<i32>,
    offsets_f: Vec<f32>,
    /// The stencils in f32 with their texel offsets from the pixel: the period's, and the own
    /// half transit's.
    taps: Vec<Tap>,
    own_tap: Tap,
    /// The texel offsets from a step's lane-0 pixel of the two ends of each row its stencils
    /// read, [`AHEAD`] steps further on ([`prefetch`]).
    ahead: Vec<isize>,
    /// The level the bundles run at.
    simd: Simd,
}

/// A stencil in f32 ([`eval_f32`]): its top-left tap's offset from the pixel in the map's
/// row-major order, and its weights.
#[derive(Clone, Copy)]
struct Tap {
    at: isize,
    tx: f32,
    ty: f32,
}

impl<'a> Plan<'a> {
    fn new(map: &'a HeightMap, dir: &Direction, planet_radius: Option<f64>, simd: Simd) -> Self {
        let track = dir.track(map.cell_size);
        let per = period(&track, dir);
        let stencils = Stencils::new(&track, dir, &per);
        let kappa = planet_radius.map_or(0.0, |r| track.metres_per_t.powi(2) / (2.0 * r));
        let period_t = (dir.a as f64).hypot(dir.b as f64);
        let ts: Vec<f64> = stencils.period.iter().map(|s| s.t).collect();
        // Every τ of a line: at most (rows/|b| + 2) periods; F bits of fraction keep it < 2^30.
        let tau_max = (map.height as f64 / dir.b.abs() as f64 + 2.0) * period_t;
        let bits = ((1u64 << 30) as f64 / tau_max)
            .log2()
            .floor()
            .clamp(0.0, 24.0);
        let w = map.width as isize;
        let tap = |s: &super::horizon::Stencil| Tap {
            at: s.dy as isize * w + s.dx as isize,
            tx: s.tx as f32,
            ty: s.ty as f32,
        };
        let (taps, own_tap) = (
            stencils.period.iter().map(tap).collect(),
            tap(&stencils.own),
        );
        let units = 2f64.powi(bits as i32);
        let offsets: Vec<i32> = ts.iter().map(|&t| fixed(t, units)).collect();
        let st = &stencils;
        let back = AHEAD as isize * (dir.b as isize * w + dir.a as isize);
        let ahead = (st.lo[1]..=st.hi[1])
            .flat_map(|y| {
                [st.lo[0], LANES as i64 - 1 + st.hi[0]].map(|x| y as isize * w + x as isize - back)
            })
            .collect();
        Plan {
            map,
            dir: *dir,
            track,
            per,
            near_drop: ts.iter().map(|&t| (kappa * t * t) as f32).collect(),
            near_inv: ts.iter().map(|&t| (1.0 / t) as f32).collect(),
            ts,
            stencils,
            period_t,
            kappa,
            units,
            simd,
            offsets_f: offsets.iter().map(|&o| o as f32).collect(),
            offsets,
            taps,
            own_tap,
            ahead,
        }
    }

    /// The steps n of the bundle starting at (r₀, x₀) whose lanes' stencils all lie on the
    /// map (empty when lo > hi): r = r₀ + n·b and c₀ = x₀ + n·a are linear in n, so the
    /// conditions on the stencils' box hold on an interval.
    fn fitting(&self, (r0, x0): (i64, i64)) -> (i64, i64) {
        let (w, h) = (self.map.width as i64, self.map.height as i64);
        let st = &self.stencils;
        let (a, b) = (self.dir.a, self.dir.b);
        let rows = steps_within(-st.lo[1] - r0, h - 1 - st.hi[1] - r0, b);
        let cols = steps_within(-st.lo[0] - x0, w - LANES as i64 - st.hi[0] - x0, a);
        (rows.0.max(cols.0), rows.1.min(cols.1))
    }

    /// Whether the bundles run the AVX2 kernels (at [`Simd::Avx2`] or wider).
    #[inline(always)]
    fn avx2(&self) -> bool {
        self.simd >= Simd::Avx2
    }

    /// τ ≥ 0 to the nearest fixed-point unit ([`fixed`]).
    fn fixed(&self, tau: f64) -> i32 {
        fixed(tau, self.units)
    }
}

/// τ ≥ 0 to the nearest of `units` per t (halves up; no libm call).
fn fixed(tau: f64, units: f64) -> i32 {
    (tau * units + 0.5) as i32
}

/// The n with lo ≤ n·q ≤ hi, as an interval (empty when its start exceeds its end).
fn steps_within(lo: i64, hi: i64, q: i64) -> (i64, i64) {
    let ceil = |p: i64, q: i64| -(-p).div_euclid(q);
    match q.signum() {
        0 if lo <= 0 && 0 <= hi => (i64::MIN, i64::MAX),
        0 => (1, 0),
        1 => (ceil(lo, q), hi.div_euclid(q)),
        _ => (ceil(-hi, -q), (-lo).div_euclid(-q)),
    }
}

/// One worker's scratch.
struct Scratch {
    hulls: HullsF32,
    heights: Vec<[f32; LANES]>,
    drop: Vec<f32>,
    border: Vec<(f64, f64)>,
}

impl Scratch {
    fn new(samples: usize) -> Scratch {
        Scratch {
            hulls: HullsF32::new(),
            heights: vec![[0.0; LANES]; samples],
            drop: vec![0.0; samples],
            border: Vec::new(),
        }
    }
}

/// Walk one bundle from step n1 down to n0 (the f64 sweep's order); compiled for AVX2 as a
/// whole where detected, so that the stencils, hulls and quantisation inline into one loop.
fn bundle(
    plan: &Plan,
    sc: &mut Scratch,
    (r0, x0): (i64, i64),
    (n0, n1): (i64, i64),
    out: &[AtomicU16],
) {
    #[cfg(target_arch = "x86_64")]
    match plan.simd {
        // SAFETY: the plan's level was detected.
        Simd::Avx512 => return unsafe { bundle_avx512(plan, sc, (r0, x0), (n0, n1), out) },
        Simd::Avx2 => return unsafe { bundle_avx2(plan, sc, (r0, x0), (n0, n1), out) },
        Simd::Portable => {}
    }
    bundle_lanes(plan, sc, (r0, x0), (n0, n1), out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn bundle_avx2(
    plan: &Plan,
    sc: &mut Scratch,
    (r0, x0): (i64, i64),
    (n0, n1): (i64, i64),
    out: &[AtomicU16],
) {
    bundle_lanes(plan, sc, (r0, x0), (n0, n1), out)
}

/// [`bundle_avx2`] compiled for x86-64-v4 ([`Simd::Avx512`]): the same intrinsics in EVEX
/// encodings, with thirty-two registers for the step kernel's two dozen live vectors (its period
/// loop reloaded a dozen a round from the stack with sixteen). The same bits (a proptest against
/// the portable lanes); 0.91x the AVX2 build's time at 1024² and 0.94x at 4096² on a Xeon with
/// AVX-512 (docs/terrain.md).
///
/// The AVX2 helpers both entry points call (stencils, hull step, records, quantisation) are
/// `#[inline(always)]` with no target feature of their own, so that each entry point compiles
/// them with its features: with `#[target_feature(enable = "avx2")]` on them, LLVM kept one AVX2
/// copy of the step out of line for both, and this entry point gained nothing.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512bw,avx512cd,avx512dq,avx512vl")]
unsafe fn bundle_avx512(
    plan: &Plan,
    sc: &mut Scratch,
    (r0, x0): (i64, i64),
    (n0, n1): (i64, i64),
    out: &[AtomicU16],
) {
    bundle_lanes(plan, sc, (r0, x0), (n0, n1), out)
}

#[inline(always)]
fn bundle_lanes(
    plan: &Plan,
    sc: &mut Scratch,
    (r0, x0): (i64, i64),
    (n0, n1): (i64, i64),
    out: &[AtomicU16],
) {
    let map = plan.map;
    let (w, h) = (map.width as i64, map.height as i64);
    let (st, hs, kappa) = (&plan.stencils, &map.heights[..], plan.kappa);
    let k = plan.ts.len();
    sc.hulls.reset((n1 - n0 + 1) as usize * (k + 1));
    let inv_m = (1.0 / plan.track.metres_per_t) as f32;
    let (fit0, fit1) = plan.fitting((r0, x0));
    let mut input = LaneInput {
        count: [k as i32; LANES],
        own: [0.0; LANES],
        zp: [0.0; LANES],
        on: [-1; LANES],
    };
    let heights = &mut sc.heights;
    for n in (n0..=n1).rev() {
        let r = r0 + n * plan.dir.b;
        let c0 = x0 + n * plan.dir.a;
        let tau = n as f64 * plan.period_t;
        let xp = plan.fixed(tau);
        if kappa != 0.0 {
            for (d, &t) in sc.drop.iter_mut().zip(&plan.ts) {
                *d = (kappa * (tau + t) * (tau + t)) as f32;
            }
        }
        let base = r * w + c0;
        if (fit0..=fit1).contains(&(n - AHEAD)) {
            prefetch(plan, base);
        }
        let all_fit = (fit0..=fit1).contains(&n);
        if all_fit {
            let base = base as usize;
            input.zp.copy_from_slice(&hs[base..base + LANES]);
            eval_lanes(plan, base, &input.zp, heights, &mut input.own);
            input.count = [k as i32; LANES];
            input.on = [-1; LANES];
        } else {
            input.count = [0; LANES];
            input.on = [0; LANES];
            let rows_fit = r + st.lo[1] >= 0 && r + st.hi[1] < h;
            for j in 0..LANES {
                let c = c0 + j as i64;
                if c < 0 || c >= w {
                    continue;
                }
                let pixel = (r * w + c) as usize;
                input.on[j] = -1;
                let z = hs[pixel];
                input.zp[j] = z;
                if rows_fit && c + st.lo[0] >= 0 && c + st.hi[0] < w {
                    eval_lane(plan, pixel, z, j, heights, &mut input.own);
                    input.count[j] = k as i32;
                } else {
                    let dt = (&plan.dir, &plan.track);
                    let (own, _) = border_walk(map, dt, &plan.per, (c, r), &mut sc.border);
                    // The walk's samples in push order: reversed, they are the first ones.
                    for (s, &(_, hq)) in sc.border.iter().rev().enumerate() {
                        heights[s][j] = (hq - z as f64) as f32;
                    }
                    for row in &mut heights[sc.border.len()..] {
                        row[j] = f32::NEG_INFINITY;
                    }
                    input.own[j] = (own.1 - z as f64) as f32;
                    input.count[j] = sc.border.len() as i32;
                }
            }
        }
        let step = Step {
            xp,
            offsets: &plan.offsets,
            offsets_f: &plan.offsets_f,
            drop: &sc.drop,
            drop_p: (kappa * tau * tau) as f32,
            near_drop: &plan.near_drop,
            near_inv: &plan.near_inv,
            own_drop: (kappa * st.own.t * st.own.t) as f32,
            own_inv: (1.0 / st.own.t) as f32,
            next: plan.fixed(tau + plan.period_t) - xp,
            scale: plan.units as f32,
            shift: (2.0 * kappa * tau) as f32,
        };
        let slopes = sc.hulls.step(&step, &input, heights, plan.avx2());
        let q = quantise_lanes(&slopes, inv_m, plan.avx2());
        let first = base as usize;
        if all_fit {
            // Every lane's pixel is on the map: one store of the eight texels, which no
            // other lane or worker writes (the pixels of a bundle are its own).
            let to = &out[first..first + LANES];
            // SAFETY: eight consecutive texels of `out`, written by this lane alone and read
            // by no one until the sweep returns (an AtomicU16 has u16's layout).
            unsafe { std::ptr::copy_nonoverlapping(q.as_ptr(), to[0].as_ptr(), LANES) };
        } else {
            for j in 0..LANES {
                if input.on[j] != 0 {
                    out[(base + j as i64) as usize].store(q[j], Ordering::Relaxed);
                }
            }
        }
    }
}

/// How many steps ahead of the walk [`prefetch`] asks for the map's rows. On Puget Sound
/// 4096² (64 directions) 1 to 8 steps all gain; 2 gained most, 7 % of the user time against
/// prefetching the step being taken.
const AHEAD: i64 = 2;

/// Ask for the map's texels under the stencils of the step [`AHEAD`] steps on from the one
/// whose lane 0 is pixel `base` (row-major), when all of them are on the map (the caller's
/// test): the walk crosses the map along its direction, b rows a step, so the hardware's
/// prefetchers do not see its rows coming (at 4096², 64 directions, the stencils' loads took a
/// third of the build's time without this).
#[inline(always)]
fn prefetch(plan: &Plan, base: i64) {
    #[cfg(target_arch = "x86_64")]
    for &o in &plan.ahead {
        // SAFETY: SSE is part of x86-64; a prefetch is only a hint, and `wrapping_offset`
        // forms its address without dereferencing it (the caller's test keeps it on the map).
        unsafe {
            use std::arch::x86_64::*;
            let p = plan.map.heights.as_ptr().wrapping_offset(base as isize + o);
            _mm_prefetch::<_MM_HINT_T0>(p as *const i8);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (plan, base);
}

/// A stencil's bilinear sample in f32 ([`Stencil::eval`]'s operations) relative to the
/// pixel's height z: each row's first tap less z, plus the row's own difference times the
/// weight, so that a sample near the pixel keeps the precision of its height difference, not
/// of the heights. (The row's difference b − a is one rounding of the exact one, exact where
/// the taps are within a factor two: no less precise than (b − z) − (a − z), and two
/// subtractions fewer; the planes of Puget Sound at 512² and 1024² did not change.) Unlike the
/// f64 `eval`, no clamp
/// to the taps' range: the blend is a convex combination, which f32 rounding can carry past
/// the range by an ulp of the height difference at most, far below the error budget; the
/// clamp's eight operations were 2–3 % of a horizon build, and on Puget Sound at 1024² and
/// 4096² (64 directions) no quantised angle changed without them.
#[inline]
fn eval_f32(tap: &Tap, hs: &[f32], pixel: usize, w: usize, z: f32) -> f32 {
    let i = (pixel as isize + tap.at) as usize;
    let (a, b, c, d) = (hs[i], hs[i + 1], hs[i + w], hs[i + w + 1]);
    let (tx, ty) = (tap.tx, tap.ty);
    let top = (a - z) + (b - a) * tx;
    let bottom = (c - z) + (d - c) * tx;
    top + (bottom - top) * ty
}

/// Every stencil of the lanes' pixels `base + j` (all taps on the map), relative to their
/// heights `z`: the period's into `heights`, the own half transit into `own`.
#[inline(always)]
fn eval_lanes(
    plan: &Plan,
    base: usize,
    z: &[f32; LANES],
    heights: &mut [[f32; LANES]],
    own: &mut [f32; LANES],
) {
    let (hs, w) = (&plan.map.heights[..], plan.map.width);
    #[cfg(target_arch = "x86_64")]
    if plan.avx2() {
        // Every tap of every lane on the map (the caller's test), checked once for the box.
        let st = &plan.stencils;
        let lo = base as isize + st.lo[1] as isize * w as isize + st.lo[0] as isize;
        let hi = base as isize + st.hi[1] as isize * w as isize + st.hi[0] as isize;
        assert!(lo >= 0 && hi + LANES as isize <= hs.len() as isize);
        // SAFETY: AVX2 was detected; every tap lies in the box just checked.
        unsafe {
            let p = hs.as_ptr().add(base);
            for (tap, out) in plan.taps.iter().zip(heights.iter_mut()) {
                eval_avx2(tap, p, w, z, out);
            }
            eval_avx2(&plan.own_tap, p, w, z, own);
        }
        return;
    }
    for (j, &zj) in z.iter().enumerate() {
        eval_lane(plan, base + j, zj, j, heights, own);
    }
}

/// Every stencil of lane j's pixel (all its taps on the map), relative to its height `z`.
#[inline(always)]
fn eval_lane(
    plan: &Plan,
    pixel: usize,
    z: f32,
    j: usize,
    heights: &mut [[f32; LANES]],
    own: &mut [f32; LANES],
) {
    let (hs, w) = (&plan.map.heights[..], plan.map.width);
    for (tap, row) in plan.taps.iter().zip(heights.iter_mut()) {
        row[j] = eval_f32(tap, hs, pixel, w, z);
    }
    own[j] = eval_f32(&plan.own_tap, hs, pixel, w, z);
}

/// [`eval_f32`] of the eight lanes whose pixel 0 is at `p`: the same operations, the same bits.
///
/// # Safety
/// AVX2 must be available (the caller an AVX2 or wider `#[target_feature]` entry point, into which
/// this inlines), and the taps of lanes 0..LANES must lie in the map `p` points into.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn eval_avx2(tap: &Tap, p: *const f32, w: usize, z: &[f32; LANES], out: &mut [f32; LANES]) {
    use std::arch::x86_64::*;
    let (tx, ty) = (_mm256_set1_ps(tap.tx), _mm256_set1_ps(tap.ty));
    let p = p.offset(tap.at);
    let z = _mm256_loadu_ps(z.as_ptr());
    let (a, b) = (_mm256_loadu_ps(p), _mm256_loadu_ps(p.add(1)));
    let (c, d) = (_mm256_loadu_ps(p.add(w)), _mm256_loadu_ps(p.add(w + 1)));
    let top = _mm256_add_ps(_mm256_sub_ps(a, z), _mm256_mul_ps(_mm256_sub_ps(b, a), tx));
    let bottom = _mm256_add_ps(_mm256_sub_ps(c, z), _mm256_mul_ps(_mm256_sub_ps(d, c), tx));
    let v = _mm256_add_ps(top, _mm256_mul_ps(_mm256_sub_ps(bottom, top), ty));
    _mm256_storeu_ps(out.as_mut_ptr(), v);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::horizon::directions;
    use crate::terrain::horizon::test_maps::{map, steep};
    use proptest::prelude::*;

    fn sweep(map: &HeightMap, dir: &Direction, radius: Option<f64>, simd: Simd) -> Vec<u16> {
        let out: Vec<AtomicU16> = (0..map.width * map.height)
            .map(|_| AtomicU16::new(u16::MAX))
            .collect();
        sweep_steep_u16(map, dir, radius, simd, &out);
        out.into_iter().map(AtomicU16::into_inner).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The AVX2 bundles (stencils, hulls, quantisation), and their x86-64-v4 build where
        /// the CPU has AVX-512, give the portable lanes' bits on every pixel, near the borders
        /// too, flat and curved.
        #[test]
        fn avx2_bundles_equal_the_portable_ones(
            w in 8usize..90, h in 8usize..90, seed in any::<u64>(), k in 0usize..64,
            radius in prop::sample::select(vec![None, Some(6.371e6), Some(2000.0)]),
        ) {
            // CI machines have AVX2 (x86-64-v3): there the comparison must run.
            if !crate::cpu::has_avx2() {
                prop_assert!(std::env::var_os("CI").is_none(), "no AVX2 on this CI machine");
                return Ok(());
            }
            let m = map(w, h, seed);
            let d = steep(directions(64, m.cell_size)[k]);
            let slow = sweep(&m, &d, radius, Simd::Portable);
            prop_assert!(slow.iter().all(|&v| v != u16::MAX), "a texel was not written");
            for simd in Simd::available().into_iter().skip(1) {
                let fast = sweep(&m, &d, radius, simd);
                let same = fast.iter().zip(&slow).filter(|(a, b)| a == b).count();
                prop_assert_eq!(same, w * h, "{:?} {}x{} {:?}", simd, w, h, d);
            }
        }

        /// `steps_within` is exactly the n with lo ≤ n·q ≤ hi (brute force over a window
        /// wider than every answer drawn here).
        #[test]
        fn steps_within_is_the_brute_force_interval(
            lo in -60i64..60, span in -5i64..60, q in -7i64..8,
        ) {
            let hi = lo + span;
            let (a, b) = steps_within(lo, hi, q);
            for n in -200i64..=200 {
                let inside = lo <= n * q && n * q <= hi;
                prop_assert_eq!(inside, a <= n && n <= b, "n {} q {} [{}, {}]", n, q, lo, hi);
            }
        }

        /// A bundle's all-fit interval holds exactly the steps at which every lane's stencils
        /// lie on the map (the box test per step that it replaces).
        #[test]
        fn fitting_steps_are_those_whose_stencils_lie_on_the_map(
            w in 8usize..70, h in 8usize..70, k in 0usize..64,
        ) {
            let m = map(w, h, 7);
            let d = steep(directions(64, m.cell_size)[k]);
            let plan = Plan::new(&m, &d, None, Simd::Portable);
            let (st, (wi, hi)) = (&plan.stencils, (w as i64, h as i64));
            for &(r0, x0, n0, n1) in &bundle_list(&m, &d) {
                let (f0, f1) = plan.fitting((r0, x0));
                for n in n0..=n1 {
                    let (r, c0) = (r0 + n * d.b, x0 + n * d.a);
                    let fits = r + st.lo[1] >= 0
                        && r + st.hi[1] < hi
                        && c0 + st.lo[0] >= 0
                        && c0 + LANES as i64 - 1 + st.hi[0] < wi;
                    prop_assert_eq!(fits, f0 <= n && n <= f1, "{:?} bundle {:?} n {}", d, (r0, x0), n);
                }
            }
        }
    }
}
