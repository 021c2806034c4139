//! What the CPU can run, detected once at run time: the kernels that have an AVX2 version
//! (the BVH traversal, the horizon sweep's bundles, the certified shadow sweep) call these and
//! fall back to their portable code, which gives the same results, everywhere else.

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
