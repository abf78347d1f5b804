//! Inverse kinematics: the restricted inverse of `J0`, the closed form (eqs 5-6) as the exact
//! inverse of eqs 3-4 on both branches, and the numerical solver of the `K`-harmonic family,
//! which must reproduce the closed form for `K = 1`.

// Reference values are quoted to 20 digits, beyond f64, as computed.
#![allow(clippy::excessive_precision)]

use backbone_kin::{
    BackboneCurve, Branch, HarmonicIk, IkOptions, J0_FIRST_ZERO, KinError, end_point, inverse_j0,
    inverse_kinematics,
};
use proptest::prelude::*;
use std::f64::consts::PI;
use test_support::config::expensive;

#[test]
fn inverse_j0_reference_values() {
    // 20-digit references (mpmath findroot on besselj(0, A) - y).
    let references = [
        (0.999, 0.063_253_461_478_954_152),
        (0.9, 0.640_630_877_158_849_06),
        (0.75, 1.034_111_267_466_248_3),
        (0.5, 1.521_144_057_668_765_1),
        (0.25, 1.954_831_807_118_135_3),
        (0.1, 2.218_683_833_698_330_5),
        (1e-6, 2.404_823_631_461_697_2),
    ];
    for (y, a) in references {
        let got = inverse_j0(y).unwrap();
        assert!(
            (got - a).abs() <= 4e-16 * a.max(1.0),
            "J0^-1({y}) = {got}, expected {a}"
        );
    }
    assert!((J0_FIRST_ZERO - 2.404_825_557_695_772_8).abs() < 1e-16);
}

proptest! {
    #[test]
    fn inverse_j0_round_trip(amplitude in 0.0f64..=J0_FIRST_ZERO) {
        let y = libm::j0(amplitude);
        let back = inverse_j0(y).unwrap();
        prop_assert!((0.0..=J0_FIRST_ZERO).contains(&back));
        prop_assert!((libm::j0(back) - y).abs() <= 4e-16, "J0({back}) = {} vs {y}", libm::j0(back));
        // The amplitude is as accurate as the conditioning dA = dy / J1(A) allows.
        prop_assert!((back - amplitude).abs() * libm::j1(amplitude) <= 1e-15, "{back} vs {amplitude}");
    }

    #[test]
    fn inverse_j0_is_decreasing_and_exact_in_value(y in 0.0f64..=1.0, dy in 0.0f64..0.1) {
        let a = inverse_j0(y).unwrap();
        prop_assert!((libm::j0(a) - y).abs() <= 4e-16);
        let lower = (y - dy).max(0.0);
        prop_assert!(inverse_j0(lower).unwrap() >= a);
    }

    /// IK after FK recovers the modal coordinates on both branches, over the reachable set
    /// `|a2| <= A <= 2.3`, and FK after IK hits the target.
    #[test]
    fn closed_form_round_trip(
        length in 0.1f64..10.0,
        amplitude in 1e-3f64..2.3,
        psi in -PI..PI,
        alpha0 in -10.0f64..10.0,
    ) {
        let a = [amplitude * psi.cos(), amplitude * psi.sin()];
        let branch = if a[0] >= 0.0 { Branch::Positive } else { Branch::Negative };
        let target = end_point(length, a, alpha0).unwrap();
        let back = inverse_kinematics(length, target, alpha0, branch).unwrap();
        let tip = end_point(length, back, alpha0).unwrap();
        prop_assert!((tip[0] - target[0]).abs() <= 1e-13 * length && (tip[1] - target[1]).abs() <= 1e-13 * length);
        prop_assert!((back[1] - a[1]).abs() <= 1e-12, "a2 {} vs {}", back[1], a[1]);
        // An error dA = dy / J1(A) (dy ~ 1e-15 from rounding r / l and J0) moves
        // a1 = ±sqrt(A^2 - a2^2) by A dA / |a1|, at most sqrt(2 A dA).
        let d_amplitude = 1e-15 / libm::j1(amplitude);
        let slack = 2.0 * (amplitude * d_amplitude / a[0].abs()).min((2.0 * amplitude * d_amplitude).sqrt()) + 1e-12;
        prop_assert!((back[0] - a[0]).abs() <= slack, "a1 {} vs {}", back[0], a[0]);
        // The other branch is the mirror image: same a2, opposite a1, same end point.
        let other = match branch { Branch::Positive => Branch::Negative, Branch::Negative => Branch::Positive };
        let mirror = inverse_kinematics(length, target, alpha0, other).unwrap();
        prop_assert_eq!(mirror, [-back[0], back[1]]);
    }

    /// The numerical solver with `K = 1` converges from a nearby guess to the closed form.
    #[test]
    fn numeric_ik_reduces_to_closed_form(
        amplitude in 0.2f64..2.2,
        psi in -1.4f64..1.4,
        negative in any::<bool>(),
        alpha0 in -PI..PI,
        nudge in prop::array::uniform2(-0.02f64..0.02),
    ) {
        // |a1| >= A cos(1.4) keeps the branches apart (they meet at a1 = 0).
        let sign = if negative { -1.0 } else { 1.0 };
        let a = [sign * amplitude * psi.cos(), amplitude * psi.sin()];
        let target = end_point(1.0, a, alpha0).unwrap();
        let branch = if a[0] >= 0.0 { Branch::Positive } else { Branch::Negative };
        let closed = inverse_kinematics(1.0, target, alpha0, branch).unwrap();
        let mut ik = HarmonicIk::new(1.0, 1, alpha0).unwrap();
        let mut guess = [a[0] + nudge[0], a[1] + nudge[1]];
        let report = ik.solve(target, &mut guess).unwrap();
        prop_assert!(report.residual <= 1e-14);
        prop_assert!((guess[0] - closed[0]).abs() <= 1e-10 && (guess[1] - closed[1]).abs() <= 1e-10,
            "numeric {guess:?} vs closed {closed:?}");
    }
}

