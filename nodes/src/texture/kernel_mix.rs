//! What `interp` computes for each column of a table sample: the
//! windowed-sinc evaluation ([`SincKernel::eval`]) of the mix
//! a0·u0\[n\] + a1·u1\[n\] of two cells, bit for bit, with its taps four
//! at a time in AVX2 intrinsics on CPUs that have them (each table sample
//! weighs 2·W/c taps of two cells: the texture chains' largest cost).
//!
//! Each lane performs the scalar tap's operations in the same order —
//! u = c·(p − n), x = |u|·512, i = ⌊x⌋, h = g\[i\] + (x − i)·(g\[i+1\] − g\[i\]),
//! the mix a0·u0\[n\] + a1·u1\[n\], its product with h — with separate
//! multiplies and adds, so each weight and term has the scalar bits; the
//! two sums then take the four in order, tap by tap, as the scalar loop
//! does. A block whose x is not below the table's last point (which the
//! scalar code reads as 0, or NaN) goes through the scalar taps.

use super::kernel::{ratio, SincKernel};

/// [`SincKernel::eval`] of the mix a0·u0\[n\] + a1·u1\[n\] (n below the
/// shorter length) at position `p` with cutoff `c`, bit for bit.
#[inline]
pub fn eval_mix(k: &SincKernel, p: f64, c: f64, u0: &[f64], u1: &[f64], a0: f64, a1: f64) -> f64 {
    let len = u0.len().min(u1.len());
    let (u0, u1) = (&u0[..len], &u1[..len]);
    let Some((first, last)) = k.span(p, c, len) else { return 0.0 };
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2_fma() {
        // SAFETY: the CPU has AVX2; `span` keeps `first ..= last` below `len`.
        let (acc, norm) = unsafe { mix_sums(k, p, c, first, last, u0, u1, a0, a1) };
        return ratio(acc, norm);
    }
    let (mut acc, mut norm) = (0.0, 0.0);
    k.taps(p, c, first, last + 1, &mut acc, &mut norm, |q| a0 * u0[q] + a1 * u1[q]);
    ratio(acc, norm)
}

