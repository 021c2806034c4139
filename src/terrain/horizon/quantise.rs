//! The horizon f32 sweep's quantisation ([`crate::terrain::horizon::sweep_f32`]): each lane's slope to the
//! horizon map's u16 step, through Cephes' `atanf` in f32 and the step count in f32, N lanes
//! per instruction ([`crate::terrain::horizon::lanes`]) with a portable twin that gives the same u16 (a
//! proptest).
//!
//! **The step in f32.** `encode` rounds x = (deg + 90)/STEP_DEG in f64. Here the angle stays
//! in radians and x − ½ = atan·K + 32767 with K = 65535/π, rounded up (ties down, so that flat
//! ground's 0° gives 32767 as `encode` does). Both f32 roundings together are at most 2⁻¹⁰ +
//! 2⁻¹⁰ of a step (the product below 2¹⁵, the sum below 2¹⁶), less than the `atanf` error
//! itself (2 ulp of π/2: 5·10⁻³ of a step), and the old path's f32 conversion to degrees
//! cost as much (1.4·10⁻³ of a step). So a value can differ from `encode`'s by one step only
//! within 0.01 of a step from a midpoint; the unit test bounds every value's distance from
//! the exact step of the f32 slope, and `tests/terrain/horizon.rs` the map's from the exact
//! horizon. It saves the two f64 divisions and conversions of `encode` per lane.

#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::lanes::Lanes;

/// 65535/π: u16 steps per radian (the map's step is 180°/65535).
const STEPS_PER_RAD: f32 = (65535.0 / std::f64::consts::PI) as f32;

/// The u16 step of an angle `atan` (radians, from [`atan_f32`]): ⌈atan·K + 32767⌉ clamped to
/// the u16 range (module notes); a NaN gives 0, as `encode` does.
#[inline(always)]
fn step_of(atan: f32) -> u16 {
    (atan * STEPS_PER_RAD + 32767.0).ceil().clamp(0.0, 65535.0) as u16
}

/// Slopes (t units) to the horizon map's u16: atan of slope/metres_per_t ([`atan_f32`]), then
/// its step ([`step_of`]). The portable twin of [`quantise_simd`].
#[inline(always)]
pub(super) fn quantise<const N: usize>(slopes: &[f32; N], inv_m: f32) -> [u16; N] {
    let mut out = [0u16; N];
    for (o, &s) in out.iter_mut().zip(slopes) {
        *o = step_of(atan_f32(s * inv_m));
    }
    out
}

/// [`quantise`] on N lanes of `V`: [`atan_f32`]'s selects as blends, then [`step_of`]; the
/// same operations, the same bits (a proptest).
///
/// # Safety
/// The CPU must have `V`'s features (the caller an entry point compiled for them, into which
/// this inlines).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn quantise_simd<V: Lanes<N>, const N: usize>(
    slopes: &[f32; N],
    inv_m: f32,
) -> [u16; N] {
    let f = V::splat_f;
    let v = V::mul(V::load_f(slopes.as_ptr()), f(inv_m));
    let sign = V::sign(v);
    let a = V::abs(v);
    let big = V::gt(a, f(TAN_3PI_8));
    let mid = V::gt(a, f(TAN_PI_8));
    let r_big = V::div(f(-1.0), a);
    let r_mid = V::div(V::sub(a, f(1.0)), V::add(a, f(1.0)));
    let r = V::blend_f(V::blend_f(a, r_mid, mid), r_big, big);
    let base = V::blend_f(
        V::blend_f(f(0.0), f(std::f32::consts::FRAC_PI_4), mid),
        f(std::f32::consts::FRAC_PI_2),
        big,
    );
    let z = V::mul(r, r);
    let [c0, c1, c2, c3] = ATAN_POLY;
    let mut p = V::sub(V::mul(f(c0), z), f(c1));
    p = V::add(V::mul(p, z), f(c2));
    p = V::sub(V::mul(p, z), f(c3));
    p = V::add(V::mul(V::mul(p, z), r), r);
    let atan = V::or_f(V::abs(V::add(base, p)), sign);
    // The step (`step_of`): ceil is exact; `max` returns its second operand, 0, for NaN.
    let x = V::add(V::mul(atan, f(STEPS_PER_RAD)), f(32767.0));
    let x = V::min(V::max(V::ceil(x), f(0.0)), f(65535.0));
    let mut out = [0u16; N];
    V::store_u16(out.as_mut_ptr(), V::to_i(x));
    out
}

