//! [`super::exact_tanh::tanh`] of four lanes in AVX2 intrinsics: each lane
//! the same operations in the same order as the scalar function, so the
//! same bits (a test checks it on the scalar function's whole sweep).
//!
//! The scalar function branches on |x| (and its `expm1` on the reduced
//! argument's k); here every lane computes every branch tanh can reach and
//! a blend keeps its own, so four tanh cost about one scalar call's
//! operations plus the blends: two divisions per four values (expm1's
//! quotient, and tanh's −t/(t + 2) or 2/(t + 2) as one division whose
//! numerator is chosen per lane). On the arguments tanh gives it — y = −2|x|
//! in (−2, 0) or 2|x| in [2, 44) — expm1's k is 0, −1, −2, −3 or 3…63,
//! never 1, so the k = 1 branch is not computed. A lane holding NaN sends
//! all four to the scalar function.

#[cfg(target_arch = "x86_64")]
use super::exact_tanh::{tanh_body, INV_LN2, LN2_HI, LN2_LO, Q};
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// tanh of four values, each bit for bit [`super::exact_tanh::tanh`].
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
    if _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_UNORD_Q>(xv, xv)) != 0 {
        return x.map(tanh_body);
    }
    let sign = splat(-0.0);
    let one = splat(1.0);
    let a = _mm256_andnot_pd(sign, xv);
    // |x| < 1: expm1(−2|x|); else expm1(2|x|).
    let below_one = _mm256_cmp_pd::<_CMP_LT_OQ>(a, one);
    let y = _mm256_blendv_pd(_mm256_add_pd(a, a), _mm256_mul_pd(splat(-2.0), a), below_one);

    // expm1(y): the reduction y = k·ln 2 + r. k = 0 where |y| ≤ ½ln 2 (high
    // word ≤ 0x3fd62e42), ±1 below 1.5·ln 2 (high word < 0x3ff0a2b2), else
    // trunc(y/ln 2 ± ½). With t = k the one formula below is each branch's
    // (t·LN2_HI and t·LN2_LO are exact for t = 0, ±1).
    let y_sign = _mm256_and_pd(sign, y);
    let ay = _mm256_andnot_pd(sign, y);
    let k_general = _mm256_round_pd::<{ _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC }>(_mm256_add_pd(
        _mm256_mul_pd(splat(INV_LN2), y),
        _mm256_or_pd(splat(0.5), y_sign),
    ));
    let k_zero = _mm256_cmp_pd::<_CMP_LT_OQ>(ay, splat(f64::from_bits(0x3fd6_2e43_0000_0000)));
    let k_unit = _mm256_cmp_pd::<_CMP_LT_OQ>(ay, splat(f64::from_bits(0x3ff0_a2b2_0000_0000)));
    let t =
        _mm256_blendv_pd(_mm256_blendv_pd(k_general, _mm256_or_pd(one, y_sign), k_unit), _mm256_setzero_pd(), k_zero);
    let hi = _mm256_fnmadd_pd(t, splat(LN2_HI), y);
    let lo = _mm256_mul_pd(t, splat(LN2_LO));
    let r = _mm256_sub_pd(hi, lo);
    let c = _mm256_sub_pd(_mm256_sub_pd(hi, r), lo);

    // The rational approximation.
    let hfx = _mm256_mul_pd(splat(0.5), r);
    let hxs = _mm256_mul_pd(r, hfx);
    let r1 = _mm256_fmadd_pd(hxs, splat(Q[0]), one);
    let h2 = _mm256_mul_pd(hxs, hxs);
    let r2 = _mm256_fmadd_pd(hxs, splat(Q[2]), splat(Q[1]));
    let h4 = _mm256_mul_pd(h2, h2);
    let r3 = _mm256_fmadd_pd(hxs, splat(Q[4]), splat(Q[3]));
    let rr = _mm256_fmadd_pd(h4, r3, _mm256_fmadd_pd(h2, r2, r1));
    let tt = _mm256_fnmadd_pd(rr, hfx, splat(3.0));
    let den = _mm256_fnmadd_pd(r, tt, splat(6.0));
    let e = _mm256_mul_pd(_mm256_div_pd(_mm256_sub_pd(rr, tt), den), hxs);

    // Each k's last steps.
    let at_zero = _mm256_sub_pd(r, _mm256_fmsub_pd(r, e, hxs));
    let e = _mm256_sub_pd(_mm256_fmsub_pd(r, _mm256_sub_pd(e, c), c), hxs);
    let at_minus_one = _mm256_fmadd_pd(splat(0.5), _mm256_sub_pd(r, e), splat(-0.5));
    let e_minus_r = _mm256_sub_pd(e, r);
    let k64 = _mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(t));
    let k_bits = _mm256_slli_epi64::<52>(k64);
    let scale = |v: __m256d| _mm256_castsi256_pd(_mm256_add_epi64(_mm256_castpd_si256(v), k_bits));
    let two_minus_k = _mm256_castsi256_pd(_mm256_slli_epi64::<52>(_mm256_sub_epi64(_mm256_set1_epi64x(1023), k64)));
    let far = _mm256_sub_pd(scale(_mm256_sub_pd(one, e_minus_r)), one);
    let mid = scale(_mm256_sub_pd(_mm256_sub_pd(one, two_minus_k), e_minus_r));
    let high = scale(_mm256_add_pd(_mm256_sub_pd(r, _mm256_add_pd(e, two_minus_k)), one));
    let is_far = _mm256_or_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(t, splat(-2.0)), _mm256_cmp_pd::<_CMP_GT_OQ>(t, splat(56.0)));
    let mut em1 = _mm256_blendv_pd(high, mid, _mm256_cmp_pd::<_CMP_LT_OQ>(t, splat(20.0)));
    em1 = _mm256_blendv_pd(em1, far, is_far);
    em1 = _mm256_blendv_pd(em1, at_minus_one, _mm256_cmp_pd::<_CMP_EQ_OQ>(t, splat(-1.0)));
    em1 = _mm256_blendv_pd(em1, at_zero, k_zero);

    // tanh: −t/(t + 2) below 1, 1 − 2/(t + 2) above, one division.
    let num = _mm256_blendv_pd(splat(2.0), _mm256_xor_pd(em1, sign), below_one);
    let q = _mm256_div_pd(num, _mm256_add_pd(em1, splat(2.0)));
    let mut z = _mm256_blendv_pd(_mm256_sub_pd(one, q), q, below_one);
    z = _mm256_blendv_pd(z, one, _mm256_cmp_pd::<_CMP_GE_OQ>(a, splat(22.0)));
    z = _mm256_xor_pd(z, _mm256_and_pd(sign, xv));
    let tiny = _mm256_cmp_pd::<_CMP_LT_OQ>(a, splat(f64::from_bits(0x3c80_0000_0000_0000)));
    z = _mm256_blendv_pd(z, _mm256_mul_pd(xv, _mm256_add_pd(one, xv)), tiny);
    let mut out = [0.0; 4];
    _mm256_storeu_pd(out.as_mut_ptr(), z);
    out
}

