//! Dense linear algebra on small matrices (a handful of rows: the modal matrices of a reduced
//! arm, the stage matrices of LQR and iLQR, the consequent fit of ANFIS), on plain row-major
//! slices owned by a workspace (column-major in [`LeastSquares`]): nothing allocates but
//! [`LeastSquares::new`].
//!
//! At this size hand-written loops beat a general dense-matrix library several times over (the
//! per-call overhead of faer's Cholesky exceeds the whole `3 x 3` solve), and they are short
//! enough to check by eye. One algorithm per file:
//!
//! | file | what |
//! |---|---|
//! | `products.rs` | `a b`, `a^T b`, `a b^T`, the symmetric part |
//! | `cholesky.rs` | `L L^T` in place, its triangular solves |
//! | `ldlt.rs` | `L D L^T` in place over [`Lane`](crate::Lane)s, its solves |
//! | `lu.rs` | Gaussian elimination with partial pivoting |
//! | `eigen.rs` | the extreme eigenvalues of a symmetric matrix (cyclic Jacobi) |
//! | `exponential.rs` | `exp(a)` by scaling and squaring |
//! | `least_squares.rs` | ridge least squares by Householder QR |

mod cholesky;
mod eigen;
mod exponential;
mod ldlt;
mod least_squares;
mod lu;
mod products;

pub use cholesky::{back_substitute, cholesky, cholesky_solve, forward_substitute};
pub use eigen::symmetric_eigen_extremes;
pub use exponential::exponential;
pub use ldlt::{ldlt_in_place, ldlt_solve_in_place, ldlt_solve_rows_in_place};
pub use least_squares::{LeastSquares, LeastSquaresError};
pub use lu::lu_solve;
pub use products::{
    multiply, multiply_by_transposed, multiply_sized, multiply_transposed,
    multiply_transposed_sized, symmetrise,
};

#[cfg(test)]
/// A deterministic `r x c` matrix with entries in [-1, 1].
pub(crate) fn test_matrix(r: usize, c: usize, seed: u64) -> Vec<f64> {
    let mut state = seed;
    (0..r * c)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}
