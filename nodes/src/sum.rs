//! Compensated summation, for sinks that average long streams, and the
//! [`Accumulator`] a scaled sum ([`crate::wide_sum`]) is built on: this
//! compensated [`Sum`] or a plain `f64`.

/// A running sum: what [`crate::wide_sum`] scales. Implemented by [`Sum`]
/// (compensated) and by `f64` (plain `+=`, for code whose results must stay
/// what its plain sums gave, bit for bit).
pub trait Accumulator: Copy + Default {
    /// Adds `x`.
    fn add(&mut self, x: f64);
    /// The sum.
    fn value(&self) -> f64;
    /// Multiplies the sum by `f` (a power of two: exact unless it underflows).
    fn scale(&mut self, f: f64);
}

/// A running sum that keeps the rounding error of every addition
/// (Kahan–Babuška–Neumaier; the error term by Knuth's branch-free TwoSum,
/// which random data cannot mispredict). 10⁸ additions lose no precision.
#[derive(Debug, Default, Clone, Copy)]
pub struct Sum {
    s: f64,
    c: f64,
}

impl Sum {
    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.s + x;
        let bp = t - self.s;
        self.c += (self.s - (t - bp)) + (x - bp);
        self.s = t;
    }

    /// The sum.
    pub fn value(&self) -> f64 {
        self.s + self.c
    }
}

/// Two [`Sum`]s run side by side: each lane goes through exactly the
/// operations of its own [`Sum::add`], in the same order (so the sums are
/// the same bits), both lanes in one two-lane instruction each on x86-64
/// (SSE2, which every x86-64 has), one lane after the other elsewhere.
#[derive(Debug, Clone, Copy)]
pub struct SumPair {
    #[cfg(target_arch = "x86_64")]
    s: std::arch::x86_64::__m128d,
    #[cfg(target_arch = "x86_64")]
    c: std::arch::x86_64::__m128d,
    #[cfg(not(target_arch = "x86_64"))]
    lanes: [Sum; 2],
}

#[cfg(target_arch = "x86_64")]
impl SumPair {
    /// The pair holding `a` and `b`.
    pub fn new(a: Sum, b: Sum) -> Self {
        use std::arch::x86_64::_mm_set_pd;
        // SAFETY: SSE2 is part of every x86-64 processor (the target's baseline).
        unsafe { Self { s: _mm_set_pd(b.s, a.s), c: _mm_set_pd(b.c, a.c) } }
    }

    /// Adds `x` to the first sum and `y` to the second.
    #[inline]
    pub fn add(&mut self, x: f64, y: f64) {
        use std::arch::x86_64::{_mm_add_pd, _mm_set_pd, _mm_sub_pd};
        // SAFETY: SSE2 is part of every x86-64 processor (the target's baseline).
        unsafe {
            let v = _mm_set_pd(y, x);
            let t = _mm_add_pd(self.s, v);
            let bp = _mm_sub_pd(t, self.s);
            let e = _mm_add_pd(_mm_sub_pd(self.s, _mm_sub_pd(t, bp)), _mm_sub_pd(v, bp));
            self.c = _mm_add_pd(self.c, e);
            self.s = t;
        }
    }

    /// The two sums.
    pub fn sums(&self) -> (Sum, Sum) {
        let lane = |v: std::arch::x86_64::__m128d| {
            let mut a = [0.0; 2];
            // SAFETY: `a` holds two f64, the 16 bytes an unaligned store writes;
            // SSE2 is part of every x86-64 processor.
            unsafe { std::arch::x86_64::_mm_storeu_pd(a.as_mut_ptr(), v) };
            a
        };
        let (s, c) = (lane(self.s), lane(self.c));
        (Sum { s: s[0], c: c[0] }, Sum { s: s[1], c: c[1] })
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl SumPair {
    /// The pair holding `a` and `b`.
    pub fn new(a: Sum, b: Sum) -> Self {
        Self { lanes: [a, b] }
    }

    /// Adds `x` to the first sum and `y` to the second.
    #[inline]
    pub fn add(&mut self, x: f64, y: f64) {
        self.lanes[0].add(x);
        self.lanes[1].add(y);
    }

    /// The two sums.
    pub fn sums(&self) -> (Sum, Sum) {
        (self.lanes[0], self.lanes[1])
    }
}

impl Accumulator for Sum {
    #[inline]
    fn add(&mut self, x: f64) {
        Sum::add(self, x);
    }
    fn value(&self) -> f64 {
        Sum::value(self)
    }
    fn scale(&mut self, f: f64) {
        self.s *= f;
        self.c *= f;
    }
}

impl Accumulator for f64 {
    #[inline]
    fn add(&mut self, x: f64) {
        *self += x;
    }
    fn value(&self) -> f64 {
        *self
    }
    fn scale(&mut self, f: f64) {
        *self *= f;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_what_a_naive_sum_loses() {
        let mut s = Sum::default();
        let mut naive = 0.0;
        for x in std::iter::once(1e16).chain(std::iter::repeat_n(1.0, 1000)).chain(std::iter::once(-1e16)) {
            s.add(x);
            naive += x;
        }
        assert_eq!(s.value(), 1000.0);
        assert_ne!(naive, 1000.0);
    }

    #[test]
    fn a_pair_is_two_sums_bit_for_bit() {
        let (mut a, mut b) = (Sum::default(), Sum::default());
        let mut pair = SumPair::new(a, b);
        let mut x = 0.3f64;
        for k in 0..10_000 {
            x = (x * 3.7 * (1.0 - x)).clamp(1e-9, 1.0);
            let (u, v) = (x * 1e8 - 5e7, (k as f64).powi(3) * x);
            a.add(u);
            b.add(v);
            pair.add(u, v);
        }
        let (pa, pb) = pair.sums();
        assert_eq!((pa.s.to_bits(), pa.c.to_bits()), (a.s.to_bits(), a.c.to_bits()));
        assert_eq!((pb.s.to_bits(), pb.c.to_bits()), (b.s.to_bits(), b.c.to_bits()));
        assert_ne!(a.c, 0.0);
    }
}
