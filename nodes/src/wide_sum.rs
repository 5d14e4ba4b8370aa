//! Sums of samples, and of their squares, that stay right where a plain f64
//! sum over- or underflows: the mean of samples near ±f64::MAX, the RMS of
//! samples whose squares overflow (|x| ≳ 1e154) or underflow (|x| ≲ 1e-154).
//!
//! Both keep the running sum the code had before ([`Accumulator`]: the
//! compensated [`Sum`] or a plain `f64`) and scale the samples by a power
//! of two only once they leave an ordinary range, so on ordinary samples
//! the result is the plain one, bit for bit; scaling by a power of two is
//! exact, so it costs nothing but the parts that are negligible anyway
//! (terms below 2⁻⁵⁰⁰ of the largest).
//!
//! - [`WideSum`] divides every sample by 2⁶⁴ from the first one above 2⁹⁶⁰
//!   on (below that, fewer than 2⁶³ samples cannot overflow the sum).
//! - [`SumSq`] divides every sample by 2^e, e the binary exponent of the
//!   largest |x| so far, once that leaves [2⁻⁴⁴⁸, 2⁴⁴⁸] (LAPACK's `dlassq`
//!   keeps a scale the same way; here it is a power of two and moves only
//!   when it must). Its root comes back as a [`Scaled`] m·2^e, since the
//!   root of a sum of squares of differences of finite samples can exceed
//!   f64::MAX.

use crate::sum::{Accumulator, Sum};

/// 2^e for e in the normal range −1022 ..= 1023, exactly.
fn pow2(e: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&e), "2^{e} is not a normal f64");
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// x·2^e for any e, in steps of normal powers of two (so the factor is
/// always exact): ±inf beyond f64::MAX, 0 or subnormal below the normal
/// range.
pub fn ldexp(mut x: f64, mut e: i32) -> f64 {
    while e > 1023 && x.is_finite() && x != 0.0 {
        x *= pow2(1023);
        e -= 1023;
    }
    while e < -1022 && x != 0.0 && x.is_finite() {
        x *= pow2(-1022);
        e += 1022;
    }
    x * pow2(e.clamp(-1022, 1023))
}

/// The binary exponent of a finite, non-zero |a|: 2^e ≤ |a| < 2^(e+1).
fn exponent(a: f64) -> i32 {
    let a = a.abs();
    if a < f64::MIN_POSITIVE {
        return exponent(a * pow2(64)) - 64;
    }
    ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// Multiplies `acc` by 2^k, in exact steps.
fn scale_pow2<A: Accumulator>(acc: &mut A, mut k: i32) {
    while k != 0 {
        let step = k.clamp(-1022, 1023);
        acc.scale(pow2(step));
        k -= step;
    }
}

/// A value m·2^e kept apart, so that it may lie beyond f64's range while
/// m stays inside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaled {
    /// The mantissa part.
    pub m: f64,
    /// The power of two it is scaled by.
    pub e: i32,
}

impl Scaled {
    /// m·2^e as an f64: ±inf beyond ±f64::MAX.
    pub fn value(self) -> f64 {
        ldexp(self.m, self.e)
    }

    /// m·2^e cut to ±f64::MAX, and whether it had to be.
    pub fn saturated(self) -> (f64, bool) {
        let v = self.value();
        if v.is_infinite() {
            (f64::MAX.copysign(v), true)
        } else {
            (v, false)
        }
    }

    /// self / other (m / other.m when both are unscaled, bit for bit).
    pub fn ratio(self, other: Scaled) -> f64 {
        ldexp(self.m / other.m, self.e - other.e)
    }
}

/// Where [`WideSum`] starts scaling: 2⁹⁶⁰.
const WIDE_AT: f64 = f64::from_bits((960 + 1023) << 52);
/// The power of two [`WideSum`] scales by, once scaling: 2⁻⁶⁴ (2⁶³
/// samples of at most f64::MAX sum to at most f64::MAX / 2).
const WIDE_SHIFT: i32 = 64;

