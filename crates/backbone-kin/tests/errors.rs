//! Every error path: each `KinError` variant is reachable through the public API, and its
//! message names the condition that failed.

use backbone_kin::{
    BackboneCurve, BaseAngle, Branch, HarmonicIk, IkOptions, KinError, ModalMap, end_point,
    inverse_j0, inverse_kinematics, joint_positions, tip_position,
};
use std::collections::BTreeSet;

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
        KinError::TooMany { .. } => "TooMany",
        other => panic!("a variant this test does not cover: {other:?}"),
    }
}

const ALL: [&str; 14] = [
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
    "TooMany",
];

/// Each case: the error, the variant expected, and words its message must contain.
fn cases() -> Vec<(KinError, &'static str, Vec<&'static str>)> {
    let curve = BackboneCurve::paper(1.0, 0.5, 0.5, 0.0).unwrap();
    let mut straight = HarmonicIk::new(1.0, 2, 0.0).unwrap();
    let mut stingy = HarmonicIk::new(1.0, 2, 0.0)
        .unwrap()
        .with_options(IkOptions {
            tolerance: 1e-14,
            max_iterations: 1,
        })
        .unwrap();
    vec![
        (
            HarmonicIk::new(1.0, usize::MAX, 0.0).unwrap_err(),
            "TooMany",
            vec!["at most", "harmonics"],
        ),
        (
            end_point(1.0, [f64::NAN, 0.0], 0.0).unwrap_err(),
            "NonFinite",
            vec!["a1", "finite", "NaN"],
        ),
        (
            inverse_kinematics(1.0, [0.5, f64::INFINITY], 0.0, Branch::Positive).unwrap_err(),
            "NonFinite",
            vec!["target y", "finite"],
        ),
        (
            inverse_kinematics(1.0, [0.5, 0.0], f64::NAN, Branch::Positive).unwrap_err(),
            "NonFinite",
            vec!["alpha0", "finite"],
        ),
        (
            inverse_j0(f64::NAN).unwrap_err(),
            "NonFinite",
            vec!["J0 value", "finite"],
        ),
        (
            curve.point(f64::NAN).unwrap_err(),
            "NonFinite",
            vec!["arc length", "finite"],
        ),
        (
            end_point(0.0, [0.0, 0.0], 0.0).unwrap_err(),
            "NonPositiveLength",
            vec!["curve length", "positive", "0"],
        ),
        (
            BackboneCurve::paper(-1.0, 0.0, 0.0, 0.0).unwrap_err(),
            "NonPositiveLength",
            vec!["curve length", "-1"],
        ),
        (
            tip_position(&[0.1, -0.1], &[0.0, 0.0]).unwrap_err(),
            "NonPositiveLength",
            vec!["link length", "-0.1"],
        ),
        (
            ModalMap::new(&[0.1, f64::INFINITY], 1, BaseAngle::Free).unwrap_err(),
            "NonPositiveLength",
            vec!["link length", "inf"],
        ),
        (
            HarmonicIk::new(1.0, 1, 0.0)
                .unwrap()
                .with_options(IkOptions {
                    tolerance: 0.0,
                    max_iterations: 5,
                })
                .unwrap_err(),
            "NonPositiveLength",
            vec!["IK tolerance"],
        ),
        (
            tip_position(&[], &[]).unwrap_err(),
            "NoLinks",
            vec!["at least one link"],
        ),
        (
            joint_positions(&[], &[], &mut []).unwrap_err(),
            "NoLinks",
            vec!["at least one link"],
        ),
        (
            ModalMap::uniform(0, 1, BaseAngle::Free).unwrap_err(),
            "NoLinks",
            vec!["at least one link"],
        ),
        (
            BackboneCurve::new(1.0, &[], 0.0).unwrap_err(),
            "NoHarmonics",
            vec!["at least one harmonic"],
        ),
        (
            HarmonicIk::new(1.0, 0, 0.0).unwrap_err(),
            "NoHarmonics",
            vec!["at least one harmonic"],
        ),
        (
            ModalMap::paper(3)
                .unwrap()
                .joint_angles(&[0.0; 2], &mut [0.0; 3])
                .unwrap_err(),
            "Dimension",
            vec!["modal coordinates", "2 entries", "expected 3"],
        ),
        (
            joint_positions(&[0.1; 3], &[0.0; 3], &mut [[0.0; 2]; 3]).unwrap_err(),
            "Dimension",
            vec!["joint positions", "3 entries", "expected 4"],
        ),
        (
            tip_position(&[0.1; 3], &[0.0; 2]).unwrap_err(),
            "Dimension",
            vec!["joint angles", "expected 3"],
        ),
        (
            curve.end_point_jacobian(&mut [0.0; 3]).unwrap_err(),
            "Dimension",
            vec!["end-point jacobian", "expected 4"],
        ),
        (
            straight.solve([0.5, 0.0], &mut [0.0; 3]).unwrap_err(),
            "Dimension",
            vec!["initial guess", "expected 4"],
        ),
        (
            BackboneCurve::new(1.0, &[0.1, 0.2, 0.3], 0.0).unwrap_err(),
            "UnpairedModes",
            vec!["pairs", "odd", "3"],
        ),
        (
            curve.point(1.5).unwrap_err(),
            "ArcLength",
            vec!["s = 1.5", "outside the curve", "[0, 1]"],
        ),
        (
            curve.inclination(-0.1).unwrap_err(),
            "ArcLength",
            vec!["s = -0.1", "outside"],
        ),
        (
            curve.curvature(2.0).unwrap_err(),
            "ArcLength",
            vec!["outside"],
        ),
        (
            BackboneCurve::paper(1.0, 1e6, 0.0, 0.0).unwrap_err(),
            "TooOscillatory",
            vec!["oscillates too fast", "nodes needed"],
        ),
        (
            inverse_j0(1.5).unwrap_err(),
            "J0Domain",
            vec!["inverse of J0", "[0, 1]", "1.5"],
        ),
        (
            inverse_j0(-0.25).unwrap_err(),
            "J0Domain",
            vec!["[0, 1]", "-0.25"],
        ),
        (
            inverse_kinematics(1.0, [1.5, 0.0], 0.0, Branch::Positive).unwrap_err(),
            "OutOfReach",
            vec!["out of reach", "r = 1.5", "l = 1"],
        ),
        (
            HarmonicIk::new(2.0, 1, 0.0)
                .unwrap()
                .solve([0.0, 3.0], &mut [0.0; 2])
                .unwrap_err(),
            "OutOfReach",
            vec!["out of reach", "r = 3", "l = 2"],
        ),
        (
            inverse_kinematics(1.0, [0.0, 0.0], 0.0, Branch::Positive).unwrap_err(),
            "AtBase",
            vec!["at the base", "a2"],
        ),
        (
            inverse_kinematics(1.0, [0.0, 0.5], 0.0, Branch::Negative).unwrap_err(),
            "A2ExceedsAmplitude",
            vec!["alpha0 = 0", "|a2| = 1.57", "A = 1.52", "|a2| <= A"],
        ),
        // From the straight guess the end point cannot move along the base direction.
        (
            straight.solve([0.5, 0.0], &mut [0.0; 4]).unwrap_err(),
            "NotConverged",
            vec!["did not converge", "end-point error"],
        ),
        (
            stingy
                .solve([-0.2, 0.3], &mut [0.1, 0.1, 0.0, 0.0])
                .unwrap_err(),
            "NotConverged",
            vec!["after 1 iterations"],
        ),
    ]
}

