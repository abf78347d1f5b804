//! References against independent checks: the forward kinematics of the modal reference lands
//! on the path, and the exact rates and accelerations match finite differences.

use backbone_kin::{Branch, end_point};
use proptest::prelude::*;
use sim_core::SimError;
use sim_core::reference::{CartesianPath, PathShape, Reference, Sinusoid, Step};
use std::f64::consts::FRAC_PI_2;

fn paper_path(branch: Branch) -> CartesianPath {
    let shape = PathShape::Sine {
        amplitude: 0.4,
        wavenumber: 5.0,
        phase: 0.0,
        offset: 0.2,
        x_start: 0.08,
        x_end: 0.4,
    };
    CartesianPath::new(shape, 5.0, 1.0, FRAC_PI_2, branch).unwrap()
}

/// Central differences of `a` and `a_dot` of `reference` at `t`.
fn finite_differences(reference: &dyn Reference, t: f64, h: f64) -> ([f64; 2], [f64; 2]) {
    let (before, after) = (
        reference.sample(t - h).unwrap(),
        reference.sample(t + h).unwrap(),
    );
    let rate = |i: usize| (after.a[i] - before.a[i]) / (2.0 * h);
    let accel = |i: usize| (after.a_dot[i] - before.a_dot[i]) / (2.0 * h);
    ([rate(0), rate(1)], [accel(0), accel(1)])
}

#[test]
fn step_switches_at_its_time_and_has_no_rates() {
    let step = Step::new([0.1, 0.2], [-0.3, 0.4], 1.5).unwrap();
    assert_eq!(step.sample(1.4999).unwrap().a, [0.1, 0.2]);
    let after = step.sample(1.5).unwrap();
    assert_eq!(after.a, [-0.3, 0.4]);
    assert_eq!((after.a_dot, after.a_ddot), ([0.0; 2], [0.0; 2]));
    assert_eq!(
        Step::constant([0.5, 0.6]).unwrap().sample(0.0).unwrap().a,
        [0.5, 0.6]
    );
    assert!(matches!(
        Step::new([0.0; 2], [f64::NAN, 0.0], 1.0),
        Err(SimError::InvalidSetting { .. })
    ));
    assert!(Step::new([0.0; 2], [0.0; 2], -1.0).is_err());
}

proptest! {
    #[test]
    fn sinusoid_rates_match_finite_differences(
        offset in prop::array::uniform2(-1.0f64..1.0),
        amplitude in prop::array::uniform2(-0.5f64..0.5),
        frequency in prop::array::uniform2(0.0f64..3.0),
        phase in prop::array::uniform2(-3.0f64..3.0),
        t in 0.0f64..10.0,
    ) {
        let sine = Sinusoid::new(offset, amplitude, frequency, phase).unwrap();
        let s = sine.sample(t).unwrap();
        let (rate, accel) = finite_differences(&sine, t, 1e-5);
        for i in 0..2 {
            let w = std::f64::consts::TAU * frequency[i];
            let exact = offset[i] + amplitude[i] * (w * t + phase[i]).sin();
            prop_assert!((s.a[i] - exact).abs() < 1e-14);
            prop_assert!((s.a_dot[i] - rate[i]).abs() < 1e-7 * (1.0 + w * w * w));
            prop_assert!((s.a_ddot[i] - accel[i]).abs() < 1e-7 * (1.0 + w * w * w * w));
        }
    }

    #[test]
    fn paper_path_reference_ends_on_the_path_with_exact_rates(
        t in 0.01f64..4.99,
        positive in any::<bool>(),
    ) {
        let branch = if positive { Branch::Positive } else { Branch::Negative };
        let path = paper_path(branch);
        let s = path.sample(t).unwrap();
        // The backbone curve's end point (eqs 3-4) is on y = 0.4 sin(5x) + 0.2, at constant x-speed.
        let tip = end_point(1.0, s.a, FRAC_PI_2).unwrap();
        let x = 0.08 + 0.32 * t / 5.0;
        prop_assert!((tip[0] - x).abs() < 1e-12 && (tip[1] - (0.4 * (5.0 * x).sin() + 0.2)).abs() < 1e-12);
        let p = path.point(t);
        prop_assert!((p[0] - x).abs() < 1e-15 && (p[1] - (0.4 * (5.0 * x).sin() + 0.2)).abs() < 1e-15);
        let on_branch = if positive { s.a[0] > 0.0 } else { s.a[0] < 0.0 };
        prop_assert!(on_branch);
        let (rate, accel) = finite_differences(&path, t, 1e-5);
        for i in 0..2 {
            prop_assert!((s.a_dot[i] - rate[i]).abs() < 1e-8, "rate {i}: {} vs {}", s.a_dot[i], rate[i]);
            prop_assert!((s.a_ddot[i] - accel[i]).abs() < 1e-7, "accel {i}: {} vs {}", s.a_ddot[i], accel[i]);
        }
    }

    #[test]
    fn polyline_reference_follows_its_segments(
        t in 0.001f64..2.999,
        corner in prop::array::uniform2(0.2f64..0.5),
    ) {
        let points = vec![[0.3, 0.3], corner, [0.1, 0.6]];
        let path = CartesianPath::new(PathShape::Polyline(points.clone()), 3.0, 1.0, 1.2, Branch::Positive).unwrap();
        let s = path.sample(t).unwrap();
        let tip = end_point(1.0, s.a, 1.2).unwrap();
        let p = path.point(t);
        prop_assert!((tip[0] - p[0]).abs() < 1e-12 && (tip[1] - p[1]).abs() < 1e-12);
        // p lies on one of the two segments.
        let on_segment = |a: [f64; 2], b: [f64; 2]| {
            let cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
            let within = (p[0] - a[0]) * (p[0] - b[0]) + (p[1] - a[1]) * (p[1] - b[1]) <= 1e-15;
            cross.abs() < 1e-12 && within
        };
        prop_assert!(on_segment(points[0], points[1]) || on_segment(points[1], points[2]));
        // Away from the corner the rates match finite differences (the corner is a kink).
        let seg1 = (corner[0] - 0.3f64).hypot(corner[1] - 0.3);
        let total = seg1 + (0.1 - corner[0]).hypot(0.6 - corner[1]);
        let t_corner = 3.0 * seg1 / total;
        if (t - t_corner).abs() > 1e-4 {
            let (rate, accel) = finite_differences(&path, t, 1e-6);
            for i in 0..2 {
                prop_assert!((s.a_dot[i] - rate[i]).abs() < 1e-6 * (1.0 + s.a_dot[i].abs()));
                prop_assert!((s.a_ddot[i] - accel[i]).abs() < 1e-4 * (1.0 + s.a_ddot[i].abs()));
            }
        }
    }
}

