//! MATLAB `mapminmax`: maps a signal linearly so its minimum and maximum
//! become −1 and +1.
//!
//! y = (y_max − y_min)·(x − x_min)/(x_max − x_min) + y_min with y_min = −1,
//! y_max = +1 (MATLAB Neural Network Toolbox, `mapminmax`, default range).
//! A constant signal (x_max = x_min) has no range to map; MATLAB then uses a
//! gain of 1 with the offset x_min, so the constant maps to −1 — done the
//! same here, so such a channel carries no information and no NaN.

use serde::{Deserialize, Serialize};

/// The map of one channel, fitted to data.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MapMinMax {
    /// Smallest value of the fitted data.
    pub min: f64,
    /// Largest value of the fitted data.
    pub max: f64,
}

impl MapMinMax {
    /// The map that takes the range of `x` (finite values) to [−1, 1].
    /// `None` for data without a finite value.
    pub fn fit(x: &[f64]) -> Option<Self> {
        let mut it = x.iter().copied().filter(|v| v.is_finite());
        let first = it.next()?;
        let (min, max) = it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v)));
        Some(Self { min, max })
    }

    /// True when the fitted data was constant (the map is then a shift to −1).
    pub fn is_constant(&self) -> bool {
        let g = 2.0 / (self.max - self.min);
        g.is_nan() || g.is_infinite() || g <= 0.0
    }

    /// The gain (y_max − y_min)/(x_max − x_min), or 1 for a constant channel.
    #[inline]
    pub fn gain(&self) -> f64 {
        let g = 2.0 / (self.max - self.min);
        if g.is_finite() && g > 0.0 {
            g
        } else {
            1.0
        }
    }

    /// x → y.
    #[inline]
    pub fn apply(&self, x: f64) -> f64 {
        (x - self.min) * self.gain() - 1.0
    }

    /// y → x (the inverse map).
    #[inline]
    pub fn reverse(&self, y: f64) -> f64 {
        (y + 1.0) / self.gain() + self.min
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_the_range_to_minus_one_one_like_matlab() {
        // MATLAB: [y, ps] = mapminmax([1 2 4]) gives y = [-1 -0.3333 1].
        let m = MapMinMax::fit(&[1.0, 2.0, 4.0]).unwrap();
        assert_eq!(m.apply(1.0), -1.0);
        assert!((m.apply(2.0) + 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(m.apply(4.0), 1.0);
        for x in [-3.0, 0.5, 1.7, 10.0] {
            assert!((m.reverse(m.apply(x)) - x).abs() < 1e-12);
        }
    }

    #[test]
    fn a_constant_channel_maps_to_minus_one_without_nan() {
        // MATLAB: mapminmax([5 5 5]) gives [-1 -1 -1].
        let m = MapMinMax::fit(&[5.0, 5.0, 5.0]).unwrap();
        assert!(m.is_constant());
        assert_eq!(m.apply(5.0), -1.0);
        assert_eq!(m.apply(6.0), 0.0);
        assert_eq!(m.reverse(-1.0), 5.0);
    }

    #[test]
    fn ignores_non_finite_values_and_refuses_no_data() {
        let m = MapMinMax::fit(&[f64::NAN, -2.0, f64::INFINITY, 2.0]).unwrap();
        assert_eq!((m.min, m.max), (-2.0, 2.0));
        assert!(MapMinMax::fit(&[]).is_none());
        assert!(MapMinMax::fit(&[f64::NAN]).is_none());
        // A range too small to divide by still gives a finite map.
        let tiny = MapMinMax { min: 0.0, max: 1e-320 };
        assert!(tiny.apply(0.5).is_finite() && tiny.reverse(0.3).is_finite());
    }
}
