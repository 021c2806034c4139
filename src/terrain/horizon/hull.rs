//! The upper convex hulls of the horizon sweep's lines ([`crate::terrain::horizon`], docs/algorithms.md
//! §4.4), one per lane of a bundle ([`crate::terrain::horizon::sweep`]): a push that keeps the hull
//! upper-convex, and the tangent query from a point left of every vertex. The scalar
//! operations serve one lane at a time; [`Hulls::step_avx2`] runs four lanes in AVX2 with the
//! same operations in the same order (no FMA), so it gives the same bits (a proptest holds
//! them equal).
//!
//! **Layout.** Lane j's vertices (τ, f) are `xs[j·cap ..]`, `ys[j·cap ..]`, the last one
//! leftmost (pushed last); the AVX2 step keeps the top two of four lanes in registers and
//! gathers the next one from memory on a pop.
//!
//! **Tangent.** Slopes rise from the leftmost vertex to the tangent point, then fall; a vertex
//! is popped while its slope from (τ, z) is at most the next one's, compared as
//! `(y₁ − z)(x₂ − τ) ≤ (y₂ − z)(x₁ − τ)` (both x − τ > 0: no division in the loop).
//!
//! **Angles.** [`atan_degrees`] turns the lanes' tangents into degrees at once.

/// Lines per bundle of the sweep ([`crate::terrain::horizon::sweep`]): two groups of four f64 lanes.
pub const LANES: usize = 8;

/// The hulls of the lanes of one bundle.
pub(super) struct Hulls {
    xs: Vec<f64>,
    ys: Vec<f64>,
    len: [i64; LANES],
    cap: usize,
}

impl Hulls {
    pub fn new() -> Hulls {
        Hulls {
            xs: Vec::new(),
            ys: Vec::new(),
            len: [0; LANES],
            cap: 0,
        }
    }

    /// Empty every lane, with room for `cap` vertices each.
    pub fn reset(&mut self, cap: usize) {
        if cap > self.cap {
            self.cap = cap;
            self.xs.resize(cap * LANES, 0.0);
            self.ys.resize(cap * LANES, 0.0);
        }
        self.len = [0; LANES];
    }

    /// Push a point left of every vertex of lane j, popping the vertices it makes non-convex
    /// (a vertex not above the segment from q to the next one can never be a tangent point
    /// from the left).
    #[inline]
    pub fn push(&mut self, j: usize, q: (f64, f64)) {
        let base = j * self.cap;
        let mut n = self.len[j] as usize;
        while n >= 2 {
            let a = (self.xs[base + n - 1], self.ys[base + n - 1]);
            let b = (self.xs[base + n - 2], self.ys[base + n - 2]);
            if (a.1 - q.1) * (b.0 - q.0) <= (b.1 - q.1) * (a.0 - q.0) {
                n -= 1;
            } else {
                break;
            }
        }
        self.xs[base + n] = q.0;
        self.ys[base + n] = q.1;
        self.len[j] = n as i64 + 1;
    }

    /// The steepest slope from (tau, z) to lane j's vertices (all to its right), None for an
    /// empty hull. Pops the vertices before the tangent point: the caller then pushes a point
    /// at (tau, z) (to rounding), under whose chord to the tangent point they lie, so no later
    /// query from further left can need them (Timonen & Westerholm's amortised O(1)).
    #[inline]
    pub fn tangent(&mut self, j: usize, tau: f64, z: f64) -> Option<f64> {
        let base = j * self.cap;
        let mut n = self.len[j] as usize;
        while n >= 2 {
            let (x1, y1) = (self.xs[base + n - 1], self.ys[base + n - 1]);
            let (x2, y2) = (self.xs[base + n - 2], self.ys[base + n - 2]);
            if (y1 - z) * (x2 - tau) <= (y2 - z) * (x1 - tau) {
                n -= 1;
            } else {
                break;
            }
        }
        self.len[j] = n as i64;
        (n >= 1).then(|| (self.ys[base + n - 1] - z) / (self.xs[base + n - 1] - tau))
    }
}

