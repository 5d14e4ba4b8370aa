//! Dense linear algebra for fitting models: the lower triangle of a Gram
//! matrix accumulated tile by tile, and the Cholesky factorization that
//! solves the normal equations. The products run on ndarray's
//! `general_mat_mul` (the `matrixmultiply` kernels, which pick AVX/FMA at
//! run time); the factorization is written here (Golub & Van Loan,
//! *Matrix Computations*, 4th ed., Algorithm 4.2.1, the column-oriented
//! "gaxpy" Cholesky).

pub mod cholesky;
pub mod gram;

pub use cholesky::{Cholesky, NotPositiveDefinite};
pub use gram::add_lower_gram;
