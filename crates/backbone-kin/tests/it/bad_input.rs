//! Every refusal of backbone-kin in one table: each row is a call on bad input, the [`KinError`]
//! it must return, and what its message must say. The rows named in `docs/bad-input.md`
//! (`backbone-kin/tests/it/bad_input.rs::<row>`) are rows here; together the rows reach every
//! `KinError` variant through the public API. Calls that write to an output are made on a
//! sentinel-filled buffer, which must come back untouched.

use backbone_kin::{
    BackboneCurve, BaseAngle, BasePose, Branch, HarmonicIk, IkOptions, KinError, MAX_HARMONICS,
    MAX_LINKS, ModalMap, SpatialIk, SpatialModalMap, end_point, inverse_j0, inverse_kinematics,
    joint_positions, tip_position,
};
use lane_math::{Classify, ErrorClass};
use std::collections::BTreeSet;
use std::f64::consts::FRAC_PI_2;
use test_support::refusal::{Row, SENTINEL, check, exactly, row, starts, untouched, words};

/// The variant's name. `KinError` is `#[non_exhaustive]`, so a variant added later reaches the
/// last arm and fails the test until it is covered here.
fn variant(error: &KinError) -> &'static str {
    match error {
        KinError::NonFinite { .. } => "NonFinite",
        KinError::NonPositiveLength { .. } => "NonPositiveLength",
        KinError::NoLinks => "NoLinks",
        KinError::NoHarmonics => "NoHarmonics",
        KinError::Dimension { .. } => "Dimension",
        KinError::UnpairedModes { .. } => "UnpairedModes",
        KinError::ArcLength { .. } => "ArcLength",
        KinError::TooOscillatory { .. } => "TooOscillatory",
        KinError::J0Domain { .. } => "J0Domain",
        KinError::OutOfReach { .. } => "OutOfReach",
        KinError::AtBase { .. } => "AtBase",
        KinError::A2ExceedsAmplitude { .. } => "A2ExceedsAmplitude",
        KinError::NotConverged { .. } => "NotConverged",
        KinError::Stationary { .. } => "Stationary",
        KinError::TooMany { .. } => "TooMany",
        KinError::GuessTooLarge { .. } => "GuessTooLarge",
        KinError::AnswerTooOscillatory { .. } => "AnswerTooOscillatory",
        other => panic!("a variant this test does not cover: {other:?}"),
    }
}

const ALL: [&str; 17] = [
    "NonFinite",
    "NonPositiveLength",
    "NoLinks",
    "NoHarmonics",
    "Dimension",
    "UnpairedModes",
    "ArcLength",
    "TooOscillatory",
    "J0Domain",
    "OutOfReach",
    "AtBase",
    "A2ExceedsAmplitude",
    "NotConverged",
    "Stationary",
    "TooMany",
    "GuessTooLarge",
    "AnswerTooOscillatory",
];

/// The spatial solver of `n` links of 1 mm with `k` harmonics per plane at the default base.
fn spatial_ik(n: usize, k: usize) -> SpatialIk {
    let map = SpatialModalMap::new(&vec![1e-3; n], k).unwrap();
    SpatialIk::new(map, BasePose::default()).unwrap()
}