#[test]
fn path_holds_its_ends() {
    let path = paper_path(Branch::Positive);
    for t in [5.0, 5.3, 100.0] {
        let s = path.sample(t).unwrap();
        assert_eq!((s.a_dot, s.a_ddot), ([0.0; 2], [0.0; 2]));
        let tip = end_point(1.0, s.a, FRAC_PI_2).unwrap();
        assert!((tip[0] - 0.4).abs() < 1e-12);
    }
    let before = path.sample(-1.0).unwrap();
    assert_eq!(before.a, path.sample(0.0).unwrap().a);
    assert_eq!(before.a_dot, [0.0; 2]);
    assert!(path.sample(0.0).unwrap().a_dot[0] != 0.0);
    assert_eq!(path.travel_time(), 5.0);
}

#[test]
fn bad_paths_are_refused_with_the_reason() {
    let sine = |x_end: f64| PathShape::Sine {
        amplitude: 0.4,
        wavenumber: 5.0,
        phase: 0.0,
        offset: 0.2,
        x_start: 0.08,
        x_end,
    };
    // Beyond the arm's reach.
    let err = CartesianPath::new(sine(1.2), 5.0, 1.0, FRAC_PI_2, Branch::Positive).unwrap_err();
    match &err {
        SimError::Unreachable { t, x, .. } => assert!(*t > 0.0 && *x > 0.08, "{err}"),
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("unreachable"));
    // Ending at the straight curve r = l.
    let err = CartesianPath::new(
        PathShape::Polyline(vec![[0.3, 0.5], [0.0, 1.0]]),
        1.0,
        1.0,
        FRAC_PI_2,
        Branch::Positive,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            SimError::SingularPoint { .. } | SimError::Unreachable { .. }
        ),
        "{err}"
    );
    for (shape, time) in [
        (sine(0.08), 5.0),
        (sine(0.4), 0.0),
        (sine(f64::NAN), 5.0),
        (PathShape::Polyline(vec![[0.3, 0.3]]), 1.0),
        (
            PathShape::Polyline(vec![[0.3, 0.3], [0.3, 0.3], [0.2, 0.4]]),
            1.0,
        ),
    ] {
        let err = CartesianPath::new(shape, time, 1.0, FRAC_PI_2, Branch::Positive).unwrap_err();
        assert!(matches!(err, SimError::InvalidSetting { .. }), "{err}");
    }
}
