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
}
