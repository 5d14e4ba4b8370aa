//! The exact tanh of the NARX network's hidden layers, written out: the
//! algorithm of the C library's `tanh`, step by step, so that the forward
//! pass can run it four neurons at a time ([`super::exact_tanh_avx2`])
//! instead of calling the library once per neuron.
//!
//! # What "exact" is
//!
//! Until now the hidden layers called the standard library's `f64::tanh`,
//! which on Linux is glibc's `tanh`: fdlibm's algorithm (`s_tanh.c`), whose
//! `expm1` (`s_expm1.c`, glibc's variant with its polynomial split in
//! three) glibc builds a second time with fused multiply-adds and picks at
//! run time on CPUs with FMA. [`tanh`] here performs that FMA build's
//! operations in its order — every product, sum, fused multiply-add and
//! division the same, read off glibc 2.36's machine code — so its result
//! is the library's bit for bit on such a machine (a test checks this on
//! millions of points wherever the platform is glibc on x86-64 with FMA),
//! and it is the same bits on every platform, with or without that
//! library. Every other test holds it within one ulp of `f64::tanh`.
//!
//! # The algorithm (fdlibm, glibc)
//!
//! With a = |x|:
//!
//! ```text
//! a < 2⁻⁵⁵:     tanh = x·(1 + x)
//! a < 1:        t = expm1(−2a),  tanh = ±(−t/(t + 2))
//! a < 22:       t = expm1(2a),   tanh = ±(1 − 2/(t + 2))
//! otherwise:    tanh = ±1
//! ```
//!
//! and expm1(y) reduces y = k·ln 2 + r (ln 2 in two parts, k = 0 when
//! |y| ≤ ½ln 2, k = ±1 up to 1.5 ln 2), evaluates e^r − 1 by a rational
//! approximation (Q1…Q5, one division) with a correction term c for the
//! rounding of the reduction, and scales by 2^k from its bits; the last
//! steps differ by k (0, −1, 1, ≤ −2 or > 56, < 20, up to 56). The
//! constants are fdlibm's.

/// 1.0 in the polynomial's `1 + hxs·Q1`.
const ONE: f64 = 1.0;
/// ln 2, high part (its last 21 bits zero, so k·LN2_HI is exact).
pub(super) const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
/// ln 2 − LN2_HI.
pub(super) const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// 1/ln 2.
pub(super) const INV_LN2: f64 = f64::from_bits(0x3ff7_1547_652b_82fe);
/// The scaled coefficients of expm1's rational approximation (fdlibm).
pub(super) const Q: [f64; 5] = [
    f64::from_bits(0xbfa1_1111_1111_10f4),
    f64::from_bits(0x3f5a_01a0_19fe_5585),
    f64::from_bits(0xbf14_ce19_9eaa_dbb7),
    f64::from_bits(0x3ed0_cfca_86e6_5239),
    f64::from_bits(0xbe8a_fdb7_6e09_c32d),
];
/// fdlibm's `huge` and `tiny`.
const HUGE: f64 = 1.0e300;
const TINY: f64 = 1.0e-300;
/// Above this, expm1 overflows (fdlibm's `o_threshold`).
const O_THRESHOLD: f64 = f64::from_bits(0x4086_2e42_fefa_39ef);

/// The high 32 bits of |x|'s representation (fdlibm's `ix`/`hx`).
#[inline(always)]
pub(super) fn high_abs(x: f64) -> u32 {
    ((x.to_bits() >> 32) as u32) & 0x7fff_ffff
}

/// x·2^k for a finite x whose exponent stays in range, by adding k to the
/// exponent field (as glibc does).
#[inline(always)]
fn scale(x: f64, k: i32) -> f64 {
    f64::from_bits(x.to_bits().wrapping_add(((k as i64) << 52) as u64))
}