/// A running sum of samples whose total may overflow: plain (the
/// accumulator's own sum) until a sample exceeds 2⁹⁶⁰, every sample divided
/// by 2⁶⁴ from then on.
#[derive(Debug, Default, Clone, Copy)]
pub struct WideSum<A: Accumulator = Sum> {
    acc: A,
    scaled: bool,
}

impl<A: Accumulator> WideSum<A> {
    /// Adds `x` (a non-finite `x` makes the sum non-finite, as a plain sum).
    #[inline]
    pub fn add(&mut self, x: f64) {
        if !self.scaled && x.abs() > WIDE_AT && x.is_finite() {
            self.acc.scale(pow2(-WIDE_SHIFT));
            self.scaled = true;
        }
        self.acc.add(if self.scaled { x * pow2(-WIDE_SHIFT) } else { x });
    }

    /// The running sum itself, while no sample has been scaled: then adding
    /// an [`ordinary`] sample is adding it to this, bit for bit (for block
    /// loops that keep the sum in a register).
    pub fn plain_mut(&mut self) -> Option<&mut A> {
        (!self.scaled).then_some(&mut self.acc)
    }

    /// The sum divided by `n`, as m·2^e (e = 0, m the plain sum / n, until
    /// the sum was scaled).
    pub fn mean_scaled(&self, n: f64) -> Scaled {
        Scaled { m: self.acc.value() / n, e: if self.scaled { WIDE_SHIFT } else { 0 } }
    }

    /// The mean of `n` added samples: the plain sum / n until the sum was
    /// scaled, then within ±f64::MAX (as the mean of finite samples is;
    /// the cut only undoes the rounding of the last bit).
    pub fn mean(&self, n: f64) -> f64 {
        let s = self.mean_scaled(n);
        if self.scaled {
            s.saturated().0
        } else {
            s.m
        }
    }
}

/// [`SumSq`] scales once the largest |x| leaves [2⁻⁴⁴⁸, 2⁴⁴⁸].
const SQ_LO: f64 = f64::from_bits((1023 - 448) << 52);
/// The upper end of that range, 2⁴⁴⁸ (2⁶³ squares of it are 2⁹⁵⁹).
const SQ_HI: f64 = f64::from_bits((1023 + 448) << 52);
/// The smallest scale exponent (so that 2^−e stays a finite f64).
const SQ_MIN_E: i32 = -1000;

/// Whether `x` is 0 or 2⁻⁴⁴⁸ ≤ |x| ≤ 2⁴⁴⁸: a sample both sums add plainly
/// while they are unscaled ([`WideSum::plain_mut`], [`SumSq::plain_mut`]).
/// False for NaN and ±∞.
#[inline]
pub fn ordinary(x: f64) -> bool {
    let a = x.abs();
    (SQ_LO..=SQ_HI).contains(&a) | (x == 0.0)
}

/// A running sum of squares Σx² = sum·4^e, with 2^e the binary exponent
/// of the largest |x| once that leaves [2⁻⁴⁴⁸, 2⁴⁴⁸] (and 1 while it does
/// not: then it is the plain sum of x·x, bit for bit).
#[derive(Debug, Clone, Copy)]
pub struct SumSq<A: Accumulator = Sum> {
    acc: A,
    max: f64,
    e: i32,
    inv: f64,
}

impl<A: Accumulator> Default for SumSq<A> {
    fn default() -> Self {
        Self { acc: A::default(), max: 0.0, e: 0, inv: 1.0 }
    }
}

impl<A: Accumulator> SumSq<A> {
    /// Adds x² (a non-finite `x` makes the sum non-finite, as a plain sum).
    #[inline]
    pub fn add(&mut self, x: f64) {
        let a = x.abs();
        if a > self.max {
            self.grow(a);
        }
        let y = x * self.inv;
        self.acc.add(y * y);
    }

    /// Adds (x − r)², also where x − r overflows (|x − r| ≤ 2·f64::MAX for
    /// finite x and r).
    #[inline]
    pub fn add_diff(&mut self, x: f64, r: f64) {
        let d = x - r;
        if d.is_finite() || !x.is_finite() || !r.is_finite() {
            self.add(d);
            return;
        }
        if self.e < 1024 {
            self.max = f64::MAX;
            self.rescale(1024);
        }
        let y = x * self.inv - r * self.inv;
        self.acc.add(y * y);
    }

