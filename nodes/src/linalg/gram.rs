//! The lower triangle of a Gram matrix, accumulated from blocks of rows.

use ndarray::linalg::general_mat_mul;
use ndarray::{s, Array2, ArrayView2};

/// Tile side of the triangular accumulation: tiles on or below the
/// diagonal are multiplied, those above it skipped (about half the
/// multiply-adds of the full product).
const TILE: usize = 128;

/// C ← β·C + AᵀA on the lower triangle of C (tiles that straddle the
/// diagonal are computed whole, so a few entries above it are written
/// too; read only the lower triangle). `a` is m × p, `c` p × p; β is 0
/// (replace) or 1 (accumulate).
pub fn add_lower_gram(c: &mut Array2<f64>, a: ArrayView2<'_, f64>, accumulate: bool) {
    let p = a.ncols();
    assert_eq!(c.dim(), (p, p), "Gram matrix of the wrong shape");
    let beta = if accumulate { 1.0 } else { 0.0 };
    for i0 in (0..p).step_by(TILE) {
        let i1 = (i0 + TILE).min(p);
        let ai = a.slice(s![.., i0..i1]);
        // Rows i0..i1 of C, columns 0..i1: the tiles left of and on the diagonal.
        let mut ci = c.slice_mut(s![i0..i1, 0..i1]);
        general_mat_mul(1.0, &ai.t(), &a.slice(s![.., 0..i1]), beta, &mut ci);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn equals_the_full_product_on_the_lower_triangle() {
        let mut r = Rng::new(3);
        for (m, p) in [(1, 1), (5, 3), (200, 64), (300, 65), (77, 150)] {
            let a = Array2::from_shape_fn((m, p), |_| r.gaussian());
            let b = Array2::from_shape_fn((m, p), |_| r.gaussian());
            let full = a.t().dot(&a) + b.t().dot(&b);
            let mut c = Array2::from_elem((p, p), f64::NAN);
            add_lower_gram(&mut c, a.view(), false);
            add_lower_gram(&mut c, b.view(), true);
            for i in 0..p {
                for j in 0..=i {
                    let (got, want) = (c[(i, j)], full[(i, j)]);
                    assert!((got - want).abs() <= 1e-12 * want.abs().max(1.0), "({i},{j}) of {m}×{p}: {got} vs {want}");
                }
            }
        }
    }
}