/// e^y − 1, as glibc 2.36's FMA build of fdlibm's `expm1` computes it
/// (inlined into [`tanh`], whose FMA build runs its multiply-adds as
/// instructions; called on its own it rounds the same, more slowly where
/// the crate is not compiled with FMA).
#[inline(always)]
pub fn expm1(y: f64) -> f64 {
    let hx = high_abs(y);
    let negative = y.is_sign_negative();
    // Filter out huge and non-finite arguments.
    if hx >= 0x4043_687a {
        // |y| ≥ 56·ln 2
        if hx >= 0x4086_2e42 {
            if hx >= 0x7ff0_0000 {
                let lo = y.to_bits() as u32;
                if (hx & 0xf_ffff) | lo != 0 {
                    return y + y; // NaN
                }
                return if negative { -1.0 } else { y };
            }
            if y > O_THRESHOLD {
                return HUGE * HUGE; // overflow
            }
        }
        if negative {
            return TINY - ONE; // e^y < 2⁻⁵⁶: −1 rounded
        }
    }
    // Argument reduction: y = hi − lo = k·ln 2 + r, c the rounding of hi − lo.
    let (x, c, k) = if hx > 0x3fd6_2e42 {
        // |y| > ½·ln 2
        let (hi, lo, k) = if hx < 0x3ff0_a2b2 {
            // and < 1.5·ln 2
            if negative {
                (y + LN2_HI, -LN2_LO, -1)
            } else {
                (y - LN2_HI, LN2_LO, 1)
            }
        } else {
            let k = (INV_LN2 * y + if negative { -0.5 } else { 0.5 }) as i32;
            let t = k as f64;
            ((-t).mul_add(LN2_HI, y), t * LN2_LO, k)
        };
        let x = hi - lo;
        (x, (hi - x) - lo, k)
    } else if hx < 0x3c90_0000 {
        // |y| < 2⁻⁵⁴: e^y − 1 = y rounded
        return y;
    } else {
        (y, 0.0, 0)
    };
    // The rational approximation on the reduced argument.
    let hfx = 0.5 * x;
    let hxs = x * hfx;
    let r1 = hxs.mul_add(Q[0], ONE);
    let h2 = hxs * hxs;
    let r2 = hxs.mul_add(Q[2], Q[1]);
    let h4 = h2 * h2;
    let r3 = hxs.mul_add(Q[4], Q[3]);
    let r = h4.mul_add(r3, h2.mul_add(r2, r1));
    let t = (-r).mul_add(hfx, 3.0);
    let e = (r - t) / (-x).mul_add(t, 6.0) * hxs;
    if k == 0 {
        return x - x.mul_add(e, -hxs);
    }
    let e = x.mul_add(e - c, -c) - hxs;
    match k {
        -1 => 0.5f64.mul_add(x - e, -0.5),
        1 => {
            if x < -0.25 {
                (e - (x + 0.5)) * -2.0
            } else {
                (x - e).mul_add(2.0, ONE)
            }
        }
        k if !(-1..=56).contains(&k) => scale(ONE - (e - x), k) - ONE,
        k if k < 20 => {
            // 1 − 2^−k, exact
            let t = f64::from_bits((0x3ff0_0000u64 - (0x20_0000u64 >> k)) << 32);
            scale(t - (e - x), k)
        }
        k => {
            let t = f64::from_bits(((0x3ff - k) as u64) << 52); // 2^−k
            scale((x - (e + t)) + ONE, k)
        }
    }
}

/// tanh(x), as glibc's `tanh` computes it with the FMA build of `expm1`
/// (module documentation): within one ulp of tanh, the same bits on
/// every platform.
#[inline]
pub fn tanh(x: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::has_avx2_fma() {
        // SAFETY: the CPU has FMA.
        return unsafe { tanh_fma(x) };
    }
    tanh_body(x)
}

/// [`tanh_body`] compiled with FMA: its multiply-adds are instructions,
/// not calls to the C library's `fma`.
///
/// # Safety
///
/// The CPU must have FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn tanh_fma(x: f64) -> f64 {
    tanh_body(x)
}

