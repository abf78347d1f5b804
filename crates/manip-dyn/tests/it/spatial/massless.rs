//! Massless links (the cross of a universal joint written as two revolute joints, as URDF has
//! it): valid, and every algorithm agrees with a second one on chains holding them, as long as
//! each massless link has mass beyond it; where it has none, the joint is named.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use manip_dyn::DynError;
use manip_dyn::spatial::{
    self, SpatialBatchData, SpatialData, SpatialDerivativeData, SpatialModel, aba, aba_batch,
    aba_derivatives, nonlinear_effects,
};
use proptest::prelude::*;

use super::sample::{MASSLESS, massless_chain_and_state, massless_snake, snake};
use crate::common::{axpy, mat_vec, max_abs};

fn mass(model: &SpatialModel, data: &mut SpatialData, q: &[f64]) -> Mat<f64> {
    let n = model.n_links();
    let mut m = Mat::zeros(n, n);
    spatial::mass_matrix(model, data, q, m.as_mut()).unwrap();
    m
}

/// The ABA's `qdd` against the Cholesky solve of `M qdd = tau - C qd - G` (CRBA and RNEA), and
/// the ABA derivatives' `M^-1` against the Cholesky inverse; returns the largest difference
/// relative to the scale of each.
fn against_cholesky(model: &SpatialModel, q: &[f64], v: &[f64], tau: &[f64]) -> (f64, f64) {
    let n = model.n_links();
    let mut data = SpatialData::new(model);
    let mut qdd = vec![0.0; n];
    aba(model, &mut data, q, v, tau, &mut qdd).unwrap();
    let inverse = mass(model, &mut data, q)
        .llt(Side::Lower)
        .unwrap()
        .inverse();
    let mut nle = vec![0.0; n];
    nonlinear_effects(model, &mut data, q, v, &mut nle).unwrap();
    let cholesky = mat_vec(&inverse, &axpy(tau, -1.0, &nle));
    let qdd_error = qdd
        .iter()
        .zip(&cholesky)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / (1.0 + max_abs(&cholesky));
    let mut derivatives = SpatialDerivativeData::new(model);
    aba_derivatives(model, &mut data, &mut derivatives, q, v, tau).unwrap();
    let scale = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(inverse[(i, j)].abs()));
    let minv_error = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| {
            m.max((derivatives.d_input()[(i, j)] - inverse[(i, j)]).abs())
        })
        / scale;
    (qdd_error, minv_error)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn chains_with_massless_links_match_the_cholesky_solve(
        (model, q, v, tau) in massless_chain_and_state(20),
    ) {
        let (qdd_error, minv_error) = against_cholesky(&model, &q, &v, &tau);
        prop_assert!(qdd_error < 1e-8, "qdd off by {qdd_error:e}");
        prop_assert!(minv_error < 1e-8, "M^-1 off by {minv_error:e}");
        // The batch gives each state the bits it gets alone.
        let n = model.n_links();
        let states = 9;
        let spread = |x: &[f64]| -> Vec<f64> {
            (0..states).flat_map(|s| x.iter().map(move |x| x * (1.0 + 0.01 * s as f64))).collect()
        };
        let (qs, vs, taus) = (spread(&q), spread(&v), spread(&tau));
        let mut batch = vec![0.0; n * states];
        aba_batch(&model, &mut SpatialBatchData::new(&model), &qs, &vs, &taus, &mut batch).unwrap();
        let mut data = SpatialData::new(&model);
        for s in 0..states {
            let range = s * n..(s + 1) * n;
            let mut one = vec![0.0; n];
            aba(&model, &mut data, &qs[range.clone()], &vs[range.clone()], &taus[range.clone()], &mut one).unwrap();
            prop_assert_eq!(&batch[range], one.as_slice());
        }
    }
}

#[test]
fn the_snake_with_massless_crosses_matches_the_cholesky_solve() {
    let model = massless_snake();
    let n = model.n_links();
    let q: Vec<f64> = (0..n).map(|i| 0.4 * (0.7 * i as f64).sin()).collect();
    let v: Vec<f64> = (0..n).map(|i| 0.8 * (1.3 * i as f64).cos()).collect();
    let tau: Vec<f64> = (0..n).map(|i| 0.01 * (0.5 * i as f64).sin()).collect();
    let (qdd_error, minv_error) = against_cholesky(&model, &q, &v, &tau);
    assert!(qdd_error < 1e-10, "qdd off by {qdd_error:e}");
    assert!(minv_error < 1e-10, "M^-1 off by {minv_error:e}");
    // The same snake with each link's mass split between its two bodies is a different chain:
    // the crosses carry mass there, so the dynamics differ (the test sees the massless bodies).
    let mut data = SpatialData::new(&model);
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    aba(&model, &mut data, &q, &v, &tau, &mut a).unwrap();
    aba(
        &snake(),
        &mut SpatialData::new(&snake()),
        &q,
        &v,
        &tau,
        &mut b,
    )
    .unwrap();
    assert!(a.iter().zip(&b).any(|(x, y)| (x - y).abs() > 1e-3));
}

#[test]
fn a_joint_moving_only_massless_links_is_named() {
    let snake = massless_snake();
    let mut joints = snake.joints().to_vec();
    let mut links = snake.links().to_vec();
    // A third joint (about x) at the tip moving another massless link: joint 20 moves nothing.
    joints.push(spatial::SpatialJoint::revolute(
        [1.0, 0.0, 0.0],
        spatial::Transform::translation([0.1, 0.0, 0.0]),
    ));
    links.push(MASSLESS);
    let model = SpatialModel::new(joints, links, [0.0, 0.0, -9.81]).unwrap();
    let n = model.n_links();
    let mut data = SpatialData::new(&model);
    let zeros = vec![0.0; n];
    let error = aba(&model, &mut data, &zeros, &zeros, &zeros, &mut vec![0.0; n]).unwrap_err();
    assert_eq!(error, DynError::SingularJoint { index: 20 });
    let mut derivatives = SpatialDerivativeData::new(&model);
    let error =
        aba_derivatives(&model, &mut data, &mut derivatives, &zeros, &zeros, &zeros).unwrap_err();
    assert_eq!(error, DynError::SingularJoint { index: 20 });
    assert!(
        error
            .to_string()
            .starts_with("joint 20: the articulated inertia")
    );
    // The check before a run names the same joint, and none of a chain with mass beyond each.
    assert_eq!(spatial::singular_joint(&model, &zeros), Some(20));
    assert_eq!(
        spatial::singular_joint(&snake, &vec![0.0; snake.n_links()]),
        None
    );
    // A position vector of the wrong length is the caller's to name.
    assert_eq!(spatial::singular_joint(&model, &zeros[1..]), None);
}
