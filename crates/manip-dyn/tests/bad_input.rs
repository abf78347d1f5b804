//! One test per manip-dyn row of `docs/bad-input.md` (the numerically singular mass matrix is
//! `tests/errors.rs::a_numerically_singular_mass_matrix_is_reported`): each bad input is refused
//! with the named [`DynError`] variant, nothing is written to the output, and the workspace stays
//! usable.

use faer::Mat;
use manip_dyn::{
    ChainData, ChainModel, DynError, Link, MAX_LINKS, aba, forward_dynamics, gravity,
    kinetic_energy, mass_matrix, rnea,
};

/// A value no algorithm writes: an output still holding it was left untouched.
const SENTINEL: f64 = -12345.0;

fn arm() -> ChainModel {
    ChainModel::uniform(3, 0.2, 0.4, 9.81).unwrap()
}

/// The link parameter an `InvalidLink` error names.
fn invalid_quantity(result: Result<ChainModel, DynError>) -> &'static str {
    match result {
        Err(
            DynError::InvalidLink { quantity, .. }
            | DynError::InvalidLinkParameter { quantity, .. },
        ) => quantity,
        other => panic!("expected InvalidLink, got {other:?}"),
    }
}

#[test]
fn zero_links() {
    assert!(matches!(
        ChainModel::uniform(0, 0.1, 0.1, 9.81),
        Err(DynError::NoLinks)
    ));
    let err = ChainModel::new(vec![], 9.81).unwrap_err();
    assert!(matches!(err, DynError::NoLinks));
    assert_eq!(err.to_string(), "a chain needs at least one link");
}

#[test]
fn huge_link_count() {
    for n in [MAX_LINKS + 1, 1_000_000_000, usize::MAX] {
        let err = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap_err();
        assert!(
            matches!(err, DynError::TooManyLinks { got, max: MAX_LINKS, .. } if got == n),
            "{err:?}"
        );
        assert_eq!(
            err.to_string(),
            format!("a chain may have at most {MAX_LINKS} links, got {n}")
        );
    }
    let link = Link::uniform_beam(0.1, 0.1).unwrap();
    assert!(matches!(
        ChainModel::new(vec![link; MAX_LINKS + 1], 9.81),
        Err(DynError::TooManyLinks { .. })
    ));
}

#[test]
fn non_positive_or_non_finite_length() {
    for length in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(
            invalid_quantity(ChainModel::uniform(2, length, 0.1, 9.81)),
            "length"
        );
    }
}

#[test]
fn non_positive_or_non_finite_mass() {
    for mass in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let err = Link::new(0.1, mass, 0.05, 1e-4).unwrap_err();
        assert!(
            matches!(
                err,
                DynError::InvalidLinkParameter {
                    quantity: "mass",
                    ..
                }
            ),
            "{err:?}"
        );
    }
}

#[test]
fn negative_or_non_finite_inertia() {
    for inertia in [-1e-6, f64::NAN, f64::INFINITY] {
        let err = Link::new(0.1, 0.1, 0.05, inertia).unwrap_err();
        assert!(
            matches!(
                err,
                DynError::InvalidLinkParameter {
                    quantity: "inertia",
                    requirement: "non-negative and finite",
                    ..
                }
            ),
            "{err:?}"
        );
    }
}

#[test]
fn point_mass_link_is_allowed() {
    // Zero inertia about the centre of mass is a point mass: a simple pendulum of length c,
    // whose exact acceleration from rest is -g cos(q) / c.
    let (c, g, q) = (0.7, 9.81, 0.4);
    let pendulum = ChainModel::new(vec![Link::new(1.0, 2.0, c, 0.0).unwrap()], g).unwrap();
    let mut data = ChainData::new(&pendulum);
    let mut qdd = [0.0];
    aba(&pendulum, &mut data, &[q], &[0.0], &[0.0], &mut qdd).unwrap();
    assert!((qdd[0] + g * q.cos() / c).abs() < 1e-12, "{qdd:?}");
    forward_dynamics(&pendulum, &mut data, &[q], &[0.0], &[0.0], &mut qdd).unwrap();
    assert!((qdd[0] + g * q.cos() / c).abs() < 1e-12, "{qdd:?}");
}

#[test]
fn point_mass_on_the_joint() {
    // A point mass on the joint axis: the joint would drive nothing, M would be singular.
    let err = Link::new(0.1, 0.1, 0.0, 0.0).unwrap_err();
    assert!(
        matches!(
            err,
            DynError::InvalidLinkParameter {
                quantity: "inertia about the joint (inertia + mass * com^2)",
                ..
            }
        ),
        "{err:?}"
    );
    assert!(
        err.to_string()
            .contains("point mass must sit off the joint")
    );
}