#[cfg(target_arch = "x86_64")]
impl Hulls {
    /// One pixel of lanes 4g … 4g + 3, as the scalar sweep does it lane by lane: push the
    /// period's samples (τ + ts[s], heights[s] − κ(τ + ts[s])²) for s from last to first, take
    /// the tangent from (τ, z) (popping as [`Hulls::tangent`] does), then push `full` the same
    /// way. Returns each lane's tangent slope, −∞ for an empty hull. Bit for bit
    /// [`Hulls::push`] and [`Hulls::tangent`].
    ///
    /// # Safety
    /// AVX2 must be available; each lane must have room for `ts.len() + 1` more vertices, and
    /// `heights` must be as long as `ts`.
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments, unused_assignments)]
    pub unsafe fn step_avx2(
        &mut self,
        g: usize,
        ts: &[f64],
        heights: &[[f64; LANES]],
        full: (f64, &[f64; LANES]),
        tau: f64,
        kappa: f64,
        z: [f64; 4],
    ) -> [f64; 4] {
        use std::arch::x86_64::*;
        assert!(heights.len() == ts.len() && 4 * g + 4 <= LANES);
        let first = 4 * g as i64;
        let lanes = _mm256_set_epi64x(first + 3, first + 2, first + 1, first);
        let row = _mm256_mul_epi32(lanes, _mm256_set1_epi64x(self.cap as i64)); // lane · cap
        let (xs, ys) = (self.xs.as_mut_ptr(), self.ys.as_mut_ptr());
        let lenp = self.len.as_mut_ptr().add(4 * g) as *mut __m256i;
        let mut len = _mm256_loadu_si256(lenp);
        let (zero, one) = (_mm256_setzero_si256(), _mm256_set1_epi64x(1));
        // Each lane's vertex at depth len − k (index clamped at 0; unused where len < k).
        let at = |len: __m256i, k: i64| {
            let d = _mm256_sub_epi64(len, _mm256_set1_epi64x(k));
            let d = _mm256_blendv_epi8(d, zero, _mm256_cmpgt_epi64(zero, d));
            let i = _mm256_add_epi64(row, d);
            (
                _mm256_i64gather_pd::<8>(xs, i),
                _mm256_i64gather_pd::<8>(ys, i),
            )
        };
        let (mut t1, mut t2, mut t3) = (at(len, 1), at(len, 2), at(len, 3));
        // One masked pop: where a lane has two vertices and its top one fails the test
        // against (px, py), drop it (the next two move up, the third comes from memory).
        // Evaluates to the mask of the lanes that popped.
        macro_rules! pop_once {
            ($px:expr, $py:expr, $refill:expr) => {{
                let l = _mm256_mul_pd(_mm256_sub_pd(t1.1, $py), _mm256_sub_pd(t2.0, $px));
                let r = _mm256_mul_pd(_mm256_sub_pd(t2.1, $py), _mm256_sub_pd(t1.0, $px));
                let deep = _mm256_castsi256_pd(_mm256_cmpgt_epi64(len, one));
                let pop = _mm256_and_pd(deep, _mm256_cmp_pd::<_CMP_LE_OQ>(l, r));
                len = _mm256_add_epi64(len, _mm256_castpd_si256(pop)); // −1 where popped
                let blend = |a: (__m256d, __m256d), b: (__m256d, __m256d)| {
                    (
                        _mm256_blendv_pd(a.0, b.0, pop),
                        _mm256_blendv_pd(a.1, b.1, pop),
                    )
                };
                t1 = blend(t1, t2);
                t2 = blend(t2, t3);
                if $refill {
                    t3 = blend(t3, at(len, 3));
                }
                pop
            }};
        }
        // Pop until no lane's top vertex fails. Two rounds without a gather or a branch (most
        // pushes pop at most twice): after them t1 is right in every lane, t2 wherever the
        // lane did not pop twice, t3 wherever it did not pop at all — enough for the push
        // unless some lane popped twice; then the top two are read back from memory and the
        // rounds go on with a gather each.
        macro_rules! pop_while {
            ($px:expr, $py:expr) => {{
                pop_once!($px, $py, false);
                let twice = pop_once!($px, $py, false);
                if _mm256_movemask_pd(twice) != 0 {
                    (t2, t3) = (at(len, 2), at(len, 3));
                    while _mm256_movemask_pd(pop_once!($px, $py, true)) != 0 {}
                }
            }};
        }
        // Push (qx, qy) on every lane: pop, write it at depth len, make it the top.
        macro_rules! push {
            ($qx:expr, $qy:expr) => {{
                let (qx, qy) = ($qx, $qy);
                let qxv = _mm256_set1_pd(qx);
                pop_while!(qxv, qy);
                let mut idx = [0i64; 4];
                _mm256_storeu_si256(idx.as_mut_ptr() as *mut __m256i, _mm256_add_epi64(row, len));
                let mut y = [0.0f64; 4];
                _mm256_storeu_pd(y.as_mut_ptr(), qy);
                for (&i, &y) in idx.iter().zip(&y) {
                    *xs.add(i as usize) = qx;
                    *ys.add(i as usize) = y;
                }
                len = _mm256_add_epi64(len, one);
                t3 = t2;
                t2 = t1;
                t1 = (qxv, qy);
            }};
        }
        // A sample of every lane on the line's parabola: f = h − κτ² (as the scalar sweep).
        let sample = |t: f64, h: &[f64; LANES]| {
            let qx = tau + t;
            let drop = kappa * qx * qx;
            let h = _mm256_loadu_pd(h.as_ptr().add(4 * g));
            (qx, _mm256_sub_pd(h, _mm256_set1_pd(drop)))
        };
        for (t, h) in ts.iter().zip(heights).rev() {
            let (qx, qy) = sample(*t, h);
            push!(qx, qy);
        }
        // The tangent from (τ, z).
        let (tv, zv) = (_mm256_set1_pd(tau), _mm256_loadu_pd(z.as_ptr()));
        pop_while!(tv, zv);
        // No shift follows the query: t3 is read back wherever a lane popped.
        t3 = at(len, 3);
        let slope = _mm256_div_pd(_mm256_sub_pd(t1.1, zv), _mm256_sub_pd(t1.0, tv));
        let empty = _mm256_castsi256_pd(_mm256_cmpgt_epi64(one, len));
        let slope = _mm256_blendv_pd(slope, _mm256_set1_pd(f64::NEG_INFINITY), empty);
        let (qx, qy) = sample(full.0, full.1);
        push!(qx, qy);
        _mm256_storeu_si256(lenp, len);
        let mut out = [0.0; 4];
        _mm256_storeu_pd(out.as_mut_ptr(), slope);
        out
    }
}

