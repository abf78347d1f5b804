//! Bad input gets a clear error, never a panic or a NaN.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;
use modal_reduce::{
    JacobiSettings, ReduceError, ReducedData, ReducedModel, forward_dynamics,
    forward_dynamics_by_projection, jacobi_forward_dynamics, joint_torques, kinetic_energy,
    potential_energy, project_torques, reduced_terms, reduced_terms_by_projection,
};

fn paper() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap()
}

#[test]
fn map_and_chain_must_agree_on_the_number_of_links() {
    let error = ReducedModel::new(
        ChainModel::uniform(5, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(6).unwrap(),
    )
    .unwrap_err();
    assert_eq!(
        error,
        ReduceError::LinkCountMismatch {
            joints: 6,
            links: 5
        }
    );
    assert_eq!(
        error.to_string(),
        "the modal map has 6 joints but the chain has 5 links"
    );
}

#[test]
fn rank_deficient_maps_are_refused() {
    // Three coordinates on two links; seven coordinates on five links.
    for (n, harmonics, base) in [
        (2, 1, BaseAngle::Free),
        (1, 1, BaseAngle::Fixed(0.0)),
        (5, 3, BaseAngle::Free),
    ] {
        let error = ReducedModel::new(
            ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap(),
            ModalMap::uniform(n, harmonics, base).unwrap(),
        )
        .unwrap_err();
        assert!(
            matches!(error, ReduceError::RankDeficient { .. }),
            "{error:?}"
        );
        assert!(
            error.to_string().contains("column-rank-deficient"),
            "{error}"
        );
    }
    // The smallest full-rank cases are accepted.
    for (n, harmonics, base) in [
        (3, 1, BaseAngle::Free),
        (2, 1, BaseAngle::Fixed(0.3)),
        (5, 2, BaseAngle::Free),
    ] {
        ReducedModel::new(
            ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap(),
            ModalMap::uniform(n, harmonics, base).unwrap(),
        )
        .unwrap();
    }
}

#[test]
fn wrong_sizes_are_refused() {
    let model = paper();
    let mut data = ReducedData::new(&model);
    let (ok, short, mut out, mut out_short) = ([0.1; 3], [0.1; 2], [0.0; 3], [0.0; 2]);
    let dim = |name: &'static str, expected: usize, found: usize| ReduceError::Dimension {
        name,
        expected,
        found,
    };
    assert_eq!(
        reduced_terms(&model, &mut data, &short, &ok),
        Err(dim("a", 3, 2))
    );
    assert_eq!(
        reduced_terms_by_projection(&model, &mut data, &ok, &short),
        Err(dim("a_dot", 3, 2))
    );
    assert_eq!(
        forward_dynamics(&model, &mut data, &ok, &ok, &short, &mut out),
        Err(dim("tau_star", 3, 2))
    );
    assert_eq!(
        forward_dynamics_by_projection(&model, &mut data, &ok, &ok, &ok, &mut out_short),
        Err(dim("a_ddot", 3, 2))
    );
    let mut tau = [0.0; 9];
    assert_eq!(
        joint_torques(&model, &mut data, &ok, &ok, &ok, &mut tau),
        Err(dim("tau", 10, 9))
    );
    assert_eq!(
        project_torques(&model, &tau, &mut out),
        Err(dim("tau", 10, 9))
    );
    assert_eq!(
        project_torques(&model, &[0.0; 10], &mut out_short),
        Err(dim("tau_star", 3, 2))
    );
    assert_eq!(
        kinetic_energy(&model, &mut data, &ok, &short),
        Err(dim("a_dot", 3, 2))
    );
    assert_eq!(
        potential_energy(&model, &mut data, &short),
        Err(dim("a", 3, 2))
    );
    assert_eq!(dim("a", 3, 2).to_string(), "a has 2 entries, expected 3");
}

