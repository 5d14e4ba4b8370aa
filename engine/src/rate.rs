//! Rates as integer ratios to the graph's base rate.

use std::fmt;

/// A rate relative to the base rate: `base × mul / div`, with one of `mul`
/// and `div` equal to 1 (every rate is an integer multiple or divisor).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Ratio {
    /// Samples per base tick (≥ 1).
    pub mul: u64,
    /// Base ticks per sample (≥ 1).
    pub div: u64,
}

impl Ratio {
    /// The base rate itself.
    pub const ONE: Ratio = Ratio { mul: 1, div: 1 };

    /// The ratio of `rate` to `base`, if one divides the other exactly
    /// (within 1e-9 relative).
    pub fn of(rate: f64, base: f64) -> Option<Ratio> {
        if !(rate.is_finite() && base.is_finite() && rate > 0.0 && base > 0.0) {
            return None;
        }
        let close = |x: f64| {
            let r = x.round();
            ((1.0..=1e9).contains(&r) && (x - r).abs() <= 1e-9 * x.max(1.0)).then_some(r as u64)
        };
        if rate >= base {
            close(rate / base).map(|mul| Ratio { mul, div: 1 })
        } else {
            close(base / rate).map(|div| Ratio { mul: 1, div })
        }
    }

    /// The rate in Hz for a given base rate.
    pub fn hz(&self, base: f64) -> f64 {
        base * self.mul as f64 / self.div as f64
    }

    /// Number of samples at this rate whose time falls in base ticks
    /// `[t0, t0 + n)` (sample `k` of a divided rate falls at tick `k·div`).
    #[inline]
    pub fn count(&self, t0: u64, n: u64) -> u64 {
        if self.div == 1 {
            n * self.mul
        } else {
            (t0 + n).div_ceil(self.div) - t0.div_ceil(self.div)
        }
    }

    /// Index at this rate of the first sample at or after base tick `t0`.
    #[inline]
    pub fn first(&self, t0: u64) -> u64 {
        if self.div == 1 {
            t0 * self.mul
        } else {
            t0.div_ceil(self.div)
        }
    }

    /// Base ticks covered by `samples` samples at this rate (rounded down).
    pub fn ticks_for(&self, samples: u64) -> u64 {
        if self.div == 1 {
            samples / self.mul
        } else {
            samples.saturating_mul(self.div)
        }
    }
}

impl fmt::Display for Ratio {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.div == 1 {
            write!(f, "×{}", self.mul)
        } else {
            write!(f, "÷{}", self.div)
        }
    }
}

/// Greatest common divisor.
pub fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Least common multiple.
pub fn lcm(a: u64, b: u64) -> u64 {
    a / gcd(a, b) * b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratios_of_common_rates() {
        assert_eq!(Ratio::of(40.0, 1000.0), Some(Ratio { mul: 1, div: 25 }));
        assert_eq!(Ratio::of(10_000.0, 1000.0), Some(Ratio { mul: 10, div: 1 }));
        assert_eq!(Ratio::of(333.0, 1000.0), None);
        assert_eq!(Ratio::of(0.0, 1000.0), None);
    }

    #[test]
    fn counts_add_up_over_any_split() {
        let r = Ratio { mul: 1, div: 25 };
        // Over 1000 ticks there are 40 samples, however the span is cut.
        assert_eq!(r.count(0, 1000), 40);
        let mut total = 0;
        let mut t = 0;
        for n in [1, 7, 24, 25, 26, 100, 817] {
            total += r.count(t, n);
            t += n;
        }
        assert_eq!(total, r.count(0, t));
        assert_eq!(r.count(0, 1), 1);
        assert_eq!(r.count(1, 24), 0);
        assert_eq!(Ratio { mul: 10, div: 1 }.count(5, 3), 30);
    }
}
