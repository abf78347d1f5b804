//! Helpers of manip-dyn's integration tests; the random arms and the finite differences are
//! the workspace's (`test_support`).

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use manip_dyn::{ChainData, ChainModel};

pub use test_support::numeric::{axpy, max_abs, ridders};
pub use test_support::sample::{arm_and_state, link};

/// `M(q)` as a new faer matrix.
pub fn mass(model: &ChainModel, data: &mut ChainData, q: &[f64]) -> Mat<f64> {
    let n = model.n_links();
    let mut m = Mat::zeros(n, n);
    manip_dyn::mass_matrix(model, data, q, m.as_mut()).unwrap();
    m
}

/// The Christoffel Coriolis matrix as a new faer matrix.
pub fn coriolis_mat(model: &ChainModel, data: &mut ChainData, q: &[f64], v: &[f64]) -> Mat<f64> {
    let n = model.n_links();
    let mut c = Mat::zeros(n, n);
    manip_dyn::coriolis_matrix(model, data, q, v, c.as_mut()).unwrap();
    c
}

/// `m x`.
pub fn mat_vec(m: &Mat<f64>, x: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)] * x[j]).sum())
        .collect()
}

/// Largest absolute entry of a matrix.
pub fn max_abs_mat(m: &Mat<f64>) -> f64 {
    let mut acc = 0.0f64;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            acc = acc.max(m[(i, j)].abs());
        }
    }
    acc
}

/// Centre-of-mass positions `r_i` of every link, by direct forward kinematics (independent of
/// the crate).
pub fn com_positions(model: &ChainModel, q: &[f64]) -> Vec<[f64; 2]> {
    let mut phi = 0.0;
    let mut joint = [0.0, 0.0];
    let mut out = Vec::new();
    for (link, theta) in model.links().iter().zip(q) {
        phi += theta;
        let (s, c) = f64::sin_cos(phi);
        out.push([joint[0] + link.com * c, joint[1] + link.com * s]);
        joint = [joint[0] + link.length * c, joint[1] + link.length * s];
    }
    out
}

/// An upper bound of the 2-norm condition number of an SPD matrix: `lambda_max(M) <= trace(M)
/// <= n max_i M_ii`, and the same for `M^-1`.
pub fn condition_estimate(m: &Mat<f64>) -> f64 {
    let n = m.nrows();
    let inverse = m.llt(Side::Lower).unwrap().inverse();
    let largest = (0..n).map(|i| m[(i, i)]).fold(0.0, f64::max) * n as f64;
    let inverse_largest = (0..n).map(|i| inverse[(i, i)]).fold(0.0, f64::max) * n as f64;
    largest * inverse_largest
}
