//! The weighted-average operator 𝒲𝒜 of dissertation Eq. 6.1.
//!
//! 𝒲𝒜(y₁, y₂, x₁, x₂, x₃) = (x₂ − x₃)/(x₂ − x₁) · y₁ + (x₃ − x₁)/(x₂ − x₁) · y₂,
//! where x is a frequency (Eq. 6.1, 6.2), a scanning velocity (Eq. 6.3) or a
//! mass (Eq. 6.4, steps 1.1 and 1.2).

/// The two weights (w₁, w₂) of Eq. 6.1 for x₃ between x₁ and x₂.
///
/// x₃ is clamped to the interval first (§6.4: a condition outside the grid
/// takes the nearest extreme), so the weights are always in [0, 1] and sum
/// to 1. When x₁ = x₂ (a grid with a single load or velocity) the interval
/// is a point: the weights are (1, 0), never a division by zero.
pub fn weights(x1: f64, x2: f64, x3: f64) -> (f64, f64) {
    let (lo, hi) = if x1 <= x2 { (x1, x2) } else { (x2, x1) };
    let span = x2 - x1;
    if span.abs() <= f64::EPSILON * lo.abs().max(hi.abs()).max(1.0) || !span.is_finite() {
        return (1.0, 0.0);
    }
    let x3 = if x3.is_nan() { lo } else { x3.clamp(lo, hi) };
    let w2 = ((x3 - x1) / span).clamp(0.0, 1.0);
    (1.0 - w2, w2)
}

/// 𝒲𝒜(y₁, y₂, x₁, x₂, x₃) of Eq. 6.1 sample by sample, over the length of
/// the shorter signal.
pub fn wa(y1: &[f64], y2: &[f64], x1: f64, x2: f64, x3: f64) -> Vec<f64> {
    let (w1, w2) = weights(x1, x2, x3);
    y1.iter().zip(y2).map(|(a, b)| w1 * a + w2 * b).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_the_dissertation_examples() {
        // §6.1: f₃ = 15 between 10 and 20 → 0.5 / 0.5.
        assert_eq!(weights(10.0, 20.0, 15.0), (0.5, 0.5));
        // Fig. 6.3: f₃ = 19 → 0.1 / 0.9; Fig. 6.4: f₃ = 12 → 0.8 / 0.2.
        let (a, b) = weights(10.0, 20.0, 19.0);
        assert!((a - 0.1).abs() < 1e-15 && (b - 0.9).abs() < 1e-15);
        let (a, b) = weights(10.0, 20.0, 12.0);
        assert!((a - 0.8).abs() < 1e-15 && (b - 0.2).abs() < 1e-15);
        // Extremes: x₃ = x₁ gives y₁, x₃ = x₂ gives y₂ (§6.1).
        assert_eq!(weights(10.0, 20.0, 10.0), (1.0, 0.0));
        assert_eq!(weights(10.0, 20.0, 20.0), (0.0, 1.0));
    }

    #[test]
    fn outside_the_interval_takes_the_extreme_and_a_point_interval_is_safe() {
        assert_eq!(weights(60.0, 110.0, 20.0), (1.0, 0.0));
        assert_eq!(weights(60.0, 110.0, 500.0), (0.0, 1.0));
        assert_eq!(weights(4.0, 4.0, 7.0), (1.0, 0.0));
        assert_eq!(weights(4.0, 4.0, f64::NAN), (1.0, 0.0));
        assert_eq!(weights(60.0, 110.0, f64::NAN), (1.0, 0.0));
        assert_eq!(wa(&[1.0, 2.0, 3.0], &[3.0, 4.0], 0.0, 1.0, 0.25), vec![1.5, 2.5]);
    }
}
