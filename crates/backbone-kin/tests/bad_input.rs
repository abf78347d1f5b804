//! One test per backbone-kin row of `docs/bad-input.md`: each bad input is refused with the named
//! [`KinError`] variant and nothing is written to the output.

use backbone_kin::{
    BackboneCurve, BaseAngle, Branch, HarmonicIk, IkOptions, KinError, MAX_HARMONICS, MAX_LINKS,
    ModalMap, end_point, inverse_j0, inverse_kinematics, joint_positions, tip_position,
};
use std::f64::consts::FRAC_PI_2;

/// A value no function writes: an output still holding it was left untouched.
const SENTINEL: f64 = -12345.0;

#[test]
fn zero_links() {
    assert_eq!(tip_position(&[], &[]), Err(KinError::NoLinks));
    let err = ModalMap::uniform(0, 1, BaseAngle::Free).unwrap_err();
    assert_eq!(err, KinError::NoLinks);
    assert_eq!(err.to_string(), "a manipulator needs at least one link");
    assert_eq!(
        ModalMap::new(&[], 1, BaseAngle::Free),
        Err(KinError::NoLinks)
    );
}

#[test]
fn zero_harmonics() {
    assert!(matches!(
        ModalMap::uniform(10, 0, BaseAngle::Free),
        Err(KinError::NoHarmonics)
    ));
    assert!(matches!(
        HarmonicIk::new(1.0, 0, 0.0),
        Err(KinError::NoHarmonics)
    ));
    assert!(matches!(
        BackboneCurve::new(1.0, &[], 0.0),
        Err(KinError::NoHarmonics)
    ));
}

#[test]
fn huge_link_count() {
    for n in [MAX_LINKS + 1, 1_000_000_000, usize::MAX] {
        let err = ModalMap::uniform(n, 1, BaseAngle::Free).unwrap_err();
        assert_eq!(
            err,
            KinError::TooMany {
                what: "links",
                got: n,
                max: MAX_LINKS
            }
        );
    }
    let err = ModalMap::new(&vec![0.1; MAX_LINKS + 1], 1, BaseAngle::Free).unwrap_err();
    assert!(matches!(err, KinError::TooMany { what: "links", .. }));
    assert_eq!(
        err.to_string(),
        format!(
            "at most {MAX_LINKS} links are supported, got {}",
            MAX_LINKS + 1
        )
    );
}

#[test]
fn huge_harmonic_count() {
    for k in [MAX_HARMONICS + 1, usize::MAX] {
        let err = HarmonicIk::new(1.0, k, 0.0).unwrap_err();
        assert_eq!(
            err,
            KinError::TooMany {
                what: "harmonics",
                got: k,
                max: MAX_HARMONICS
            }
        );
        assert!(matches!(
            ModalMap::uniform(10, k, BaseAngle::Free),
            Err(KinError::TooMany {
                what: "harmonics",
                ..
            })
        ));
    }
}

#[test]
fn non_positive_link_length() {
    for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let err = tip_position(&[0.1, bad], &[0.0; 2]).unwrap_err();
        assert!(
            matches!(
                err,
                KinError::NonPositiveLength {
                    name: "link length",
                    ..
                }
            ),
            "{err:?}"
        );
        assert!(matches!(
            ModalMap::new(&[0.1, bad, 0.1], 1, BaseAngle::Free),
            Err(KinError::NonPositiveLength { .. })
        ));
    }
    assert_eq!(
        tip_position(&[-0.5], &[0.0]).unwrap_err().to_string(),
        "link length must be positive and finite, got -0.5"
    );
}

#[test]
fn link_lengths_overflowing_their_sum() {
    let err = tip_position(&[1e308, 1e308], &[0.0; 2]).unwrap_err();
    assert!(
        matches!(
            err,
            KinError::NonPositiveLength {
                name: "curve length (the sum of the link lengths)",
                value,
            } if value.is_infinite()
        ),
        "{err:?}"
    );
    assert!(matches!(
        ModalMap::new(&[1e308, 1e308], 1, BaseAngle::Fixed(0.0)),
        Err(KinError::NonPositiveLength { .. })
    ));
}

#[test]
fn non_finite_joint_angle() {
    let mut points = [[SENTINEL; 2]; 3];
    let err = joint_positions(&[0.1; 2], &[0.0, f64::NAN], &mut points).unwrap_err();
    assert!(matches!(err, KinError::NonFinite { name: "joint angles", value } if value.is_nan()));
    assert_eq!(err.to_string(), "joint angles must be finite, got NaN");
    assert_eq!(points, [[SENTINEL; 2]; 3]);
}

