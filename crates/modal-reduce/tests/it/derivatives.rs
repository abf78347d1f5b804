//! The analytic derivatives of the reduced forward dynamics against (1) the same derivatives
//! built from the full chain's (`-M*^-1 J^T (d tau / d theta) J`, with `manip_dyn`'s analytic
//! Jacobians and `M* = J^T M J` formed with faer) and (2) central finite differences with
//! step-size control, over random arms, modal families (1-3 harmonics, `alpha0` free or fixed)
//! and states.

use crate::common::*;
use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef, Side};
use manip_dyn::{ChainData, DerivativeData, rnea_derivatives};
use modal_reduce::{
    ReduceError, ReducedData, ReducedDerivatives, ReducedModel, forward_dynamics,
    reduced_derivatives,
};
use proptest::prelude::*;

/// A model (3-30 links, 1-3 harmonics) and a state `(a, a_dot, tau*)`.
fn model_and_inputs() -> impl Strategy<Value = (ReducedModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    model_with_harmonics(3..=30, 3).prop_flat_map(|model| {
        let m = model.n_coords();
        (
            Just(model),
            prop::collection::vec(-1.5..1.5f64, m),
            prop::collection::vec(-2.0..2.0f64, m),
            prop::collection::vec(-3.0..3.0f64, m),
        )
    })
}

fn jacobian(model: &ReducedModel) -> Mat<f64> {
    let map = model.map();
    Mat::from_fn(map.n_joints(), map.n_coords(), |i, j| map.entry(i, j))
}

/// Asserts `analytic == expected` entrywise to `tolerance` times the larger matrix's largest
/// entry plus `floor` (for matrices that vanish, or the error estimate of finite differences).
fn assert_close(
    analytic: MatRef<'_, f64>,
    expected: MatRef<'_, f64>,
    tolerance: f64,
    floor: f64,
    name: &str,
) -> Result<(), TestCaseError> {
    let scale = max_abs(&to_vec(expected)).max(max_abs(&to_vec(analytic)));
    for i in 0..expected.nrows() {
        for j in 0..expected.ncols() {
            let error = (analytic[(i, j)] - expected[(i, j)]).abs();
            prop_assert!(
                error <= tolerance * scale + floor,
                "{name}[{i}][{j}]: {} vs {} (scale {scale})",
                analytic[(i, j)],
                expected[(i, j)]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(expensive())]

    #[test]
    fn reduced_derivatives_equal_the_projected_full_derivatives(
        (model, a, a_dot, tau_star) in model_and_inputs()
    ) {
        let mut data = ReducedData::new(&model);
        let mut derivatives = ReducedDerivatives::new(&model);
        reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star).unwrap();
        let mut a_ddot = vec![0.0; a.len()];
        forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot).unwrap();
        prop_assert_eq!(derivatives.a_ddot(), &a_ddot[..]);

        // The full chain at theta = J a + theta_0, J a_dot, J a_ddot.
        let chain = model.chain();
        let j = jacobian(&model);
        let theta = joint_angles(model.map(), &a);
        let theta_dot = joint_rates(model.map(), &a_dot);
        let theta_ddot = joint_rates(model.map(), &a_ddot);
        let mut full = DerivativeData::new(chain);
        rnea_derivatives(chain, &mut ChainData::new(chain), &mut full, &theta, &theta_dot, &theta_ddot)
            .unwrap();
        let m_star = j.transpose() * full.d_input() * &j;
        let inverse = m_star.llt(Side::Lower).unwrap().inverse();
        let d_a = -(&inverse * (j.transpose() * full.d_q() * &j));
        let d_a_dot = -(&inverse * (j.transpose() * full.d_v() * &j));
        // Both sides solve with M*, whose conditioning grows with the harmonics.
        let cond = max_abs(&to_vec(m_star.as_ref())) * max_abs(&to_vec(inverse.as_ref()));
        let tolerance = 1e-13 * cond.max(1.0);
        assert_close(derivatives.d_a(), d_a.as_ref(), tolerance, 1e-12, "d a_ddot / d a")?;
        assert_close(derivatives.d_a_dot(), d_a_dot.as_ref(), tolerance, 1e-12, "d a_ddot / d a_dot")?;
        assert_close(derivatives.d_tau_star(), inverse.as_ref(), tolerance, 1e-12, "d a_ddot / d tau*")?;
    }

    #[test]
    fn reduced_derivatives_match_finite_differences(
        (model, a, a_dot, tau_star) in model_and_inputs()
    ) {
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let mut derivatives = ReducedDerivatives::new(&model);
        reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star).unwrap();
        let inputs = [a, a_dot, tau_star];
        let analytic = [derivatives.d_a(), derivatives.d_a_dot(), derivatives.d_tau_star()];
        for (which, analytic) in analytic.into_iter().enumerate() {
            let mut fd = Mat::<f64>::zeros(m, m);
            // Ridders' own error estimate: where the dynamics bend sharply (a nearly singular
            // M*, accelerations of thousands of rad/s^2) the extrapolation is less accurate than
            // 1e-6 of the scale, and it says so.
            let mut fd_error = 0.0f64;
            for k in 0..m {
                let mut moved = inputs.clone();
                let (column, error) = ridders(
                    |x| {
                        moved[which][k] = x;
                        let mut out = vec![0.0; m];
                        forward_dynamics(&model, &mut data, &moved[0], &moved[1], &moved[2], &mut out)
                            .unwrap();
                        out
                    },
                    inputs[which][k],
                    0.1,
                );
                fd_error = fd_error.max(error);
                for i in 0..m {
                    fd[(i, k)] = column[i];
                }
            }
            assert_close(
                analytic,
                fd.as_ref(),
                1e-6,
                1e-12 + 10.0 * fd_error,
                ["d_a", "d_a_dot", "d_tau_star"][which],
            )?;
        }
    }
}

#[test]
fn workspaces_and_inputs_are_checked() {
    use backbone_kin::ModalMap;
    use manip_dyn::ChainModel;
    let model = paper_arm();
    let other = ReducedModel::new(
        ChainModel::uniform(8, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(8).unwrap(),
    )
    .unwrap();
    let mut data = ReducedData::new(&model);
    let mut wrong = ReducedDerivatives::new(&other);
    let state = [0.1; 3];
    let error =
        reduced_derivatives(&model, &mut data, &mut wrong, &state, &state, &state).unwrap_err();
    assert!(matches!(error, ReduceError::Dimension { .. }), "{error}");
    let mut derivatives = ReducedDerivatives::new(&model);
    let error = reduced_derivatives(
        &model,
        &mut data,
        &mut derivatives,
        &state,
        &state,
        &[0.0, f64::INFINITY, 0.0],
    )
    .unwrap_err();
    assert!(error.to_string().contains("tau_star"), "{error}");
    let error = reduced_derivatives(
        &model,
        &mut data,
        &mut derivatives,
        &state,
        &[0.0; 2],
        &state,
    )
    .unwrap_err();
    assert!(error.to_string().contains("a_dot"), "{error}");
}