/// [`tanh4`] on x86-64, [`super::exact_tanh::tanh`] lane by lane
/// elsewhere (equal results), for code compiled with AVX2 and FMA.
///
/// # Safety
///
/// On x86-64 the CPU must have AVX2 and FMA.
#[inline(always)]
pub unsafe fn tanh4_avx2(x: [f64; 4]) -> [f64; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        tanh4(x)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        x.map(super::exact_tanh::tanh)
    }
}

/// Replaces every value of `v` by its [`super::exact_tanh::tanh`], four
/// at a time with [`tanh4`] where the CPU has AVX2 and FMA (the same bits
/// either way; a test checks every length from 0 to 9).
pub fn tanh_in_place(v: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2_fma() {
        // SAFETY: the CPU has AVX2 and FMA.
        unsafe { tanh_in_place_avx2(v) };
        return;
    }
    for x in v {
        *x = super::exact_tanh::tanh(*x);
    }
}

/// [`tanh_in_place`] compiled for AVX2.
///
/// # Safety
///
/// The CPU must have AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn tanh_in_place_avx2(v: &mut [f64]) {
    let mut chunks = v.chunks_exact_mut(4);
    for c in &mut chunks {
        let y = tanh4([c[0], c[1], c[2], c[3]]);
        c.copy_from_slice(&y);
    }
    for x in chunks.into_remainder() {
        *x = tanh_body(*x);
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::super::exact_tanh::{tanh, tests::sweep};
    use super::*;

    #[test]
    fn in_place_equals_the_scalar_function_at_every_length() {
        let xs: Vec<f64> = sweep().into_iter().step_by(if cfg!(miri) { 97 } else { 997 }).collect();
        for len in 0..10 {
            for w in xs.chunks_exact(len.max(1)).take(2000) {
                let mut v = w[..len].to_vec();
                tanh_in_place(&mut v);
                for (g, x) in v.iter().zip(&w[..len]) {
                    let want = tanh(*x);
                    assert!(g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()), "len {len}: tanh({x:e})");
                }
            }
        }
    }

    #[test]
    fn four_lanes_equal_the_scalar_function_bit_for_bit() {
        if !crate::cpu::has_avx2_fma() {
            return;
        }
        // (Under Miri, .ci/miri, the sweep is shorter.)
        let mut xs = sweep();
        xs.extend([f64::NAN, 0.5, -f64::NAN, 3.0]);
        // Each value in every lane, beside different neighbours.
        for rot in 0..4 {
            for w in xs.chunks_exact(4) {
                let mut v = [w[0], w[1], w[2], w[3]];
                v.rotate_left(rot);
                // SAFETY: AVX2 and FMA checked above.
                let got = unsafe { tanh4(v) };
                for (g, x) in got.iter().zip(v) {
                    let want = tanh(x);
                    assert!(
                        g.to_bits() == want.to_bits() || (g.is_nan() && want.is_nan()),
                        "tanh({x:e}): {g:e} vs {want:e}"
                    );
                }
            }
        }
    }
}