/// Every refusal.
fn rows() -> Vec<Row<KinError>> {
    let curve = BackboneCurve::paper(1.0, 0.5, 0.5, 0.0).unwrap();
    let paper_map = ModalMap::paper(10).unwrap();
    let mut straight = HarmonicIk::new(1.0, 2, 0.0).unwrap();
    let stingy = IkOptions {
        tolerance: 1e-14,
        max_iterations: 1,
    };
    let mut stingy = HarmonicIk::new(1.0, 2, 0.0)
        .unwrap()
        .with_options(stingy)
        .unwrap();
    let mut rows = vec![
        // No links, no harmonics.
        exactly(
            "zero_links",
            ModalMap::uniform(0, 1, BaseAngle::Free).unwrap_err(),
            |e| *e == KinError::NoLinks,
            "a manipulator needs at least one link",
        ),
        words(
            "zero_links",
            tip_position(&[], &[]).unwrap_err(),
            |e| *e == KinError::NoLinks,
            &["at least one link"],
        ),
        row(
            "zero_links",
            ModalMap::new(&[], 1, BaseAngle::Free).unwrap_err(),
            |e| *e == KinError::NoLinks,
        ),
        words(
            "zero_links",
            joint_positions(&[], &[], &mut []).unwrap_err(),
            |e| *e == KinError::NoLinks,
            &["at least one link"],
        ),
        row(
            "zero_harmonics",
            ModalMap::uniform(10, 0, BaseAngle::Free).unwrap_err(),
            |e| *e == KinError::NoHarmonics,
        ),
        words(
            "zero_harmonics",
            HarmonicIk::new(1.0, 0, 0.0).unwrap_err(),
            |e| *e == KinError::NoHarmonics,
            &["at least one harmonic"],
        ),
        words(
            "zero_harmonics",
            BackboneCurve::new(1.0, &[], 0.0).unwrap_err(),
            |e| *e == KinError::NoHarmonics,
            &["at least one harmonic"],
        ),
        // Counts beyond the limits.
        exactly(
            "huge_link_count",
            ModalMap::new(&vec![0.1; MAX_LINKS + 1], 1, BaseAngle::Free).unwrap_err(),
            |e| matches!(e, KinError::TooMany { what: "links", .. }),
            "at most 1000000 links are supported, got 1000001",
        ),
        words(
            "huge_harmonic_count",
            HarmonicIk::new(1.0, usize::MAX, 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::TooMany {
                        what: "harmonics",
                        ..
                    }
                )
            },
            &["at most", "harmonics"],
        ),
        // Lengths.
        exactly(
            "non_positive_link_length",
            tip_position(&[-0.5], &[0.0]).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
            "link length must be positive and finite, got -0.5",
        ),
        words(
            "non_positive_link_length",
            tip_position(&[0.1, -0.1], &[0.0, 0.0]).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
            &["link length", "-0.1"],
        ),
        // Finite joint angles whose running sum (a link's absolute angle) overflows.
        exactly(
            "non_finite",
            tip_position(&[0.5, 0.5, 0.5], &[1e308, 1e308, 0.0]).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { index: Some(1), .. }),
            "absolute link angles (running sums of the joint angles)[1] must be finite, got inf",
        ),
        words(
            "non_finite",
            joint_positions(&[0.5, 0.5], &[-1e308, -1e308], &mut [[0.0; 2]; 3]).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { index: Some(1), .. }),
            &["absolute link angles", "-inf"],
        ),
        words(
            "non_positive_link_length",
            ModalMap::new(&[0.1, f64::INFINITY], 1, BaseAngle::Free).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
            &["link length", "inf"],
        ),
        row(
            "link_lengths_overflowing_their_sum",
            tip_position(&[1e308, 1e308], &[0.0; 2]).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonPositiveLength {
                        name: "curve length (the sum of the link lengths)",
                        value,
                    } if value.is_infinite()
                )
            },
        ),
        row(
            "link_lengths_overflowing_their_sum",
            ModalMap::new(&[1e308, 1e308], 1, BaseAngle::Fixed(0.0)).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
        ),
        words(
            "non_positive_curve_length",
            end_point(0.0, [0.0, 0.0], 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonPositiveLength {
                        name: "curve length",
                        ..
                    }
                )
            },
            &["curve length", "positive", "0"],
        ),
        words(
            "non_positive_curve_length",
            BackboneCurve::paper(-1.0, 0.0, 0.0, 0.0).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
            &["curve length", "-1"],
        ),
        // Non-finite values; outputs untouched.
        exactly(
            "non_finite_joint_angle",
            untouched([[SENTINEL; 2]; 3], |points| {
                joint_positions(&[0.1; 2], &[0.0, f64::NAN], points)
            }),
            |e| {
                matches!(
                    e,
                    KinError::NonFinite { name: "joint angles", index: Some(1), value }
                        if value.is_nan()
                )
            },
            "joint angles[1] must be finite, got NaN",
        ),
        words(
            "non_finite_modal_coordinate",
            end_point(1.0, [f64::NAN, 0.0], 0.0).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { name: "a1", .. }),
            &["a1", "finite", "NaN"],
        ),
        row(
            "non_finite_modal_coordinate",
            untouched([SENTINEL; 10], |theta| {
                paper_map.joint_angles(&[0.1, f64::INFINITY, 0.3], theta)
            }),
            |e| {
                matches!(
                    e,
                    KinError::NonFinite {
                        name: "modal coordinates",
                        ..
                    }
                )
            },
        ),
        row(
            "non_finite_base_angle",
            ModalMap::paper_fixed_alpha0(10, f64::NAN).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { name: "alpha0", .. }),
        ),
        row(
            "non_finite_base_angle",
            HarmonicIk::new(1.0, 1, f64::INFINITY).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { name: "alpha0", .. }),
        ),
        words(
            "non_finite_base_angle",
            inverse_kinematics(1.0, [0.5, 0.0], f64::NAN, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { name: "alpha0", .. }),
            &["alpha0", "finite"],
        ),
        row(
            "non_finite_target",
            inverse_kinematics(1.0, [f64::NAN, 0.5], FRAC_PI_2, Branch::Positive).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonFinite {
                        name: "target x",
                        ..
                    }
                )
            },
        ),
        words(
            "non_finite_target",
            inverse_kinematics(1.0, [0.5, f64::INFINITY], 0.0, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { .. }),
            &["target y", "finite"],
        ),
        row(
            "non_finite_target",
            untouched([SENTINEL; 2], |a| {
                HarmonicIk::new(1.0, 1, FRAC_PI_2)
                    .unwrap()
                    .solve([0.3, f64::INFINITY], a)
            }),
            |e| {
                matches!(
                    e,
                    KinError::NonFinite {
                        name: "target y",
                        ..
                    }
                )
            },
        ),
        // Sizes; outputs untouched.
        words(
            "mismatched_joint_angles",
            tip_position(&[0.1; 3], &[0.0; 2]).unwrap_err(),
            |e| {
                *e == KinError::Dimension {
                    name: "joint angles",
                    expected: 3,
                    found: 2,
                }
            },
            &["joint angles", "expected 3"],
        ),
        words(
            "output_buffer_of_wrong_size",
            untouched([[SENTINEL; 2]; 3], |points| {
                joint_positions(&[0.1; 3], &[0.0; 3], points)
            }),
            |e| {
                *e == KinError::Dimension {
                    name: "joint positions",
                    expected: 4,
                    found: 3,
                }
            },
            &["joint positions", "3 entries", "expected 4"],
        ),
        row(
            "output_buffer_of_wrong_size",
            untouched([SENTINEL; 9], |theta| {
                paper_map.joint_angles(&[0.1, 0.2, 0.3], theta)
            }),
            |e| {
                *e == KinError::Dimension {
                    name: "joint output",
                    expected: 10,
                    found: 9,
                }
            },
        ),
        words(
            "output_buffer_of_wrong_size",
            untouched([SENTINEL; 3], |theta| {
                ModalMap::paper(3).unwrap().joint_angles(&[0.0; 2], theta)
            }),
            |e| matches!(e, KinError::Dimension { .. }),
            &["modal coordinates", "2 entries", "expected 3"],
        ),
        words(
            "output_buffer_of_wrong_size",
            untouched([SENTINEL; 3], |jacobian| curve.end_point_jacobian(jacobian)),
            |e| matches!(e, KinError::Dimension { .. }),
            &["end-point jacobian", "expected 4"],
        ),
        // The curve.
        words(
            "unpaired_modal_coordinates",
            BackboneCurve::new(1.0, &[0.1, 0.2, 0.3], 0.0).unwrap_err(),
            |e| *e == KinError::UnpairedModes { got: 3 },
            &["pairs", "odd count 3"],
        ),
        exactly(
            "arc_length_outside_the_curve",
            curve.inclination(1.5).unwrap_err(),
            |e| matches!(e, KinError::ArcLength { .. }),
            "arc length s = 1.5 is outside the curve [0, 1]",
        ),
        words(
            "arc_length_outside_the_curve",
            curve.point(1.5).unwrap_err(),
            |e| matches!(e, KinError::ArcLength { .. }),
            &["s = 1.5", "outside the curve", "[0, 1]"],
        ),
        words(
            "arc_length_outside_the_curve",
            curve.inclination(-0.1).unwrap_err(),
            |e| matches!(e, KinError::ArcLength { .. }),
            &["s = -0.1", "outside"],
        ),
        words(
            "arc_length_outside_the_curve",
            curve.curvature(2.0).unwrap_err(),
            |e| matches!(e, KinError::ArcLength { .. }),
            &["outside"],
        ),
        words(
            "arc_length_outside_the_curve",
            curve.point(f64::NAN).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { .. }),
            &["arc length", "finite"],
        ),
        row(
            "curve_too_oscillatory",
            BackboneCurve::new(1.0, &[1e12, 0.0], 0.0)
                .and_then(|curve| curve.point(1.0))
                .unwrap_err(),
            |e| matches!(e, KinError::TooOscillatory { .. }),
        ),
        words(
            "curve_too_oscillatory",
            BackboneCurve::new(1.0, &[1e308, 2.0, 3.0, 4.0], 0.0).unwrap_err(),
            |e| matches!(e, KinError::TooOscillatory { .. }),
            &[
                "oscillates too fast",
                "an overflowing number of nodes needed",
            ],
        ),
        words(
            "curve_too_oscillatory",
            BackboneCurve::paper(1.0, 1e6, 0.0, 0.0).unwrap_err(),
            |e| matches!(e, KinError::TooOscillatory { .. }),
            &["oscillates too fast", "nodes needed"],
        ),
        // The spatial inverse kinematics from a guess: bounded before it iterates, and an answer
        // whose curve fk cannot evaluate (from a guess of 10s on 512 links of 1 mm, K = 16, the
        // solve converges to a residual of 1e-15 m) is refused.
        exactly(
            "spatial_ik_guess_too_large",
            spatial_ik(2, 1)
                .solve_evaluable([0.1, 0.0, 0.0], Some(&[0.0, 10.5, 0.0, 0.0]), &mut [0.0; 4])
                .unwrap_err(),
            |e| matches!(e, KinError::GuessTooLarge { index: 1, .. }),
            "guess entries must be at most 10 in magnitude, got 10.5",
        ),
        words(
            "spatial_ik_answer_too_oscillatory",
            spatial_ik(512, 16)
                .solve_evaluable([0.1, 0.1, 0.1], Some(&[10.0; 64]), &mut [0.0; 64])
                .unwrap_err(),
            |e| matches!(e, KinError::AnswerTooOscillatory { .. }),
            &[
                "the solution's curve (",
                "cannot be evaluated by fk: the curve oscillates too fast",
                "start from a guess of smaller coordinates",
            ],
        ),
        // The inverse of J0 and the closed-form inverse kinematics.
        words(
            "inverse_j0_outside_its_range",
            inverse_j0(1.5).unwrap_err(),
            |e| matches!(e, KinError::J0Domain { .. }),
            &["inverse of J0", "[0, 1]", "1.5"],
        ),
        words(
            "inverse_j0_outside_its_range",
            inverse_j0(-0.25).unwrap_err(),
            |e| matches!(e, KinError::J0Domain { .. }),
            &["[0, 1]", "-0.25"],
        ),
        row(
            "inverse_j0_outside_its_range",
            inverse_j0(-0.1).unwrap_err(),
            |e| matches!(e, KinError::J0Domain { .. }),
        ),
        words(
            "inverse_j0_outside_its_range",
            inverse_j0(f64::NAN).unwrap_err(),
            |e| matches!(e, KinError::NonFinite { .. }),
            &["J0 value", "finite"],
        ),
        starts(
            "target_out_of_reach",
            inverse_kinematics(1.0, [0.8, 0.8], FRAC_PI_2, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::OutOfReach { .. }),
            "target out of reach",
        ),
        words(
            "target_out_of_reach",
            inverse_kinematics(1.0, [1.5, 0.0], 0.0, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::OutOfReach { .. }),
            &["out of reach", "r = 1.5", "l = 1"],
        ),
        row(
            "target_at_the_base",
            inverse_kinematics(1.0, [0.0, 0.0], FRAC_PI_2, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::AtBase { .. }),
        ),
        words(
            "target_at_the_base",
            inverse_kinematics(1.0, [0.0, 0.0], 0.0, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::AtBase { .. }),
            &["at the base", "a2"],
        ),
        // Almost fully stretched (A small) but far from the base direction alpha0 = pi/2.
        row(
            "target_needs_a2_beyond_the_amplitude",
            inverse_kinematics(1.0, [0.99, 0.0], FRAC_PI_2, Branch::Positive).unwrap_err(),
            |e| matches!(e, KinError::A2ExceedsAmplitude { .. }),
        ),
        words(
            "target_needs_a2_beyond_the_amplitude",
            inverse_kinematics(1.0, [0.0, 0.5], 0.0, Branch::Negative).unwrap_err(),
            |e| matches!(e, KinError::A2ExceedsAmplitude { .. }),
            &["alpha0 = 0", "|a2| = 1.57", "A = 1.52", "|a2| <= A"],
        ),
        // The numerical inverse kinematics; guesses untouched where the call is refused up front.
        row(
            "numerical_ik_target_out_of_reach",
            untouched([0.1, 0.2, 0.3, 0.4], |a| {
                HarmonicIk::new(1.0, 2, FRAC_PI_2)
                    .unwrap()
                    .solve([1.0, 1.0], a)
            }),
            |e| matches!(e, KinError::OutOfReach { .. }),
        ),
        words(
            "numerical_ik_target_out_of_reach",
            HarmonicIk::new(2.0, 1, 0.0)
                .unwrap()
                .solve([0.0, 3.0], &mut [0.0; 2])
                .unwrap_err(),
            |e| matches!(e, KinError::OutOfReach { .. }),
            &["out of reach", "r = 3", "l = 2"],
        ),
        row(
            "numerical_ik_guess_of_wrong_size",
            untouched([SENTINEL; 3], |a| {
                HarmonicIk::new(1.0, 2, FRAC_PI_2)
                    .unwrap()
                    .solve([0.3, 0.6], a)
            }),
            |e| {
                *e == KinError::Dimension {
                    name: "initial guess",
                    expected: 4,
                    found: 3,
                }
            },
        ),
        words(
            "numerical_ik_guess_of_wrong_size",
            straight.solve([0.5, 0.0], &mut [0.0; 3]).unwrap_err(),
            |e| matches!(e, KinError::Dimension { .. }),
            &["initial guess", "expected 4"],
        ),
        // From the straight guess the end point cannot move at all (to first order).
        words(
            "numerical_ik_from_a_stationary_guess",
            straight.solve([0.5, 0.0], &mut [0.0; 4]).unwrap_err(),
            |e| matches!(e, KinError::Stationary { iterations: 0, .. }),
            &[
                "cannot move from the guess",
                "end-point error",
                "another guess",
            ],
        ),
        words(
            "numerical_ik_not_converged",
            stingy
                .solve([-0.2, 0.3], &mut [0.1, 0.1, 0.0, 0.0])
                .unwrap_err(),
            |e| matches!(e, KinError::NotConverged { .. }),
            &["after 1 iterations"],
        ),
        words(
            "numerical_ik_tolerance_not_positive",
            HarmonicIk::new(1.0, 1, 0.0)
                .unwrap()
                .with_options(IkOptions {
                    tolerance: 0.0,
                    max_iterations: 5,
                })
                .unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
            &["IK tolerance"],
        ),
    ];
    // Every count beyond its limit, up to usize::MAX.
    for n in [MAX_LINKS + 1, 1_000_000_000, usize::MAX] {
        let error = ModalMap::uniform(n, 1, BaseAngle::Free).unwrap_err();
        assert_eq!(
            error,
            KinError::TooMany {
                what: "links",
                got: n,
                max: MAX_LINKS
            }
        );
        rows.push(row("huge_link_count", error, |e| {
            matches!(e, KinError::TooMany { what: "links", .. })
        }));
    }
    for k in [MAX_HARMONICS + 1, usize::MAX] {
        let error = HarmonicIk::new(1.0, k, 0.0).unwrap_err();
        assert_eq!(
            error,
            KinError::TooMany {
                what: "harmonics",
                got: k,
                max: MAX_HARMONICS
            }
        );
        rows.push(row("huge_harmonic_count", error, |e| {
            matches!(
                e,
                KinError::TooMany {
                    what: "harmonics",
                    ..
                }
            )
        }));
        rows.push(row(
            "huge_harmonic_count",
            ModalMap::uniform(10, k, BaseAngle::Free).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::TooMany {
                        what: "harmonics",
                        ..
                    }
                )
            },
        ));
    }
    // Every kind of bad length and tolerance.
    for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        rows.push(row(
            "non_positive_link_length",
            tip_position(&[0.1, bad], &[0.0; 2]).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonPositiveLength {
                        name: "link length",
                        ..
                    }
                )
            },
        ));
        rows.push(row(
            "non_positive_link_length",
            ModalMap::new(&[0.1, bad, 0.1], 1, BaseAngle::Free).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
        ));
    }
    for length in [0.0, -1.0, f64::NAN] {
        rows.push(row(
            "non_positive_curve_length",
            end_point(length, [0.1, 0.2], 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonPositiveLength {
                        name: "curve length",
                        ..
                    }
                )
            },
        ));
        rows.push(row(
            "non_positive_curve_length",
            BackboneCurve::paper(length, 0.1, 0.2, 0.0).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
        ));
        rows.push(row(
            "non_positive_curve_length",
            HarmonicIk::new(length, 1, 0.0).unwrap_err(),
            |e| matches!(e, KinError::NonPositiveLength { .. }),
        ));
    }
    let curve = BackboneCurve::paper(1.0, 0.3, 0.2, 0.0).unwrap();
    for s in [-0.1, 1.5, f64::NAN] {
        rows.push(row(
            "arc_length_outside_the_curve",
            curve.point(s).unwrap_err(),
            |e| matches!(e, KinError::ArcLength { .. } | KinError::NonFinite { .. }),
        ));
    }
    for tolerance in [0.0, -1e-9, f64::NAN, f64::INFINITY] {
        let options = IkOptions {
            tolerance,
            max_iterations: 10,
        };
        rows.push(row(
            "numerical_ik_tolerance_not_positive",
            HarmonicIk::new(1.0, 1, 0.0)
                .unwrap()
                .with_options(options)
                .unwrap_err(),
            |e| {
                matches!(
                    e,
                    KinError::NonPositiveLength {
                        name: "IK tolerance",
                        ..
                    } | KinError::NonFinite {
                        name: "IK tolerance",
                        ..
                    }
                )
            },
        ));
    }
    rows
}