#[test]
fn a_workspace_of_another_model_is_refused() {
    let model = paper();
    let other = ReducedModel::new(
        ChainModel::uniform(12, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(12).unwrap(),
    )
    .unwrap();
    let mut data = ReducedData::new(&other);
    let error = reduced_terms(&model, &mut data, &[0.0; 3], &[0.0; 3]).unwrap_err();
    assert!(
        matches!(
            error,
            ReduceError::Dimension {
                name: "workspace links",
                ..
            }
        ),
        "{error:?}"
    );
}

#[test]
fn non_finite_inputs_are_refused() {
    let model = paper();
    let mut data = ReducedData::new(&model);
    let mut out = [0.0; 3];
    let error = reduced_terms(&model, &mut data, &[0.0, f64::NAN, 0.0], &[0.0; 3]).unwrap_err();
    assert!(
        matches!(
            error,
            ReduceError::NonFinite {
                name: "a",
                index: 1,
                ..
            }
        ),
        "{error:?}"
    );
    assert_eq!(error.to_string(), "a[1] must be finite, got NaN");
    let error = forward_dynamics(
        &model,
        &mut data,
        &[0.0; 3],
        &[0.0, 0.0, f64::INFINITY],
        &[0.0; 3],
        &mut out,
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            ReduceError::NonFinite {
                name: "a_dot",
                index: 2,
                ..
            }
        ),
        "{error:?}"
    );
    let error = forward_dynamics_by_projection(
        &model,
        &mut data,
        &[0.0; 3],
        &[0.0; 3],
        &[f64::NAN; 3],
        &mut out,
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            ReduceError::NonFinite {
                name: "tau_star",
                index: 0,
                ..
            }
        ),
        "{error:?}"
    );
    let mut tau = [0.0; 10];
    let error = joint_torques(
        &model,
        &mut data,
        &[0.0; 3],
        &[0.0; 3],
        &[f64::NEG_INFINITY; 3],
        &mut tau,
    )
    .unwrap_err();
    assert!(
        matches!(error, ReduceError::NonFinite { name: "a_ddot", .. }),
        "{error:?}"
    );
    let error = potential_energy(&model, &mut data, &[f64::NAN; 3]).unwrap_err();
    assert!(
        matches!(error, ReduceError::NonFinite { name: "a", .. }),
        "{error:?}"
    );
}

#[test]
fn overflow_is_an_error_not_a_nan() {
    let model = paper();
    let mut data = ReducedData::new(&model);
    let mut out = [0.0; 3];
    let error = forward_dynamics(
        &model,
        &mut data,
        &[0.0; 3],
        &[1e200, 0.0, 0.0],
        &[0.0; 3],
        &mut out,
    )
    .unwrap_err();
    assert!(
        matches!(error, ReduceError::NonFiniteResult { .. }),
        "{error:?}"
    );
    let error = forward_dynamics(
        &model,
        &mut data,
        &[0.0; 3],
        &[0.0; 3],
        &[1e308, -1e308, 1e308],
        &mut out,
    )
    .unwrap_err();
    assert!(
        matches!(error, ReduceError::NonFiniteResult { name: "a_ddot" }),
        "{error:?}"
    );
    assert!(error.is_numerical() && !error.is_invalid_input() && !error.is_unreachable());
    let mut tau = [0.0; 10];
    let error = joint_torques(
        &model,
        &mut data,
        &[0.0; 3],
        &[1e200; 3],
        &[0.0; 3],
        &mut tau,
    )
    .unwrap_err();
    assert!(matches!(error, ReduceError::Dyn(_)), "{error:?}");
}

#[test]
fn jacobi_settings_are_checked() {
    let model = paper();
    let mut data = ReducedData::new(&model);
    let mut out = [0.0; 3];
    for (settings, name) in [
        (
            JacobiSettings {
                tolerance: 0.0,
                max_iterations: 10,
            },
            "tolerance",
        ),
        (
            JacobiSettings {
                tolerance: f64::NAN,
                max_iterations: 10,
            },
            "tolerance",
        ),
        (
            JacobiSettings {
                tolerance: 1e-12,
                max_iterations: 0,
            },
            "max_iterations",
        ),
    ] {
        let error = jacobi_forward_dynamics(
            &model, &mut data, &[0.0; 3], &[0.0; 3], &[0.0; 3], &settings, &mut out,
        )
        .unwrap_err();
        assert!(
            matches!(error, ReduceError::InvalidSetting { name: n, .. } if n == name),
            "{error:?}"
        );
    }
}

#[test]
fn wrapped_errors_keep_their_class() {
    let numerical = ReduceError::Dyn(manip_dyn::DynError::NotPositiveDefinite);
    assert!(numerical.is_numerical() && !numerical.is_invalid_input());
    let unreachable = ReduceError::Kin(backbone_kin::KinError::OutOfReach {
        r: 2.0,
        length: 1.0,
    });
    assert!(unreachable.is_unreachable() && !unreachable.is_numerical());
    assert!(!unreachable.is_invalid_input());
    let input = ReduceError::Dyn(manip_dyn::DynError::NoLinks);
    assert!(input.is_invalid_input() && !input.is_numerical() && !input.is_unreachable());
    let diverged = ReduceError::JacobiDiverged {
        spectral_radius: 1.5,
    };
    assert!(diverged.is_numerical());
}