#[test]
fn non_finite_centre_of_mass() {
    let link = Link::uniform_beam(0.1, 0.1).unwrap();
    let bad = Link {
        com: f64::NAN,
        ..link
    };
    let err = ChainModel::new(vec![link, bad], 9.81).unwrap_err();
    assert!(matches!(
        err,
        DynError::InvalidLink {
            index: 1,
            quantity: "centre of mass",
            ..
        }
    ));
}

#[test]
fn non_finite_gravity() {
    let err = ChainModel::uniform(2, 0.1, 0.1, f64::INFINITY).unwrap_err();
    assert!(matches!(err, DynError::InvalidGravity(g) if g.is_infinite()));
    assert_eq!(err.to_string(), "gravity must be finite, got inf");
}

#[test]
fn input_of_wrong_length() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let mut tau = [SENTINEL; 3];
    let err = rnea(&arm, &mut data, &[0.1; 2], &[0.0; 3], &[0.0; 3], &mut tau).unwrap_err();
    assert_eq!(
        err,
        DynError::Dimension {
            name: "q",
            expected: 3,
            got: 2
        }
    );
    assert_eq!(err.to_string(), "q has 2 entries, expected 3");
    assert_eq!(tau, [SENTINEL; 3]);
}

#[test]
fn output_of_wrong_length() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let mut qdd = [SENTINEL; 4];
    let err = aba(&arm, &mut data, &[0.1; 3], &[0.0; 3], &[0.0; 3], &mut qdd).unwrap_err();
    assert!(matches!(
        err,
        DynError::Dimension {
            name: "qdd",
            expected: 3,
            got: 4
        }
    ));
    assert_eq!(qdd, [SENTINEL; 4]);
}

#[test]
fn matrix_output_of_wrong_shape() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let mut m = Mat::from_fn(3, 4, |_, _| SENTINEL);
    let err = mass_matrix(&arm, &mut data, &[0.1; 3], m.as_mut()).unwrap_err();
    assert!(matches!(
        err,
        DynError::Dimension {
            name: "out (columns)",
            expected: 3,
            got: 4
        }
    ));
    assert!((0..3).all(|i| (0..4).all(|j| m[(i, j)] == SENTINEL)));
}

#[test]
fn non_finite_input_leaves_output_and_workspace_usable() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let mut qdd = [SENTINEL; 3];
    let err = forward_dynamics(
        &arm,
        &mut data,
        &[0.1; 3],
        &[0.0, f64::NAN, 0.0],
        &[0.0; 3],
        &mut qdd,
    )
    .unwrap_err();
    assert!(matches!(err, DynError::NonFinite { name: "v", index: 1, value } if value.is_nan()));
    assert_eq!(err.to_string(), "v[1] must be finite, got NaN");
    assert_eq!(qdd, [SENTINEL; 3]);
    // The workspace that saw the error gives what a fresh one gives.
    let (q, v, tau) = ([0.3, -0.2, 0.5], [0.4, 0.1, -0.3], [0.2, 0.0, -0.1]);
    forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut qdd).unwrap();
    let mut fresh = [0.0; 3];
    forward_dynamics(&arm, &mut ChainData::new(&arm), &q, &v, &tau, &mut fresh).unwrap();
    assert_eq!(qdd, fresh);
}

#[test]
fn workspace_of_another_chain() {
    let arm = arm();
    let other = ChainModel::uniform(5, 0.1, 0.1, 9.81).unwrap();
    let mut data = ChainData::new(&other);
    let mut out = [SENTINEL; 3];
    let err = gravity(&arm, &mut data, &[0.0; 3], &mut out).unwrap_err();
    assert!(matches!(
        err,
        DynError::Dimension {
            expected: 3,
            got: 5,
            ..
        }
    ));
    assert!(
        err.to_string()
            .contains("ChainData built for another model")
    );
    assert_eq!(out, [SENTINEL; 3]);
}

#[test]
fn overflowing_result() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let err = kinetic_energy(&arm, &mut data, &[0.0; 3], &[1e200; 3]).unwrap_err();
    assert!(matches!(err, DynError::NonFiniteResult { .. }), "{err:?}");
    assert!(err.to_string().contains("too large for double precision"));
}

#[test]
fn a_bad_link_is_named_by_its_real_index_or_by_none() {
    // A lone link has no index, so its message claims none ...
    let err = Link::new(0.1, -1.0, 0.05, 0.0).unwrap_err();
    assert_eq!(
        err.to_string(),
        "link mass must be positive and finite, got -1"
    );
    // ... and a chain names the link where it sits.
    let good = Link::uniform_beam(0.1, 0.1).unwrap();
    let bad = Link { mass: -1.0, ..good };
    let err = ChainModel::new(vec![good, good, bad], 9.81).unwrap_err();
    assert_eq!(
        err.to_string(),
        "link 2: mass must be positive and finite, got -1"
    );
    assert_eq!(Link::new(0.1, -1.0, 0.05, 0.0).unwrap_err().at_link(2), err);
}
