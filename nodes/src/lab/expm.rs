//! Matrix exponential of small dense matrices and exact zero-order-hold
//! discretization of linear systems.
//!
//! `expm` is scaling and squaring with the diagonal Padé(6,6) approximant:
//! A is scaled by 2^-s until its ∞-norm is at most 1/2, the approximant
//! r(X) = D(X)^-1 N(X) is formed and squared s times (Moler & Van Loan,
//! "Nineteen dubious ways to compute the exponential of a matrix, twenty-five
//! years later", SIAM Review 45 (2003), method 3; the bound there gives a
//! relative backward error below 1e-15 for q = 6 and ‖X‖ ≤ 1/2).

/// A square matrix stored row-major, `n × n`.
#[derive(Debug, Clone, PartialEq)]
pub struct Mat {
    /// Dimension.
    pub n: usize,
    /// Entries, row by row.
    pub a: Vec<f64>,
}

impl Mat {
    /// The zero matrix.
    pub fn zeros(n: usize) -> Self {
        Self { n, a: vec![0.0; n * n] }
    }

    /// The identity.
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n);
        for i in 0..n {
            m.a[i * n + i] = 1.0;
        }
        m
    }

    /// From rows (all of length `rows.len()`).
    pub fn from_rows(rows: &[&[f64]]) -> Self {
        let n = rows.len();
        let mut m = Self::zeros(n);
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), n, "row {i} has {} entries, expected {n}", r.len());
            m.a[i * n..(i + 1) * n].copy_from_slice(r);
        }
        m
    }

    /// Entry (i, j).
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }

    /// Sets entry (i, j).
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        self.a[i * self.n + j] = v;
    }

    /// The matrix product `self · b`.
    pub fn mul(&self, b: &Mat) -> Mat {
        let n = self.n;
        let mut c = Mat::zeros(n);
        for i in 0..n {
            for k in 0..n {
                let x = self.a[i * n + k];
                if x != 0.0 {
                    for j in 0..n {
                        c.a[i * n + j] += x * b.a[k * n + j];
                    }
                }
            }
        }
        c
    }

    /// `self · s`.
    pub fn scale(&self, s: f64) -> Mat {
        Mat { n: self.n, a: self.a.iter().map(|x| x * s).collect() }
    }

    /// The ∞-norm (largest absolute row sum).
    pub fn norm_inf(&self) -> f64 {
        (0..self.n)
            .map(|i| self.a[i * self.n..(i + 1) * self.n].iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// Solves `self · X = b` by Gaussian elimination with partial pivoting;
    /// `None` if the matrix is singular to working precision.
    pub fn solve(&self, b: &Mat) -> Option<Mat> {
        let n = self.n;
        let mut m = self.a.clone();
        let mut x = b.a.clone();
        for col in 0..n {
            let p = (col..n).max_by(|&i, &j| m[i * n + col].abs().total_cmp(&m[j * n + col].abs()))?;
            if m[p * n + col].abs() < 1e-300 || !m[p * n + col].is_finite() {
                return None;
            }
            if p != col {
                for j in 0..n {
                    m.swap(p * n + j, col * n + j);
                    x.swap(p * n + j, col * n + j);
                }
            }
            let d = m[col * n + col];
            for i in col + 1..n {
                let f = m[i * n + col] / d;
                if f != 0.0 {
                    for j in col..n {
                        m[i * n + j] -= f * m[col * n + j];
                    }
                    for j in 0..n {
                        x[i * n + j] -= f * x[col * n + j];
                    }
                }
            }
        }
        for col in (0..n).rev() {
            let d = m[col * n + col];
            for j in 0..n {
                let mut s = x[col * n + j];
                for k in col + 1..n {
                    s -= m[col * n + k] * x[k * n + j];
                }
                x[col * n + j] = s / d;
            }
        }
        Some(Mat { n, a: x })
    }
}

/// Coefficients of the diagonal Padé(6,6) approximant of e^x:
/// c_k = (2q−k)! q! / ((2q)! k! (q−k)!), q = 6.
const PADE6: [f64; 7] = [1.0, 0.5, 5.0 / 44.0, 1.0 / 66.0, 1.0 / 792.0, 1.0 / 15840.0, 1.0 / 665280.0];

/// e^A. `None` only if A holds NaN or Inf (or is too large to exponentiate).
pub fn expm(a: &Mat) -> Option<Mat> {
    let n = a.n;
    if a.a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let norm = a.norm_inf();
    let s = if norm > 0.5 { (norm / 0.5).log2().ceil() as i32 } else { 0 };
    if s > 1000 {
        return None;
    }
    let x = a.scale(0.5f64.powi(s));
    // Powers X^0 … X^6.
    let mut pw = vec![Mat::identity(n), x.clone()];
    for k in 2..=6 {
        let next = pw[k - 1].mul(&x);
        pw.push(next);
    }
    let mut num = Mat::zeros(n);
    let mut den = Mat::zeros(n);
    for (k, p) in pw.iter().enumerate() {
        let c = PADE6[k];
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        for (i, v) in p.a.iter().enumerate() {
            num.a[i] += c * v;
            den.a[i] += sign * c * v;
        }
    }
    let mut r = den.solve(&num)?;
    for _ in 0..s {
        r = r.mul(&r);
    }
    if r.a.iter().all(|x| x.is_finite()) {
        Some(r)
    } else {
        None
    }
}

/// The exact zero-order-hold discretization of ẋ = A x + B u over a step `h`:
/// x(t+h) = Φ x(t) + Γ u(t) with Φ = e^{Ah}, Γ = ∫₀ʰ e^{Aτ} dτ B, both read
/// from the exponential of the block matrix [[A, B], [0, 0]]·h.
/// `a` is n × n row-major, `b` is n × m row-major; returns (Φ, Γ) row-major.
pub fn zoh(a: &[f64], b: &[f64], n: usize, m: usize, h: f64) -> Option<(Vec<f64>, Vec<f64>)> {
    let big = n + m;
    let mut z = Mat::zeros(big);
    for i in 0..n {
        for j in 0..n {
            z.set(i, j, a[i * n + j] * h);
        }
        for j in 0..m {
            z.set(i, n + j, b[i * m + j] * h);
        }
    }
    let e = expm(&z)?;
    let mut phi = vec![0.0; n * n];
    let mut gam = vec![0.0; n * m];
    for i in 0..n {
        for j in 0..n {
            phi[i * n + j] = e.get(i, j);
        }
        for j in 0..m {
            gam[i * m + j] = e.get(i, n + j);
        }
    }
    Some((phi, gam))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat, b: &Mat, tol: f64) -> bool {
        a.a.iter().zip(&b.a).all(|(x, y)| (x - y).abs() <= tol * (1.0 + y.abs()))
    }

    /// Taylor series summed until the terms vanish (reference for small norms).
    fn taylor(a: &Mat) -> Mat {
        let mut sum = Mat::identity(a.n);
        let mut term = Mat::identity(a.n);
        for k in 1..60 {
            term = term.mul(a).scale(1.0 / k as f64);
            for (s, t) in sum.a.iter_mut().zip(&term.a) {
                *s += t;
            }
        }
        sum
    }

    #[test]
    fn diagonal_and_zero() {
        let a = Mat::from_rows(&[&[1.0, 0.0, 0.0], &[0.0, -2.0, 0.0], &[0.0, 0.0, 0.0]]);
        let e = expm(&a).unwrap();
        let want = Mat::from_rows(&[&[1f64.exp(), 0.0, 0.0], &[0.0, (-2f64).exp(), 0.0], &[0.0, 0.0, 1.0]]);
        assert!(close(&e, &want, 1e-14), "{e:?}");
        assert!(close(&expm(&Mat::zeros(4)).unwrap(), &Mat::identity(4), 0.0));
    }

    #[test]
    fn rotation_generator_gives_rotation() {
        for theta in [0.1, 1.0, 3.0, 50.0] {
            let a = Mat::from_rows(&[&[0.0, theta], &[-theta, 0.0]]);
            let e = expm(&a).unwrap();
            let (c, s) = (f64::cos(theta), f64::sin(theta));
            let want = Mat::from_rows(&[&[c, s], &[-s, c]]);
            assert!(close(&e, &want, 1e-12), "theta {theta}: {e:?}");
        }
    }

    #[test]
    fn nilpotent_is_a_finite_series() {
        // Strictly upper triangular: e^N = I + N + N²/2 exactly.
        let a = Mat::from_rows(&[&[0.0, 2.0, 3.0], &[0.0, 0.0, 4.0], &[0.0, 0.0, 0.0]]);
        let want = Mat::from_rows(&[&[1.0, 2.0, 3.0 + 4.0], &[0.0, 1.0, 4.0], &[0.0, 0.0, 1.0]]);
        assert!(close(&expm(&a).unwrap(), &want, 1e-14));
    }

    #[test]
    fn matches_taylor_and_inverse_for_general_matrices() {
        let a = Mat::from_rows(&[
            &[0.3, -0.7, 0.2, 0.1],
            &[0.5, -0.1, 0.9, -0.4],
            &[-0.6, 0.2, 0.1, 0.3],
            &[0.05, 0.4, -0.2, -0.8],
        ]);
        for scale in [0.1, 1.0, 4.0] {
            let s = a.scale(scale);
            let e = expm(&s).unwrap();
            assert!(close(&e, &taylor(&s), 1e-12), "scale {scale}");
            // e^A e^-A = I.
            let prod = e.mul(&expm(&s.scale(-1.0)).unwrap());
            assert!(close(&prod, &Mat::identity(4), 1e-12), "scale {scale}");
        }
    }

    #[test]
    fn damped_oscillator_matches_closed_form_even_when_stiff() {
        // ẍ + 2ζω ẋ + ω² x = 0, state (x, ẋ); closed form for ζ < 1.
        for (w, zeta, h) in
            [(2.0 * std::f64::consts::PI * 225.0, 0.18, 1e-3), (2.0 * std::f64::consts::PI * 150e3, 0.05, 1e-3)]
        {
            let a = Mat::from_rows(&[&[0.0, 1.0], &[-w * w, -2.0 * zeta * w]]).scale(h);
            let e = expm(&a).unwrap();
            let wd = w * (1.0 - zeta * zeta).sqrt();
            let decay = (-zeta * w * h).exp();
            let (c, s) = ((wd * h).cos(), (wd * h).sin());
            let want = Mat::from_rows(&[
                &[decay * (c + zeta * w / wd * s), decay * s / wd],
                &[-decay * w * w / wd * s, decay * (c - zeta * w / wd * s)],
            ]);
            for (x, y) in e.a.iter().zip(&want.a) {
                assert!((x - y).abs() <= 1e-10 * (1.0 + y.abs()) + 1e-12, "w {w}: {x} vs {y}");
            }
        }
    }

    #[test]
    fn zoh_of_first_order_lag() {
        // ẋ = −a x + a u: Φ = e^{−ah}, Γ = 1 − e^{−ah}.
        let (a, h) = (300.0, 1e-3);
        let (phi, gam) = zoh(&[-a], &[a], 1, 1, h).unwrap();
        assert!((phi[0] - (-a * h).exp()).abs() < 1e-15);
        assert!((gam[0] - (1.0 - (-a * h).exp())).abs() < 1e-15);
    }

    #[test]
    fn refuses_non_finite() {
        assert!(expm(&Mat::from_rows(&[&[f64::NAN]])).is_none());
        assert!(expm(&Mat::from_rows(&[&[f64::INFINITY]])).is_none());
    }
}
