//! One test per modal-reduce row of `docs/bad-input.md`: each bad input is refused with the named
//! [`ReduceError`] variant, nothing is written to the output, and the workspace stays usable.

use backbone_kin::{BaseAngle, KinError, ModalMap};
use manip_dyn::{ChainModel, DynError};
use modal_reduce::{
    JacobiSettings, ReduceError, ReducedData, ReducedModel, forward_dynamics,
    jacobi_forward_dynamics, joint_torques, kinetic_energy, project_torques,
};

/// A value no function writes: an output still holding it was left untouched.
const SENTINEL: f64 = -12345.0;

fn chain(n: usize) -> ChainModel {
    ChainModel::uniform(n, 1.0 / n as f64, 0.1, 9.81).unwrap()
}

/// The paper's arm with `(a1, a2, alpha0)`.
fn paper_arm() -> ReducedModel {
    ReducedModel::new(chain(10), ModalMap::paper(10).unwrap()).unwrap()
}

#[test]
fn map_and_chain_link_counts_differ() {
    let err = ReducedModel::new(chain(10), ModalMap::paper(9).unwrap()).unwrap_err();
    assert!(matches!(
        err,
        ReduceError::LinkCountMismatch {
            joints: 9,
            links: 10
        }
    ));
    assert_eq!(
        err.to_string(),
        "the modal map has 9 joints but the chain has 10 links"
    );
}

#[test]
fn map_built_for_other_link_lengths() {
    // 20 tapered links: the paper's equal-link map would put them at the wrong arc lengths.
    let lengths: Vec<f64> = (0..20)
        .map(|i| 0.075 - 0.05 * f64::from(i) / 19.0)
        .collect();
    let links = lengths
        .iter()
        .map(|&length| manip_dyn::Link::uniform_beam(length, 0.1).unwrap())
        .collect();
    let tapered = ChainModel::new(links, 9.81).unwrap();
    let err = ReducedModel::new(tapered.clone(), ModalMap::paper(20).unwrap()).unwrap_err();
    assert!(
        matches!(err, ReduceError::GeometryMismatch { link: 0, .. }),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("ReducedModel::from_chain"),
        "{err}"
    );
    // The map of the chain's own links, or proportional ones, is accepted, and from_chain
    // builds the same model.
    let scaled: Vec<f64> = lengths.iter().map(|x| 3.0 * x).collect();
    let own = ModalMap::new(&scaled, 1, BaseAngle::Free).unwrap();
    let by_map = ReducedModel::new(tapered.clone(), own).unwrap();
    let direct = ReducedModel::from_chain(tapered, 1, BaseAngle::Free).unwrap();
    for i in 0..20 {
        for j in 0..3 {
            approx::assert_abs_diff_eq!(
                by_map.map().entry(i, j),
                direct.map().entry(i, j),
                epsilon = 1e-14
            );
        }
    }
    // Equal links of any length match the paper's map.
    ReducedModel::new(chain(7), ModalMap::paper(7).unwrap()).unwrap();
    assert!(matches!(
        ReducedModel::from_chain(chain(4), 0, BaseAngle::Free),
        Err(ReduceError::Kin(KinError::NoHarmonics))
    ));
}

#[test]
fn three_coordinates_on_fewer_than_three_links() {
    for n in [1, 2] {
        let err = ReducedModel::new(chain(n), ModalMap::paper(n).unwrap()).unwrap_err();
        assert!(
            matches!(err, ReduceError::RankDeficient { links, coords: 3, .. } if links == n),
            "{n}: {err:?}"
        );
        assert!(
            err.to_string()
                .contains("use fewer modal coordinates or more links")
        );
    }
    assert!(ReducedModel::new(chain(3), ModalMap::paper(3).unwrap()).is_ok());
}

#[test]
fn more_harmonics_than_the_links_resolve() {
    // K harmonics with alpha0 fixed are 2K coordinates: 2K - 1 links cannot carry them.
    for k in 1..=4 {
        let n = 2 * k - 1;
        let map = ModalMap::uniform(n, k, BaseAngle::Fixed(0.3)).unwrap();
        let err = ReducedModel::new(chain(n), map).unwrap_err();
        assert!(
            matches!(err, ReduceError::RankDeficient { .. }),
            "K = {k}: {err:?}"
        );
    }
    // Twice as many links as coordinates is plenty.
    let map = ModalMap::uniform(16, 4, BaseAngle::Fixed(0.3)).unwrap();
    assert!(ReducedModel::new(chain(16), map).is_ok());
}

#[test]
fn huge_link_count_is_refused_upstream() {
    // Neither the chain nor the map of a huge arm is ever allocated; both errors convert.
    let dyn_err: ReduceError = ChainModel::uniform(usize::MAX, 0.1, 0.1, 9.81)
        .unwrap_err()
        .into();
    assert!(matches!(
        dyn_err,
        ReduceError::Dyn(DynError::TooManyLinks { .. })
    ));
    let kin_err: ReduceError = ModalMap::paper(usize::MAX).unwrap_err().into();
    assert!(matches!(
        kin_err,
        ReduceError::Kin(KinError::TooMany { what: "links", .. })
    ));
    assert!(
        kin_err
            .to_string()
            .starts_with("modal map: at most 1000000 links")
    );
}

