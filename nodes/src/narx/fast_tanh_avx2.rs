//! [`super::fast_tanh::tanh_lanes_fused`] of four lanes written in AVX2
//! intrinsics: the same operations in the same order, so the same results
//! bit for bit (a test checks it on the fast tanh's whole sweep).
//!
//! Why: written lane by lane, the polynomial was split by the compiler into
//! one two-lane vector and two scalar chains (122 instructions for four
//! values, 57 of them scalar); here every step is one 4-wide instruction
//! (about 40). Measured in docs/benchmarks.md.

#[cfg(target_arch = "x86_64")]
use super::fast_tanh::{C, LN2_HI, LN2_LO, MAGIC, SATURATE, SWITCH};
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// tanh of four values, each as [`super::fast_tanh::tanh`] with fused
/// multiply-adds (within [`super::fast_tanh::MAX_ABS_ERROR`]).
///
/// # Safety
///
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
pub unsafe fn tanh4(x: [f64; 4]) -> [f64; 4] {
    let splat = |v: f64| _mm256_set1_pd(v);
    let xv = _mm256_loadu_pd(x.as_ptr());
    let sign = splat(-0.0);
    // min(SATURATE, a) returns a when a is NaN: NaN flows through.
    let a = _mm256_min_pd(splat(SATURATE), _mm256_andnot_pd(sign, xv));
    let t = _mm256_add_pd(a, a);
    let m = _mm256_fmadd_pd(t, splat(std::f64::consts::LOG2_E), splat(MAGIC));
    let k = _mm256_sub_pd(m, splat(MAGIC));
    // (−k)·c + t fused equals −(k·c) + t fused: negation is exact.
    let r = _mm256_fnmadd_pd(k, splat(LN2_LO), _mm256_fnmadd_pd(k, splat(LN2_HI), t));
    let r2 = _mm256_mul_pd(r, r);
    let r4 = _mm256_mul_pd(r2, r2);
    let r8 = _mm256_mul_pd(r4, r4);
    let pair = |hi: f64, lo: f64| _mm256_fmadd_pd(splat(hi), r, splat(lo));
    let p01 = pair(C[1], C[0]);
    let p23 = pair(C[3], C[2]);
    let p45 = pair(C[5], C[4]);
    let p67 = pair(C[7], C[6]);
    let p89 = pair(C[9], C[8]);
    let pab = pair(C[11], C[10]);
    let p0 = _mm256_fmadd_pd(p23, r2, p01);
    let p1 = _mm256_fmadd_pd(p67, r2, p45);
    let p2 = _mm256_fmadd_pd(pab, r2, p89);
    let q = _mm256_mul_pd(r, _mm256_fmadd_pd(p2, r8, _mm256_fmadd_pd(p1, r4, p0)));
    // 2^k from its bits: the low bits of m hold k.
    let kb = _mm256_sub_epi64(_mm256_castpd_si256(m), _mm256_set1_epi64x(MAGIC.to_bits() as i64));
    let s = _mm256_castsi256_pd(_mm256_slli_epi64::<52>(_mm256_add_epi64(kb, _mm256_set1_epi64x(1023))));
    let em1 = _mm256_fmadd_pd(s, q, _mm256_sub_pd(s, splat(1.0)));
    let big = _mm256_cmp_pd::<_CMP_GT_OQ>(a, splat(SWITCH));
    let num = _mm256_blendv_pd(em1, splat(2.0), big);
    let quot = _mm256_div_pd(num, _mm256_add_pd(em1, splat(2.0)));
    let v = _mm256_blendv_pd(quot, _mm256_sub_pd(splat(1.0), quot), big);
    let y = _mm256_or_pd(_mm256_andnot_pd(sign, v), _mm256_and_pd(sign, xv));
    let mut out = [0.0; 4];
    _mm256_storeu_pd(out.as_mut_ptr(), y);
    out
}

/// The fused fast tanh of four lanes for code compiled with AVX2 and FMA:
/// [`tanh4`] on x86-64, [`super::fast_tanh::tanh_lanes_fused`] elsewhere
/// (equal results).
///
/// # Safety
///
/// On x86-64 the CPU must have AVX2 and FMA.
#[inline(always)]
pub unsafe fn tanh4_fused(x: [f64; 4]) -> [f64; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        tanh4(x)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        super::fast_tanh::tanh_lanes_fused(x)
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::super::fast_tanh::tanh_lanes_fused;
    use super::*;

    #[test]
    fn equals_the_portable_fused_tanh_bit_for_bit() {
        if !(std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")) {
            return;
        }
        // Under Miri (which checks the intrinsics' memory use, slowly) a
        // coarser sweep over the same ranges.
        let (fine_steps, step, per_binade) = if cfg!(miri) { (3_000, 1e-2, 1) } else { (3_000_000, 1e-5, 16) };
        let fine = (-fine_steps..=fine_steps).map(|i| i as f64 * step);
        let binades = (-1000 * per_binade..1000 * per_binade).flat_map(|i| {
            let v = (i as f64 / per_binade as f64).exp2();
            [v, -v]
        });
        let specials =
            [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 0.5, -0.5, 20.0, 1e308, f64::MIN_POSITIVE];
        let xs: Vec<f64> = fine.chain(binades).chain(specials).collect();
        for c in xs.chunks(4) {
            let mut x = [0.25; 4];
            x[..c.len()].copy_from_slice(c);
            // SAFETY: AVX2 and FMA were detected above.
            let got = unsafe { tanh4(x) };
            let want = tanh_lanes_fused(x);
            for l in 0..4 {
                assert_eq!(got[l].to_bits(), want[l].to_bits(), "x = {}: {} vs {}", x[l], got[l], want[l]);
            }
        }
    }
}
