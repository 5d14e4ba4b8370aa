//! The exponential, written out: glibc's `exp` step by step, so that hot
//! loops (the display's twin, the simulated display's friction) run it
//! inline instead of through the C library's two calls, with the same
//! bits.
//!
//! # What "the same" is
//!
//! `f64::exp` on Linux is glibc's `exp` (Arm's optimized-routines
//! algorithm, `e_exp.c`), which glibc builds a second time with fused
//! multiply-adds and picks at run time on x86-64 CPUs with FMA; its
//! exported `exp` then wraps that in a second call that sets `errno`.
//! [`exp`] performs the FMA build's operations in its order — every
//! product, sum and fused multiply-add the same, read off glibc 2.36's
//! machine code — so its result is the library's bit for bit on such a
//! machine (a test checks millions of points, every table entry and every
//! special range, wherever the platform is glibc on x86-64 with FMA), and
//! the same bits on every platform. Every other test holds it within one
//! ulp of `f64::exp`. `errno` is not set.
//!
//! # The algorithm (glibc `e_exp.c`)
//!
//! ```text
//! x = k·ln 2/128 + r,  |r| ≤ ln 2/256     (k = round(x·128/ln 2), ln 2/128 in two parts)
//! 2^(k/128) = 2^(k div 128) · s_i · (1 + tail_i),  i = k mod 128   (table)
//! e^x ≈ scale + scale·(tail + r + r²(C2 + r·C3) + r⁴(C4 + r·C5))
//! ```
//!
//! Arguments below 2⁻⁵⁴ in magnitude give 1 + x; from 512 up the scale's
//! exponent could leave the range and is rebuilt (`special_case`), with
//! the subnormal results rounded once; ±∞ and NaN as IEEE says.

pub mod lanes;
mod table;

use table::TAB;

/// 128/ln 2.
const INV_LN2_N: f64 = f64::from_bits(0x4067_1547_652b_82fe);
/// −ln 2/128, high part (its last 17 bits zero, so k·it is exact).
const NEG_LN2_HI_N: f64 = f64::from_bits(0xbf76_2e42_fefa_0000);
/// −ln 2/128 − `NEG_LN2_HI_N`.
const NEG_LN2_LO_N: f64 = f64::from_bits(0xbd0c_f79a_bc9e_3b3a);
/// The polynomial's coefficients C2 … C5 (glibc's `__exp_data.poly`).
const C2: f64 = f64::from_bits(0x3fdf_ffff_ffff_fdbd);
const C3: f64 = f64::from_bits(0x3fc5_5555_5555_543c);
const C4: f64 = f64::from_bits(0x3fa5_5555_cf17_2b91);
const C5: f64 = f64::from_bits(0x3f81_1111_67a4_d017);
/// 1.5·2⁵²: adding it rounds x·128/ln 2 to an integer in the low bits.
const SHIFT: f64 = f64::from_bits(0x4338_0000_0000_0000);
/// 2¹⁰⁰⁹ and 2⁻¹⁰²², the special case's rescaling.
const TWO_1009: f64 = f64::from_bits(0x7f00_0000_0000_0000);
const TWO_M1022: f64 = f64::from_bits(0x0010_0000_0000_0000);

/// e^x as glibc's FMA build of `exp` computes it (module documentation):
/// within one ulp of e^x, the same bits on every platform.
#[inline]
pub fn exp(x: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2_fma() {
        // SAFETY: the CPU has FMA.
        return unsafe { exp_fma(x) };
    }
    exp_body(x)
}

/// [`exp_body`] compiled with FMA: its multiply-adds are instructions,
/// not calls to the C library's `fma`.
///
/// # Safety
///
/// The CPU must have FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn exp_fma(x: f64) -> f64 {
    exp_body(x)
}

/// [`exp`] without the CPU check, for loops compiled with FMA (where its
/// multiply-adds are instructions and it inlines); elsewhere it gives the
/// same bits, its `mul_add`s through the C library's `fma`.
#[inline(always)]
pub fn exp_body(x: f64) -> f64 {
    let bits = x.to_bits();
    let mut abstop = ((bits >> 52) & 0x7ff) as u32;
    // Outside 2⁻⁵⁴ ≤ |x| < 512 (0x3c9 and 0x408 are those exponents).
    if abstop.wrapping_sub(0x3c9) >= 0x408 - 0x3c9 {
        if abstop < 0x3c9 {
            return 1.0 + x; // tiny (and ±0): 1, rounded
        }
        if abstop >= 0x409 {
            // |x| ≥ 1024
            if bits == f64::NEG_INFINITY.to_bits() {
                return 0.0;
            }
            if abstop == 0x7ff {
                return 1.0 + x; // +∞, NaN
            }
            return if bits >> 63 != 0 { 0.0 } else { f64::INFINITY }; // underflow, overflow
        }
        abstop = 0; // 512 ≤ |x| < 1024: the scale is rebuilt below
    }
    let z = x.mul_add(INV_LN2_N, SHIFT);
    let ki = z.to_bits();
    let kd = z - SHIFT;
    let r = kd.mul_add(NEG_LN2_HI_N, x);
    let r = kd.mul_add(NEG_LN2_LO_N, r);
    let idx = 2 * (ki & 0x7f) as usize;
    let tail = f64::from_bits(TAB[idx]);
    let sbits = TAB[idx + 1].wrapping_add(ki << 45);
    let r2 = r * r;
    let t = r.mul_add(C3, C2).mul_add(r2, r + tail);
    let tmp = (r2 * r2).mul_add(r.mul_add(C5, C4), t);
    if abstop == 0 {
        return special_case(tmp, sbits, ki);
    }
    let scale = f64::from_bits(sbits);
    scale.mul_add(tmp, scale)
}

