//! The square law above a measured floor, y = (f^p + (b·x²)^p)^(1/p): the
//! fit of a measure that reads a floor f with the effect off (x = 0) and
//! the square law b·x² of electrovibration once the effect rises above it.
//!
//! The two are combined as a p-norm, p fitted: p = 1 would add them, p = 2
//! adds them in quadrature (the rms of two independent signals), p → ∞
//! takes the larger alone. A measure made of the largest swings of a
//! signal — `peaks`' mean of the 50 largest peak-to-peak amplitudes — takes
//! each of its swings from the floor's events or from the vibration,
//! whichever is larger, so it lies between quadrature and the larger alone
//! (p > 2). The floor is measured, not fitted: f is the mean y at x = 0, and
//! the curve passes through it. b > 0 and 1 ≤ p ≤ 100 are fitted by least
//! squares over the points at x ≠ 0 (Levenberg–Marquardt on ln b and ln p,
//! from several starts), and R² is taken over those points.

/// A fitted square law over a floor and how well it fits.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorFit {
    /// The floor f: the mean of the points at x = 0.
    pub floor: f64,
    /// The square law's coefficient b (y → b·x² far above the floor).
    pub b: f64,
    /// The norm's exponent p (2: in quadrature).
    pub p: f64,
    /// R² = 1 − SS_res / SS_tot over the points at x ≠ 0, the ones fitted
    /// (1 for a perfect fit).
    pub r2: f64,
}

/// Why a floor fit cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FloorFitError {
    /// A point holds NaN or an infinity.
    #[error("a point is not finite")]
    NonFinite,
    /// No point at x = 0.
    #[error("no point at x = 0, where the floor is measured (add 0 to the sweep)")]
    NoFloor,
    /// The floor is not above 0.
    #[error("the floor measured at x = 0 is {0}, not above 0")]
    FloorNotPositive(f64),
    /// Fewer than two distinct x² besides 0.
    #[error("{0} distinct value(s) of x² besides 0: the fit needs two")]
    TooFewPoints(usize),
    /// No point at x ≠ 0 lies above the floor.
    #[error("no point lies above the floor measured at x = 0: the square law never shows")]
    NothingAboveFloor,
}

/// The largest p fitted: beyond it the curve is the larger of floor and law.
const P_MAX: f64 = 100.0;

/// (f^p + s^p)^(1/p) for f > 0, s ≥ 0, without overflow.
fn combine(f: f64, s: f64, p: f64) -> f64 {
    let m = f.max(s);
    m * ((f / m).powf(p) + (s / m).powf(p)).powf(1.0 / p)
}

impl FloorFit {
    /// The curve at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        combine(self.floor, self.b * x * x, self.p)
    }

    /// The model with its coefficients written out.
    pub fn formula(&self) -> String {
        format!(
            "y = (f^p + (b·x^2)^p)^(1/p), f = {:.6} (measured at x = 0), b = {:.6}, p = {:.4}",
            self.floor, self.b, self.p
        )
    }
}

/// Parameters θ = (ln b, ln p).
type Theta = [f64; 2];

/// The points at x ≠ 0 with the floor: the least-squares problem.
struct Problem {
    floor: f64,
    /// (x², y) of the points at x ≠ 0.
    pts: Vec<(f64, f64)>,
}

impl Problem {
    fn sse(&self, t: Theta) -> f64 {
        let (b, p) = (t[0].exp(), t[1].exp());
        self.pts.iter().map(|&(x2, y)| (combine(self.floor, b * x2, p) - y).powi(2)).sum()
    }

