//! The horizon line sweep in f32 (docs/algorithms.md §4.4): the bundles of [`crate::terrain::horizon::sweep`]
//! — the same lines, periods, stencils and walk order — with f32 samples, hulls over fixed-point
//! coordinates, bundles of eight lines in AVX2 or sixteen in AVX-512 ([`crate::terrain::horizon::hull_f32`],
//! [`crate::terrain::horizon::lanes`]), and the angles quantised to the horizon map's u16 on the way out
//! ([`crate::terrain::horizon::quantise`]). The f64 sweep is the exact reference (bit for bit the per-pixel
//! walk up to rounding); this one is what [`crate::terrain::horizon::map::HorizonMap::build`] runs. Its error
//! against the exact horizon is measured in `tests/terrain/horizon.rs` and docs/terrain.md: f32
//! rounding of the samples and of the slopes, 3e-5° on Puget Sound 4096² (the u16 step is 0.0027°),
//! up to 2e-3° next to a synthetic 178 m cliff between half-metre texels.
//!
//! **Precondition:** a direction (a, b) with |b| ≥ |a| (b ≠ 0), as for the f64 bundles;
//! [`crate::terrain::horizon::sweep::Sweeper`] transposes the map for the others.

use crate::cpu::Simd;
use crate::heightmap::HeightMap;
use crate::terrain::horizon::hull_f32::{HullsF32, LaneInput, Step};
#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::lanes::{Avx2, Avx512};
#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::plan::eval_simd;
use crate::terrain::horizon::plan::{eval_lane, prefetch, Plan, AHEAD};
use crate::terrain::horizon::quantise::quantise;
#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::quantise::quantise_simd;
use crate::terrain::horizon::{border_walk, bundle_list, Direction};
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
    match simd {
        #[cfg(target_arch = "x86_64")]
        Simd::Avx512 => sweep_lanes::<16, _>(Avx512, map, dir, planet_radius, out),
        #[cfg(target_arch = "x86_64")]
        Simd::Avx2 => sweep_lanes::<8, _>(Avx2, map, dir, planet_radius, out),
        _ => sweep_lanes::<8, _>(Portable, map, dir, planet_radius, out),
    }
}

/// [`sweep_steep_u16`] in bundles of N lines, run by kernel `K` (a level the CPU runs).
fn sweep_lanes<const N: usize, K: Kernel<N>>(
    kernel: K,
    map: &HeightMap,
    dir: &Direction,
    planet_radius: Option<f64>,
    out: &[AtomicU16],
) {
    // The kernel needs its level's instructions: never above what the CPU runs.
    let cpu = Simd::widest();
    assert!(
        K::LEVEL <= cpu,
        "{:?} asked of a CPU that runs {cpu:?}",
        K::LEVEL
    );
    let plan = Plan::new(map, dir, planet_radius, N);
    let bundles = bundle_list(map, dir, N);
    bundles.par_chunks(8).for_each_init(
        || Scratch::<N>::new(plan.ts.len()),
        |scratch, chunk| {
            for &(r0, x0, n0, n1) in chunk {
                // SAFETY: the kernel's level was checked against the CPU's above.
                unsafe { kernel.walk(&plan, scratch, (r0, x0), (n0, n1), out) };
            }
        },
    );
}

/// The lanes a bundle of N lines runs in: the portable code ([`Portable`], any N) or a vector
/// width ([`Avx2`], eight lanes; [`Avx512`], sixteen): its stencils, hull step and
/// quantisation, the same bits in each (the proptests below and in the kernels' modules).
///
/// # Safety
/// Every method requires the kernel's CPU features (none for [`Portable`]).
trait Kernel<const N: usize>: Copy + Send + Sync {
    /// The instructions the kernel needs.
    const LEVEL: Simd;
    /// Walk one bundle ([`bundle_lanes`]), compiled for the kernel's features as a whole.
    unsafe fn walk(
        self,
        plan: &Plan,
        sc: &mut Scratch<N>,
        start: (i64, i64),
        steps: (i64, i64),
        out: &[AtomicU16],
    );
    /// Every stencil of the lanes' pixels `base + j`, all taps on the map ([`eval_lane`]).
    unsafe fn eval(
        self,
        plan: &Plan,
        base: usize,
        z: &[f32; N],
        heights: &mut [[f32; N]],
        own: &mut [f32; N],
    );
    /// One pixel step of the lanes' hulls ([`HullsF32::step`]).
    unsafe fn step(
        self,
        hulls: &mut HullsF32<N>,
        s: &Step,
        l: &LaneInput<N>,
        heights: &[[f32; N]],
    ) -> [f32; N];
    /// The lanes' slopes to u16 steps ([`quantise`]).
    unsafe fn quantise(self, slopes: &[f32; N], inv_m: f32) -> [u16; N];
}

