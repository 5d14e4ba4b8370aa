//! Dense linear algebra for fitting models and for the live synthesis:
//! the lower triangle of a Gram matrix accumulated tile by tile, the
//! Cholesky factorization that solves the normal equations, and dot
//! products — one at a time ([`dot`]) or many rows against one vector at
//! once with the same bits ([`dot_columns()`]). The Gram products run on
//! ndarray's `general_mat_mul` (the `matrixmultiply` kernels, which pick
//! AVX/FMA at run time); the factorization is written here (Golub & Van
//! Loan, *Matrix Computations*, 4th ed., Algorithm 4.2.1, the
//! column-oriented "gaxpy" Cholesky).

pub mod cholesky;
pub mod dot_columns;
pub mod gram;

pub use cholesky::{Cholesky, NotPositiveDefinite};
pub use dot_columns::dot_columns;
pub use gram::add_lower_gram;

/// Σ a_i·b_i over two slices of one length, in four running sums (which a
/// compiler turns into vector lanes).
#[inline(always)]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}