/// Cephes' `atanf` reduction bounds, tan(3π/8) and tan(π/8), and its polynomial's magnitudes
/// ((c₀z − c₁)z + c₂)z − c₃, shared by [`atan_f32`] and [`quantise_simd`].
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
/// a polynomial of degree 4 in x²), written with selects so that lanes vectorise.
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
    use proptest::prelude::*;

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
        /// The vector quantisation, eight lanes of AVX2 and sixteen of AVX-512 where the CPU
        /// has them, gives the portable one's u16 on every lane.
        #[test]
        fn vector_quantise_equals_the_portable_one(
            slopes in prop::array::uniform16(any_slope()),
            inv_m in prop_oneof![Just(1.0f32), Just(1.0 / 40.0), 1e-4f32..1e2],
        ) {
            // CI machines have AVX2 (x86-64-v3): there the comparison must run.
            if !crate::cpu::has_avx2() {
                prop_assert!(std::env::var_os("CI").is_none(), "no AVX2 on this CI machine");
                return Ok(());
            }
            let want = quantise(&slopes, inv_m);
            #[cfg(target_arch = "x86_64")]
            for simd in crate::cpu::Simd::available().into_iter().skip(1) {
                use crate::terrain::horizon::lanes::{Avx2, Avx512};
                // SAFETY: the level was detected.
                let got: [u16; 16] = unsafe {
                    match simd {
                        crate::cpu::Simd::Avx2 => {
                            let half = |h: usize| slopes[h..h + 8].try_into().unwrap();
                            let (lo, hi) = (
                                quantise_simd::<Avx2, 8>(&half(0), inv_m),
                                quantise_simd::<Avx2, 8>(&half(8), inv_m),
                            );
                            std::array::from_fn(|j| if j < 8 { lo[j] } else { hi[j - 8] })
                        }
                        _ => quantise_simd::<Avx512, 16>(&slopes, inv_m),
                    }
                };
                prop_assert_eq!(got, want, "{:?}", simd);
            }
        }
    }

    /// Every step against the exact one of its f32 slope (f64 `atan`, unrounded): within half
    /// a step plus [`STEP_SLACK`]; flat ground (±0) gives 32767 as `encode` does, ±∞ the ends,
    /// NaN 0. Slopes over every magnitude and, for each step, the f32 slopes at its midpoint.
    #[test]
    fn steps_are_the_exact_ones_within_rounding() {
        use crate::terrain::horizon::encode;
        let k = 65535.0 / std::f64::consts::PI;
        let mut vs: Vec<f32> =
            crate::terrain::horizon::hull::test_values::magnitudes(200_000, 24, 30)
                .into_iter()
                .flat_map(|v| [v as f32, -(v as f32)])
                .collect();
        for q in 0..65535u32 {
            let mid = ((q as f64 + 0.5 - 32767.5) / k).tan() as f32;
            // The f32 values around it, an ulp or so apart.
            vs.extend((-3..=3).map(|j| mid * (1.0 + j as f32 * f32::EPSILON)));
        }
        let (mut worst, mut off_encode) = (0.0f64, 0usize);
        for &v in &vs {
            let x = (v as f64).atan() * k + 32767.5;
            let q = step_of(atan_f32(v));
            worst = worst.max((q as f64 - x).abs());
            let e = encode(atan_f32(v) as f64 * (180.0 / std::f64::consts::PI));
            assert!(q.abs_diff(e) <= 1, "{v:e}: {q} against encode's {e}");
            off_encode += (q != e) as usize;
        }
        eprintln!(
            "worst {:.5} steps; {off_encode} of {} differ from encode's",
            worst,
            vs.len()
        );
        assert!(worst <= 0.5 + STEP_SLACK, "worst {worst} steps");
        assert_eq!(
            [step_of(atan_f32(0.0)), step_of(atan_f32(-0.0))],
            [32767; 2]
        );
        let ends = [f32::INFINITY, f32::NEG_INFINITY, f32::NAN].map(|v| step_of(atan_f32(v)));
        assert_eq!(ends, [65535, 0, 0]);
    }

    /// What the f32 step may add to half a step: 2 ulp of `atanf` at π/2 (5.0·10⁻³ of a step)
    /// and the two f32 roundings (2·2⁻¹⁰), with a margin of 1.5x.
    const STEP_SLACK: f64 = 0.011;

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
        // 24 bits of mantissa and |e| ≤ 30: every value is an f32.
        let spread = crate::terrain::horizon::hull::test_values::magnitudes(200_000, 24, 30);
        xs.extend(spread.into_iter().map(|v| v as f32));
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
