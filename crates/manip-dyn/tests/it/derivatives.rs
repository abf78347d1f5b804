//! The analytic derivatives of inverse and forward dynamics against central finite differences
//! with step-size control (Ridders), the mass matrix, and the Cholesky inverse of `M`, over random
//! arms (unequal lengths, masses, centres of mass and inertias) and states.

use crate::common::*;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef, Side};
use manip_dyn::{
    ChainData, ChainModel, DerivativeData, DynError, aba, aba_derivatives, rnea, rnea_derivatives,
};
use proptest::prelude::*;
use test_support::config::scaled;

/// Relative agreement required of the analytic Jacobians with the finite differences.
const AGREEMENT: f64 = 1e-6;

/// Column `k` of the Jacobian of `f` with respect to input `which` (0, 1, 2) at `inputs`, by
/// Ridders' central differences, with Ridders' own estimate of its error.
fn fd_column(
    f: &mut impl FnMut(&[f64], &[f64], &[f64]) -> Vec<f64>,
    inputs: [&[f64]; 3],
    which: usize,
    k: usize,
) -> (Vec<f64>, f64) {
    let mut moved: [Vec<f64>; 3] = inputs.map(<[f64]>::to_vec);
    let x = inputs[which][k];
    ridders(
        |value| {
            moved[which][k] = value;
            f(&moved[0], &moved[1], &moved[2])
        },
        x,
        0.1,
    )
}

/// Asserts `analytic` (n x n) equals the finite-difference Jacobian of `f` with respect to input
/// `which`: every entry within `AGREEMENT` of the matrix's largest entry.
fn assert_matches_fd(
    analytic: MatRef<'_, f64>,
    mut f: impl FnMut(&[f64], &[f64], &[f64]) -> Vec<f64>,
    inputs: [&[f64]; 3],
    which: usize,
    name: &str,
) -> Result<(), TestCaseError> {
    let n = analytic.nrows();
    let mut fd = Mat::<f64>::zeros(n, n);
    // Ridders' own error estimate: where the dynamics bend sharply (a nearly singular M,
    // accelerations of thousands of rad/s^2) the extrapolation is less accurate than AGREEMENT
    // of the scale, and it says so (found at 2048 cases: 2.7e-5 relative).
    let mut fd_error = 0.0f64;
    for k in 0..n {
        let (column, error) = fd_column(&mut f, inputs, which, k);
        fd_error = fd_error.max(error);
        for i in 0..n {
            fd[(i, k)] = column[i];
        }
    }
    let scale = max_abs_mat(&fd);
    for i in 0..n {
        for k in 0..n {
            let error = (analytic[(i, k)] - fd[(i, k)]).abs();
            // The floor covers Jacobians that vanish (no gravity, no motion): differences of
            // rounding noise.
            prop_assert!(
                error <= AGREEMENT * scale + 1e-12 + 10.0 * fd_error,
                "{name}[{i}][{k}]: analytic {} vs finite differences {} (scale {scale}, \
                 Ridders' error estimate {fd_error})",
                analytic[(i, k)],
                fd[(i, k)]
            );
        }
    }
    Ok(())
}

fn inverse_dynamics(arm: &ChainModel) -> impl FnMut(&[f64], &[f64], &[f64]) -> Vec<f64> + '_ {
    let mut data = ChainData::new(arm);
    move |q, v, a| {
        let mut tau = vec![0.0; q.len()];
        rnea(arm, &mut data, q, v, a, &mut tau).unwrap();
        tau
    }
}

fn forward(arm: &ChainModel) -> impl FnMut(&[f64], &[f64], &[f64]) -> Vec<f64> + '_ {
    let mut data = ChainData::new(arm);
    move |q, v, tau| {
        let mut qdd = vec![0.0; q.len()];
        aba(arm, &mut data, q, v, tau, &mut qdd).unwrap();
        qdd
    }
}

