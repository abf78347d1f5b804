//! Every refusal of modal-reduce: one table of rows, each a call on bad input, the
//! [`ReduceError`] it must return and what its message says. The rows named in
//! `docs/bad-input.md` (`modal-reduce/tests/it/bad_input.rs::<row>`) are rows or tests here.
//! Calls that write to an output are made on a sentinel-filled buffer, which must come back
//! untouched, and a workspace that saw an error stays usable.

use backbone_kin::{BaseAngle, KinError, ModalMap};
use lane_math::Classify;
use manip_dyn::{ChainModel, DynError};
use modal_reduce::{
    JacobiSettings, ReduceError, ReducedData, ReducedModel, forward_dynamics,
    forward_dynamics_by_projection, jacobi_forward_dynamics, joint_torques, kinetic_energy,
    potential_energy, project_torques, reduced_terms, reduced_terms_by_projection,
};
use test_support::refusal::{Row, SENTINEL, check, exactly, row, starts, untouched, words};
use test_support::sample::{paper_reduced, tapered_lengths, uniform_chain};

/// `n` equal links making a 1 m arm.
fn chain(n: usize) -> ChainModel {
    ChainModel::uniform(n, 1.0 / n as f64, 0.1, 9.81).unwrap()
}

/// `ReduceError::Dimension`.
fn dim(name: &'static str, expected: usize, found: usize) -> ReduceError {
    ReduceError::Dimension {
        name,
        expected,
        found,
    }
}

/// Refusals of bad models.
fn model_rows() -> Vec<Row<ReduceError>> {
    // 20 tapered links: the paper's equal-link map would put them at the wrong arc lengths.
    let links = tapered_lengths()
        .iter()
        .map(|&length| manip_dyn::Link::uniform_beam(length, 0.1).unwrap())
        .collect();
    let tapered = ChainModel::new(links, 9.81).unwrap();
    let mut rows = vec![
        exactly(
            "map_and_chain_link_counts_differ",
            ReducedModel::new(chain(10), ModalMap::paper(9).unwrap()).unwrap_err(),
            |e| {
                *e == ReduceError::LinkCountMismatch {
                    joints: 9,
                    links: 10,
                }
            },
            "the modal map has 9 joints but the chain has 10 links",
        ),
        exactly(
            "map_and_chain_link_counts_differ",
            ReducedModel::new(uniform_chain(5), ModalMap::paper(6).unwrap()).unwrap_err(),
            |e| {
                *e == ReduceError::LinkCountMismatch {
                    joints: 6,
                    links: 5,
                }
            },
            "the modal map has 6 joints but the chain has 5 links",
        ),
        words(
            "map_built_for_other_link_lengths",
            ReducedModel::new(tapered, ModalMap::paper(20).unwrap()).unwrap_err(),
            |e| matches!(e, ReduceError::GeometryMismatch { link: 0, .. }),
            &["ReducedModel::from_chain"],
        ),
        row(
            "map_built_for_other_link_lengths",
            ReducedModel::from_chain(chain(4), 0, BaseAngle::Free).unwrap_err(),
            |e| matches!(e, ReduceError::Kin(KinError::NoHarmonics)),
        ),
        // Neither the chain nor the map of a huge arm is ever allocated; both errors convert.
        row(
            "huge_link_count_is_refused_upstream",
            ChainModel::uniform(usize::MAX, 0.1, 0.1, 9.81)
                .unwrap_err()
                .into(),
            |e| matches!(e, ReduceError::Dyn(DynError::TooManyLinks { .. })),
        ),
        starts(
            "huge_link_count_is_refused_upstream",
            ModalMap::paper(usize::MAX).unwrap_err().into(),
            |e| matches!(e, ReduceError::Kin(KinError::TooMany { what: "links", .. })),
            "modal map: at most 1000000 links",
        ),
    ];
    for n in [1, 2] {
        let error = ReducedModel::new(chain(n), ModalMap::paper(n).unwrap()).unwrap_err();
        assert!(
            matches!(error, ReduceError::RankDeficient { links, coords: 3, .. } if links == n),
            "{n}: {error:?}"
        );
        rows.push(words(
            "three_coordinates_on_fewer_than_three_links",
            error,
            |e| matches!(e, ReduceError::RankDeficient { coords: 3, .. }),
            &[
                "column-rank-deficient",
                "use fewer modal coordinates or more links",
            ],
        ));
    }
    // K harmonics with alpha0 fixed are 2K coordinates: 2K - 1 links cannot carry them.
    for k in 1..=4 {
        let n = 2 * k - 1;
        let map = ModalMap::uniform(n, k, BaseAngle::Fixed(0.3)).unwrap();
        rows.push(row(
            "more_harmonics_than_the_links_resolve",
            ReducedModel::new(chain(n), map).unwrap_err(),
            |e| matches!(e, ReduceError::RankDeficient { .. }),
        ));
    }
    // Three coordinates on two links; seven coordinates on five links; the most harmonics a
    // map may have on ten links (refused at once, before the O(m^3) eigenvalues that took
    // minutes for 4,097 coordinates).
    for (n, harmonics, base) in [
        (2, 1, BaseAngle::Free),
        (1, 1, BaseAngle::Fixed(0.0)),
        (5, 3, BaseAngle::Free),
        (10, backbone_kin::MAX_HARMONICS, BaseAngle::Free),
    ] {
        rows.push(words(
            "more_harmonics_than_the_links_resolve",
            ReducedModel::new(
                uniform_chain(n),
                ModalMap::uniform(n, harmonics, base).unwrap(),
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::RankDeficient { .. }),
            &["column-rank-deficient"],
        ));
    }
    rows
}

