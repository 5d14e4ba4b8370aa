//! [`super::exp_body`] four arguments at a time, in the lanes of one AVX2
//! register: each lane performs the scalar main path's operations in its
//! order — the same fused multiply-adds, products and sums, the table read
//! by a gather — so each lane has [`super::exp_body`]'s bits. Arguments
//! below 2⁻⁵⁴ in magnitude give 1 + x, as there; when any lane is 512 or
//! more in magnitude (or not finite), all four take the scalar function.

#[cfg(target_arch = "x86_64")]
use super::{exp_body, C2, C3, C4, C5, INV_LN2_N, NEG_LN2_HI_N, NEG_LN2_LO_N, SHIFT, TAB};
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// e^x in each lane of `x`, each lane [`super::exp_body`]'s bits.
///
/// # Safety
///
/// Code compiled with AVX2 and FMA calls it as a safe function; elsewhere
/// the CPU must have both.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2,fma")]
pub fn exp4(x: __m256d) -> __m256d {
    let abstop = _mm256_and_si256(_mm256_srli_epi64::<52>(_mm256_castpd_si256(x)), _mm256_set1_epi64x(0x7ff));
    // 512 ≤ |x|, ∞ and NaN (exponent 0x408 and up): the scalar function's special paths.
    if _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(abstop, _mm256_set1_epi64x(0x407)))) != 0 {
        return scalar(x);
    }
    // |x| < 2⁻⁵⁴ (exponent below 0x3c9): 1 + x.
    let tiny = _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_set1_epi64x(0x3c9), abstop));
    let shift = _mm256_set1_pd(SHIFT);
    let z = _mm256_fmadd_pd(x, _mm256_set1_pd(INV_LN2_N), shift);
    let ki = _mm256_castpd_si256(z);
    let kd = _mm256_sub_pd(z, shift);
    let r = _mm256_fmadd_pd(kd, _mm256_set1_pd(NEG_LN2_HI_N), x);
    let r = _mm256_fmadd_pd(kd, _mm256_set1_pd(NEG_LN2_LO_N), r);
    let idx = _mm256_slli_epi64::<1>(_mm256_and_si256(ki, _mm256_set1_epi64x(0x7f)));
    // SAFETY: idx ≤ 254, so idx and idx + 1 are inside the 256-word table.
    let (tail, sbits) = unsafe {
        let base = TAB.as_ptr() as *const i64;
        (_mm256_i64gather_epi64::<8>(base, idx), _mm256_i64gather_epi64::<8>(base.add(1), idx))
    };
    let tail = _mm256_castsi256_pd(tail);
    let sbits = _mm256_add_epi64(sbits, _mm256_slli_epi64::<45>(ki));
    let r2 = _mm256_mul_pd(r, r);
    let t = _mm256_fmadd_pd(_mm256_fmadd_pd(r, _mm256_set1_pd(C3), _mm256_set1_pd(C2)), r2, _mm256_add_pd(r, tail));
    let tmp = _mm256_fmadd_pd(_mm256_mul_pd(r2, r2), _mm256_fmadd_pd(r, _mm256_set1_pd(C5), _mm256_set1_pd(C4)), t);
    let scale = _mm256_castsi256_pd(sbits);
    let main = _mm256_fmadd_pd(scale, tmp, scale);
    _mm256_blendv_pd(main, _mm256_add_pd(_mm256_set1_pd(1.0), x), tiny)
}

/// [`exp_body`] lane by lane.
#[cfg(target_arch = "x86_64")]
#[cold]
#[target_feature(enable = "avx2,fma")]
fn scalar(x: __m256d) -> __m256d {
    let mut v = [0.0; 4];
    // SAFETY: `v` holds four f64.
    unsafe { _mm256_storeu_pd(v.as_mut_ptr(), x) };
    for e in v.iter_mut() {
        *e = exp_body(*e);
    }
    // SAFETY: as above.
    unsafe { _mm256_loadu_pd(v.as_ptr()) }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    #[test]
    fn four_lanes_are_the_scalar_function_bit_for_bit() {
        if !crate::cpu::has_avx2_fma() {
            return;
        }
        // The scalar function's sweep (every range, table entry and
        // special value), four consecutive arguments a register, then
        // shifted by one so each argument meets other lanes' ranges.
        let xs = super::super::tests::sweep();
        for offset in [0, 1, 2] {
            for chunk in xs[offset..].chunks_exact(4) {
                let mut got = [0.0; 4];
                // SAFETY: the CPU has AVX2 and FMA (checked above).
                unsafe { _mm256_storeu_pd(got.as_mut_ptr(), exp4(_mm256_loadu_pd(chunk.as_ptr()))) };
                for (g, x) in got.iter().zip(chunk) {
                    assert_eq!(g.to_bits(), exp_body(*x).to_bits(), "exp({x:e}) among {chunk:?}");
                }
            }
        }
    }
}