/// e^x for 512 ≤ |x| < 1024 from the main path's `tmp`, scale bits and
/// k: the scale's exponent is moved into range, the result scaled back;
/// below 1 (subnormal results) rounded once before the scaling (glibc's
/// `specialcase`).
#[cold]
#[inline(never)]
fn special_case(tmp: f64, sbits: u64, ki: u64) -> f64 {
    if ki & 0x8000_0000 == 0 {
        // k > 0: the scale's exponent overflowed by at most 460.
        let scale = f64::from_bits(sbits.wrapping_sub(1009 << 52));
        return scale.mul_add(tmp, scale) * TWO_1009;
    }
    // k < 0: the result may be subnormal.
    let scale = f64::from_bits(sbits.wrapping_add(1022 << 52));
    let st = scale * tmp;
    let mut y = scale + st;
    if y < 1.0 {
        let lo = (scale - y) + st;
        let hi = 1.0 + y;
        let lo = ((1.0 - hi) + y) + lo;
        y = (hi + lo) - 1.0;
        if y == 0.0 {
            y = 0.0; // not −0
        }
    }
    y * TWO_M1022
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glibc_check::{assert_same_bits, is_glibc_with_fma, ulps};
    use crate::rng::Rng;

    /// Arguments that cross every range and every table entry: dense
    /// sweeps where the lab's models call exp (−50 … 1), the whole range,
    /// every binade, each k mod 128 at and around its rounding points,
    /// ulp walks across each threshold, and the special values.
    pub(super) fn sweep() -> Vec<f64> {
        let n = |k: usize| if cfg!(miri) { k / 1000 } else { k };
        let mut xs = vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, 5e-324, f64::MAX, f64::MIN];
        let mut r = Rng::new(13);
        for _ in 0..n(1_000_000) {
            xs.push(-50.0 * r.uniform() + 1.0);
        }
        for _ in 0..n(600_000) {
            xs.push(1500.0 * (2.0 * r.uniform() - 1.0));
        }
        for _ in 0..n(300_000) {
            xs.push(-708.0 - 40.0 * r.uniform()); // subnormal results
        }
        for _ in 0..n(300_000) {
            xs.push(2.0 * r.uniform() - 1.0);
        }
        for e in -1074..1024 {
            for m in [1.0, 1.1, 1.37, 1.5, 1.77, 1.999] {
                xs.push(m * 2f64.powi(e));
                xs.push(-m * 2f64.powi(e));
            }
        }
        // Every table entry, at its centre and where k rounds to the next.
        let step = std::f64::consts::LN_2 / 128.0;
        for k in -1300i32..1300 {
            for f in [0.0, 0.49999, 0.5, 0.50001] {
                xs.push((k as f64 + f) * step);
            }
        }
        let walk = if cfg!(miri) { 3 } else { 200 };
        for m in [2f64.powi(-54), 512.0, 1024.0, 709.78, 708.39, 745.13, 7.0e2] {
            for s in [m, -m] {
                let mut v = f64::from_bits(s.to_bits() - walk);
                for _ in 0..2 * walk {
                    xs.push(v);
                    v = f64::from_bits(v.to_bits() + 1);
                }
            }
        }
        xs
    }

    #[test]
    fn within_one_ulp_of_the_standard_library_everywhere() {
        for x in sweep() {
            let (got, want) = (exp(x), x.exp());
            assert!(ulps(got, want) <= 1, "exp({x:e}) = {got:e}, std {want:e}");
        }
        assert!(exp(f64::NAN).is_nan());
    }

    /// Each rounding of the main path that can move a result here does:
    /// computing k's product, the last scaling or the subnormal case's
    /// sum without its fusion (or in another order) fails this test. Four
    /// fusions cannot be seen by any sample of this size: k·(ln 2/128)'s
    /// high part is exact either way, and the low part's, r·C3 + C2's and
    /// r⁴·(C4 + r·C5)'s products round by less than 2⁻¹⁷ of the result's
    /// last place, so unfused they move about one result in 10⁸ or fewer.
    #[test]
    fn equals_glibcs_exp_bit_for_bit_where_the_platform_is_glibc_with_fma() {
        if is_glibc_with_fma() {
            assert_same_bits("exp", &sweep(), exp, f64::exp);
        }
    }

    #[test]
    fn the_portable_build_gives_the_same_bits() {
        for x in sweep() {
            assert_eq!(exp(x).to_bits(), exp_body(x).to_bits(), "{x:e}");
        }
    }

    #[test]
    fn known_values_and_the_edges_of_the_range() {
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-0.0), 1.0);
        assert_eq!(exp(1.0), std::f64::consts::E);
        assert_eq!(exp(std::f64::consts::LN_2), 2.0);
        assert_eq!(exp(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp(f64::INFINITY), f64::INFINITY);
        assert_eq!(exp(710.0), f64::INFINITY);
        assert_eq!(exp(-746.0), 0.0);
        assert!(exp(-746.0).is_sign_positive());
        // The largest finite result and the smallest subnormal one.
        assert!(exp(709.78).is_finite() && exp(709.79).is_infinite());
        assert_eq!(exp(-745.1), 5e-324);
        assert_eq!(exp(1e-300), 1.0);
        // Monotone across the special case's boundaries.
        for m in [512.0f64, -512.0, -708.4, 709.7, 2f64.powi(-54), -(2f64.powi(-54))] {
            let mut v = m;
            for _ in 0..100 {
                assert!(exp(v.next_down()) <= exp(v), "exp at {v:e}");
                v = v.next_up();
            }
        }
    }
}
