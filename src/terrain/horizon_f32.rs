//! The horizon line sweep in f32 (docs/algorithms.md §4.4): the bundles of
//! [`super::horizon_sweep`] — the same lines, periods, stencils and walk order — with f32
//! samples, hulls over fixed-point coordinates, eight lanes per AVX2 instruction
//! ([`super::horizon_hull_f32`]), and the angles quantised to the horizon map's u16 on the way
//! out. The f64 sweep is the exact reference (bit for bit the per-pixel walk up to rounding);
//! this one is what [`super::horizon_map::HorizonMap::build`] runs. Its error against the exact
//! horizon is measured in `tests/terrain_horizon.rs` and docs/terrain.md: f32 rounding of the
//! samples and of the slopes, 3e-5° on Puget Sound 4096² (the u16 step is 0.0027°), up to
//! 2e-3° next to a synthetic 178 m cliff between half-metre texels.
//!
//! **Precondition:** a direction (a, b) with |b| ≥ |a| (b ≠ 0), as for the f64 bundles;
//! [`super::horizon_sweep::Sweeper`] transposes the map for the others.

use super::horizon::{border_walk, bundle_list};
use super::horizon::{encode, STEP_DEG};
use super::horizon::{period, Direction, Stencil, Stencils};
use super::horizon_hull::LANES;
use super::horizon_hull_f32::{HullsF32, LaneInput, Step};
use crate::heightmap::HeightMap;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU16, Ordering};

/// Quantised horizon angles (the horizon map's u16, row-major) of every pixel of `map` along
/// `dir` (|b| ≥ |a|) into `out`, on a planet of radius `planet_radius` metres when given.
pub(super) fn sweep_steep_u16(
    map: &HeightMap,
    dir: &Direction,
    planet_radius: Option<f64>,
    avx2: bool,
    out: &[AtomicU16],
) {
    assert!(dir.b != 0 && dir.a.abs() <= dir.b.abs());
    assert_eq!(out.len(), map.width * map.height);
    let plan = Plan::new(map, dir, planet_radius, avx2);
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
    /// Fixed-point units per t (2^F), and each period sample's t in them.
    units: f64,
    offsets: Vec<i32>,
    avx2: bool,
}

impl<'a> Plan<'a> {
    fn new(map: &'a HeightMap, dir: &Direction, planet_radius: Option<f64>, avx2: bool) -> Self {
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
        let mut plan = Plan {
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
            units: 2f64.powi(bits as i32),
            avx2,
            offsets: Vec::new(),
        };
        plan.offsets = plan.ts.iter().map(|&t| plan.fixed(t)).collect();
        plan
    }

    /// τ ≥ 0 to the nearest fixed-point unit (halves up; no libm call).
    fn fixed(&self, tau: f64) -> i32 {
        (tau * self.units + 0.5) as i32
    }
}

/// One worker's scratch.
struct Scratch {
    hulls: HullsF32,
    heights: Vec<[f32; LANES]>,
    xs: Vec<i32>,
    drop: Vec<f32>,
    border: Vec<(f64, f64)>,
}