/// atan(x) in degrees for every lane: Cephes' `atan` (S. L. Moshier; the argument reduced to
/// |x| ≤ 0.66 by atan x = π/2 − atan(1/x) above tan(3π/8) and π/4 + atan((x − 1)/(x + 1))
/// between, then a rational function of degree 4/5 in x²), lane by lane with selects (libm's
/// scalar `atan` was 10 % of a horizon build). Within 2 ulp of `f64::atan` counting the round
/// trip through degrees (the unit test), far below the f32 degrees it is stored as.
///
/// With `avx2` (detected by the caller) the same code is compiled for AVX2: the same
/// operations (no FMA is contracted), so the same bits (the unit test compares them). The
/// compiler still leaves the reductions' divisions scalar; an explicit four-lane version, with
/// both reductions computed and then selected, measured no faster (docs/terrain.md).
pub(super) fn atan_degrees(x: &[f64; LANES], avx2: bool) -> [f64; LANES] {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller detected AVX2.
        return unsafe { atan_degrees_avx2(x) };
    }
    let _ = avx2;
    atan_degrees_lanes(x)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn atan_degrees_avx2(x: &[f64; LANES]) -> [f64; LANES] {
    atan_degrees_lanes(x)
}

#[allow(clippy::excessive_precision)] // Cephes' constants as published
#[inline(always)]
fn atan_degrees_lanes(x: &[f64; LANES]) -> [f64; LANES] {
    const P: [f64; 5] = [
        -8.750608600031904122785E-1,
        -1.615753718733365076637E1,
        -7.500855792314704667340E1,
        -1.228866684490136173410E2,
        -6.485021904942025371773E1,
    ];
    const Q: [f64; 5] = [
        2.485846490142306297962E1,
        1.650270098316988542046E2,
        4.328810604912902668951E2,
        4.853903996359136964868E2,
        1.945506571482613964425E2,
    ];
    const T3P8: f64 = 2.414_213_562_373_095;
    const MOREBITS: f64 = 6.123233995736765886130E-17;
    let mut out = [0.0; LANES];
    for (o, &v) in out.iter_mut().zip(x) {
        let a = v.abs();
        let big = a > T3P8;
        let mid = !big && a > 0.66;
        let r = if big {
            -1.0 / a
        } else if mid {
            (a - 1.0) / (a + 1.0)
        } else {
            a
        };
        let base = if big {
            std::f64::consts::FRAC_PI_2
        } else if mid {
            std::f64::consts::FRAC_PI_4
        } else {
            0.0
        };
        let more = if big {
            MOREBITS
        } else if mid {
            0.5 * MOREBITS
        } else {
            0.0
        };
        let z = r * r;
        let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
        let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
        let y = base + (r * (z * p / q) + r + more);
        *o = y.copysign(v).to_degrees();
    }
    out
}

