//! Min–max normalization to [−1, 1], as MATLAB's `mapminmax` does for
//! network inputs and targets: y = 2·(x − min)/(max − min) − 1. A constant
//! channel (max = min) maps to 0 and back to its value (MATLAB passes such
//! rows through unchanged; 0 keeps them from biasing the network).

use serde::{Deserialize, Serialize};

/// The range of one channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MinMax {
    /// Smallest value seen.
    pub min: f64,
    /// Largest value seen.
    pub max: f64,
}

impl MinMax {
    /// The range of the finite values of `x`; `None` when there is none.
    pub fn of(x: &[f64]) -> Option<Self> {
        let (min, max) = x
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        (min <= max).then_some(MinMax { min, max })
    }

    /// True when the channel is constant.
    pub fn is_constant(&self) -> bool {
        self.max <= self.min
    }

    /// x → [−1, 1] (outside the range: beyond ±1, linearly).
    #[inline]
    pub fn apply(&self, x: f64) -> f64 {
        if self.is_constant() {
            0.0
        } else {
            2.0 * (x - self.min) / (self.max - self.min) - 1.0
        }
    }

    /// [−1, 1] → x.
    #[inline]
    pub fn reverse(&self, y: f64) -> f64 {
        if self.is_constant() {
            self.min
        } else {
            (y + 1.0) * 0.5 * (self.max - self.min) + self.min
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_the_range_onto_minus_one_one_and_back() {
        let m = MinMax::of(&[3.0, -1.0, 7.0, f64::NAN, 2.0]).unwrap();
        assert_eq!((m.min, m.max), (-1.0, 7.0));
        assert_eq!(m.apply(-1.0), -1.0);
        assert_eq!(m.apply(7.0), 1.0);
        assert_eq!(m.apply(3.0), 0.0);
        for x in [-5.0, 0.3, 6.9, 100.0] {
            assert!((m.reverse(m.apply(x)) - x).abs() < 1e-12);
        }
    }

    #[test]
    fn constant_and_empty_channels() {
        let c = MinMax::of(&[2.5; 10]).unwrap();
        assert!(c.is_constant());
        assert_eq!(c.apply(2.5), 0.0);
        assert_eq!(c.apply(9.0), 0.0);
        assert_eq!(c.reverse(0.3), 2.5);
        assert!(MinMax::of(&[f64::NAN, f64::INFINITY]).is_none());
        assert!(MinMax::of(&[]).is_none());
    }
}
