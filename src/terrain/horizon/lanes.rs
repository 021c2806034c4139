//! The vector operations the f32 horizon kernels ([`crate::terrain::horizon::hull_f32`],
//! [`crate::terrain::horizon::sweep_f32`]'s stencils, [`crate::terrain::horizon::quantise`]) are written in, once for
//! every width: eight lanes of AVX2 ([`Avx2`], masks as vectors of −1/0) and sixteen of AVX-512
//! ([`Avx512`], masks in mask registers). Each method is one intrinsic, or the few that stand
//! for one, with the same IEEE result at both widths (correctly rounded `+ − × ÷`, `max`/`min`
//! returning the second operand when either is NaN, round-to-nearest conversions, ordered
//! quiet comparisons), so a kernel gives the same bits per lane at either width; the proptests
//! of the kernels hold both to the portable lanes.
//!
//! Every method is `#[inline(always)]` and carries no target feature of its own: it inlines
//! into the `#[target_feature]` entry point of its width (`bundle_avx2`, `bundle_avx512` in
//! [`crate::terrain::horizon::sweep_f32`]), which compiles it with that entry point's features. Code that calls
//! these methods must not sit in a closure: a closure is compiled without the entry point's
//! features, the intrinsics in it stay calls, and the first build of the generic kernels ran
//! three times slower for it (the kernels use small macros and `#[inline(always)]` functions
//! instead).
//!
//! # Safety
//! Every method is `unsafe`: the CPU must have the width's features (the caller an entry point
//! compiled for them), and pointers must address N valid elements (records: a whole record).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// i32 per record of the vector hulls: at, y's bits, x, and x again (padding).
pub(super) const RECORD: usize = 4;

/// Lane j's record within a slot of N lanes, in bytes: the four stores of
/// [`Lanes::store_records`] each hold the records of lanes j ≡ 0, 1, 2, 3 (mod 4), in 16-byte
/// pieces in the order of their 128-bit halves or quarters.
pub(super) const fn within<const N: usize>() -> [i32; N] {
    let mut w = [0; N];
    let mut j = 0;
    while j < N {
        w[j] = ((N * RECORD * 4 / 4) * (j % 4) + 16 * (j / 4)) as i32;
        j += 1;
    }
    w
}

/// One vertex of each of the N lanes: the byte offset of its record (its slot's, at the lane's
/// place in it: what the vertex above it reads), its height and τ.
pub(super) struct Top<V: Lanes<N>, const N: usize> {
    pub at: V::I,
    pub y: V::F,
    pub x: V::I,
}

impl<V: Lanes<N>, const N: usize> Clone for Top<V, N> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<V: Lanes<N>, const N: usize> Copy for Top<V, N> {}

/// N lanes of f32 (`F`) and i32 (`I`), and a mask of N lanes (`M`).
pub(super) trait Lanes<const N: usize>: Copy {
    type F: Copy;
    type I: Copy;
    type M: Copy;

    unsafe fn load_f(p: *const f32) -> Self::F;
    unsafe fn store_f(p: *mut f32, v: Self::F);
    unsafe fn load_i(p: *const i32) -> Self::I;
    unsafe fn store_i(p: *mut i32, v: Self::I);
    unsafe fn splat_f(v: f32) -> Self::F;
    unsafe fn splat_i(v: i32) -> Self::I;