proptest! {
    #![proptest_config(scaled(4))]

    #[test]
    fn rnea_derivatives_match_finite_differences((arm, q, v, a) in arm_and_state(24)) {
        let mut data = ChainData::new(&arm);
        let mut derivatives = DerivativeData::new(&arm);
        rnea_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &a).unwrap();
        let mut tau = vec![0.0; q.len()];
        rnea(&arm, &mut data, &q, &v, &a, &mut tau).unwrap();
        prop_assert_eq!(derivatives.value(), &tau[..]);
        let inputs = [&q[..], &v[..], &a[..]];
        assert_matches_fd(derivatives.d_q(), inverse_dynamics(&arm), inputs, 0, "d tau / d q")?;
        assert_matches_fd(derivatives.d_v(), inverse_dynamics(&arm), inputs, 1, "d tau / d v")?;
        assert_matches_fd(derivatives.d_input(), inverse_dynamics(&arm), inputs, 2, "d tau / d qdd")?;
    }

    #[test]
    fn aba_derivatives_match_finite_differences((arm, q, v, tau) in arm_and_state(24)) {
        let mut data = ChainData::new(&arm);
        let mut derivatives = DerivativeData::new(&arm);
        aba_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &tau).unwrap();
        let mut qdd = vec![0.0; q.len()];
        aba(&arm, &mut data, &q, &v, &tau, &mut qdd).unwrap();
        prop_assert_eq!(derivatives.value(), &qdd[..]);
        let inputs = [&q[..], &v[..], &tau[..]];
        assert_matches_fd(derivatives.d_q(), forward(&arm), inputs, 0, "d qdd / d q")?;
        assert_matches_fd(derivatives.d_v(), forward(&arm), inputs, 1, "d qdd / d v")?;
        assert_matches_fd(derivatives.d_input(), forward(&arm), inputs, 2, "d qdd / d tau")?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::default())]

    /// `d tau / d qdd` is the mass matrix of the composite-rigid-body algorithm.
    #[test]
    fn rnea_input_derivative_is_the_mass_matrix((arm, q, v, a) in arm_and_state(120)) {
        let mut data = ChainData::new(&arm);
        let mut derivatives = DerivativeData::new(&arm);
        rnea_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &a).unwrap();
        let m = mass(&arm, &mut data, &q);
        prop_assert!(derivatives.d_input() == m.as_ref());
    }

    /// `d qdd / d tau` is the inverse of `M` from a Cholesky factorisation, and the other two
    /// Jacobians are `-M^-1` times the inverse-dynamics partials at the solution; both sides
    /// solve with the same (often ill-conditioned) `M`, so they agree to its conditioning.
    #[test]
    fn aba_derivatives_are_minus_inverse_mass_times_rnea_derivatives(
        (arm, q, v, tau) in arm_and_state(120)
    ) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let mut forward = DerivativeData::new(&arm);
        let mut inverse = DerivativeData::new(&arm);
        aba_derivatives(&arm, &mut data, &mut forward, &q, &v, &tau).unwrap();
        let qdd = forward.value().to_vec();
        rnea_derivatives(&arm, &mut data, &mut inverse, &q, &v, &qdd).unwrap();
        let m = mass(&arm, &mut data, &q);
        let m_inv = m.llt(Side::Lower).unwrap().inverse();
        let cond = condition_estimate(&m);
        let scale = max_abs_mat(&m_inv);
        for i in 0..n {
            for j in 0..n {
                let error = (forward.d_input()[(i, j)] - m_inv[(i, j)]).abs();
                prop_assert!(error <= 1e-14 * cond * scale,
                    "M^-1[{i}][{j}] off by {error} (scale {scale}, cond {cond:e})");
            }
        }
        for (analytic, partial) in [(forward.d_q(), inverse.d_q()), (forward.d_v(), inverse.d_v())] {
            let expected = -(&m_inv * partial);
            let scale = max_abs_mat(&expected).max(max_abs_mat(&m_inv) * 1e-12);
            for i in 0..n {
                for j in 0..n {
                    let error = (analytic[(i, j)] - expected[(i, j)]).abs();
                    prop_assert!(error <= 1e-14 * cond * scale,
                        "[{i}][{j}] off by {error} (scale {scale}, cond {cond:e})");
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(scaled(48))]

    /// Scaling every mass and inertia by `s` and the torques with them leaves the accelerations
    /// and their state Jacobians unchanged and divides `d qdd / d tau` by `s`: so down to the
    /// smallest link scale the chain accepts (`MIN_LINK_SCALE`, a mass of 1e-150 kg), where the
    /// articulated inertias' products would lose their digits below it.
    #[test]
    fn aba_derivatives_keep_their_digits_down_to_the_smallest_link_scale(
        (arm, q, v, tau) in arm_and_state(12)
    ) {
        let smallest = arm.links().iter().map(|l| l.mass.min(l.mass * l.length)).fold(f64::INFINITY, f64::min);
        // Just above the bound (the product of the scaled mass and length rounds).
        let s = manip_dyn::MIN_LINK_SCALE / smallest * (1.0 + 1e-12);
        let light = ChainModel::new(
            arm.links()
                .iter()
                .map(|l| manip_dyn::Link { mass: l.mass * s, inertia: l.inertia * s, ..*l })
                .collect(),
            arm.gravity(),
        )
        .unwrap();
        let light_tau: Vec<f64> = tau.iter().map(|t| t * s).collect();
        let mut data = ChainData::new(&arm);
        let (mut heavy, mut scaled_down) = (DerivativeData::new(&arm), DerivativeData::new(&arm));
        aba_derivatives(&arm, &mut data, &mut heavy, &q, &v, &tau).unwrap();
        aba_derivatives(&light, &mut data, &mut scaled_down, &q, &v, &light_tau).unwrap();
        let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale;
        let qdd_scale = heavy.value().iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (a, b) in heavy.value().iter().zip(scaled_down.value()) {
            prop_assert!(close(*a, *b, qdd_scale), "qdd {a} against {b}");
        }
        for (a, b, unscale) in [
            (heavy.d_q(), scaled_down.d_q(), 1.0),
            (heavy.d_v(), scaled_down.d_v(), 1.0),
            (heavy.d_input(), scaled_down.d_input(), s),
        ] {
            let scale = max_abs_mat(&a.to_owned());
            for i in 0..arm.n_links() {
                for j in 0..arm.n_links() {
                    prop_assert!(close(a[(i, j)], b[(i, j)] * unscale, scale),
                        "[{i}][{j}]: {} against {}", a[(i, j)], b[(i, j)] * unscale);
                }
            }
        }
    }
}

/// The paper's arm, with both workspaces reused across calls and chains of different sizes
/// refused.
#[test]
fn workspaces_are_checked() {
    let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap();
    let other = ChainModel::uniform(4, 0.1, 0.1, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let mut wrong = DerivativeData::new(&other);
    let state = [0.1; 10];
    let error = rnea_derivatives(&arm, &mut data, &mut wrong, &state, &state, &state).unwrap_err();
    assert!(
        matches!(
            error,
            DynError::Dimension {
                expected: 10,
                found: 4,
                ..
            }
        ),
        "{error}"
    );
    let error = aba_derivatives(&arm, &mut data, &mut wrong, &state, &state, &state).unwrap_err();
    assert!(error.to_string().contains("DerivativeData"), "{error}");
    let mut derivatives = DerivativeData::new(&arm);
    let mut bad = state;
    bad[3] = f64::NAN;
    let error =
        aba_derivatives(&arm, &mut data, &mut derivatives, &bad, &state, &state).unwrap_err();
    assert!(
        matches!(
            error,
            DynError::NonFinite {
                name: "q",
                index: Some(3),
                ..
            }
        ),
        "{error}"
    );
    let error =
        rnea_derivatives(&arm, &mut data, &mut derivatives, &state, &state, &bad).unwrap_err();
    assert!(
        matches!(
            error,
            DynError::NonFinite {
                name: "qdd",
                index: Some(3),
                ..
            }
        ),
        "{error}"
    );
}