impl Scratch {
    fn new(samples: usize) -> Scratch {
        Scratch {
            hulls: HullsF32::new(),
            heights: vec![[0.0; LANES]; samples],
            xs: vec![0; samples],
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
    if plan.avx2 {
        // SAFETY: the plan's avx2 was detected.
        return unsafe { bundle_avx2(plan, sc, (r0, x0), (n0, n1), out) };
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
    for n in (n0..=n1).rev() {
        let r = r0 + n * plan.dir.b;
        let c0 = x0 + n * plan.dir.a;
        let tau = n as f64 * plan.period_t;
        let xp = plan.fixed(tau);
        for (x, &off) in sc.xs.iter_mut().zip(&plan.offsets) {
            *x = xp + off;
        }
        if kappa != 0.0 {
            for (d, &t) in sc.drop.iter_mut().zip(&plan.ts) {
                *d = (kappa * (tau + t) * (tau + t)) as f32;
            }
        }
        prefetch(plan, r - AHEAD * plan.dir.b, c0 - AHEAD * plan.dir.a);
        let rows_fit = r + st.lo[1] >= 0 && r + st.hi[1] < h;
        let all_fit = rows_fit && c0 + st.lo[0] >= 0 && c0 + LANES as i64 - 1 + st.hi[0] < w;
        let mut input = LaneInput {
            heights: &[],
            count: [0; LANES],
            own: [0.0; LANES],
            zp: [0.0; LANES],
            on: [0; LANES],
        };
        if all_fit {
            let base = (r * w + c0) as usize;
            for (z, &v) in input.zp.iter_mut().zip(&hs[base..base + LANES]) {
                *z = v;
            }
            eval_lanes(plan, base, &input.zp, &mut sc.heights, &mut input.own);
            input.count = [k as i32; LANES];
            input.on = [-1; LANES];
        } else {
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
                    eval_lane(plan, pixel, z, j, &mut sc.heights, &mut input.own);
                    input.count[j] = k as i32;
                } else {
                    let dt = (&plan.dir, &plan.track);
                    let (own, _) = border_walk(map, dt, &plan.per, (c, r), &mut sc.border);
                    // The walk's samples in push order: reversed, they are the first ones.
                    for (s, &(_, hq)) in sc.border.iter().rev().enumerate() {
                        sc.heights[s][j] = (hq - z as f64) as f32;
                    }
                    for row in &mut sc.heights[sc.border.len()..] {
                        row[j] = f32::NEG_INFINITY;
                    }
                    input.own[j] = (own.1 - z as f64) as f32;
                    input.count[j] = sc.border.len() as i32;
                }
            }
        }
        input.heights = &sc.heights;
        let step = Step {
            xp,
            xs: &sc.xs,
            drop: &sc.drop,
            drop_p: (kappa * tau * tau) as f32,
            near_drop: &plan.near_drop,
            near_inv: &plan.near_inv,
            own_drop: (kappa * st.own.t * st.own.t) as f32,
            own_inv: (1.0 / st.own.t) as f32,
            dx_next: (plan.fixed(tau + plan.period_t) - xp) as f32,
            scale: plan.units as f32,
            shift: (2.0 * kappa * tau) as f32,
        };
        let slopes = sc.hulls.step(&step, &input, plan.avx2);
        let q = quantise_lanes(&slopes, inv_m, plan.avx2);
        let first = r * w + c0;
        if all_fit {
            // Every lane's pixel is on the map: one store of the eight texels, which no
            // other lane or worker writes (the pixels of a bundle are its own).
            let to = &out[first as usize..first as usize + LANES];
            // SAFETY: eight consecutive texels of `out`, written by this lane alone and read
            // by no one until the sweep returns (an AtomicU16 has u16's layout).
            unsafe { std::ptr::copy_nonoverlapping(q.as_ptr(), to[0].as_ptr(), LANES) };
        } else {
            for j in 0..LANES {
                if input.on[j] != 0 {
                    out[(first + j as i64) as usize].store(q[j], Ordering::Relaxed);
                }
            }
        }
    }
}

/// How many steps ahead of the walk [`prefetch`] asks for the map's rows. On Puget Sound
/// 4096² (64 directions) 1 to 8 steps all gain; 2 gained most, 7 % of the user time against
/// prefetching the step being taken.
const AHEAD: i64 = 2;

/// Ask for the map's texels under the stencils of the step whose lane 0 is pixel (c0, r), when
/// all of them are on the map: the walk crosses the map along its direction, b rows a step, so
/// the hardware's prefetchers do not see its rows coming (at 4096², 64 directions, the
/// stencils' loads took a third of the build's time without this).
#[inline(always)]
fn prefetch(plan: &Plan, r: i64, c0: i64) {
    #[cfg(target_arch = "x86_64")]
    {
        let (st, map) = (&plan.stencils, plan.map);
        let (w, h) = (map.width as i64, map.height as i64);
        let (ca, cb) = (c0 + st.lo[0], c0 + LANES as i64 - 1 + st.hi[0]);
        if r + st.lo[1] >= 0 && r + st.hi[1] < h && ca >= 0 && cb < w {
            for y in r + st.lo[1]..=r + st.hi[1] {
                let row = &map.heights[(y * w) as usize..][..w as usize];
                for x in [ca, cb] {
                    // SAFETY: SSE is part of x86-64; a prefetch of a texel on the map.
                    unsafe {
                        use std::arch::x86_64::*;
                        _mm_prefetch::<_MM_HINT_T0>(row.as_ptr().add(x as usize) as *const i8);
                    }
                }
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (plan, r, c0);
}

/// A stencil's bilinear sample in f32 ([`Stencil::eval`]'s operations) relative to the
/// pixel's height z: the taps less z first, so that a sample near the pixel keeps the
/// precision of its height difference, not of the heights. Unlike the f64 `eval`, no clamp
/// to the taps' range: the blend is a convex combination, which f32 rounding can carry past
/// the range by an ulp of the height difference at most, far below the error budget; the
/// clamp's eight operations were 2–3 % of a horizon build, and on Puget Sound at 1024² and
/// 4096² (64 directions) no quantised angle changed without them.
#[inline]
fn eval_f32(st: &Stencil, hs: &[f32], pixel: usize, w: usize, z: f32) -> f32 {
    let i = (pixel as isize + st.dy as isize * w as isize + st.dx as isize) as usize;
    let (a, b, c, d) = (hs[i] - z, hs[i + 1] - z, hs[i + w] - z, hs[i + w + 1] - z);
    let (tx, ty) = (st.tx as f32, st.ty as f32);
    let top = a + (b - a) * tx;
    let bottom = c + (d - c) * tx;
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
    let (hs, w, st) = (&plan.map.heights[..], plan.map.width, &plan.stencils);
    #[cfg(target_arch = "x86_64")]
    if plan.avx2 {
        // SAFETY: AVX2 was detected; every tap of every lane is on the map (the caller's test).
        unsafe {
            for (s, stencil) in st.period.iter().enumerate() {
                eval_avx2(stencil, hs, base, w, z, &mut heights[s]);
            }
            eval_avx2(&st.own, hs, base, w, z, own);
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
    let (hs, w, st) = (&plan.map.heights[..], plan.map.width, &plan.stencils);
    for (s, stencil) in st.period.iter().enumerate() {
        heights[s][j] = eval_f32(stencil, hs, pixel, w, z);
    }
    own[j] = eval_f32(&st.own, hs, pixel, w, z);
}

/// [`eval_f32`] of lanes `base + j`, eight at a time: the same operations, the same bits.
///
/// # Safety
/// AVX2 must be available, and the taps of lanes 0..LANES must lie in `hs`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn eval_avx2(
    st: &Stencil,
    hs: &[f32],
    base: usize,
    w: usize,
    z: &[f32; LANES],
    out: &mut [f32; LANES],
) {
    use std::arch::x86_64::*;
    let i = (base as isize + st.dy as isize * w as isize + st.dx as isize) as usize;
    assert!(i + w + LANES < hs.len());
    let (tx, ty) = (_mm256_set1_ps(st.tx as f32), _mm256_set1_ps(st.ty as f32));
    let p = hs.as_ptr().add(i);
    let z = _mm256_loadu_ps(z.as_ptr());
    let a = _mm256_sub_ps(_mm256_loadu_ps(p), z);
    let b = _mm256_sub_ps(_mm256_loadu_ps(p.add(1)), z);
    let c = _mm256_sub_ps(_mm256_loadu_ps(p.add(w)), z);
    let d = _mm256_sub_ps(_mm256_loadu_ps(p.add(w + 1)), z);
    let top = _mm256_add_ps(a, _mm256_mul_ps(_mm256_sub_ps(b, a), tx));
    let bottom = _mm256_add_ps(c, _mm256_mul_ps(_mm256_sub_ps(d, c), tx));
    let v = _mm256_add_ps(top, _mm256_mul_ps(_mm256_sub_ps(bottom, top), ty));
    _mm256_storeu_ps(out.as_mut_ptr(), v);
}

/// Slopes (t units) to the horizon map's u16: atan of slope/metres_per_t in degrees
/// ([`atan_f32`]), then [`encode`]'s step in f64, as the f64 sweep's map is quantised (flat
/// ground's 0° is 90/STEP_DEG = 32767.499999999996 steps in f64, so 32767 in both). The
/// portable twin of [`quantise_avx2`].
#[inline(always)]
fn quantise(slopes: &[f32; LANES], inv_m: f32) -> [u16; LANES] {
    let mut out = [0u16; LANES];
    for (o, &s) in out.iter_mut().zip(slopes) {
        let deg = atan_f32(s * inv_m) * (180.0 / std::f32::consts::PI);
        *o = encode(deg as f64);
    }
    out
}

/// [`quantise`] of eight lanes, in AVX2 where `avx2` (detected): the same operations, the
/// same bits (a proptest).
#[inline(always)]
fn quantise_lanes(slopes: &[f32; LANES], inv_m: f32, avx2: bool) -> [u16; LANES] {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: AVX2 was detected.
        return unsafe { quantise_avx2(slopes, inv_m) };
    }
    let _ = avx2;
    quantise(slopes, inv_m)
}

/// [`quantise`] on eight lanes: [`atan_f32`]'s selects as blends, then [`encode`] in two
/// halves of four f64 lanes. A NaN slope gives 0 as `encode` does (`max` returns its second
/// operand, −90°, for a NaN first one).
///
/// # Safety
/// AVX2 must be available.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn quantise_avx2(slopes: &[f32; LANES], inv_m: f32) -> [u16; LANES] {
    use std::arch::x86_64::*;
    let f = _mm256_set1_ps;
    let v = _mm256_mul_ps(_mm256_loadu_ps(slopes.as_ptr()), f(inv_m));
    let sign = _mm256_and_ps(v, f(-0.0));
    let a = _mm256_andnot_ps(f(-0.0), v);
    let big = _mm256_cmp_ps::<_CMP_GT_OQ>(a, f(TAN_3PI_8));
    let mid = _mm256_cmp_ps::<_CMP_GT_OQ>(a, f(TAN_PI_8));
    let r_big = _mm256_div_ps(f(-1.0), a);
    let r_mid = _mm256_div_ps(_mm256_sub_ps(a, f(1.0)), _mm256_add_ps(a, f(1.0)));
    let r = _mm256_blendv_ps(_mm256_blendv_ps(a, r_mid, mid), r_big, big);
    let base = _mm256_blendv_ps(
        _mm256_blendv_ps(f(0.0), f(std::f32::consts::FRAC_PI_4), mid),
        f(std::f32::consts::FRAC_PI_2),
        big,
    );
    let z = _mm256_mul_ps(r, r);
    let [c0, c1, c2, c3] = ATAN_POLY;
    let mut p = _mm256_sub_ps(_mm256_mul_ps(f(c0), z), f(c1));
    p = _mm256_add_ps(_mm256_mul_ps(p, z), f(c2));
    p = _mm256_sub_ps(_mm256_mul_ps(p, z), f(c3));
    p = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(p, z), r), r);
    let atan = _mm256_or_ps(_mm256_andnot_ps(f(-0.0), _mm256_add_ps(base, p)), sign);
    let deg = _mm256_mul_ps(atan, f(180.0 / std::f32::consts::PI));
    let half = |d: __m128| {
        let d = _mm256_max_pd(_mm256_cvtps_pd(d), _mm256_set1_pd(-90.0));
        let d = _mm256_min_pd(d, _mm256_set1_pd(90.0));
        let x = _mm256_div_pd(
            _mm256_add_pd(d, _mm256_set1_pd(90.0)),
            _mm256_set1_pd(STEP_DEG),
        );
        let whole = _mm256_cvttpd_epi32(x);
        let frac = _mm256_sub_pd(x, _mm256_cvtepi32_pd(whole));
        let up = _mm256_cmp_pd::<_CMP_GE_OQ>(frac, _mm256_set1_pd(0.5));
        // The all-ones mask of four lanes, packed to i32, is −1: subtracting it adds one.
        let up = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(
            _mm256_castpd_si256(up),
            _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6),
        ));
        _mm_sub_epi32(whole, up)
    };
    let lo = half(_mm256_castps256_ps128(deg));
    let hi = half(_mm256_extractf128_ps::<1>(deg));
    let mut out = [0u16; LANES];
    _mm_storeu_si128(out.as_mut_ptr() as *mut __m128i, _mm_packus_epi32(lo, hi));
    out
}