#[test]
fn every_refusal_is_the_expected_error_and_says_what_failed() {
    let rows = rows();
    check(&rows);
    let seen: BTreeSet<_> = rows.iter().map(|row| variant(&row.error)).collect();
    assert_eq!(seen, ALL.into_iter().collect::<BTreeSet<_>>());
}

#[test]
fn every_error_is_in_exactly_one_class() {
    for Row { name, error, .. } in rows() {
        let unreachable = matches!(
            variant(&error),
            "OutOfReach" | "AtBase" | "A2ExceedsAmplitude"
        );
        let numerical = matches!(
            variant(&error),
            "NotConverged" | "Stationary" | "AnswerTooOscillatory"
        );
        assert_eq!(error.is_unreachable(), unreachable, "{name}: {error}");
        assert_eq!(error.is_numerical(), numerical, "{name}: {error}");
        assert_eq!(
            error.is_invalid_input(),
            !(unreachable || numerical),
            "{name}: {error}"
        );
    }
}

#[test]
fn failed_calls_leave_solvers_usable() {
    // A refused numerical IK leaves the solver reusable.
    let mut ik = HarmonicIk::new(1.0, 1, 0.3).unwrap();
    assert!(ik.solve([f64::NAN, 0.0], &mut [0.0; 2]).is_err());
    let target = end_point(1.0, [0.6, 0.2], 0.3).unwrap();
    let mut a = [0.5, 0.3];
    ik.solve(target, &mut a).unwrap();
    assert!((a[0] - 0.6).abs() < 1e-10 && (a[1] - 0.2).abs() < 1e-10);
    // So does one whose target is out of reach.
    let mut ik = HarmonicIk::new(1.0, 2, FRAC_PI_2).unwrap();
    let mut a = [0.1, 0.2, 0.3, 0.4];
    assert!(ik.solve([1.0, 1.0], &mut a).is_err());
    ik.solve([0.3, 0.6], &mut a).unwrap();
}