/// [`tanh`] without the CPU check: inlined into code compiled with FMA
/// (the lanes' remainders), its multiply-adds are instructions there.
#[inline(always)]
pub(super) fn tanh_body(x: f64) -> f64 {
    let bits = x.to_bits();
    let ix = high_abs(x);
    let negative = bits >> 63 != 0;
    if ix >= 0x7ff0_0000 {
        // ±∞ → ±1, NaN → NaN
        let r = ONE / x;
        return if negative { r - ONE } else { r + ONE };
    }
    let z = if ix < 0x4036_0000 {
        // |x| < 22
        if bits << 1 == 0 {
            return x; // ±0
        }
        if ix < 0x3c80_0000 {
            return x * (ONE + x); // |x| < 2⁻⁵⁵
        }
        let a = x.abs();
        if ix >= 0x3ff0_0000 {
            let t = expm1(a + a);
            ONE - 2.0 / (t + 2.0)
        } else {
            let t = expm1(-2.0 * a);
            -t / (t + 2.0)
        }
    } else {
        ONE - TINY // |x| ≥ 22: 1, rounded
    };
    if negative {
        -z
    } else {
        z
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::glibc_check::{assert_same_bits, is_glibc_with_fma, ulps};
    use crate::rng::Rng;

    /// Arguments that cross every branch of tanh and of the expm1 calls it
    /// makes: a dense sweep, every binade, ulp walks around each threshold
    /// and each point where expm1's k changes, and the special values.
    /// Under Miri (.ci/miri) each random stretch is 1 000× shorter and each
    /// walk 100×.
    pub(crate) fn sweep() -> Vec<f64> {
        let n = |k: usize| if cfg!(miri) { k / 1000 } else { k };
        let walk = if cfg!(miri) { 3 } else { 300 };
        let mut xs = vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, 5e-324, f64::MAX];
        let mut r = Rng::new(11);
        for _ in 0..n(400_000) {
            xs.push(25.0 * (2.0 * r.uniform() - 1.0));
        }
        for _ in 0..n(200_000) {
            xs.push(3.0 * r.gaussian());
        }
        // Densely where a hidden neuron's sum mostly falls: a single
        // rounding changed in expm1 moves few results (one fusion of its
        // polynomial, about one tanh in 4.5 M; most changes far more).
        for _ in 0..n(1_000_000) {
            xs.push(2.0 * r.uniform() - 1.0);
        }
        for _ in 0..n(500_000) {
            xs.push(1.0 + 21.0 * r.uniform());
        }
        for e in -1074..1024 {
            for m in [1.0, 1.1, 1.37, 1.5, 1.77, 1.999] {
                xs.push(m * 2f64.powi(e));
            }
        }
        // Thresholds of tanh (2⁻⁵⁵, 1, 22) and of expm1 on ±2a (½ln 2,
        // 1.5 ln 2, 56 ln 2, and k = 20), and the points where k steps.
        let mut marks = vec![2f64.powi(-55), 1.0, 22.0, 0.25 * LN2_HI, 0.75 * LN2_HI, 28.0 * LN2_HI, 10.0 * LN2_HI];
        for k in -4..70 {
            marks.push((k as f64 + 0.5) * std::f64::consts::LN_2 / 2.0);
        }
        for m in marks {
            let mut v = m.abs();
            for _ in 0..walk {
                v = f64::from_bits(v.to_bits() - 1);
            }
            for _ in 0..2 * walk {
                xs.push(v);
                v = f64::from_bits(v.to_bits() + 1);
            }
        }
        let negatives: Vec<f64> = xs.iter().map(|x| -x).collect();
        xs.extend(negatives);
        xs
    }

    #[test]
    fn within_one_ulp_of_the_standard_library_everywhere() {
        for x in sweep() {
            let (got, want) = (tanh(x), x.tanh());
            assert!(ulps(got, want) <= 1, "tanh({x:e}) = {got:e}, std {want:e}");
        }
        assert!(tanh(f64::NAN).is_nan());
    }

    #[test]
    fn equals_glibcs_tanh_bit_for_bit_where_the_platform_is_glibc_with_fma() {
        // glibc picks its FMA build of expm1 on x86-64 CPUs with FMA: there
        // the written-out algorithm must give the library's bits.
        if is_glibc_with_fma() {
            assert_same_bits("tanh", &sweep(), tanh, f64::tanh);
        }
    }

    #[test]
    fn expm1_within_one_ulp_and_glibcs_bits_on_its_whole_range() {
        let glibc_fma = is_glibc_with_fma();
        let mut r = Rng::new(2);
        let mut ys: Vec<f64> = (0..200_000).map(|_| 80.0 * (2.0 * r.uniform() - 1.0)).collect();
        // Densely where tanh calls it: (−2, 0) and [2, 44).
        ys.extend((0..1_000_000).map(|_| -2.0 * r.uniform()));
        ys.extend((0..1_000_000).map(|_| 2.0 + 42.0 * r.uniform()));
        ys.extend((0..1_000_000).map(|_| -0.35 * r.uniform()));
        ys.extend([0.0, -0.0, 1e-300, -1e-300, 0.3, -0.3, 0.5, -0.5, 709.0, 710.0, -800.0, f64::INFINITY]);
        ys.extend([f64::NEG_INFINITY, 0.2 * LN2_HI, -0.9 * LN2_HI, 1.2 * LN2_HI, -1.2 * LN2_HI, 20.5 * LN2_HI]);
        for y in ys {
            let (got, want) = (expm1(y), y.exp_m1());
            assert!(ulps(got, want) <= 1, "expm1({y:e}) = {got:e}, std {want:e}");
            if glibc_fma {
                assert_eq!(got.to_bits(), want.to_bits(), "expm1({y:e})");
            }
        }
        assert!(expm1(f64::NAN).is_nan());
    }

    #[test]
    fn the_portable_build_gives_the_same_bits() {
        // Off x86-64, or on a CPU without FMA, the body runs without the FMA
        // instructions (`mul_add` rounds once either way).
        for x in sweep() {
            let (a, b) = (tanh(x), tanh_body(x));
            assert!(a.to_bits() == b.to_bits(), "{x:e}");
        }
    }

    #[test]
    fn odd_bounded_and_saturating() {
        for x in sweep() {
            let y = tanh(x);
            assert_eq!(tanh(-x).to_bits(), (-y).to_bits(), "{x:e}");
            assert!(y.abs() <= 1.0, "{x:e}");
        }
        assert_eq!(tanh(30.0), 1.0);
        assert_eq!(tanh(f64::NEG_INFINITY), -1.0);
        assert_eq!(tanh(1e-20), 1e-20);
    }
}
