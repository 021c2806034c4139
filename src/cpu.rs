//! What the CPU can run, detected once at run time: the kernels that have an AVX2 version
//! (the BVH traversal, the horizon sweep's bundles, the certified shadow sweep) call these and
//! fall back to their portable code, which gives the same results, everywhere else. The f32
//! horizon bundles also run sixteen lanes in AVX-512 ([`Simd::Avx512`]). And
//! memory in huge pages for the large arrays that kernels read in strides ([`huge_vec`]).

/// AVX2 (x86-64-v3 machines; every CI machine of this project).
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// AVX2 and FMA (for kernels whose AVX2 version fuses multiply-adds).
pub fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        has_avx2() && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The instruction sets a kernel with vector versions can run here, in order of width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Simd {
    /// The portable code.
    Portable,
    /// AVX2 (x86-64-v3): sixteen 256-bit registers.
    Avx2,
    /// x86-64-v4 (AVX-512 F, BW, CD, DQ, VL): thirty-two 512-bit registers and eight mask
    /// registers. The f32 horizon bundles run sixteen lanes here; the same results as
    /// [`Simd::Avx2`].
    Avx512,
}

impl Simd {
    /// The widest level this CPU runs.
    pub fn widest() -> Simd {
        if has_avx512() {
            Simd::Avx512
        } else if has_avx2() {
            Simd::Avx2
        } else {
            Simd::Portable
        }
    }

    /// [`Simd::widest`] capped by `RELUME_SIMD` (`portable`, `avx2`) when set: the levels
    /// compared in one binary.
    pub fn detect() -> Simd {
        let cap = match std::env::var("RELUME_SIMD").as_deref() {
            Ok("portable") => Simd::Portable,
            Ok("avx2") => Simd::Avx2,
            _ => Simd::Avx512,
        };
        Simd::widest().min(cap)
    }

    /// Every level this CPU runs, narrowest first (for tests that compare them).
    pub fn available() -> Vec<Simd> {
        [Simd::Portable, Simd::Avx2, Simd::Avx512]
            .into_iter()
            .filter(|&s| s <= Simd::widest())
            .collect()
    }
}

/// x86-64-v4's AVX-512 subsets (F, BW, CD, DQ, VL), with AVX2 and FMA.
pub fn has_avx512() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        has_avx2_fma()
            && std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512cd")
            && std::is_x86_feature_detected!("avx512dq")
            && std::is_x86_feature_detected!("avx512vl")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// A vector with room for `n` elements, filled by `fill`, in memory that Linux is asked to back
/// with transparent huge pages (2 MiB) where it can: `madvise(MADV_HUGEPAGE)` before the first
/// touch, which takes effect where THP is `always` or `madvise` (Debian's default) and is
/// ignored elsewhere. For arrays a kernel walks across rather than along: the horizon sweep
/// reads the map b rows a step, a new 4 KiB page for every row, and its TLB misses took about
/// a tenth of a 4096² build (docs/terrain.md).
pub fn huge_vec<T: Copy>(n: usize, fill: impl FnOnce(&mut Vec<T>)) -> Vec<T> {
    let mut v: Vec<T> = Vec::with_capacity(n);
    advise_huge(v.as_ptr() as usize, n * std::mem::size_of::<T>());
    fill(&mut v);
    v
}

/// `madvise(MADV_HUGEPAGE)` on the whole pages of [start, start + bytes).
fn advise_huge(start: usize, bytes: usize) {
    #[cfg(target_os = "linux")]
    {
        let page = 4096;
        let a = (start + page - 1) & !(page - 1);
        let b = (start + bytes) & !(page - 1);
        if b > a {
            // SAFETY: advice on whole pages of an allocation the caller owns; it changes no
            // contents, and failure (no THP in this kernel) is harmless.
            unsafe { libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (start, bytes);
}

#[cfg(test)]
mod tests {
    use super::Simd;

    /// The levels a test compares are the portable one and up to the widest detected, in order;
    /// the default level is the widest (no `RELUME_SIMD` in the test environment).
    #[test]
    fn levels_run_from_portable_to_the_widest() {
        let all = Simd::available();
        assert_eq!(all.first(), Some(&Simd::Portable));
        assert_eq!(all.last(), Some(&Simd::widest()));
        assert!(all.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(all.len(), Simd::widest() as usize + 1);
        if std::env::var_os("RELUME_SIMD").is_none() {
            assert_eq!(Simd::detect(), Simd::widest());
        }
        assert_eq!(Simd::widest() == Simd::Avx512, super::has_avx512());
    }

    /// The contents are `fill`'s, at every size (none, less than a page, many pages).
    #[test]
    fn huge_vec_holds_what_fill_wrote() {
        for n in [0usize, 3, 1 << 20] {
            let v: Vec<u32> = super::huge_vec(n, |v| v.extend((0..n as u32).map(|i| i ^ 7)));
            assert_eq!(v.len(), n);
            assert!(v.iter().enumerate().all(|(i, &x)| x == i as u32 ^ 7));
        }
    }
}
