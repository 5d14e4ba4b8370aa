//! Least-squares polynomial fits with their coefficient of determination,
//! for the curves drawn through a sweep's results.

/// A fitted polynomial y = Σ c_k x^k and how well it fits.
#[derive(Debug, Clone, PartialEq)]
pub struct PolyFit {
    /// Coefficients, lowest order first.
    pub coef: Vec<f64>,
    /// R² = 1 − SS_res / SS_tot (1 for a perfect fit; 1 by convention when
    /// the data are constant and fitted exactly).
    pub r2: f64,
}

impl PolyFit {
    /// The polynomial at `x`.
    pub fn eval(&self, x: f64) -> f64 {
        self.coef.iter().rev().fold(0.0, |acc, c| acc * x + c)
    }

    /// `y = a + b·x + c·x²` with the coefficients written out (a power a
    /// restricted fit leaves out, exactly 0, is not written).
    pub fn formula(&self) -> String {
        let mut s = format!("y = {:.6}", self.coef[0]);
        for (k, c) in self.coef.iter().enumerate().skip(1).filter(|(_, c)| **c != 0.0) {
            let sign = if *c < 0.0 { '−' } else { '+' };
            let pow = if k == 1 { "x".to_string() } else { format!("x^{k}") };
            s.push_str(&format!(" {sign} {:.6}·{pow}", c.abs()));
        }
        s
    }
}

/// Fits a polynomial of `degree` to the points by least squares (normal
/// equations on x scaled to [−1, 1], solved by Gaussian elimination with
/// partial pivoting). `None` with fewer than `degree + 1` distinct x values
/// or non-finite points.
pub fn polyfit(points: &[(f64, f64)], degree: usize) -> Option<PolyFit> {
    let n = degree + 1;
    if points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return None;
    }
    let mut xs: Vec<f64> = points.iter().map(|p| p.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    if xs.len() < n {
        return None;
    }
    // Scale x to [−1, 1] so the normal equations stay well conditioned.
    let (lo, hi) = (xs[0], xs[xs.len() - 1]);
    let (mid, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    let t = |x: f64| (x - mid) / half;
    let mut a = vec![vec![0.0; n + 1]; n];
    for &(x, y) in points {
        let tx = t(x);
        let pw: Vec<f64> = (0..2 * n).scan(1.0, |p, _| Some(std::mem::replace(p, *p * tx))).collect();
        for i in 0..n {
            for j in 0..n {
                a[i][j] += pw[i + j];
            }
            a[i][n] += pw[i] * y;
        }
    }
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        for r in 0..n {
            if r != col {
                let f = a[r][col] / a[col][col];
                let pivot_row = a[col].clone();
                for (v, p) in a[r].iter_mut().zip(pivot_row) {
                    *v -= f * p;
                }
            }
        }
    }
    let scaled: Vec<f64> = (0..n).map(|i| a[i][n] / a[i][i]).collect();
    // Back to powers of x: expand Σ s_k ((x − mid)/half)^k.
    let mut coef = vec![0.0; n];
    for (k, s) in scaled.iter().enumerate() {
        // (x − mid)^k / half^k by the binomial theorem.
        let mut binom = 1.0;
        for (j, c) in coef.iter_mut().enumerate().take(k + 1) {
            *c += s * binom * (-mid).powi((k - j) as i32) / half.powi(k as i32);
            binom = binom * (k - j) as f64 / (j + 1) as f64;
        }
    }
    let fit = PolyFit { coef, r2: 0.0 };
    let mean = points.iter().map(|p| p.1).sum::<f64>() / points.len() as f64;
    let ss_tot: f64 = points.iter().map(|p| (p.1 - mean).powi(2)).sum();
    let ss_res: f64 = points.iter().map(|p| (p.1 - fit.eval(p.0)).powi(2)).sum();
    let r2 = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else if ss_res == 0.0 {
        1.0
    } else {
        0.0
    };
    Some(PolyFit { r2, ..fit })
}

/// The square law y = a + b·x² by least squares (the law of
/// electrovibration's static friction increase and vibration against the
/// input intensity, dissertation §3.1.2: no linear term). `None` with fewer
/// than two distinct x² values or non-finite points.
pub fn square_law(points: &[(f64, f64)]) -> Option<PolyFit> {
    if points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return None;
    }
    // A straight line through (x², y).
    let squared: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x * x, y)).collect();
    let line = polyfit(&squared, 1)?;
    Some(PolyFit { coef: vec![line.coef[0], 0.0, line.coef[1]], r2: line.r2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_quadratic() {
        let pts: Vec<(f64, f64)> =
            (1..=10).map(|k| k as f64 / 10.0).map(|x| (x, 0.02 + 0.05 * x + 0.2 * x * x)).collect();
        let f = polyfit(&pts, 2).unwrap();
        for (got, want) in f.coef.iter().zip([0.02, 0.05, 0.2]) {
            assert!((got - want).abs() < 1e-12, "{:?}", f.coef);
        }
        assert!((f.r2 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_square_law_has_no_linear_term_and_recovers_its_coefficients() {
        let pts: Vec<(f64, f64)> = (1..=10).map(|k| k as f64 / 10.0).map(|x| (x, 0.1 + 0.07 * x * x)).collect();
        let f = square_law(&pts).unwrap();
        assert!(
            (f.coef[0] - 0.1).abs() < 1e-12 && f.coef[1] == 0.0 && (f.coef[2] - 0.07).abs() < 1e-12,
            "{:?}",
            f.coef
        );
        assert!((f.r2 - 1.0).abs() < 1e-12);
        assert_eq!(f.formula(), "y = 0.100000 + 0.070000·x^2");
        // Data with a dip (a floor, then the law) fit worse than a free quadratic.
        let dip: Vec<(f64, f64)> =
            (1..=10).map(|k| k as f64 / 10.0).map(|x| (x, 0.115 - 0.133 * x + 0.201 * x * x)).collect();
        assert!(square_law(&dip).unwrap().r2 < polyfit(&dip, 2).unwrap().r2);
        assert!(square_law(&[(1.0, 1.0), (-1.0, 2.0)]).is_none(), "one distinct x²");
    }

    #[test]
    fn linear_fit_matches_the_closed_form() {
        // Least squares line through (0,1), (1,2), (2,2), (3,4): slope 0.9, intercept 0.9.
        let f = polyfit(&[(0.0, 1.0), (1.0, 2.0), (2.0, 2.0), (3.0, 4.0)], 1).unwrap();
        assert!((f.coef[1] - 0.9).abs() < 1e-12 && (f.coef[0] - 0.9).abs() < 1e-12, "{:?}", f.coef);
        // R² = 1 − 0.7/4.75.
        assert!((f.r2 - (1.0 - 0.7 / 4.75)).abs() < 1e-12, "{}", f.r2);
    }

    #[test]
    fn stays_accurate_far_from_the_origin() {
        let pts: Vec<(f64, f64)> =
            (0..20).map(|k| 1e6 + k as f64).map(|x| (x, 3.0 * (x - 1e6).powi(2) - 1.0)).collect();
        let f = polyfit(&pts, 2).unwrap();
        for &(x, y) in &pts {
            assert!((f.eval(x) - y).abs() < 1e-3 * (1.0 + y.abs()), "{x}: {} vs {y}", f.eval(x));
        }
    }

    #[test]
    fn too_few_points_or_non_finite_give_none() {
        assert!(polyfit(&[(1.0, 1.0), (1.0, 2.0), (2.0, 3.0)], 2).is_none());
        assert!(polyfit(&[(1.0, f64::NAN), (2.0, 2.0), (3.0, 3.0)], 1).is_none());
    }
}
