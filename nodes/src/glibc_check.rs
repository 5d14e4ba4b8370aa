//! Test helpers for the functions written out from glibc's C library
//! (`narx::exact_tanh`, `exact_exp`): the distance in ulps between two
//! results, whether this platform's `f64` functions are the glibc build
//! they were read from, and the check that a function gives the standard
//! library's bits there.

/// Units in the last place between `a` and `b` (0 for equal bits; ±0 one
/// apart, as the ordering of their representations has them).
pub(crate) fn ulps(a: f64, b: f64) -> u64 {
    let key = |v: f64| {
        let b = v.to_bits() as i64;
        if b < 0 {
            i64::MIN - b
        } else {
            b
        }
    };
    key(a).abs_diff(key(b))
}

/// Whether the standard library's functions are glibc's FMA builds here
/// (glibc on x86-64, with a CPU that has FMA): where the written-out
/// functions must give their bits.
pub(crate) fn is_glibc_with_fma() -> bool {
    cfg!(all(target_arch = "x86_64", target_os = "linux", target_env = "gnu")) && crate::cpu::has_avx2_fma()
}

/// Fails, listing a few, if `ours` and `std` differ in any bit on `xs`.
pub(crate) fn assert_same_bits(what: &str, xs: &[f64], ours: impl Fn(f64) -> f64, std: impl Fn(f64) -> f64) {
    let differ: Vec<f64> = xs.iter().copied().filter(|&x| ours(x).to_bits() != std(x).to_bits()).collect();
    assert!(differ.is_empty(), "{what}: {} arguments differ, e.g. {:?}", differ.len(), &differ[..differ.len().min(5)]);
}