proptest! {
    #![proptest_config(expensive())]

    /// `K = 2, 3`: from a guess near a known solution the solver lands on the target, checked
    /// by an independent evaluation of the curve's end point.
    #[test]
    fn numeric_ik_reaches_targets_of_the_harmonic_family(
        harmonics in 2usize..=3,
        truth in prop::collection::vec(-0.8f64..0.8, 6),
        nudge in prop::collection::vec(-0.2f64..0.2, 6),
        alpha0 in -PI..PI,
        length in 0.5f64..3.0,
    ) {
        let m = 2 * harmonics;
        let target = BackboneCurve::new(length, &truth[..m], alpha0).unwrap().end_point();
        let mut a: Vec<f64> = truth[..m].iter().zip(&nudge).map(|(t, n)| t + n).collect();
        let mut ik = HarmonicIk::new(length, harmonics, alpha0).unwrap();
        let report = ik.solve(target, &mut a).unwrap();
        prop_assert!(report.residual <= 1e-14 * length);
        let tip = BackboneCurve::new(length, &a, alpha0).unwrap().point(length).unwrap();
        prop_assert!((tip[0] - target[0]).abs() <= 1e-13 * length && (tip[1] - target[1]).abs() <= 1e-13 * length);
    }
}

#[test]
fn closed_form_seed_solves_the_harmonic_problem_at_once() {
    // The two-mode solution, padded with zero higher harmonics, already solves the K = 3 problem.
    let (alpha0, target) = (PI / 2.0, [0.3, 0.5]);
    let a = inverse_kinematics(1.0, target, alpha0, Branch::Positive).unwrap();
    let mut ik = HarmonicIk::new(1.0, 3, alpha0).unwrap();
    let mut guess = [a[0], a[1], 0.0, 0.0, 0.0, 0.0];
    let report = ik.solve(target, &mut guess).unwrap();
    assert!(report.iterations <= 1, "{report:?}");
    assert!((guess[0] - a[0]).abs() < 1e-12 && (guess[1] - a[1]).abs() < 1e-12);
}

#[test]
fn numeric_ik_reaches_targets_the_two_mode_curve_cannot() {
    // With alpha0 = 0 a target straight up needs |a2| = pi/2 > A: unreachable for K = 1 ...
    let target = [0.0, 0.5];
    let err = inverse_kinematics(1.0, target, 0.0, Branch::Positive).unwrap_err();
    assert!(matches!(err, KinError::A2ExceedsAmplitude { .. }), "{err}");
    // ... but two harmonics reach it.
    let mut ik = HarmonicIk::new(1.0, 2, 0.0).unwrap();
    let mut a = [0.5, 1.0, 0.3, 0.3];
    ik.solve(target, &mut a).unwrap();
    let tip = BackboneCurve::new(1.0, &a, 0.0)
        .unwrap()
        .point(1.0)
        .unwrap();
    assert!(
        (tip[0] - target[0]).abs() < 1e-13 && (tip[1] - target[1]).abs() < 1e-13,
        "{tip:?}"
    );
}

#[test]
fn closed_form_edges_of_the_reachable_set() {
    // a1 = 0 (|a2| = A) and the straight curve (A = 0) invert without error.
    for a in [[0.0, 0.8], [0.0, -2.3], [0.0, 0.0], [0.0, 1e-9]] {
        let target = end_point(1.0, a, 0.4).unwrap();
        let back = inverse_kinematics(1.0, target, 0.4, Branch::Positive).unwrap();
        assert!(
            back[0].abs() < 1e-7 && (back[1] - a[1]).abs() < 1e-12,
            "{a:?} -> {back:?}"
        );
    }
    // Reaching the base's neighbourhood: r / l = J0(2.4) ~ 2e-3, a2 = 0.
    let target = end_point(1.0, [2.4, 0.0], 0.0).unwrap();
    let back = inverse_kinematics(1.0, target, 0.0, Branch::Positive).unwrap();
    assert!(
        (back[0] - 2.4).abs() < 1e-12 && back[1].abs() < 1e-15,
        "{back:?}"
    );
    // alpha0 is an angle: a full turn changes nothing.
    let target = [0.2, -0.4];
    let once = inverse_kinematics(1.0, target, -1.0, Branch::Negative).unwrap();
    let turned = inverse_kinematics(1.0, target, -1.0 + 4.0 * PI, Branch::Negative).unwrap();
    assert!((once[0] - turned[0]).abs() < 1e-12 && (once[1] - turned[1]).abs() < 1e-12);
}