/// The portable lanes: one lane at a time, the twin of the vector kernels.
#[derive(Clone, Copy)]
struct Portable;

impl<const N: usize> Kernel<N> for Portable {
    const LEVEL: Simd = Simd::Portable;
    unsafe fn walk(
        self,
        plan: &Plan,
        sc: &mut Scratch<N>,
        start: (i64, i64),
        steps: (i64, i64),
        out: &[AtomicU16],
    ) {
        bundle_lanes(self, plan, sc, start, steps, out)
    }
    #[inline(always)]
    unsafe fn eval(
        self,
        plan: &Plan,
        base: usize,
        z: &[f32; N],
        heights: &mut [[f32; N]],
        own: &mut [f32; N],
    ) {
        for (j, &zj) in z.iter().enumerate() {
            eval_lane(plan, base + j, zj, j, heights, own);
        }
    }
    #[inline(always)]
    unsafe fn step(
        self,
        hulls: &mut HullsF32<N>,
        s: &Step,
        l: &LaneInput<N>,
        heights: &[[f32; N]],
    ) -> [f32; N] {
        hulls.step(s, l, heights)
    }
    #[inline(always)]
    unsafe fn quantise(self, slopes: &[f32; N], inv_m: f32) -> [u16; N] {
        quantise(slopes, inv_m)
    }
}

/// The vector kernels: [`Lanes`] `V` of N lanes, walked by the entry point `$walk`.
#[cfg(target_arch = "x86_64")]
macro_rules! vector_kernel {
    ($v:ty, $n:literal, $walk:ident, $level:expr) => {
        impl Kernel<$n> for $v {
            const LEVEL: Simd = $level;
            unsafe fn walk(
                self,
                plan: &Plan,
                sc: &mut Scratch<$n>,
                start: (i64, i64),
                steps: (i64, i64),
                out: &[AtomicU16],
            ) {
                $walk(plan, sc, start, steps, out)
            }
            #[inline(always)]
            unsafe fn eval(
                self,
                plan: &Plan,
                base: usize,
                z: &[f32; $n],
                heights: &mut [[f32; $n]],
                own: &mut [f32; $n],
            ) {
                eval_simd::<$v, $n>(plan, base, z, heights, own)
            }
            #[inline(always)]
            unsafe fn step(
                self,
                hulls: &mut HullsF32<$n>,
                s: &Step,
                l: &LaneInput<$n>,
                heights: &[[f32; $n]],
            ) -> [f32; $n] {
                hulls.step_simd::<$v>(s, l, heights)
            }
            #[inline(always)]
            unsafe fn quantise(self, slopes: &[f32; $n], inv_m: f32) -> [u16; $n] {
                quantise_simd::<$v, $n>(slopes, inv_m)
            }
        }
    };
}
#[cfg(target_arch = "x86_64")]
vector_kernel!(Avx2, 8, bundle_avx2, Simd::Avx2);
#[cfg(target_arch = "x86_64")]
vector_kernel!(Avx512, 16, bundle_avx512, Simd::Avx512);

/// One worker's scratch.
struct Scratch<const N: usize> {
    hulls: HullsF32<N>,
    heights: Vec<[f32; N]>,
    drop: Vec<f32>,
    border: Vec<(f64, f64)>,
}

impl<const N: usize> Scratch<N> {
    fn new(samples: usize) -> Self {
        Scratch {
            hulls: HullsF32::new(),
            heights: vec![[0.0; N]; samples],
            drop: vec![0.0; samples],
            border: Vec::new(),
        }
    }
}

/// [`bundle_lanes`] in eight lanes of AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn bundle_avx2(
    plan: &Plan,
    sc: &mut Scratch<8>,
    start: (i64, i64),
    steps: (i64, i64),
    out: &[AtomicU16],
) {
    bundle_lanes(Avx2, plan, sc, start, steps, out)
}

/// [`bundle_lanes`] in sixteen lanes of AVX-512 (x86-64-v4).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512bw,avx512cd,avx512dq,avx512vl")]
unsafe fn bundle_avx512(
    plan: &Plan,
    sc: &mut Scratch<16>,
    start: (i64, i64),
    steps: (i64, i64),
    out: &[AtomicU16],
) {
    bundle_lanes(Avx512, plan, sc, start, steps, out)
}