#[cfg(target_arch = "x86_64")]
use super::kernel::OVERSAMPLING;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// The weighted sum and the sum of weights of taps `first ..= last` of the
/// mix a0·u0 + a1·u1 at position `p`, cutoff `c`: the scalar loop's two
/// sums, bit for bit.
///
/// # Safety
///
/// The CPU must have AVX2, and `last` must be below `u0.len()` and
/// `u1.len()`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
unsafe fn mix_sums(
    k: &SincKernel,
    p: f64,
    c: f64,
    first: usize,
    last: usize,
    u0: &[f64],
    u1: &[f64],
    a0: f64,
    a1: f64,
) -> (f64, f64) {
    debug_assert!(last < u0.len() && last < u1.len());
    let table = k.table();
    let at = |q: usize| a0 * u0[q] + a1 * u1[q];
    let (mut acc, mut norm) = (0.0, 0.0);
    // x below this reads the table at i and i + 1 < len (the scalar code's
    // condition for a nonzero weight, and NaN fails it).
    let limit = _mm256_set1_pd((table.len() - 1) as f64);
    let (pv, cv) = (_mm256_set1_pd(p), _mm256_set1_pd(c));
    let over = _mm256_set1_pd(OVERSAMPLING as f64);
    let sign = _mm256_set1_pd(-0.0);
    let (a0v, a1v) = (_mm256_set1_pd(a0), _mm256_set1_pd(a1));
    let mut n = first;
    // n + l as f64, counted in f64 (exact: n < 2⁵³) as the scalar loop does.
    let mut at_n = _mm256_add_pd(_mm256_set1_pd(n as f64), _mm256_set_pd(3.0, 2.0, 1.0, 0.0));
    let four = _mm256_set1_pd(4.0);
    while n + 3 <= last {
        let u = _mm256_mul_pd(cv, _mm256_sub_pd(pv, at_n));
        let x = _mm256_mul_pd(_mm256_andnot_pd(sign, u), over);
        if _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(x, limit)) != 0b1111 {
            k.taps(p, c, n, n + 4, &mut acc, &mut norm, at);
            n += 4;
            at_n = _mm256_add_pd(at_n, four);
            continue;
        }
        // 0 ≤ x < len − 1 < 2³¹: truncation is the scalar `x as u32`.
        let i = _mm256_cvttpd_epi32(x);
        // g[i], g[i + 1] of each lane in one load: [g0 g0' | g2 g2'] and
        // [g1 g1' | g3 g3'], whose interleaves are the four g[i] and g[i + 1].
        let mut idx = [0u32; 4];
        _mm_storeu_si128(idx.as_mut_ptr().cast(), i);
        let pair = |l: usize| _mm_loadu_pd(table.as_ptr().add(idx[l] as usize));
        let even = _mm256_set_m128d(pair(2), pair(0));
        let odd = _mm256_set_m128d(pair(3), pair(1));
        let lo = _mm256_unpacklo_pd(even, odd);
        let hi = _mm256_unpackhi_pd(even, odd);
        let frac = _mm256_sub_pd(x, _mm256_cvtepi32_pd(i));
        let h = _mm256_add_pd(lo, _mm256_mul_pd(frac, _mm256_sub_pd(hi, lo)));
        let mix = _mm256_add_pd(
            _mm256_mul_pd(a0v, _mm256_loadu_pd(u0.as_ptr().add(n))),
            _mm256_mul_pd(a1v, _mm256_loadu_pd(u1.as_ptr().add(n))),
        );
        let term = _mm256_mul_pd(h, mix);
        let (mut hs, mut ts) = ([0.0; 4], [0.0; 4]);
        _mm256_storeu_pd(hs.as_mut_ptr(), h);
        _mm256_storeu_pd(ts.as_mut_ptr(), term);
        for l in 0..4 {
            acc += ts[l];
            norm += hs[l];
        }
        n += 4;
        at_n = _mm256_add_pd(at_n, four);
    }
    k.taps(p, c, n, last + 1, &mut acc, &mut norm, at);
    (acc, norm)
}

#[cfg(test)]
mod tests {
    use super::eval_mix;
    use crate::texture::kernel::SincKernel;

    #[test]
    fn the_mix_gives_the_scalar_loops_bits() {
        let mut r = crate::rng::Rng::new(11);
        let u0: Vec<f64> = (0..3000).map(|_| r.gaussian()).collect();
        let u1: Vec<f64> = (0..2500).map(|n| (n as f64 * 0.37).sin() + 1e-3 * n as f64).collect();
        for k in [SincKernel::for_interp(16), SincKernel::new(2, 1.0, 5.0), SincKernel::for_interp(64)] {
            // Fewer under Miri, which interprets every instruction.
            for case in 0..if cfg!(miri) { 40 } else { 4000 } {
                let p = -40.0 + 2600.0 * r.uniform();
                let c = [1.0, 0.9, 0.45, 0.05, 1e-3, 0.9 / (1.0 + 9.0 * r.uniform())][case % 6];
                let (a0, a1) = (r.uniform(), r.gaussian());
                let want = k.eval(p, c, u0.len().min(u1.len()), |q| a0 * u0[q] + a1 * u1[q]);
                let got = eval_mix(&k, p, c, &u0, &u1, a0, a1);
                assert_eq!(got.to_bits(), want.to_bits(), "p {p}, c {c}");
            }
            // Ends, integer positions, a position past the cells, NaN.
            for p in [0.0, 3.0, 2499.0, 2499.5, 2510.0, 1e9, f64::NAN, f64::INFINITY] {
                for c in [1.0, 0.3, 1e-3] {
                    let want = k.eval(p, c, 2500, |q| 0.25 * u0[q] - 2.0 * u1[q]);
                    let got = eval_mix(&k, p, c, &u0, &u1, 0.25, -2.0);
                    assert_eq!(got.to_bits(), want.to_bits(), "p {p}, c {c}");
                }
            }
        }
    }
}
