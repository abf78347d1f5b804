//! Shared strategies and helpers of the integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use manip_dyn::{ChainData, ChainModel, Link};
use proptest::collection::vec;
use proptest::prelude::*;

/// A random link: length 0.05-1 m, mass 0.05-2 kg, centre of mass anywhere from behind the joint
/// to beyond the far end, inertia 1-30 % of `m L^2`.
pub fn link() -> impl Strategy<Value = Link> {
    (0.05..1.0f64, 0.05..2.0f64, -0.2..1.2f64, 0.01..0.3f64).prop_map(|(length, mass, c, k)| {
        Link::new(length, mass, c * length, k * mass * length * length).unwrap()
    })
}

/// Number of links: small chains often, up to `max`.
pub fn links(max: usize) -> impl Strategy<Value = usize> {
    prop_oneof![1..=max.min(6), 1..=max]
}

/// A random chain of `n` links with gravity 0-20 m/s^2.
pub fn chain(n: usize) -> impl Strategy<Value = ChainModel> {
    (vec(link(), n), 0.0..20.0f64).prop_map(|(links, g)| ChainModel::new(links, g).unwrap())
}

/// A random vector of `n` entries in `[-r, r]`.
pub fn values(n: usize, r: f64) -> impl Strategy<Value = Vec<f64>> {
    vec(-r..=r, n)
}

/// A chain of at most `max` links and a state: angles, rates, accelerations (or torques).
pub fn arm_and_state(
    max: usize,
) -> impl Strategy<Value = (ChainModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    links(max).prop_flat_map(|n| {
        (
            chain(n),
            values(n, std::f64::consts::PI),
            values(n, 2.0),
            values(n, 5.0),
        )
    })
}

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

/// Largest absolute entry.
pub fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |acc, v| acc.max(v.abs()))
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

/// `x + s y`.
pub fn axpy(x: &[f64], s: f64, y: &[f64]) -> Vec<f64> {
    x.iter().zip(y).map(|(a, b)| a + s * b).collect()
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

/// The derivative of `f: R -> R^k` at `x` by central differences with step-size control
/// (Ridders' extrapolation: central differences at steps `h, h/1.4, h/1.4^2, ...`, extrapolated
/// to zero step by Neville's scheme, keeping the estimate whose error estimate is smallest).
/// Returns the derivative and its error estimate (largest absolute entry).
pub fn ridders(mut f: impl FnMut(f64) -> Vec<f64>, x: f64, h: f64) -> (Vec<f64>, f64) {
    const SHRINK: f64 = 1.4;
    const STEPS: usize = 10;
    let central = |f: &mut dyn FnMut(f64) -> Vec<f64>, step: f64| -> Vec<f64> {
        let (plus, minus) = (f(x + step), f(x - step));
        plus.iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * step))
            .collect()
    };
    let distance = |a: &[f64], b: &[f64]| max_abs(&axpy(a, -1.0, b));
    let mut table: Vec<Vec<Vec<f64>>> = vec![vec![central(&mut f, h)]];
    let (mut best, mut error) = (table[0][0].clone(), f64::INFINITY);
    let mut step = h;
    for i in 1..STEPS {
        step /= SHRINK;
        let mut row = vec![central(&mut f, step)];
        let mut factor = SHRINK * SHRINK;
        for j in 1..=i {
            let next: Vec<f64> = row[j - 1]
                .iter()
                .zip(&table[i - 1][j - 1])
                .map(|(a, b)| (a * factor - b) / (factor - 1.0))
                .collect();
            factor *= SHRINK * SHRINK;
            let estimate = distance(&next, &row[j - 1]).max(distance(&next, &table[i - 1][j - 1]));
            if estimate <= error {
                error = estimate;
                best = next.clone();
            }
            row.push(next);
        }
        let diverging = distance(&row[i], &table[i - 1][i - 1]);
        table.push(row);
        if diverging >= 2.0 * error {
            break;
        }
    }
    (best, error)
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