/// Walk one bundle from step n1 down to n0 (the f64 sweep's order) in kernel `K`; inlined
/// whole into each kernel's entry point, so that the stencils, hulls and quantisation compile
/// into one loop with its features. (The kernels' helpers are `#[inline(always)]` with no
/// target feature of their own: with `#[target_feature(enable = "avx2")]` on them, LLVM kept
/// one AVX2 copy of the hull step out of line for the AVX2 and x86-64-v4 entry points alike.)
///
/// # Safety
/// The CPU must have `K`'s features.
#[inline(always)]
unsafe fn bundle_lanes<const N: usize, K: Kernel<N>>(
    kernel: K,
    plan: &Plan,
    sc: &mut Scratch<N>,
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
        count: [k as i32; N],
        own: [0.0; N],
        zp: [0.0; N],
        on: [-1; N],
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
            input.zp.copy_from_slice(&hs[base..base + N]);
            kernel.eval(plan, base, &input.zp, heights, &mut input.own);
            input.count = [k as i32; N];
            input.on = [-1; N];
        } else {
            input.count = [0; N];
            input.on = [0; N];
            let rows_fit = r + st.lo[1] >= 0 && r + st.hi[1] < h;
            for j in 0..N {
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
        let slopes = kernel.step(&mut sc.hulls, &step, &input, heights);
        let q = kernel.quantise(&slopes, inv_m);
        let first = base as usize;
        if all_fit {
            // Every lane's pixel is on the map: one store of the N texels, which no other
            // bundle or worker writes (the pixels of a bundle are its own).
            let to = &out[first..first + N];
            // SAFETY: N consecutive texels of `out`, written by this bundle alone and read by
            // no one until the sweep returns (an AtomicU16 has u16's layout).
            unsafe { std::ptr::copy_nonoverlapping(q.as_ptr(), to[0].as_ptr(), N) };
        } else {
            for j in 0..N {
                if input.on[j] != 0 {
                    out[(base + j as i64) as usize].store(q[j], Ordering::Relaxed);
                }
            }
        }
    }
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

    /// Maps narrower or shorter than a bundle, and widths around one and two bundles of eight
    /// and sixteen lanes: every level and the sixteen portable lanes give the portable eight
    /// lanes' bits on every pixel, for every one of 16 directions.
    #[test]
    fn every_level_agrees_on_maps_of_a_bundles_width() {
        for (w, h) in [
            (1, 1),
            (1, 5),
            (3, 2),
            (7, 9),
            (8, 8),
            (9, 3),
            (15, 17),
            (16, 16),
        ]
        .into_iter()
        .chain([(17, 12), (31, 4), (32, 33), (33, 16), (48, 2)])
        {
            let m = map(w, h, (w * 131 + h) as u64);
            for d in directions(16, m.cell_size).into_iter().map(steep) {
                let slow = sweep(&m, &d, None, Simd::Portable);
                assert!(
                    slow.iter().all(|&v| v != u16::MAX),
                    "{w}x{h} {d:?}: unwritten"
                );
                let out: Vec<AtomicU16> = (0..w * h).map(|_| AtomicU16::new(u16::MAX)).collect();
                sweep_lanes::<16, _>(Portable, &m, &d, None, &out);
                let wide: Vec<u16> = out.into_iter().map(AtomicU16::into_inner).collect();
                assert_eq!(wide, slow, "sixteen portable lanes, {w}x{h} {d:?}");
                for simd in Simd::available().into_iter().skip(1) {
                    assert_eq!(sweep(&m, &d, None, simd), slow, "{simd:?} {w}x{h} {d:?}");
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The vector bundles (stencils, hulls, quantisation) — eight lanes of AVX2, and
        /// sixteen of AVX-512 where the CPU has it — and the portable lanes in bundles of
        /// sixteen give the portable eight lanes' bits on every pixel, near the borders too,
        /// flat and curved.
        #[test]
        fn vector_bundles_equal_the_portable_ones(
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
            let out: Vec<AtomicU16> = (0..w * h).map(|_| AtomicU16::new(u16::MAX)).collect();
            sweep_lanes::<16, _>(Portable, &m, &d, radius, &out);
            let wide: Vec<u16> = out.into_iter().map(AtomicU16::into_inner).collect();
            prop_assert!(wide == slow, "sixteen portable lanes {}x{} {:?}", w, h, d);
            for simd in Simd::available().into_iter().skip(1) {
                let fast = sweep(&m, &d, radius, simd);
                let same = fast.iter().zip(&slow).filter(|(a, b)| a == b).count();
                prop_assert_eq!(same, w * h, "{:?} {}x{} {:?}", simd, w, h, d);
            }
        }
    }
}