    /// The running sum of squares itself, while it is unscaled, for adding
    /// a block of [`ordinary`] samples whose largest |x| is `peak`: then
    /// adding x² to this is [`SumSq::add`] of each, bit for bit (the scale
    /// stays 1, as every new largest |x| is within [2⁻⁴⁴⁸, 2⁴⁴⁸]); the
    /// largest |x| is raised to `peak` here. `None` once scaled.
    pub fn plain_mut(&mut self, peak: f64) -> Option<&mut A> {
        if self.e != 0 {
            return None;
        }
        debug_assert!(ordinary(peak));
        self.max = self.max.max(peak);
        Some(&mut self.acc)
    }

    /// The largest |x| so far is `a` (finite): the scale follows it.
    #[cold]
    fn grow(&mut self, a: f64) {
        if !a.is_finite() {
            return;
        }
        self.max = a;
        let e = if (SQ_LO..=SQ_HI).contains(&a) { 0 } else { exponent(a).max(SQ_MIN_E) };
        if e != self.e {
            self.rescale(e);
        }
    }

    /// Rescales the sum to exponent `e`.
    fn rescale(&mut self, e: i32) {
        scale_pow2(&mut self.acc, 2 * (self.e - e));
        self.e = e;
        self.inv = ldexp(1.0, -e);
    }

    /// True when every x added was 0.
    pub fn is_zero(&self) -> bool {
        self.acc.value() == 0.0
    }

    /// √(Σx² / n), the RMS of `n` samples, as m·2^e (m = √(sum / n), the
    /// plain result, while unscaled).
    pub fn root_mean(&self, n: f64) -> Scaled {
        Scaled { m: (self.acc.value() / n).max(0.0).sqrt(), e: self.e }
    }

    /// √(Σx² / Σy²), y the squares summed in `other` (√(sum / other's sum),
    /// the plain result, while neither is scaled); +inf or NaN where `other`
    /// is zero, as the plain quotient.
    pub fn sqrt_ratio(&self, other: &SumSq<A>) -> f64 {
        let (a, b) = (self.acc.value(), other.acc.value());
        let q = a / b;
        let root = if q.is_normal() || q == 0.0 || !b.is_normal() { q.sqrt() } else { a.sqrt() / b.sqrt() };
        ldexp(root, self.e - other.e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible spread of ordinary samples (a few decades).
    fn ordinary(n: usize) -> Vec<f64> {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi((s % 7) as i32 - 3)
            })
            .collect()
    }

    #[test]
    fn ldexp_and_exponent_are_exact() {
        assert_eq!(ldexp(1.5, 0), 1.5);
        assert_eq!(ldexp(1.0, -1074), 5e-324);
        assert_eq!(ldexp(1.0, 1023), 2f64.powi(1023));
        assert_eq!(ldexp(1.0, 1024), f64::INFINITY);
        assert_eq!(ldexp(ldexp(1.5, -1060), 1060), 1.5);
        assert_eq!(ldexp(ldexp(f64::MAX, -2000), 2000), f64::MAX);
        assert_eq!(ldexp(f64::MAX, 1), f64::INFINITY);
        assert_eq!(exponent(1.0), 0);
        assert_eq!(exponent(f64::MAX), 1023);
        assert_eq!(exponent(5e-324), -1074);
        assert_eq!(exponent(-3.0), 1);
    }