/// Refusals of per-step calls on the paper's model (`(a1, a2, alpha0)` on 10 links).
fn call_rows() -> Vec<Row<ReduceError>> {
    let model = paper_reduced(10);
    let mut data = ReducedData::new(&model);
    let mut other = ReducedData::new(&paper_reduced(12));
    let mut smaller =
        ReducedData::new(&ReducedModel::new(chain(5), ModalMap::paper(5).unwrap()).unwrap());
    let (ok, short) = ([0.1; 3], [0.1; 2]);
    let mut rows = vec![
        // States and outputs of the wrong length.
        row(
            "state_of_wrong_length",
            untouched([SENTINEL; 3], |a_ddot| {
                forward_dynamics(&model, &mut data, &[0.1; 2], &[0.0; 3], &[0.0; 3], a_ddot)
            }),
            |e| *e == dim("a", 3, 2),
        ),
        exactly(
            "state_of_wrong_length",
            reduced_terms(&model, &mut data, &short, &ok).unwrap_err(),
            |e| *e == dim("a", 3, 2),
            "a has 2 entries, expected 3",
        ),
        row(
            "state_of_wrong_length",
            reduced_terms_by_projection(&model, &mut data, &ok, &short).unwrap_err(),
            |e| *e == dim("a_dot", 3, 2),
        ),
        row(
            "state_of_wrong_length",
            untouched([SENTINEL; 3], |out| {
                forward_dynamics(&model, &mut data, &ok, &ok, &short, out)
            }),
            |e| *e == dim("tau_star", 3, 2),
        ),
        row(
            "state_of_wrong_length",
            kinetic_energy(&model, &mut data, &ok, &short).unwrap_err(),
            |e| *e == dim("a_dot", 3, 2),
        ),
        row(
            "state_of_wrong_length",
            potential_energy(&model, &mut data, &short).unwrap_err(),
            |e| *e == dim("a", 3, 2),
        ),
        row(
            "output_of_wrong_length",
            untouched([SENTINEL; 2], |out| {
                forward_dynamics_by_projection(&model, &mut data, &ok, &ok, &ok, out)
            }),
            |e| *e == dim("a_ddot", 3, 2),
        ),
        row(
            "output_of_wrong_length",
            untouched([SENTINEL; 9], |tau| {
                joint_torques(&model, &mut data, &[0.1; 3], &[0.0; 3], &[0.0; 3], tau)
            }),
            |e| *e == dim("tau", 10, 9),
        ),
        row(
            "output_of_wrong_length",
            untouched([SENTINEL; 3], |out| project_torques(&model, &[0.0; 9], out)),
            |e| *e == dim("tau", 10, 9),
        ),
        exactly(
            "output_of_wrong_length",
            untouched([SENTINEL; 2], |tau_star| {
                project_torques(&model, &[0.0; 10], tau_star)
            }),
            |e| *e == dim("tau_star", 3, 2),
            "tau_star has 2 entries, expected 3",
        ),
        // Non-finite states.
        exactly(
            "non_finite_state_leaves_output_and_workspace_usable",
            untouched([SENTINEL; 3], |a_ddot| {
                forward_dynamics(
                    &model,
                    &mut data,
                    &[0.1, f64::NAN, 0.3],
                    &[0.0; 3],
                    &[0.0; 3],
                    a_ddot,
                )
            }),
            |e| {
                matches!(
                    e,
                    ReduceError::NonFinite {
                        name: "a",
                        index: Some(1),
                        ..
                    }
                )
            },
            "a[1] must be finite, got NaN",
        ),
        exactly(
            "non_finite_state_leaves_output_and_workspace_usable",
            reduced_terms(&model, &mut data, &[0.0, f64::NAN, 0.0], &[0.0; 3]).unwrap_err(),
            |e| {
                matches!(
                    e,
                    ReduceError::NonFinite {
                        name: "a",
                        index: Some(1),
                        ..
                    }
                )
            },
            "a[1] must be finite, got NaN",
        ),
        row(
            "non_finite_state_leaves_output_and_workspace_usable",
            untouched([SENTINEL; 3], |out| {
                forward_dynamics(
                    &model,
                    &mut data,
                    &[0.0; 3],
                    &[0.0, 0.0, f64::INFINITY],
                    &[0.0; 3],
                    out,
                )
            }),
            |e| {
                matches!(
                    e,
                    ReduceError::NonFinite {
                        name: "a_dot",
                        index: Some(2),
                        ..
                    }
                )
            },
        ),
        row(
            "non_finite_state_leaves_output_and_workspace_usable",
            untouched([SENTINEL; 3], |out| {
                forward_dynamics_by_projection(
                    &model,
                    &mut data,
                    &[0.0; 3],
                    &[0.0; 3],
                    &[f64::NAN; 3],
                    out,
                )
            }),
            |e| {
                matches!(
                    e,
                    ReduceError::NonFinite {
                        name: "tau_star",
                        index: Some(0),
                        ..
                    }
                )
            },
        ),
        row(
            "non_finite_state_leaves_output_and_workspace_usable",
            untouched([SENTINEL; 10], |tau| {
                joint_torques(
                    &model,
                    &mut data,
                    &[0.0; 3],
                    &[0.0; 3],
                    &[f64::NEG_INFINITY; 3],
                    tau,
                )
            }),
            |e| matches!(e, ReduceError::NonFinite { name: "a_ddot", .. }),
        ),
        row(
            "non_finite_state_leaves_output_and_workspace_usable",
            potential_energy(&model, &mut data, &[f64::NAN; 3]).unwrap_err(),
            |e| matches!(e, ReduceError::NonFinite { name: "a", .. }),
        ),
        // A workspace of another model.
        row(
            "workspace_of_another_model",
            kinetic_energy(&model, &mut smaller, &[0.0; 3], &[0.0; 3]).unwrap_err(),
            |e| matches!(e, ReduceError::Dimension { .. }),
        ),
        row(
            "workspace_of_another_model",
            reduced_terms(&model, &mut other, &[0.0; 3], &[0.0; 3]).unwrap_err(),
            |e| {
                matches!(
                    e,
                    ReduceError::Dimension {
                        name: "workspace links",
                        ..
                    }
                )
            },
        ),
        // Overflow is an error, not a NaN.
        row(
            "overflowing_result",
            forward_dynamics(
                &model,
                &mut data,
                &[0.1; 3],
                &[1e200; 3],
                &[0.0; 3],
                &mut [0.0; 3],
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::NonFiniteResult { .. }),
        ),
        row(
            "overflowing_result",
            forward_dynamics(
                &model,
                &mut data,
                &[0.0; 3],
                &[1e200, 0.0, 0.0],
                &[0.0; 3],
                &mut [0.0; 3],
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::NonFiniteResult { .. }),
        ),
        row(
            "overflowing_result",
            forward_dynamics(
                &model,
                &mut data,
                &[0.0; 3],
                &[0.0; 3],
                &[1e308, -1e308, 1e308],
                &mut [0.0; 3],
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::NonFiniteResult { name: "a_ddot" }),
        ),
        row(
            "overflowing_result",
            joint_torques(
                &model,
                &mut data,
                &[0.0; 3],
                &[1e200; 3],
                &[0.0; 3],
                &mut [0.0; 10],
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::Dyn(_)),
        ),
        // The eq-18 iteration.
        words(
            "jacobi_iteration_diverges",
            jacobi_forward_dynamics(
                &model,
                &mut data,
                &[0.3, 0.2, 1.0],
                &[0.0; 3],
                &[0.0; 3],
                &JacobiSettings::default(),
                &mut [0.0; 3],
            )
            .unwrap_err(),
            |e| matches!(e, ReduceError::JacobiDiverged { spectral_radius } if *spectral_radius >= 1.0),
            &["solve M* a_ddot = rhs directly"],
        ),
    ];
    // Finite coordinates whose joint values overflow in the map: numerical, not the joints'
    // input refused by the chain's dynamics.
    let huge = [f64::MAX; 3];
    let overflows = [
        (
            joint_torques(
                &model,
                &mut data,
                &huge,
                &[0.0; 3],
                &[0.0; 3],
                &mut [0.0; 10],
            ),
            "theta = J a + theta_0",
        ),
        (
            joint_torques(
                &model,
                &mut data,
                &[0.0; 3],
                &[0.0; 3],
                &huge,
                &mut [0.0; 10],
            ),
            "theta_ddot = J a_ddot",
        ),
        (
            kinetic_energy(&model, &mut data, &[0.0; 3], &huge).map(drop),
            "theta_dot = J a_dot",
        ),
        (
            potential_energy(&model, &mut data, &huge).map(drop),
            "theta = J a + theta_0",
        ),
        (
            reduced_terms_by_projection(&model, &mut data, &huge, &[0.0; 3]),
            "theta = J a + theta_0",
        ),
    ];
    for (result, name) in overflows {
        let error = result.unwrap_err();
        assert!(
            matches!(&error, ReduceError::NonFiniteResult { name: n } if *n == name),
            "{name}: {error:?}"
        );
        rows.push(row("overflowing_result", error, |e| {
            matches!(e, ReduceError::NonFiniteResult { .. })
        }));
    }
    let bad_settings = [
        (0.0, 10, "tolerance"),
        (f64::NAN, 10, "tolerance"),
        (1e-12, 0, "max_iterations"),
    ];
    for (tolerance, max_iterations, name) in bad_settings {
        let settings = JacobiSettings {
            tolerance,
            max_iterations,
        };
        let error = untouched([SENTINEL; 3], |a_ddot| {
            jacobi_forward_dynamics(
                &model, &mut data, &[0.1; 3], &[0.0; 3], &[0.0; 3], &settings, a_ddot,
            )
        });
        assert!(
            matches!(error, ReduceError::InvalidSetting { name: n, .. } if n == name),
            "{settings:?}: {error:?}"
        );
        rows.push(row("jacobi_settings_out_of_domain", error, |e| {
            matches!(e, ReduceError::InvalidSetting { .. })
        }));
    }
    let map = ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2).unwrap();
    let fixed = ReducedModel::new(chain(10), map).unwrap();
    let settings = JacobiSettings {
        tolerance: 1e-15,
        max_iterations: 1,
    };
    rows.push(row(
        "jacobi_iteration_out_of_budget",
        jacobi_forward_dynamics(
            &fixed,
            &mut ReducedData::new(&fixed),
            &[0.3, 0.2],
            &[0.0; 2],
            &[0.0; 2],
            &settings,
            &mut [0.0; 2],
        )
        .unwrap_err(),
        |e| matches!(e, ReduceError::JacobiNotConverged { iterations: 1, .. }),
    ));
    rows
}