#[test]
fn mismatched_joint_angles() {
    let err = tip_position(&[0.1; 3], &[0.0; 2]).unwrap_err();
    assert_eq!(
        err,
        KinError::Dimension {
            name: "joint angles",
            expected: 3,
            got: 2
        }
    );
}

#[test]
fn output_buffer_of_wrong_size() {
    let mut points = [[SENTINEL; 2]; 3];
    let err = joint_positions(&[0.1; 3], &[0.0; 3], &mut points).unwrap_err();
    assert!(matches!(
        err,
        KinError::Dimension {
            name: "joint positions",
            expected: 4,
            got: 3
        }
    ));
    assert_eq!(points, [[SENTINEL; 2]; 3]);
    let map = ModalMap::paper(10).unwrap();
    let mut theta = [SENTINEL; 9];
    assert!(matches!(
        map.joint_angles(&[0.1, 0.2, 0.3], &mut theta),
        Err(KinError::Dimension {
            name: "joint output",
            expected: 10,
            got: 9
        })
    ));
    assert_eq!(theta, [SENTINEL; 9]);
}

#[test]
fn non_positive_curve_length() {
    for length in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            end_point(length, [0.1, 0.2], 0.0),
            Err(KinError::NonPositiveLength {
                name: "curve length",
                ..
            })
        ));
        assert!(matches!(
            BackboneCurve::paper(length, 0.1, 0.2, 0.0),
            Err(KinError::NonPositiveLength { .. })
        ));
        assert!(matches!(
            HarmonicIk::new(length, 1, 0.0),
            Err(KinError::NonPositiveLength { .. })
        ));
    }
}

#[test]
fn non_finite_modal_coordinate() {
    assert!(matches!(
        end_point(1.0, [f64::NAN, 0.0], 0.0),
        Err(KinError::NonFinite { name: "a1", .. })
    ));
    let map = ModalMap::paper(10).unwrap();
    let mut theta = [SENTINEL; 10];
    let err = map
        .joint_angles(&[0.1, f64::INFINITY, 0.3], &mut theta)
        .unwrap_err();
    assert!(matches!(
        err,
        KinError::NonFinite {
            name: "modal coordinates",
            ..
        }
    ));
    assert_eq!(theta, [SENTINEL; 10]);
}

#[test]
fn non_finite_base_angle() {
    assert!(matches!(
        ModalMap::paper_fixed_alpha0(10, f64::NAN),
        Err(KinError::NonFinite { name: "alpha0", .. })
    ));
    assert!(matches!(
        HarmonicIk::new(1.0, 1, f64::INFINITY),
        Err(KinError::NonFinite { name: "alpha0", .. })
    ));
}

#[test]
fn unpaired_modal_coordinates() {
    let err = BackboneCurve::new(1.0, &[0.1, 0.2, 0.3], 0.0).unwrap_err();
    assert_eq!(err, KinError::UnpairedModes { got: 3 });
    assert!(err.to_string().contains("odd count 3"));
}

#[test]
fn arc_length_outside_the_curve() {
    let curve = BackboneCurve::paper(1.0, 0.3, 0.2, 0.0).unwrap();
    for s in [-0.1, 1.5, f64::NAN] {
        assert!(
            matches!(
                curve.point(s),
                Err(KinError::ArcLength { .. }) | Err(KinError::NonFinite { .. })
            ),
            "{s}"
        );
    }
    assert_eq!(
        curve.inclination(1.5).unwrap_err().to_string(),
        "arc length s = 1.5 is outside the curve [0, 1]"
    );
}

#[test]
fn curve_too_oscillatory() {
    let err = BackboneCurve::new(1.0, &[1e12, 0.0], 0.0)
        .and_then(|curve| curve.point(1.0))
        .unwrap_err();
    assert!(matches!(err, KinError::TooOscillatory { .. }), "{err:?}");
}

#[test]
fn inverse_j0_outside_its_range() {
    for value in [1.5, -0.1] {
        assert!(
            matches!(inverse_j0(value), Err(KinError::J0Domain { .. })),
            "{value}"
        );
    }
    assert!(matches!(
        inverse_j0(f64::NAN),
        Err(KinError::NonFinite { .. })
    ));
}

