//! What the CPU can run, detected once at run time: the kernels that have an AVX2 version
//! (the BVH traversal, the horizon sweep's bundles, the certified shadow sweep) call these and
//! fall back to their portable code, which gives the same results, everywhere else. And memory
//! in huge pages for the large arrays that kernels read in strides ([`huge_vec`]).

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