#[test]
fn bad_models_are_refused() {
    check(&model_rows());
}

#[test]
fn bad_calls_are_refused_and_write_nothing() {
    check(&call_rows());
}

#[test]
fn the_smallest_full_rank_models_are_accepted() {
    for (n, harmonics, base) in [
        (3, 1, BaseAngle::Free),
        (2, 1, BaseAngle::Fixed(0.3)),
        (5, 2, BaseAngle::Free),
    ] {
        ReducedModel::new(
            uniform_chain(n),
            ModalMap::uniform(n, harmonics, base).unwrap(),
        )
        .unwrap();
    }
    assert!(ReducedModel::new(chain(3), ModalMap::paper(3).unwrap()).is_ok());
    // Twice as many links as coordinates is plenty.
    let map = ModalMap::uniform(16, 4, BaseAngle::Fixed(0.3)).unwrap();
    assert!(ReducedModel::new(chain(16), map).is_ok());
}

#[test]
fn a_map_of_the_chain_s_own_link_lengths_is_accepted() {
    let lengths = tapered_lengths();
    let links = lengths
        .iter()
        .map(|&length| manip_dyn::Link::uniform_beam(length, 0.1).unwrap())
        .collect();
    let tapered = ChainModel::new(links, 9.81).unwrap();
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
}

