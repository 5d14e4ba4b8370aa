//! What this CPU can run: the one check behind every kernel that has an
//! AVX2 build beside its portable one (the NARX forward pass, the Volterra
//! model, the live synthesis' horizon, `interp`'s kernel taps).

/// Whether this CPU has AVX2 and FMA, so that a function compiled with
/// `#[target_feature(enable = "avx2,fma")]` may run (std caches the answer;
/// always false off x86-64).
pub fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
