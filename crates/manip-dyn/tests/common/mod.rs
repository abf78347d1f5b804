//! Shared strategies and helpers of the integration tests.
#![allow(dead_code)] // each test binary uses a different subset

use faer::Mat;
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