/// Inputs for the `atan` tests of this module and of [`crate::terrain::horizon::quantise`].
#[cfg(test)]
pub(super) mod test_values {
    /// `n` pseudo-random values ±m·2^e of every magnitude for the `atan` tests: m with `bits`
    /// bits of mantissa in [0, 1), e in [−half, half), the sign and both from one xorshift.
    pub fn magnitudes(n: usize, bits: u32, half: i32) -> Vec<f64> {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                let m = (s >> (64 - bits)) as f64 / (1u64 << bits) as f64;
                let e = ((s >> 3) % (2 * half as u64)) as i32 - half;
                (if s & 1 == 0 { m } else { -m }) * 2f64.powi(e)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lanes' atan against libm's, in ulps of the radians, over every magnitude (with ±0,
    /// the reduction's break points and ±∞).
    #[test]
    fn lane_atan_matches_libm_within_a_few_ulp() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.66,
            -0.66,
            2.414_213_562_373_095,
            1.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        xs.extend(test_values::magnitudes(200_000, 53, 40));
        let mut worst = 0.0f64;
        for c in xs.chunks(LANES) {
            let mut x = [0.0; LANES];
            x[..c.len()].copy_from_slice(c);
            let got = atan_degrees(&x, false);
            assert_eq!(
                got.map(f64::to_bits),
                atan_degrees(&x, crate::cpu::has_avx2()).map(f64::to_bits),
                "the AVX2 build differs"
            );
            for (&v, &g) in x.iter().zip(&got) {
                let want = v.atan();
                let ulp =
                    (want.abs().max(f64::MIN_POSITIVE) * f64::EPSILON).max(f64::EPSILON * 1e-300);
                worst = worst.max((g.to_radians() - want).abs() / ulp);
                assert_eq!(g.is_sign_negative(), want.is_sign_negative(), "{v}");
            }
        }
        // Measured 1.78 ulp, counting the round trip through degrees (an ulp or so each way).
        assert!(worst <= 4.0, "worst {worst} ulp");
    }
}