#[test]
fn state_of_wrong_length() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [SENTINEL; 3];
    let err = forward_dynamics(
        &model,
        &mut data,
        &[0.1; 2],
        &[0.0; 3],
        &[0.0; 3],
        &mut a_ddot,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        ReduceError::Dimension {
            name: "a",
            expected: 3,
            got: 2
        }
    ));
    assert_eq!(a_ddot, [SENTINEL; 3]);
}

#[test]
fn output_of_wrong_length() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut tau = [SENTINEL; 9];
    let err =
        joint_torques(&model, &mut data, &[0.1; 3], &[0.0; 3], &[0.0; 3], &mut tau).unwrap_err();
    assert!(matches!(
        err,
        ReduceError::Dimension {
            expected: 10,
            got: 9,
            ..
        }
    ));
    assert_eq!(tau, [SENTINEL; 9]);
    let mut tau_star = [SENTINEL; 2];
    assert!(matches!(
        project_torques(&model, &[0.0; 10], &mut tau_star),
        Err(ReduceError::Dimension {
            name: "tau_star",
            ..
        })
    ));
    assert_eq!(tau_star, [SENTINEL; 2]);
}

#[test]
fn non_finite_state_leaves_output_and_workspace_usable() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [SENTINEL; 3];
    let err = forward_dynamics(
        &model,
        &mut data,
        &[0.1, f64::NAN, 0.3],
        &[0.0; 3],
        &[0.0; 3],
        &mut a_ddot,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        ReduceError::NonFinite {
            name: "a",
            index: 1,
            ..
        }
    ));
    assert_eq!(err.to_string(), "a[1] must be finite, got NaN");
    assert_eq!(a_ddot, [SENTINEL; 3]);
    let (a, a_dot, tau) = ([0.3, -0.2, 1.2], [0.4, 0.1, -0.3], [0.2, 0.0, -0.1]);
    forward_dynamics(&model, &mut data, &a, &a_dot, &tau, &mut a_ddot).unwrap();
    let mut fresh = [0.0; 3];
    let mut fresh_data = ReducedData::new(&model);
    forward_dynamics(&model, &mut fresh_data, &a, &a_dot, &tau, &mut fresh).unwrap();
    assert_eq!(a_ddot, fresh);
}

#[test]
fn workspace_of_another_model() {
    let model = paper_arm();
    let other = ReducedModel::new(chain(5), ModalMap::paper(5).unwrap()).unwrap();
    let mut data = ReducedData::new(&other);
    let err = kinetic_energy(&model, &mut data, &[0.0; 3], &[0.0; 3]).unwrap_err();
    assert!(matches!(err, ReduceError::Dimension { .. }), "{err:?}");
}

#[test]
fn overflowing_result() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [SENTINEL; 3];
    let result = forward_dynamics(
        &model,
        &mut data,
        &[0.1; 3],
        &[1e200; 3],
        &[0.0; 3],
        &mut a_ddot,
    );
    assert!(
        matches!(result, Err(ReduceError::NonFiniteResult { .. })),
        "{result:?}"
    );
}

#[test]
fn jacobi_settings_out_of_domain() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let bad = [
        JacobiSettings {
            tolerance: 0.0,
            max_iterations: 10,
        },
        JacobiSettings {
            tolerance: f64::NAN,
            max_iterations: 10,
        },
        JacobiSettings {
            tolerance: 1e-12,
            max_iterations: 0,
        },
    ];
    for settings in bad {
        let mut a_ddot = [SENTINEL; 3];
        let err = jacobi_forward_dynamics(
            &model,
            &mut data,
            &[0.1; 3],
            &[0.0; 3],
            &[0.0; 3],
            &settings,
            &mut a_ddot,
        )
        .unwrap_err();
        assert!(
            matches!(err, ReduceError::InvalidSetting { .. }),
            "{settings:?}: {err:?}"
        );
        assert_eq!(a_ddot, [SENTINEL; 3]);
    }
}

#[test]
fn jacobi_iteration_diverges() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [0.0; 3];
    let err = jacobi_forward_dynamics(
        &model,
        &mut data,
        &[0.3, 0.2, 1.0],
        &[0.0; 3],
        &[0.0; 3],
        &JacobiSettings::default(),
        &mut a_ddot,
    )
    .unwrap_err();
    assert!(
        matches!(err, ReduceError::JacobiDiverged { spectral_radius } if spectral_radius >= 1.0),
        "{err:?}"
    );
    assert!(err.to_string().contains("solve M* a_ddot = rhs directly"));
}

#[test]
fn jacobi_iteration_out_of_budget() {
    let map = ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2).unwrap();
    let model = ReducedModel::new(chain(10), map).unwrap();
    let mut data = ReducedData::new(&model);
    let settings = JacobiSettings {
        tolerance: 1e-15,
        max_iterations: 1,
    };
    let mut a_ddot = [0.0; 2];
    let err = jacobi_forward_dynamics(
        &model,
        &mut data,
        &[0.3, 0.2],
        &[0.0; 2],
        &[0.0; 2],
        &settings,
        &mut a_ddot,
    )
    .unwrap_err();
    assert!(
        matches!(err, ReduceError::JacobiNotConverged { iterations: 1, .. }),
        "{err:?}"
    );
}