#[test]
fn target_out_of_reach() {
    let err = inverse_kinematics(1.0, [0.8, 0.8], FRAC_PI_2, Branch::Positive).unwrap_err();
    assert!(matches!(err, KinError::OutOfReach { .. }));
    assert!(err.is_unreachable());
    assert!(err.to_string().starts_with("target out of reach"));
}

#[test]
fn target_at_the_base() {
    let err = inverse_kinematics(1.0, [0.0, 0.0], FRAC_PI_2, Branch::Positive).unwrap_err();
    assert!(matches!(err, KinError::AtBase { .. }));
    assert!(err.is_unreachable());
}

#[test]
fn target_needs_a2_beyond_the_amplitude() {
    // Almost fully stretched (A small) but far from the base direction alpha0 = pi/2.
    let err = inverse_kinematics(1.0, [0.99, 0.0], FRAC_PI_2, Branch::Positive).unwrap_err();
    assert!(
        matches!(err, KinError::A2ExceedsAmplitude { .. }),
        "{err:?}"
    );
    assert!(err.is_unreachable());
}

#[test]
fn non_finite_target() {
    assert!(matches!(
        inverse_kinematics(1.0, [f64::NAN, 0.5], FRAC_PI_2, Branch::Positive),
        Err(KinError::NonFinite {
            name: "target x",
            ..
        })
    ));
    let mut ik = HarmonicIk::new(1.0, 1, FRAC_PI_2).unwrap();
    let mut a = [SENTINEL; 2];
    assert!(matches!(
        ik.solve([0.3, f64::INFINITY], &mut a),
        Err(KinError::NonFinite {
            name: "target y",
            ..
        })
    ));
    assert_eq!(a, [SENTINEL; 2]);
}

#[test]
fn numerical_ik_target_out_of_reach() {
    let mut ik = HarmonicIk::new(1.0, 2, FRAC_PI_2).unwrap();
    let mut a = [0.1, 0.2, 0.3, 0.4];
    let err = ik.solve([1.0, 1.0], &mut a).unwrap_err();
    assert!(matches!(err, KinError::OutOfReach { .. }));
    assert_eq!(a, [0.1, 0.2, 0.3, 0.4]);
    // The solver stays usable.
    ik.solve([0.3, 0.6], &mut a).unwrap();
}

#[test]
fn numerical_ik_guess_of_wrong_size() {
    let mut ik = HarmonicIk::new(1.0, 2, FRAC_PI_2).unwrap();
    let mut a = [SENTINEL; 3];
    assert!(matches!(
        ik.solve([0.3, 0.6], &mut a),
        Err(KinError::Dimension {
            name: "initial guess",
            expected: 4,
            got: 3
        })
    ));
    assert_eq!(a, [SENTINEL; 3]);
}

#[test]
fn numerical_ik_not_converged() {
    let options = IkOptions {
        tolerance: 1e-14,
        max_iterations: 0,
    };
    let mut ik = HarmonicIk::new(1.0, 1, FRAC_PI_2)
        .unwrap()
        .with_options(options)
        .unwrap();
    let mut a = [0.0, 0.0];
    let err = ik.solve([0.3, 0.6], &mut a).unwrap_err();
    assert!(
        matches!(err, KinError::NotConverged { iterations: 0, .. }),
        "{err:?}"
    );
    // Small numbers in exponent form, not as 17-digit decimals.
    let message = err.to_string();
    assert!(
        message.contains("e-1 after 0 iterations (tolerance 1e-14)"),
        "{message}"
    );
    assert!(err.to_string().contains("did not converge"));
    assert!(a.iter().all(|x| x.is_finite()));
}

#[test]
fn numerical_ik_tolerance_not_positive() {
    for tolerance in [0.0, -1e-9, f64::NAN, f64::INFINITY] {
        let options = IkOptions {
            tolerance,
            max_iterations: 10,
        };
        let result = HarmonicIk::new(1.0, 1, 0.0).unwrap().with_options(options);
        assert!(
            matches!(
                result,
                Err(KinError::NonPositiveLength {
                    name: "IK tolerance",
                    ..
                }) | Err(KinError::NonFinite {
                    name: "IK tolerance",
                    ..
                })
            ),
            "{tolerance}: {result:?}"
        );
    }
}

#[test]
#[should_panic(expected = "index out of bounds")]
fn modal_map_entry_out_of_range() {
    // An accessor, indexed like a slice: a column past the last panics instead of silently
    // reading the next row's first entry.
    let map = ModalMap::paper(10).unwrap();
    let _ = map.entry(0, map.n_coords());
}