#[test]
fn numeric_ik_options() {
    let ik = HarmonicIk::new(1.0, 2, 0.0).unwrap();
    assert_eq!(ik.options(), IkOptions::default());
    assert_eq!(ik.harmonics(), 2);
    let loose = IkOptions {
        tolerance: 1e-6,
        max_iterations: 5,
    };
    let mut ik = ik.with_options(loose).unwrap();
    let mut a = [0.3, 0.3, 0.0, 0.0];
    let report = ik.solve([0.5, 0.5], &mut a).unwrap();
    assert!(report.iterations <= 5 && report.residual <= 1e-6);
}

/// The convergence rates quoted in the `harmonic_ik` module docs, on a fixed pseudo-random sample
/// (a 64-bit LCG, so the sample is the same on every machine).
#[test]
fn numeric_ik_convergence_rates() {
    let mut state = 12345u64;
    let mut uniform = |half_width: f64| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * half_width
    };
    for (spread, required) in [(0.5, 399), (1.0, 388), (2.0, 388)] {
        for harmonics in 1..=3 {
            let mut converged = 0;
            for _ in 0..400 {
                let alpha0 = uniform(0.5);
                let truth: Vec<f64> = (0..2 * harmonics).map(|_| uniform(spread)).collect();
                let target = BackboneCurve::new(1.0, &truth, alpha0).unwrap().end_point();
                let mut a: Vec<f64> = (0..2 * harmonics).map(|_| uniform(0.5)).collect();
                let mut ik = HarmonicIk::new(1.0, harmonics, alpha0).unwrap();
                if ik.solve(target, &mut a).is_ok() {
                    converged += 1;
                }
            }
            assert!(
                converged >= required,
                "spread {spread}, K = {harmonics}: {converged}/400"
            );
        }
    }
}

#[test]
fn targets_beyond_the_first_branch_are_named_as_such_and_solvable_from_a_guess() {
    // a = [3.127, 0] is past the first zero of J0: the end point lies behind the base.
    let (alpha0, a) = (PI / 2.0, [3.127, 0.0]);
    let target = end_point(1.0, a, alpha0).unwrap();
    assert!(
        target[0].abs() < 1e-15 && (target[1] + 0.3).abs() < 1e-3,
        "{target:?}"
    );
    // The closed form searches the first branch only, and says so.
    let err = inverse_kinematics(1.0, target, alpha0, Branch::Positive).unwrap_err();
    assert!(matches!(err, KinError::A2ExceedsAmplitude { .. }), "{err}");
    assert!(err.to_string().contains("first branch of J0"), "{err}");
    // A guess on the second branch reaches it numerically.
    let mut ik = HarmonicIk::new(1.0, 1, alpha0).unwrap();
    let mut guess = [3.0, 0.2];
    ik.solve(target, &mut guess).unwrap();
    let reached = end_point(1.0, guess, alpha0).unwrap();
    assert!((reached[0] - target[0]).abs() < 1e-13 && (reached[1] - target[1]).abs() < 1e-13);
    assert!(guess[0].hypot(guess[1]) > J0_FIRST_ZERO);
}

/// `solve_unguided` reaches every end point of the `K = 2, 3` families with coordinates in
/// `[-0.5, 0.5]^{2K}`, including those the `K = 1` closed form cannot start from (`|a2| > A`,
/// 32 of the 200 `K = 2` targets here), and keeps the closed form's start where it works.
#[test]
fn unguided_ik_reaches_what_the_family_reaches() {
    let mut state = 2024u64;
    let mut uniform = |half_width: f64| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * half_width
    };
    for harmonics in [2, 3] {
        let mut beyond_closed_form = 0;
        for _ in 0..200 {
            let alpha0 = uniform(0.5);
            let truth: Vec<f64> = (0..2 * harmonics).map(|_| uniform(0.5)).collect();
            let target = BackboneCurve::new(1.0, &truth, alpha0).unwrap().end_point();
            let mut ik = HarmonicIk::new(1.0, harmonics, alpha0).unwrap();
            let mut a = vec![0.0; 2 * harmonics];
            let report = ik.solve_unguided(target, Branch::Positive, &mut a).unwrap();
            let reached = BackboneCurve::new(1.0, &a, alpha0).unwrap().end_point();
            assert!(
                (reached[0] - target[0]).hypot(reached[1] - target[1]) <= 1e-14,
                "K = {harmonics}, {truth:?}: {report:?}"
            );
            match inverse_kinematics(1.0, target, alpha0, Branch::Positive) {
                Ok(closed) => {
                    let mut from_closed = vec![0.0; 2 * harmonics];
                    from_closed[..2].copy_from_slice(&closed);
                    if ik.solve(target, &mut from_closed).is_ok() {
                        assert_eq!(a, from_closed);
                    }
                }
                Err(_) => beyond_closed_form += 1,
            }
        }
        assert!(
            beyond_closed_form > 0,
            "K = {harmonics}: no target beyond the closed form"
        );
    }
}