/// `numerical_ik_not_converged`: the guess holds the last iterate, and small numbers are printed
/// in exponent form, not as 17-digit decimals.
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
    let message = err.to_string();
    assert!(
        message.contains("e-1 after 0 iterations (tolerance 1e-14)"),
        "{message}"
    );
    assert!(message.contains("did not converge") && message.ends_with("from another guess it may"));
    assert!(a.iter().all(|x| x.is_finite()));
}

/// `numerical_ik_from_a_stationary_guess`: the straight arm, where the paper's modes move the
/// tip by nothing to first order, is named as the cause (it read "did not converge ... after 0
/// iterations").
#[test]
fn numerical_ik_from_a_stationary_guess() {
    let mut ik = HarmonicIk::new(0.3, 1, 0.7).unwrap();
    let mut a = [0.0, 0.0];
    let err = ik.solve([0.1, 0.1], &mut a).unwrap_err();
    assert!(
        matches!(err, KinError::Stationary { iterations: 0, residual } if residual > 0.1),
        "{err:?}"
    );
    assert_eq!(err.class(), ErrorClass::Numerical);
    let message = err.to_string();
    assert!(
        message.starts_with("numerical inverse kinematics cannot move from the guess: ")
            && message.ends_with("start from another guess"),
        "{message}"
    );
    // A guess off the straight arm solves it.
    let mut a = [0.01, 0.0];
    assert!(ik.solve([0.1, 0.1], &mut a).is_ok());
}

#[test]
#[should_panic(expected = "index out of bounds")]
fn modal_map_entry_out_of_range() {
    // An accessor, indexed like a slice: a column past the last panics instead of silently
    // reading the next row's first entry.
    let map = ModalMap::paper(10).unwrap();
    let _ = map.entry(0, map.n_coords());
}