/// Cephes' `atanf` reduction bounds, tan(3π/8) and tan(π/8), and its polynomial's magnitudes
/// ((c₀z − c₁)z + c₂)z − c₃, shared by [`atan_f32`] and [`quantise_avx2`].
#[allow(clippy::excessive_precision)] // Cephes' constants as published
const TAN_3PI_8: f32 = 2.414_213_562_373_095;
#[allow(clippy::excessive_precision)]
const TAN_PI_8: f32 = 0.414_213_562_373_095_0;
#[allow(clippy::excessive_precision)]
const ATAN_POLY: [f32; 4] = [
    8.053_744_495_38e-2,
    1.387_768_560_32e-1,
    1.997_771_064_78e-1,
    3.333_294_915_39e-1,
];

/// atan(x) in f32: Cephes' `atanf` (S. L. Moshier; the argument reduced to |x| ≤ tan(π/8)
/// by atan x = π/2 − atan(1/x) above tan(3π/8) and π/4 + atan((x − 1)/(x + 1)) between, then
/// a polynomial of degree 4 in x²), written with selects so that eight lanes vectorise.
/// Within 2 ulp of f64's atan (the unit test), about 1e-5° — far below the u16 step.
#[inline(always)]
pub(super) fn atan_f32(v: f32) -> f32 {
    let a = v.abs();
    let big = a > TAN_3PI_8;
    let mid = a > TAN_PI_8;
    let r_big = -1.0 / a;
    let r_mid = (a - 1.0) / (a + 1.0);
    let r = if big {
        r_big
    } else if mid {
        r_mid
    } else {
        a
    };
    let base = if big {
        std::f32::consts::FRAC_PI_2
    } else if mid {
        std::f32::consts::FRAC_PI_4
    } else {
        0.0
    };
    let z = r * r;
    let [c0, c1, c2, c3] = ATAN_POLY;
    let p = (((c0 * z - c1) * z + c2) * z - c3) * z * r + r;
    (base + p).copysign(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::horizon::directions;
    use crate::terrain::horizon::test_maps::{map, steep};
    use proptest::prelude::*;

    fn sweep(map: &HeightMap, dir: &Direction, radius: Option<f64>, avx2: bool) -> Vec<u16> {
        let out: Vec<AtomicU16> = (0..map.width * map.height)
            .map(|_| AtomicU16::new(u16::MAX))
            .collect();
        sweep_steep_u16(map, dir, radius, avx2, &out);
        out.into_iter().map(AtomicU16::into_inner).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The AVX2 bundles (stencils, hulls, quantisation) give the portable lanes' bits on
        /// every pixel, near the borders too, flat and curved.
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
            let fast = sweep(&m, &d, radius, true);
            let slow = sweep(&m, &d, radius, false);
            prop_assert!(slow.iter().all(|&v| v != u16::MAX), "a texel was not written");
            let same = fast.iter().zip(&slow).filter(|(a, b)| a == b).count();
            prop_assert_eq!(same, w * h, "{}x{} {:?}", w, h, d);
        }
    }

    /// Slopes of every magnitude and the edge cases: ±0 (flat ground's 0°, just under a
    /// step's midpoint in f64), ±∞, NaN, the extremes of f32 and atan's break points.
    fn any_slope() -> impl Strategy<Value = f32> {
        prop_oneof![
            any::<f32>(),
            (-1e3f32..1e3),
            (-2.5f32..2.5),
            prop::sample::select(vec![
                0.0f32,
                -0.0,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NAN,
                0.414_213_57,
                -2.414_213_6,
                1.0,
                f32::MIN_POSITIVE,
                f32::MAX,
            ]),
        ]
    }

    proptest! {
        /// The AVX2 quantisation gives the portable one's u16 on every lane.
        #[test]
        fn avx2_quantise_equals_the_portable_one(
            slopes in prop::array::uniform8(any_slope()),
            inv_m in prop_oneof![Just(1.0f32), Just(1.0 / 40.0), 1e-4f32..1e2],
        ) {
            if !crate::cpu::has_avx2() {
                prop_assert!(std::env::var_os("CI").is_none(), "no AVX2 on this CI machine");
                return Ok(());
            }
            prop_assert_eq!(quantise_lanes(&slopes, inv_m, true), quantise(&slopes, inv_m));
        }
    }

    /// The f32 atan against f64's over every magnitude (with ±0, the break points and ±∞).
    #[test]
    fn atan_f32_matches_f64_within_two_ulp() {
        let mut xs = vec![
            0.0f32,
            -0.0,
            0.414_213_57,
            2.414_213_6,
            1.0,
            f32::INFINITY,
            -1e30,
        ];
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let m = (s >> 40) as f32 / (1u64 << 24) as f32;
            let e = ((s >> 3) % 60) as i32 - 30;
            xs.push(if s & 1 == 0 { m } else { -m } * 2f32.powi(e));
        }
        let mut worst = 0.0f64;
        for &v in &xs {
            let want = (v as f64).atan();
            let got = atan_f32(v) as f64;
            let ulp = (want.abs() as f32).max(f32::MIN_POSITIVE) as f64 * f32::EPSILON as f64;
            worst = worst.max((got - want).abs() / ulp);
        }
        // Measured: see the assertion's message when it fails.
        assert!(worst <= 2.0, "worst {worst} ulp");
    }
}
