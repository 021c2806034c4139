//! The vertex records of the AVX2 hulls ([`super::horizon_hull_f32`]): a slot's eight 16-byte
//! records written as four vector stores after a transpose, read back per lane as eight
//! 16-byte loads and a transpose (in place of three eight-lane gathers), the per-lane pick of
//! two vertices, and the least of eight lanes.

use super::horizon_hull::LANES;

/// The least of eight i32 lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn min_lane(v: std::arch::x86_64::__m256i) -> i32 {
    use std::arch::x86_64::*;
    let m = _mm_min_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
    let m = _mm_min_epi32(m, _mm_shuffle_epi32::<0b01_00_11_10>(m));
    let m = _mm_min_epi32(m, _mm_shuffle_epi32::<0b10_11_00_01>(m));
    _mm_cvtsi128_si32(m)
}

/// One vertex of each of the eight lanes: the byte offset of its record (its slot's, at the
/// lane's place in it: what the vertex above it reads), its height and τ.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(super) struct Top {
    pub at: std::arch::x86_64::__m256i,
    pub y: std::arch::x86_64::__m256,
    pub x: std::arch::x86_64::__m256i,
}

/// i32 per record of the AVX2 hulls: at, y's bits, x, and x again (padding).
pub(super) const RECORD: usize = 4;

/// Each lane's record within a slot, in bytes ([`store_records`]' order): 32·(j mod 4) +
/// 16·(j div 4).
pub(super) const WITHIN: [i32; LANES] = [0, 32, 64, 96, 16, 48, 80, 112];

/// Record the eight lanes' vertices `v` at `to` (one slot): lanes j and j + 4 share 32 bytes,
/// so lane j's record starts at byte 32·(j mod 4) + 16·(j div 4).
///
/// # Safety
/// AVX2 must be available (the caller an AVX2 or wider `#[target_feature]` entry point, into which
/// this inlines); `to` must have room for `LANES * RECORD` i32.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn store_records(to: *mut i32, v: Top) {
    use std::arch::x86_64::*;
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

/// The eight lanes' records at byte offsets `at` from `base` ([`store_records`]' layout):
/// eight 16-byte loads and a transpose, in place of three eight-lane gathers (39 µops each
/// on Zen 3).
///
/// # Safety
/// AVX2 must be available (the caller an AVX2 or wider `#[target_feature]` entry point, into which
/// this inlines); each lane's offset must address a whole record within `base`'s
/// buffer.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn load_records(base: *const i32, at: std::arch::x86_64::__m256i) -> Top {
    use std::arch::x86_64::*;
    let mut off = [0u32; LANES];
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

/// `b` in the lanes of mask `m`, else `a`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn pick(a: Top, b: Top, m: std::arch::x86_64::__m256i) -> Top {
    use std::arch::x86_64::*;
    Top {
        at: _mm256_blendv_epi8(a.at, b.at, m),
        y: _mm256_blendv_ps(a.y, b.y, _mm256_castsi256_ps(m)),
        x: _mm256_blendv_epi8(a.x, b.x, m),
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    proptest! {
        /// The lane minimum of [`super::min_lane`] is the least of the eight values.
        #[test]
        fn min_lane_is_the_least_lane(v in prop::array::uniform8(any::<i32>())) {
            if !crate::cpu::has_avx2() {
                prop_assert!(std::env::var_os("CI").is_none(), "no AVX2 on this CI machine");
                return Ok(());
            }
            #[cfg(target_arch = "x86_64")]
            {
                use std::arch::x86_64::*;
                // SAFETY: AVX2 was detected; an unaligned load of eight i32.
                let got = unsafe { super::min_lane(_mm256_loadu_si256(v.as_ptr() as *const __m256i)) };
                prop_assert_eq!(got, *v.iter().min().unwrap());
            }
        }
    }
}