#[test]
fn a_refused_call_leaves_the_workspace_usable() {
    let model = paper_reduced(10);
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [0.0; 3];
    let nan = [0.1, f64::NAN, 0.3];
    assert!(forward_dynamics(&model, &mut data, &nan, &[0.0; 3], &[0.0; 3], &mut a_ddot).is_err());
    let (a, a_dot, tau) = ([0.3, -0.2, 1.2], [0.4, 0.1, -0.3], [0.2, 0.0, -0.1]);
    forward_dynamics(&model, &mut data, &a, &a_dot, &tau, &mut a_ddot).unwrap();
    let mut fresh = [0.0; 3];
    let mut fresh_data = ReducedData::new(&model);
    forward_dynamics(&model, &mut fresh_data, &a, &a_dot, &tau, &mut fresh).unwrap();
    assert_eq!(a_ddot, fresh);
}

#[test]
fn every_refusal_is_in_exactly_one_class() {
    for Row { name, error, .. } in model_rows().into_iter().chain(call_rows()) {
        let numerical = matches!(
            error,
            ReduceError::NonFiniteResult { .. }
                | ReduceError::JacobiDiverged { .. }
                | ReduceError::JacobiNotConverged { .. }
                | ReduceError::NotPositiveDefinite
        ) || matches!(error, ReduceError::Dyn(ref e) if e.is_numerical());
        let unreachable = error.is_unreachable();
        assert_eq!(error.is_numerical(), numerical, "{name}: {error}");
        assert_eq!(
            error.is_invalid_input(),
            !(numerical || unreachable),
            "{name}: {error}"
        );
    }
}

#[test]
fn wrapped_errors_keep_their_class() {
    let numerical = ReduceError::Dyn(DynError::NotPositiveDefinite);
    assert!(numerical.is_numerical() && !numerical.is_invalid_input());
    let unreachable = ReduceError::Kin(KinError::OutOfReach {
        r: 2.0,
        length: 1.0,
    });
    assert!(unreachable.is_unreachable() && !unreachable.is_numerical());
    assert!(!unreachable.is_invalid_input());
    let input = ReduceError::Dyn(DynError::NoLinks);
    assert!(input.is_invalid_input() && !input.is_numerical() && !input.is_unreachable());
    let diverged = ReduceError::JacobiDiverged {
        spectral_radius: 1.5,
    };
    assert!(diverged.is_numerical());
}