#[test]
fn every_variant_is_reachable_and_says_what_failed() {
    let mut seen = BTreeSet::new();
    for (error, expected, words) in cases() {
        assert_eq!(variant(&error), expected, "{error:?}");
        let message = error.to_string();
        for word in words {
            assert!(
                message.contains(word),
                "{expected}: {message:?} lacks {word:?}"
            );
        }
        seen.insert(variant(&error));
    }
    assert_eq!(seen, ALL.into_iter().collect::<BTreeSet<_>>());
}

#[test]
fn every_error_is_in_exactly_one_class() {
    for (error, _, _) in cases() {
        let unreachable = matches!(
            variant(&error),
            "OutOfReach" | "AtBase" | "A2ExceedsAmplitude"
        );
        let numerical = variant(&error) == "NotConverged";
        assert_eq!(error.is_unreachable(), unreachable, "{error}");
        assert_eq!(error.is_numerical(), numerical, "{error}");
        assert_eq!(
            error.is_invalid_input(),
            !(unreachable || numerical),
            "{error}"
        );
    }
}

#[test]
fn failed_calls_leave_outputs_and_state_usable() {
    // A refused numeric IK leaves the solver reusable.
    let mut ik = HarmonicIk::new(1.0, 1, 0.3).unwrap();
    assert!(ik.solve([f64::NAN, 0.0], &mut [0.0; 2]).is_err());
    let target = end_point(1.0, [0.6, 0.2], 0.3).unwrap();
    let mut a = [0.5, 0.3];
    ik.solve(target, &mut a).unwrap();
    assert!((a[0] - 0.6).abs() < 1e-10 && (a[1] - 0.2).abs() < 1e-10);
}