    #[test]
    fn ordinary_samples_give_the_plain_sums_bit_for_bit() {
        let x = ordinary(10_000);
        let (mut kahan, mut plain) = (SumSq::<Sum>::default(), SumSq::<f64>::default());
        let (mut ks, mut ps) = (Sum::default(), 0.0);
        let (mut wk, mut wp) = (WideSum::<Sum>::default(), WideSum::<f64>::default());
        let mut s = Sum::default();
        for &v in &x {
            kahan.add(v);
            plain.add(v);
            ks.add(v * v);
            ps += v * v;
            wk.add(v);
            wp.add(v);
            s.add(v);
        }
        let n = x.len() as f64;
        assert_eq!(kahan.root_mean(n).value().to_bits(), (ks.value() / n).sqrt().to_bits());
        assert_eq!(plain.root_mean(n).value().to_bits(), (ps / n).sqrt().to_bits());
        assert_eq!(wk.mean(n).to_bits(), (s.value() / n).to_bits());
        assert_eq!(wp.mean(n).to_bits(), (x.iter().sum::<f64>() / n).to_bits());
        let mut half = SumSq::<f64>::default();
        x.iter().for_each(|v| half.add(v / 2.0));
        assert_eq!(plain.sqrt_ratio(&half).to_bits(), (ps / (ps / 4.0)).sqrt().to_bits());
    }

    #[test]
    fn samples_near_max_give_the_true_rms_and_mean() {
        // Plain: (±f64::MAX)² overflows and the RMS is inf (Kahan: NaN).
        let mut q = SumSq::<Sum>::default();
        let mut w = WideSum::<Sum>::default();
        for v in [0.0, f64::MAX, f64::MAX, -f64::MAX, 1.0] {
            q.add(v);
            w.add(v);
        }
        let rms = q.root_mean(5.0).value();
        let want = f64::MAX * (3.0f64 / 5.0).sqrt();
        assert!((rms - want).abs() <= 4.0 * f64::EPSILON * want, "{rms:e} vs {want:e}");
        assert!((w.mean(5.0) - f64::MAX / 5.0).abs() <= 4.0 * f64::EPSILON * f64::MAX, "{}", w.mean(5.0));
        // All at MAX: the mean and RMS are MAX (the cut only undoes rounding).
        let (mut q, mut w) = (SumSq::<f64>::default(), WideSum::<f64>::default());
        for _ in 0..1000 {
            q.add(-f64::MAX);
            w.add(f64::MAX);
        }
        assert_eq!(q.root_mean(1000.0).saturated().0, f64::MAX);
        assert_eq!(w.mean(1000.0), f64::MAX);
    }

    #[test]
    fn a_difference_beyond_max_is_kept_as_a_scaled_value() {
        let (mut d, mut r) = (SumSq::<Sum>::default(), SumSq::<Sum>::default());
        d.add_diff(f64::MAX, -f64::MAX);
        d.add_diff(1.0, 1.0);
        r.add(f64::MAX);
        r.add(0.0);
        let rms = d.root_mean(2.0);
        assert_eq!(rms.saturated(), (f64::MAX, true));
        assert_eq!(rms.ratio(r.root_mean(2.0)), 2.0);
        assert_eq!(d.sqrt_ratio(&r), 2.0);
    }

    #[test]
    fn subnormal_samples_give_the_true_rms() {
        // Plain: every square underflows to 0.
        let tiny = [5e-324, -5e-324, f64::MIN_POSITIVE / 3.0, -f64::MIN_POSITIVE / 7.0, f64::MIN_POSITIVE];
        let mut q = SumSq::<f64>::default();
        tiny.iter().for_each(|&v| q.add(v));
        assert!(!q.is_zero());
        let want = (tiny.iter().map(|v| (v * 2f64.powi(1000)).powi(2)).sum::<f64>() / 5.0).sqrt() * 2f64.powi(-1000);
        assert_eq!(q.root_mean(5.0).value(), want);
        assert!(want > 1e-309, "{want:e}");
        let mut one = SumSq::<f64>::default();
        (0..10).for_each(|_| one.add(5e-324));
        assert_eq!(one.root_mean(10.0).value(), 5e-324);
        // Relative to itself: 1, not 0/0.
        assert_eq!(q.sqrt_ratio(&q), 1.0);
        // A tiny start, then ordinary samples: the tiny part is negligible.
        let mut mixed = SumSq::<f64>::default();
        mixed.add(1e-300);
        mixed.add(3.0);
        mixed.add(4.0);
        assert_eq!(mixed.root_mean(1.0).value(), 5.0);
    }
}
