//! The chain's own inverse kinematics (`ChainIk`): the discrete chain's tip, computed
//! independently through the modal map and the chain's forward kinematics, lands on the target
//! for any link lengths; and the curve-versus-chain error it removes obeys the derived bound.

use backbone_kin::{
    BackboneCurve, BaseAngle, BasePose, Branch, ChainIk, HarmonicIk, IkOptions, KinError, ModalMap,
    SpatialIk, SpatialModalMap, chain_inverse_kinematics, end_point, inverse_kinematics,
    tip_position,
};
use lane_math::Classify;
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// The chain's tip for modal coordinates `a`, by eq 8 and the chain's forward kinematics.
fn chain_tip(lengths: &[f64], a: &[f64], alpha0: f64) -> [f64; 2] {
    let map = ModalMap::new(lengths, a.len() / 2, BaseAngle::Fixed(alpha0)).unwrap();
    let mut theta = vec![0.0; lengths.len()];
    map.joint_angles(a, &mut theta).unwrap();
    tip_position(lengths, &theta).unwrap()
}

fn distance(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// 20 links tapering linearly from 0.075 m to 0.025 m: total length 1 m.
fn tapered() -> Vec<f64> {
    (0..20)
        .map(|i| 0.075 - 0.05 * f64::from(i) / 19.0)
        .collect()
}

/// `(pi^2 / 6) A (1 + A) sum L_i^3 / l^2`: the midpoint-rule bound of the module docs.
fn midpoint_bound(lengths: &[f64], amplitude: f64) -> f64 {
    let l: f64 = lengths.iter().sum();
    PI * PI / 6.0 * amplitude * (1.0 + amplitude) * lengths.iter().map(|x| x.powi(3)).sum::<f64>()
        / (l * l)
}

#[test]
fn unequal_links_curve_versus_chain() {
    let lengths = tapered();
    assert!((lengths.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    let (alpha0, amplitude, psi) = (FRAC_PI_2, 1.9, 0.3f64);
    let a = [amplitude * psi.cos(), amplitude * psi.sin()];
    let target = end_point(1.0, a, alpha0).unwrap();
    // The closed form inverts the curve exactly ...
    let closed = inverse_kinematics(1.0, target, alpha0, Branch::Positive).unwrap();
    assert!((closed[0] - a[0]).abs() < 1e-12 && (closed[1] - a[1]).abs() < 1e-12);
    // ... but the tapered chain on that curve misses the target by 2.6 mm, within the bound.
    let miss = distance(chain_tip(&lengths, &closed, alpha0), target);
    assert!((2.5e-3..2.7e-3).contains(&miss), "miss {miss}");
    assert!(miss <= midpoint_bound(&lengths, amplitude));
    // Ten equal links on the same curve: the aliasing error, 3.0e-7 m <= 2 l |J_10(A)|.
    let equal = distance(chain_tip(&[0.1; 10], &closed, alpha0), target);
    assert!(equal <= 2.0 * libm::jn(10, amplitude).abs(), "{equal}");
    assert!(equal > 2.9e-7, "{equal}");
    // The chain's inverse puts the chain on the target.
    let polished = chain_inverse_kinematics(&lengths, target, alpha0, Branch::Positive).unwrap();
    let reached = distance(chain_tip(&lengths, &polished, alpha0), target);
    assert!(reached < 1e-14, "{reached}");
    assert!(polished[0] > 0.0);
}

#[test]
fn chain_ik_needs_few_newton_steps_and_reports_them() {
    let lengths = tapered();
    let mut ik = ChainIk::new(&lengths, 1, FRAC_PI_2).unwrap();
    let mut a = [0.0; 2];
    let report = ik
        .solve_from_closed_form([0.3, 0.5], Branch::Negative, &mut a)
        .unwrap();
    assert!(a[0] <= 0.0);
    assert!((1..=5).contains(&report.iterations), "{report:?}");
    assert!(report.residual <= ik.options().tolerance);
    assert!(distance(chain_tip(&lengths, &a, FRAC_PI_2), [0.3, 0.5]) <= 1e-14);
}

#[test]
fn a_target_at_the_nominal_length_is_reached_whatever_the_method() {
    // Ten links of 0.1 m sum to 0.9999999999999999: a target at the nominal 1 m is within the
    // rounding of that sum, and every solver reaches it as the closed form does (the numerical
    // ones refused it as out of reach, so the answer depended on K).
    let lengths = [0.1; 10];
    let length: f64 = lengths.iter().sum();
    assert!(length < 1.0);
    let target = [0.0, 1.0];
    assert!(inverse_kinematics(length, target, FRAC_PI_2, Branch::Positive).is_ok());
    for k in 1..=3 {
        let mut a = vec![0.0; 2 * k];
        let report = HarmonicIk::new(length, k, FRAC_PI_2)
            .unwrap()
            .solve(target, &mut a)
            .unwrap();
        assert!(report.residual <= 1e-15, "K = {k}: {report:?}");
        let mut a = vec![0.0; 2 * k];
        let mut chain = ChainIk::new(&lengths, k, FRAC_PI_2).unwrap();
        chain.solve(target, &mut a).unwrap();
        assert!(distance(chain_tip(&lengths, &a, FRAC_PI_2), target) <= 1e-15);
    }
    let map = SpatialModalMap::new(&lengths, 1).unwrap();
    let mut spatial = SpatialIk::new(map, BasePose::default()).unwrap();
    spatial.solve([1.0, 0.0, 0.0], &mut [0.0; 4]).unwrap();
    // Past the rounding: out of reach.
    let beyond = HarmonicIk::new(length, 2, FRAC_PI_2)
        .unwrap()
        .solve([0.0, 1.0 + 1e-15], &mut [0.0; 4]);
    assert!(
        matches!(beyond, Err(KinError::OutOfReach { .. })),
        "{beyond:?}"
    );
}

#[test]
fn chain_ik_refusals() {
    let lengths = tapered();
    let mut ik = ChainIk::new(&lengths, 1, 0.0).unwrap();
    let mut a = [0.0; 2];
    assert!(matches!(
        ik.solve([1.5, 0.0], &mut a),
        Err(KinError::OutOfReach { .. })
    ));
    assert!(matches!(
        ik.solve([f64::NAN, 0.0], &mut a),
        Err(KinError::NonFinite { .. })
    ));
    assert!(matches!(
        ik.solve_from_closed_form([0.5, 0.0], Branch::Positive, &mut [0.0; 3]),
        Err(KinError::Dimension { .. })
    ));
    // Behind the base on the base direction: not on the first branch of the closed form.
    let err = ik
        .solve_from_closed_form([-0.3, 0.0], Branch::Positive, &mut a)
        .unwrap_err();
    assert!(matches!(err, KinError::A2ExceedsAmplitude { .. }), "{err}");
    assert!(ChainIk::new(&[], 1, 0.0).is_err());
    assert!(ChainIk::new(&[0.1, -0.1], 1, 0.0).is_err());
    assert!(ChainIk::new(&[0.1], 0, 0.0).is_err());
    assert!(ChainIk::new(&[0.1], 1, f64::INFINITY).is_err());
    let options = IkOptions {
        tolerance: 0.0,
        max_iterations: 5,
    };
    assert!(ik.clone().with_options(options).is_err());
}

fn arm() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.2f64..1.0, 3..40)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The curve-versus-chain error of the closed form obeys the derived midpoint bound, and the
    /// chain's inverse removes it, on random arms with unequal links.
    #[test]
    fn chain_ik_lands_the_chain_on_targets_of_the_curve(
        lengths in arm(),
        amplitude in 0.05f64..2.3,
        psi in -PI..PI,
        alpha0 in -PI..PI,
        scale in 0.1f64..10.0,
    ) {
        let lengths: Vec<f64> = lengths.iter().map(|x| x * scale).collect();
        let l: f64 = lengths.iter().sum();
        let a = [amplitude * psi.cos(), amplitude * psi.sin()];
        let target = end_point(l, a, alpha0).unwrap();
        let closed = inverse_kinematics(l, target, alpha0, Branch::Positive).unwrap();
        let miss = distance(chain_tip(&lengths, &closed, alpha0), target);
        prop_assert!(miss <= midpoint_bound(&lengths, amplitude) + 1e-14 * l, "miss {miss}");
        match chain_inverse_kinematics(&lengths, target, alpha0, Branch::Positive) {
            Ok(polished) => {
                let reached = distance(chain_tip(&lengths, &polished, alpha0), target);
                prop_assert!(reached <= 1e-12 * l, "reached {reached}");
            }
            // Only where the chain's own reach ends: a target the curve reaches at a pose
            // where the chain cannot follow (near full stretch or near the |a2| = A edge).
            Err(KinError::NotConverged { residual, .. }) => {
                prop_assert!(residual <= miss + 1e-12 * l, "{residual} vs {miss}");
            }
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    /// Targets of the chain itself are always reached, for two harmonics too.
    #[test]
    fn chain_ik_reaches_targets_of_the_chain(
        lengths in arm(),
        a in prop::array::uniform4(-0.6f64..0.6),
        alpha0 in -PI..PI,
    ) {
        let l: f64 = lengths.iter().sum();
        for harmonics in [1, 2] {
            let modes = &a[..2 * harmonics];
            let target = chain_tip(&lengths, modes, alpha0);
            let mut ik = ChainIk::new(&lengths, harmonics, alpha0).unwrap();
            let mut solution = vec![0.0; 2 * harmonics];
            let branch = if modes[0] >= 0.0 { Branch::Positive } else { Branch::Negative };
            match ik.solve_from_closed_form(target, branch, &mut solution) {
                Ok(report) => {
                    let reached = distance(chain_tip(&lengths, &solution, alpha0), target);
                    prop_assert!(reached <= 1e-12 * l, "K = {harmonics}: {reached}");
                    prop_assert!(report.residual <= ik.options().tolerance * l);
                }
                // The closed-form start needs the curve to reach the target on its first branch.
                Err(e) => prop_assert!(e.is_unreachable(), "K = {harmonics}: {e}"),
            }
        }
    }
}

#[test]
fn equal_links_agree_with_the_closed_form_to_the_aliasing_error() {
    // The paper's arm: the chain tip and the curve's end point differ by less than
    // 2 l |J_10(A)|, and so do the two inverses (J of order 1 in a).
    let lengths = [0.1; 10];
    for target in [[0.3, 0.5], [0.1, 0.9], [-0.4, 0.2]] {
        let closed = inverse_kinematics(1.0, target, FRAC_PI_2, Branch::Positive).unwrap();
        let polished =
            chain_inverse_kinematics(&lengths, target, FRAC_PI_2, Branch::Positive).unwrap();
        let amplitude = closed[0].hypot(closed[1]);
        let aliasing = 2.0 * libm::jn(10, amplitude).abs();
        let curve = BackboneCurve::paper(1.0, polished[0], polished[1], FRAC_PI_2).unwrap();
        assert!(distance(curve.end_point(), target) <= aliasing + 1e-15);
        assert!(distance(chain_tip(&lengths, &polished, FRAC_PI_2), target) < 1e-15);
    }
}

#[test]
fn chain_ik_is_the_same_at_every_scale() {
    // The problem is dimensionless: links of 1e80 m or 1e-90 m give the coordinates of links
    // of 0.1 m (the Gram matrix's determinant, the fourth power of the scale, is taken on a
    // Jacobian scaled near 1).
    let solve = |scale: f64| {
        let lengths: Vec<f64> = tapered().iter().map(|l| l * scale).collect();
        let target = [0.3 * scale, 0.5 * scale];
        let mut a = [0.0; 4];
        ChainIk::new(&lengths, 2, 0.7)
            .unwrap()
            .solve_from_closed_form(target, Branch::Positive, &mut a)
            .unwrap();
        let reached = distance(chain_tip(&lengths, &a, 0.7), target);
        assert!(reached <= 1e-14 * scale, "scale {scale:e}: {reached:e}");
        a
    };
    let unit = solve(1.0);
    for scale in [1e80, 1e-90, 1e300, 1e-300] {
        let a = solve(scale);
        for (x, y) in a.iter().zip(unit) {
            assert!(
                (x - y).abs() < 1e-9,
                "scale {scale:e}: {a:?} against {unit:?}"
            );
        }
    }
}
