//! The Cholesky factorization A = LLᵀ of a symmetric positive definite
//! matrix, read from its lower triangle, and the solves with it.

use super::dot;
use ndarray::linalg::general_mat_mul;
use ndarray::{s, Array2, Axis};

/// Columns factored together (the matrix product's width).
const PANEL: usize = 48;

/// A matrix that is not (numerically) positive definite: the pivot of
/// column `column` was not a positive finite number.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("not positive definite: pivot {pivot} at column {column}")]
pub struct NotPositiveDefinite {
    /// The column whose pivot failed.
    pub column: usize,
    /// The pivot found there (≤ 0 or not finite).
    pub pivot: f64,
}

/// The lower-triangular factor L of A = LLᵀ (row-major, only the lower
/// triangle is meaningful).
#[derive(Debug, Clone)]
pub struct Cholesky {
    l: Array2<f64>,
}

impl Cholesky {
    /// Factors the symmetric matrix whose lower triangle (diagonal
    /// included) `a` holds; its upper triangle is not read. Left-looking
    /// and blocked: each panel of 48 columns (`PANEL`) is first brought up to
    /// date by one matrix product with the columns left of it (where the
    /// work is), then factored column by column.
    pub fn factor(a: &Array2<f64>) -> Result<Self, NotPositiveDefinite> {
        let n = a.nrows();
        assert_eq!(a.ncols(), n, "Cholesky of a non-square matrix");
        let mut l = Array2::<f64>::zeros((n, n));
        for j0 in (0..n).step_by(PANEL) {
            let j1 = (j0 + PANEL).min(n);
            // The panel, rows j0.. of columns j0..j1, from A's lower triangle.
            for i in j0..n {
                for j in j0..j1.min(i + 1) {
                    l[(i, j)] = a[(i, j)];
                }
            }
            if j0 > 0 {
                // panel −= L[j0.., ..j0] · L[j0..j1, ..j0]ᵀ
                let (left, mut right) = l.view_mut().split_at(Axis(1), j0);
                let mut panel = right.slice_mut(s![j0.., ..j1 - j0]);
                general_mat_mul(-1.0, &left.slice(s![j0.., ..]), &left.slice(s![j0..j1, ..]).t(), 1.0, &mut panel);
            }
            factor_panel(&mut l, j0, j1)?;
        }
        // The products wrote above the diagonal inside the panels: clear it.
        for i in 0..n {
            for j in i + 1..n {
                l[(i, j)] = 0.0;
            }
        }
        Ok(Self { l })
    }

    /// The order of the factored matrix.
    pub fn dim(&self) -> usize {
        self.l.nrows()
    }

    /// x with A x = b (forward substitution with L, back substitution with Lᵀ).
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.dim();
        assert_eq!(b.len(), n, "right-hand side of the wrong length");
        let l = &self.l;
        let mut y = b.to_vec();
        for i in 0..n {
            let ri = l.row(i);
            let mut s = y[i];
            for k in 0..i {
                s -= ri[k] * y[k];
            }
            y[i] = s / ri[i];
        }
        for i in (0..n).rev() {
            let mut s = y[i];
            for k in i + 1..n {
                s -= l[(k, i)] * y[k];
            }
            y[i] = s / l[(i, i)];
        }
        y
    }
}

/// Factors columns j0..j1 of `l` in place, their earlier columns already
/// subtracted: within the panel, the unblocked column-oriented Cholesky.
fn factor_panel(l: &mut Array2<f64>, j0: usize, j1: usize) -> Result<(), NotPositiveDefinite> {
    let n = l.nrows();
    let contiguous = "rows of a standard-layout array are contiguous";
    for j in j0..j1 {
        let d = {
            let row_j = l.row(j);
            let rj = &row_j.as_slice().expect(contiguous)[j0..j];
            l[(j, j)] - dot(rj, rj)
        };
        if !(d > 0.0 && d.is_finite()) {
            return Err(NotPositiveDefinite { column: j, pivot: d });
        }
        let ljj = d.sqrt();
        l[(j, j)] = ljj;
        for i in j + 1..n {
            let s = {
                let (ri, rj) = (l.row(i), l.row(j));
                dot(&ri.as_slice().expect(contiguous)[j0..j], &rj.as_slice().expect(contiguous)[j0..j])
            };
            l[(i, j)] = (l[(i, j)] - s) / ljj;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use ndarray::array;

    #[test]
    fn factors_a_worked_example() {
        // Golub & Van Loan's kind of example with an exact factor:
        // A = LLᵀ for L = [[2,0,0],[6,1,0],[-8,5,3]].
        let a = array![[4.0, 12.0, -16.0], [12.0, 37.0, -43.0], [-16.0, -43.0, 98.0]];
        let c = Cholesky::factor(&a).unwrap();
        let want = array![[2.0, 0.0, 0.0], [6.0, 1.0, 0.0], [-8.0, 5.0, 3.0]];
        assert_eq!(c.l, want);
        // A x = b for x = (1, −2, 3): b = A x.
        let b = [4.0 - 24.0 - 48.0, 12.0 - 74.0 - 129.0, -16.0 + 86.0 + 294.0];
        let x = c.solve(&b);
        for (got, want) in x.iter().zip([1.0, -2.0, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{x:?}");
        }
    }

    #[test]
    fn reads_only_the_lower_triangle() {
        let mut a = array![[4.0, 999.0], [2.0, 5.0]];
        let x = Cholesky::factor(&a).unwrap().solve(&[6.0, 7.0]);
        a[(0, 1)] = 2.0;
        // Symmetric [[4,2],[2,5]] x = (6,7) → x = (1, 1).
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15, "{x:?}");
    }

    #[test]
    fn refuses_what_is_not_positive_definite() {
        let indefinite = array![[1.0, 0.0], [2.0, 1.0]];
        assert_eq!(Cholesky::factor(&indefinite).unwrap_err().column, 1);
        let zero = Array2::<f64>::zeros((3, 3));
        assert_eq!(Cholesky::factor(&zero).unwrap_err().column, 0);
        let nan = array![[f64::NAN]];
        assert!(Cholesky::factor(&nan).is_err());
    }

    #[test]
    fn solves_random_spd_systems_to_rounding() {
        // A = BᵀB + I for a random B: the residual ‖Ax − b‖ stays at rounding.
        let mut r = Rng::new(11);
        for n in [1, 7, 40, 48, 49, 130, 461] {
            let b = Array2::from_shape_fn((n + 3, n), |_| r.gaussian());
            let a = b.t().dot(&b) + Array2::<f64>::eye(n);
            let rhs: Vec<f64> = (0..n).map(|_| r.gaussian()).collect();
            let x = Cholesky::factor(&a).unwrap().solve(&rhs);
            let ax = a.dot(&ndarray::Array1::from(x));
            let err = ax.iter().zip(&rhs).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            assert!(err < 1e-9, "n = {n}: residual {err}");
        }
    }
}