    /// JᵀJ and Jᵀr at θ: ∂G/∂ln b = G·(s/G)^p and
    /// ∂G/∂ln p = G·(w_f·ln(f/G) + w_s·ln(s/G)), w = (·/G)^p.
    fn normal(&self, t: Theta) -> ([[f64; 2]; 2], [f64; 2]) {
        let (b, p) = (t[0].exp(), t[1].exp());
        let f = self.floor;
        let (mut a, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
        for &(x2, y) in &self.pts {
            let s = b * x2;
            let big = combine(f, s, p);
            let (wf, ws) = ((f / big).powf(p), (s / big).powf(p));
            let term = |w: f64, v: f64| if w > 0.0 && v > 0.0 { w * (v / big).ln() } else { 0.0 };
            let j = [big * ws, big * (term(wf, f) + term(ws, s))];
            let r = big - y;
            for i in 0..2 {
                g[i] += j[i] * r;
                for k in 0..2 {
                    a[i][k] += j[i] * j[k];
                }
            }
        }
        (a, g)
    }

    /// Levenberg–Marquardt from `t`, ln p held to [0, ln P_MAX].
    fn solve(&self, mut t: Theta) -> (Theta, f64) {
        let clamp = |t: Theta| [t[0], t[1].clamp(0.0, P_MAX.ln())];
        t = clamp(t);
        let mut sse = self.sse(t);
        let mut lambda = 1e-3;
        for _ in 0..500 {
            if sse == 0.0 || lambda > 1e16 {
                break;
            }
            let (a, g) = self.normal(t);
            let d = [a[0][0] * (1.0 + lambda) + 1e-300, a[1][1] * (1.0 + lambda) + 1e-300];
            let det = d[0] * d[1] - a[0][1] * a[1][0];
            if !det.is_finite() || det == 0.0 {
                break;
            }
            let step = [-(d[1] * g[0] - a[0][1] * g[1]) / det, -(d[0] * g[1] - a[1][0] * g[0]) / det];
            let next = clamp([t[0] + step[0], t[1] + step[1]]);
            let e = self.sse(next);
            if e.is_finite() && e < sse {
                let moved = (next[0] - t[0]).abs() + (next[1] - t[1]).abs();
                (t, sse) = (next, e);
                lambda = (lambda / 10.0).max(1e-12);
                if moved < 1e-15 * (1.0 + t[0].abs() + t[1].abs()) {
                    break;
                }
            } else {
                lambda *= 10.0;
            }
        }
        (t, sse)
    }
}

/// Fits y = (f^p + (b·x²)^p)^(1/p) to the points, f the mean y at x = 0.
/// Bad or degenerate input is an error, never a panic.
pub fn square_over_floor(points: &[(f64, f64)]) -> Result<FloorFit, FloorFitError> {
    if points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return Err(FloorFitError::NonFinite);
    }
    let at_zero: Vec<f64> = points.iter().filter(|p| p.0 == 0.0).map(|p| p.1).collect();
    if at_zero.is_empty() {
        return Err(FloorFitError::NoFloor);
    }
    let floor = at_zero.iter().sum::<f64>() / at_zero.len() as f64;
    if floor.is_nan() || floor <= 0.0 {
        return Err(FloorFitError::FloorNotPositive(floor));
    }
    let pts: Vec<(f64, f64)> = points.iter().filter(|p| p.0 != 0.0).map(|&(x, y)| (x * x, y)).collect();
    let mut squares: Vec<f64> = pts.iter().map(|p| p.0).collect();
    squares.sort_by(f64::total_cmp);
    squares.dedup();
    if squares.len() < 2 || squares[0] == 0.0 {
        // x² underflowing to 0 for a tiny x ≠ 0 is no distinct point either.
        return Err(FloorFitError::TooFewPoints(squares.iter().filter(|s| **s > 0.0).count()));
    }
    // The point furthest above the floor starts b at each p.
    let Some(&(x2, top)) = pts.iter().filter(|p| p.1 > floor).max_by(|a, b| (a.1 - floor).total_cmp(&(b.1 - floor)))
    else {
        return Err(FloorFitError::NothingAboveFloor);
    };
    let problem = Problem { floor, pts };
    let mut best: Option<(Theta, f64)> = None;
    for p in [1.0, 2.0, 4.0, 8.0, 16.0] {
        let s = top * (1.0 - (floor / top).powf(p)).powf(1.0 / p);
        let b = s / x2;
        if !(b.is_finite() && b > 0.0) {
            continue;
        }
        let (t, sse) = problem.solve([b.ln(), f64::ln(p)]);
        if sse.is_finite() && best.is_none_or(|(_, e)| sse < e) {
            best = Some((t, sse));
        }
    }
    // With a point above a positive floor every start is finite; a start
    // that is not (an x² near overflow) leaves no fit rather than a wrong one.
    let (t, sse) = best.ok_or(FloorFitError::NothingAboveFloor)?;
    let n = problem.pts.len() as f64;
    let mean = problem.pts.iter().map(|p| p.1).sum::<f64>() / n;
    let ss_tot: f64 = problem.pts.iter().map(|p| (p.1 - mean).powi(2)).sum();
    let r2 = if ss_tot > 0.0 {
        1.0 - sse / ss_tot
    } else if sse == 0.0 {
        1.0
    } else {
        0.0
    };
    Ok(FloorFit { floor, b: t[0].exp(), p: t[1].exp(), r2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(f: f64, b: f64, p: f64) -> Vec<(f64, f64)> {
        (0..=10).map(|k| k as f64 / 10.0).map(|x| (x, combine(f, b * x * x, p))).collect()
    }

    #[test]
    fn recovers_known_coefficients_exactly_on_noiseless_data() {
        for (f, b, p) in [(0.0989, 0.18, 3.27), (0.1, 0.16, 2.0), (0.05, 0.3, 1.0), (2.0, 40.0, 6.5)] {
            let fit = square_over_floor(&curve(f, b, p)).unwrap();
            assert_eq!(fit.floor, f);
            assert!((fit.b - b).abs() < 1e-9 * b && (fit.p - p).abs() < 1e-9 * p, "{fit:?} for {f} {b} {p}");
            assert!((fit.r2 - 1.0).abs() < 1e-12, "{fit:?}");
            assert!((fit.eval(0.0) - f).abs() < 1e-15, "the curve passes through the floor");
        }
    }

    #[test]
    fn the_floor_is_the_mean_at_zero_and_far_above_it_the_curve_is_the_square_law() {
        let mut pts = curve(0.1, 0.2, 2.0);
        pts[0].1 = 0.09;
        pts.push((0.0, 0.11));
        let fit = square_over_floor(&pts).unwrap();
        assert!((fit.floor - 0.1).abs() < 1e-15, "{fit:?}");
        assert!((fit.eval(100.0) / (0.2 * 1e4) - 1.0).abs() < 1e-6);
        assert!(fit
            .formula()
            .starts_with("y = (f^p + (b·x^2)^p)^(1/p), f = 0.100000 (measured at x = 0), b = 0.200000"));
    }

    #[test]
    fn noisy_data_fit_better_than_the_plain_square_law() {
        // A floor of 0.1, the law 0.18·x² above it at p = 3, ±2 % alternating noise.
        let pts: Vec<(f64, f64)> = curve(0.1, 0.18, 3.0)
            .into_iter()
            .enumerate()
            .map(|(k, (x, y))| (x, y * (1.0 + 0.02 * (-1f64).powi(k as i32))))
            .collect();
        let fit = square_over_floor(&pts).unwrap();
        let square = crate::fit::square_law(&pts).unwrap();
        assert!(fit.r2 > 0.97 && fit.r2 > square.r2, "{fit:?} against {}", square.r2);
        assert!((fit.b - 0.18).abs() < 0.02 && (2.0..4.5).contains(&fit.p), "{fit:?}");
    }

    #[test]
    fn bad_or_degenerate_input_is_an_error_not_a_panic() {
        use FloorFitError::*;
        let good = curve(0.1, 0.18, 3.0);
        assert_eq!(square_over_floor(&good[1..]), Err(NoFloor));
        let mut nan = good.clone();
        nan[3].1 = f64::NAN;
        assert_eq!(square_over_floor(&nan), Err(NonFinite));
        nan[3] = (f64::INFINITY, 1.0);
        assert_eq!(square_over_floor(&nan), Err(NonFinite));
        assert_eq!(square_over_floor(&[(0.0, 0.0), (0.5, 1.0), (1.0, 2.0)]), Err(FloorNotPositive(0.0)));
        assert_eq!(square_over_floor(&[(0.0, -1.0), (0.5, 1.0), (1.0, 2.0)]), Err(FloorNotPositive(-1.0)));
        assert_eq!(square_over_floor(&[(0.0, 0.1), (0.5, 1.0), (-0.5, 2.0)]), Err(TooFewPoints(1)));
        assert_eq!(square_over_floor(&[(0.0, 0.1)]), Err(TooFewPoints(0)));
        assert_eq!(square_over_floor(&[]), Err(NoFloor));
        assert_eq!(square_over_floor(&[(0.0, 0.1), (1e-200, 0.2), (1.0, 0.3)]), Err(TooFewPoints(1)));
        let flat: Vec<(f64, f64)> = good.iter().map(|&(x, _)| (x, 0.1)).collect();
        assert_eq!(square_over_floor(&flat), Err(NothingAboveFloor));
        // Extreme but finite input: a result or an error, never a panic or NaN.
        for pts in [
            vec![(0.0, 1e-300), (1e150, 1e300), (2e150, f64::MAX)],
            vec![(0.0, f64::MAX), (1.0, f64::MAX), (2.0, f64::MAX)],
            vec![(0.0, 1e-300), (1e-150, 1e-290), (1.0, 1.0)],
        ] {
            if let Ok(f) = square_over_floor(&pts) {
                assert!(f.b.is_finite() && f.p.is_finite() && !f.r2.is_nan(), "{f:?}");
            }
        }
    }
}