    unsafe fn add(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn sub(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn mul(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn div(a: Self::F, b: Self::F) -> Self::F;
    /// `maxps`: b where either is NaN.
    unsafe fn max(a: Self::F, b: Self::F) -> Self::F;
    /// `minps`: b where either is NaN.
    unsafe fn min(a: Self::F, b: Self::F) -> Self::F;
    unsafe fn sub_i(a: Self::I, b: Self::I) -> Self::I;
    unsafe fn add_i(a: Self::I, b: Self::I) -> Self::I;
    /// i32 to f32, rounded to nearest.
    unsafe fn to_f(a: Self::I) -> Self::F;
    /// f32 to i32, truncated.
    unsafe fn to_i(a: Self::F) -> Self::I;
    unsafe fn ceil(a: Self::F) -> Self::F;
    /// |a|, and a's sign bit alone.
    unsafe fn abs(a: Self::F) -> Self::F;
    unsafe fn sign(a: Self::F) -> Self::F;
    unsafe fn or_f(a: Self::F, b: Self::F) -> Self::F;

    /// Ordered comparisons (false where either is NaN).
    unsafe fn le(a: Self::F, b: Self::F) -> Self::M;
    unsafe fn ge(a: Self::F, b: Self::F) -> Self::M;
    unsafe fn gt(a: Self::F, b: Self::F) -> Self::M;
    unsafe fn eq_i(a: Self::I, b: Self::I) -> Self::M;
    unsafe fn gt_i(a: Self::I, b: Self::I) -> Self::M;

    /// b in the lanes of m, else a (`blendv`'s order).
    unsafe fn blend_f(a: Self::F, b: Self::F, m: Self::M) -> Self::F;
    unsafe fn blend_i(a: Self::I, b: Self::I, m: Self::M) -> Self::I;
    unsafe fn and_m(a: Self::M, b: Self::M) -> Self::M;
    /// !a & b.
    unsafe fn andnot_m(a: Self::M, b: Self::M) -> Self::M;
    unsafe fn or_m(a: Self::M, b: Self::M) -> Self::M;
    unsafe fn not_m(a: Self::M) -> Self::M;
    unsafe fn any(m: Self::M) -> bool;
    unsafe fn all(m: Self::M) -> bool;
    /// The lanes of a −1/0 vector as a mask, and back.
    unsafe fn mask_of(v: Self::I) -> Self::M;
    unsafe fn ints_of(m: Self::M) -> Self::I;

    /// The least lane.
    unsafe fn min_lane(v: Self::I) -> i32;
    /// Lanes in 0..=65535 stored as N u16.
    unsafe fn store_u16(p: *mut u16, v: Self::I);

    /// Each lane's record within a slot, in bytes ([`Lanes::store_records`]' layout).
    #[inline(always)]
    unsafe fn within() -> Self::I {
        Self::load_i(const { within::<N>() }.as_ptr())
    }
    /// Record the N lanes' vertices `v` at `to` (one slot of N records of [`RECORD`] i32:
    /// at, y's bits, x, x), as four vector stores after a transpose.
    unsafe fn store_records(to: *mut i32, v: Top<Self, N>);
    /// The N lanes' records at byte offsets `at` from `base`: N 16-byte loads and a transpose,
    /// in place of three N-lane gathers.
    unsafe fn load_records(base: *const i32, at: Self::I) -> Top<Self, N>;
}

/// `b` in the lanes of mask `m`, else `a`.
#[inline(always)]
pub(super) unsafe fn pick<V: Lanes<N>, const N: usize>(
    a: Top<V, N>,
    b: Top<V, N>,
    m: V::M,
) -> Top<V, N> {
    Top {
        at: V::blend_i(a.at, b.at, m),
        y: V::blend_f(a.y, b.y, m),
        x: V::blend_i(a.x, b.x, m),
    }
}

#[cfg(target_arch = "x86_64")]
/// Trait methods that are one intrinsic each, called with their own arguments:
/// `name(args) -> R = intrinsic;`.
macro_rules! direct {
    ($($name:ident($($a:ident: $t:ty),*) $(-> $r:ty)? = $f:ident;)*) => {
        $(
            #[inline(always)]
            unsafe fn $name($($a: $t),*) $(-> $r)? {
                $f($($a),*)
            }
        )*
    };
}

#[cfg(target_arch = "x86_64")]
/// Eight lanes of AVX2 (x86-64-v3).
#[derive(Clone, Copy)]
pub(super) struct Avx2;

#[cfg(target_arch = "x86_64")]
/// Sixteen lanes of AVX-512 (x86-64-v4: F, BW, CD, DQ, VL).
#[derive(Clone, Copy)]
pub(super) struct Avx512;

#[cfg(target_arch = "x86_64")]
impl Lanes<8> for Avx2 {
    type F = __m256;
    type I = __m256i;
    type M = __m256i;

    direct! {
        load_f(p: *const f32) -> __m256 = _mm256_loadu_ps;
        store_f(p: *mut f32, v: __m256) = _mm256_storeu_ps;
    }
    #[inline(always)]
    unsafe fn load_i(p: *const i32) -> __m256i {
        _mm256_loadu_si256(p as *const __m256i)
    }
    #[inline(always)]
    unsafe fn store_i(p: *mut i32, v: __m256i) {
        _mm256_storeu_si256(p as *mut __m256i, v)
    }
    direct! {
        splat_f(v: f32) -> __m256 = _mm256_set1_ps;
        splat_i(v: i32) -> __m256i = _mm256_set1_epi32;
        add(a: __m256, b: __m256) -> __m256 = _mm256_add_ps;
        sub(a: __m256, b: __m256) -> __m256 = _mm256_sub_ps;
        mul(a: __m256, b: __m256) -> __m256 = _mm256_mul_ps;
        div(a: __m256, b: __m256) -> __m256 = _mm256_div_ps;
        max(a: __m256, b: __m256) -> __m256 = _mm256_max_ps;
        min(a: __m256, b: __m256) -> __m256 = _mm256_min_ps;
        sub_i(a: __m256i, b: __m256i) -> __m256i = _mm256_sub_epi32;
        add_i(a: __m256i, b: __m256i) -> __m256i = _mm256_add_epi32;
        to_f(a: __m256i) -> __m256 = _mm256_cvtepi32_ps;
        to_i(a: __m256) -> __m256i = _mm256_cvttps_epi32;
        ceil(a: __m256) -> __m256 = _mm256_ceil_ps;
    }
    #[inline(always)]
    unsafe fn abs(a: __m256) -> __m256 {
        _mm256_andnot_ps(_mm256_set1_ps(-0.0), a)
    }
    #[inline(always)]
    unsafe fn sign(a: __m256) -> __m256 {
        _mm256_and_ps(a, _mm256_set1_ps(-0.0))
    }
    direct! {
        or_f(a: __m256, b: __m256) -> __m256 = _mm256_or_ps;
    }
    #[inline(always)]
    unsafe fn le(a: __m256, b: __m256) -> __m256i {
        _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(a, b))
    }
    #[inline(always)]
    unsafe fn ge(a: __m256, b: __m256) -> __m256i {
        _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(a, b))
    }
    #[inline(always)]
    unsafe fn gt(a: __m256, b: __m256) -> __m256i {
        _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GT_OQ>(a, b))
    }
    direct! {
        eq_i(a: __m256i, b: __m256i) -> __m256i = _mm256_cmpeq_epi32;
        gt_i(a: __m256i, b: __m256i) -> __m256i = _mm256_cmpgt_epi32;
    }
    #[inline(always)]
    unsafe fn blend_f(a: __m256, b: __m256, m: __m256i) -> __m256 {
        _mm256_blendv_ps(a, b, _mm256_castsi256_ps(m))
    }
    direct! {
        blend_i(a: __m256i, b: __m256i, m: __m256i) -> __m256i = _mm256_blendv_epi8;
        and_m(a: __m256i, b: __m256i) -> __m256i = _mm256_and_si256;
        andnot_m(a: __m256i, b: __m256i) -> __m256i = _mm256_andnot_si256;
        or_m(a: __m256i, b: __m256i) -> __m256i = _mm256_or_si256;
    }
    #[inline(always)]
    unsafe fn not_m(a: __m256i) -> __m256i {
        _mm256_xor_si256(a, _mm256_set1_epi32(-1))
    }
    #[inline(always)]
    unsafe fn any(m: __m256i) -> bool {
        _mm256_testz_si256(m, m) == 0
    }
    #[inline(always)]
    unsafe fn all(m: __m256i) -> bool {
        _mm256_movemask_ps(_mm256_castsi256_ps(m)) == 0xff
    }
    #[inline(always)]
    unsafe fn mask_of(v: __m256i) -> __m256i {
        v
    }
    #[inline(always)]
    unsafe fn ints_of(m: __m256i) -> __m256i {
        m
    }
    #[inline(always)]
    unsafe fn min_lane(v: __m256i) -> i32 {
        let m = _mm_min_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
        let m = _mm_min_epi32(m, _mm_shuffle_epi32::<0b01_00_11_10>(m));
        let m = _mm_min_epi32(m, _mm_shuffle_epi32::<0b10_11_00_01>(m));
        _mm_cvtsi128_si32(m)
    }
    #[inline(always)]
    unsafe fn store_u16(p: *mut u16, v: __m256i) {
        let q = _mm_packus_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
        _mm_storeu_si128(p as *mut __m128i, q)
    }
    /// Lanes j and j + 4 share 32 bytes: lane j's record starts at byte 32·(j mod 4) +
    /// 16·(j div 4).
    #[inline(always)]
    unsafe fn store_records(to: *mut i32, v: Top<Self, 8>) {
        let y = _mm256_castps_si256(v.y);
        let (a, b) = (
            _mm256_unpacklo_epi32(v.at, y),
            _mm256_unpackhi_epi32(v.at, y),
        );
        let (c, d) = (
            _mm256_unpacklo_epi32(v.x, v.x),
            _mm256_unpackhi_epi32(v.x, v.x),
        );
        let to = to as *mut __m256i;
        _mm256_storeu_si256(to, _mm256_unpacklo_epi64(a, c));
        _mm256_storeu_si256(to.add(1), _mm256_unpackhi_epi64(a, c));
        _mm256_storeu_si256(to.add(2), _mm256_unpacklo_epi64(b, d));
        _mm256_storeu_si256(to.add(3), _mm256_unpackhi_epi64(b, d));
    }
    /// Zen 3 spends 39 µops on each eight-lane gather.
    #[inline(always)]
    unsafe fn load_records(base: *const i32, at: __m256i) -> Top<Self, 8> {
        let mut off = [0u32; 8];
        _mm256_storeu_si256(off.as_mut_ptr() as *mut __m256i, at);
        let b = base as *const u8;
        let rec = |j: usize| b.add(off[j] as usize) as *const __m128i;
        let r0 = _mm256_loadu2_m128i(rec(4), rec(0));
        let r1 = _mm256_loadu2_m128i(rec(5), rec(1));
        let r2 = _mm256_loadu2_m128i(rec(6), rec(2));
        let r3 = _mm256_loadu2_m128i(rec(7), rec(3));
        let (t0, t1) = (_mm256_unpacklo_epi32(r0, r1), _mm256_unpacklo_epi32(r2, r3));
        let (t2, t3) = (_mm256_unpackhi_epi32(r0, r1), _mm256_unpackhi_epi32(r2, r3));
        Top {
            at: _mm256_unpacklo_epi64(t0, t1),
            y: _mm256_castsi256_ps(_mm256_unpackhi_epi64(t0, t1)),
            x: _mm256_unpacklo_epi64(t2, t3),
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl Lanes<16> for Avx512 {
    type F = __m512;
    type I = __m512i;
    type M = __mmask16;

    direct! {
        load_f(p: *const f32) -> __m512 = _mm512_loadu_ps;
        store_f(p: *mut f32, v: __m512) = _mm512_storeu_ps;
    }
    #[inline(always)]
    unsafe fn load_i(p: *const i32) -> __m512i {
        _mm512_loadu_si512(p as *const __m512i)
    }
    #[inline(always)]
    unsafe fn store_i(p: *mut i32, v: __m512i) {
        _mm512_storeu_si512(p as *mut __m512i, v)
    }
    direct! {
        splat_f(v: f32) -> __m512 = _mm512_set1_ps;
        splat_i(v: i32) -> __m512i = _mm512_set1_epi32;
        add(a: __m512, b: __m512) -> __m512 = _mm512_add_ps;
        sub(a: __m512, b: __m512) -> __m512 = _mm512_sub_ps;
        mul(a: __m512, b: __m512) -> __m512 = _mm512_mul_ps;
        div(a: __m512, b: __m512) -> __m512 = _mm512_div_ps;
        max(a: __m512, b: __m512) -> __m512 = _mm512_max_ps;
        min(a: __m512, b: __m512) -> __m512 = _mm512_min_ps;
        sub_i(a: __m512i, b: __m512i) -> __m512i = _mm512_sub_epi32;
        add_i(a: __m512i, b: __m512i) -> __m512i = _mm512_add_epi32;
        to_f(a: __m512i) -> __m512 = _mm512_cvtepi32_ps;
        to_i(a: __m512) -> __m512i = _mm512_cvttps_epi32;
    }
    #[inline(always)]
    unsafe fn ceil(a: __m512) -> __m512 {
        _mm512_roundscale_ps::<{ _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC }>(a)
    }
    #[inline(always)]
    unsafe fn abs(a: __m512) -> __m512 {
        _mm512_andnot_ps(_mm512_set1_ps(-0.0), a)
    }
    #[inline(always)]
    unsafe fn sign(a: __m512) -> __m512 {
        _mm512_and_ps(a, _mm512_set1_ps(-0.0))
    }
    direct! {
        or_f(a: __m512, b: __m512) -> __m512 = _mm512_or_ps;
    }
    #[inline(always)]
    unsafe fn le(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn ge(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn gt(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_GT_OQ>(a, b)
    }
    direct! {
        eq_i(a: __m512i, b: __m512i) -> __mmask16 = _mm512_cmpeq_epi32_mask;
        gt_i(a: __m512i, b: __m512i) -> __mmask16 = _mm512_cmpgt_epi32_mask;
    }
    #[inline(always)]
    unsafe fn blend_f(a: __m512, b: __m512, m: __mmask16) -> __m512 {
        _mm512_mask_blend_ps(m, a, b)
    }
    #[inline(always)]
    unsafe fn blend_i(a: __m512i, b: __m512i, m: __mmask16) -> __m512i {
        _mm512_mask_blend_epi32(m, a, b)
    }
    #[inline(always)]
    unsafe fn and_m(a: __mmask16, b: __mmask16) -> __mmask16 {
        a & b
    }
    #[inline(always)]
    unsafe fn andnot_m(a: __mmask16, b: __mmask16) -> __mmask16 {
        !a & b
    }
    #[inline(always)]
    unsafe fn or_m(a: __mmask16, b: __mmask16) -> __mmask16 {
        a | b
    }
    #[inline(always)]
    unsafe fn not_m(a: __mmask16) -> __mmask16 {
        !a
    }
    #[inline(always)]
    unsafe fn any(m: __mmask16) -> bool {
        m != 0
    }
    #[inline(always)]
    unsafe fn all(m: __mmask16) -> bool {
        m == 0xffff
    }
    #[inline(always)]
    unsafe fn mask_of(v: __m512i) -> __mmask16 {
        _mm512_test_epi32_mask(v, v)
    }
    direct! {
        ints_of(m: __mmask16) -> __m512i = _mm512_movm_epi32;
        min_lane(v: __m512i) -> i32 = _mm512_reduce_min_epi32;
    }
    #[inline(always)]
    unsafe fn store_u16(p: *mut u16, v: __m512i) {
        _mm256_storeu_si256(p as *mut __m256i, _mm512_cvtepi32_epi16(v))
    }
    /// The unpacks work within 128-bit quarters: store q holds the records of lanes
    /// q, q + 4, q + 8, q + 12, so lane j's record starts at byte 64·(j mod 4) + 16·(j div 4).
    #[inline(always)]
    unsafe fn store_records(to: *mut i32, v: Top<Self, 16>) {
        let y = _mm512_castps_si512(v.y);
        let (a, b) = (
            _mm512_unpacklo_epi32(v.at, y),
            _mm512_unpackhi_epi32(v.at, y),
        );
        let (c, d) = (
            _mm512_unpacklo_epi32(v.x, v.x),
            _mm512_unpackhi_epi32(v.x, v.x),
        );
        let to = to as *mut __m512i;
        _mm512_storeu_si512(to, _mm512_unpacklo_epi64(a, c));
        _mm512_storeu_si512(to.add(1), _mm512_unpackhi_epi64(a, c));
        _mm512_storeu_si512(to.add(2), _mm512_unpacklo_epi64(b, d));
        _mm512_storeu_si512(to.add(3), _mm512_unpackhi_epi64(b, d));
    }
    #[inline(always)]
    unsafe fn load_records(base: *const i32, at: __m512i) -> Top<Self, 16> {
        let mut off = [0u32; 16];
        _mm512_storeu_si512(off.as_mut_ptr() as *mut __m512i, at);
        let b = base as *const u8;
        let rec = |j: usize| _mm_loadu_si128(b.add(off[j] as usize) as *const __m128i);
        // Quarter q of r_i holds lane 4q + i's record. (A macro: a closure would be compiled
        // without the caller's AVX-512, and these would not inline.)
        macro_rules! r {
            ($i:expr) => {{
                let v = _mm512_castsi128_si512(rec($i));
                let v = _mm512_inserti32x4::<1>(v, rec(4 + $i));
                let v = _mm512_inserti32x4::<2>(v, rec(8 + $i));
                _mm512_inserti32x4::<3>(v, rec(12 + $i))
            }};
        }
        let (r0, r1, r2, r3) = (r!(0), r!(1), r!(2), r!(3));
        let (t0, t1) = (_mm512_unpacklo_epi32(r0, r1), _mm512_unpacklo_epi32(r2, r3));
        let (t2, t3) = (_mm512_unpackhi_epi32(r0, r1), _mm512_unpackhi_epi32(r2, r3));
        Top {
            at: _mm512_unpacklo_epi64(t0, t1),
            y: _mm512_castsi512_ps(_mm512_unpackhi_epi64(t0, t1)),
            x: _mm512_unpacklo_epi64(t2, t3),
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::cpu::Simd;
    use proptest::prelude::*;

    /// Whether the CPU runs `simd`; on a CI machine without AVX2 (x86-64-v3) a failure.
    fn runs(simd: Simd) -> bool {
        if simd == Simd::Avx2 {
            assert!(
                crate::cpu::has_avx2() || std::env::var_os("CI").is_none(),
                "no AVX2 on this CI machine"
            );
        }
        Simd::widest() >= simd
    }

    /// Record N vertices with `store_records`, read them back at the lanes' offsets (`within`)
    /// in reversed lane order with `load_records`, and check the lanes and the least lane.
    unsafe fn round_trip<V: Lanes<N>, const N: usize>(
        at: [i32; N],
        y: [f32; N],
        x: [i32; N],
    ) -> Result<(), TestCaseError> {
        let mut buf = vec![0i32; N * RECORD];
        let v = Top::<V, N> {
            at: V::load_i(at.as_ptr()),
            y: V::load_f(y.as_ptr()),
            x: V::load_i(x.as_ptr()),
        };
        V::store_records(buf.as_mut_ptr(), v);
        let w = within::<N>();
        let mut bytes = [0i32; N];
        V::store_i(bytes.as_mut_ptr(), V::within());
        prop_assert_eq!(bytes, w);
        let rev: [i32; N] = std::array::from_fn(|j| w[N - 1 - j]);
        let back = V::load_records(buf.as_ptr(), V::load_i(rev.as_ptr()));
        let (mut a, mut b, mut c) = ([0i32; N], [0f32; N], [0i32; N]);
        V::store_i(a.as_mut_ptr(), back.at);
        V::store_f(b.as_mut_ptr(), back.y);
        V::store_i(c.as_mut_ptr(), back.x);
        for j in 0..N {
            let i = N - 1 - j;
            prop_assert_eq!((a[j], b[j].to_bits(), c[j]), (at[i], y[i].to_bits(), x[i]));
        }
        prop_assert_eq!(V::min_lane(v.at), *at.iter().min().unwrap());
        Ok(())
    }

    proptest! {
        /// Records read back what was stored, lane by lane at the layout's offsets (each lane's
        /// 16 bytes at a distinct place in the slot), and the least lane is the least value:
        /// eight lanes of AVX2 and sixteen of AVX-512 where the CPU has them.
        #[test]
        fn records_read_back_what_was_stored(
            at in prop::array::uniform16(any::<i32>()),
            y in prop::array::uniform16(any::<f32>()),
            x in prop::array::uniform16(any::<i32>()),
        ) {
            let half = |v: &[i32; 16]| -> [i32; 8] { v[..8].try_into().unwrap() };
            // SAFETY: each width runs only where detected.
            unsafe {
                if runs(Simd::Avx2) {
                    round_trip::<Avx2, 8>(half(&at), y[..8].try_into().unwrap(), half(&x))?;
                }
                if runs(Simd::Avx512) {
                    round_trip::<Avx512, 16>(at, y, x)?;
                }
            }
        }
    }

    /// Every lane's record is a distinct, whole 16-byte piece of its slot.
    #[test]
    fn each_lane_has_its_own_record_in_a_slot() {
        fn check<const N: usize>() {
            let mut w: Vec<i32> = within::<N>().to_vec();
            w.sort();
            let want: Vec<i32> = (0..N as i32).map(|j| j * 16).collect();
            assert_eq!(w, want, "{N} lanes");
        }
        check::<8>();
        check::<16>();
    }
}
