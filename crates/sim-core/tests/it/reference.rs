//! References against independent checks: the forward kinematics of the modal reference lands
//! on the path, and the exact rates and accelerations match finite differences.

use backbone_kin::{BackboneCurve, BaseAngle, Branch, end_point};
use proptest::prelude::*;
use sim_core::SimError;
use sim_core::reference::{
    CartesianPath, MAX_SINE_PHASE, PathShape, Reference, ReferenceSample, Sinusoid, Step,
};
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
    CartesianPath::new(shape, 5.0, 1.0, 1, BaseAngle::Fixed(FRAC_PI_2), branch).unwrap()
}

/// The sample of `reference` at `t`.
fn at(reference: &mut dyn Reference, t: f64) -> ReferenceSample {
    let mut sample = ReferenceSample::zeros(reference.n_coords());
    reference.sample(t, &mut sample).unwrap();
    sample
}

/// Central differences of `a` and `a_dot` of `reference` at `t`.
fn finite_differences(reference: &mut dyn Reference, t: f64, h: f64) -> (Vec<f64>, Vec<f64>) {
    let (before, after) = (at(reference, t - h), at(reference, t + h));
    let m = before.n_coords();
    let rate = (0..m)
        .map(|i| (after.a[i] - before.a[i]) / (2.0 * h))
        .collect();
    let accel = (0..m)
        .map(|i| (after.a_dot[i] - before.a_dot[i]) / (2.0 * h))
        .collect();
    (rate, accel)
}

#[test]
fn step_switches_at_its_time_and_has_no_rates() {
    let mut step = Step::new(&[0.1, 0.2], &[-0.3, 0.4], 1.5).unwrap();
    assert_eq!(at(&mut step, 1.4999).a, [0.1, 0.2]);
    let after = at(&mut step, 1.5);
    assert_eq!(after.a, [-0.3, 0.4]);
    assert_eq!((after.a_dot, after.a_ddot), (vec![0.0; 2], vec![0.0; 2]));
    assert_eq!(
        at(&mut Step::constant(&[0.5, 0.6]).unwrap(), 0.0).a,
        [0.5, 0.6]
    );
    assert!(matches!(
        Step::new(&[0.0; 2], &[f64::NAN, 0.0], 1.0),
        Err(SimError::InvalidSetting { .. })
    ));
    assert!(Step::new(&[0.0; 2], &[0.0; 2], -1.0).is_err());
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
        let mut sine = Sinusoid::new(&offset, &amplitude, &frequency, &phase).unwrap();
        let s = at(&mut sine, t);
        let (rate, accel) = finite_differences(&mut sine, t, 1e-5);
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
        let mut path = paper_path(branch);
        let s = at(&mut path, t);
        // The backbone curve's end point (eqs 3-4) is on y = 0.4 sin(5x) + 0.2, at constant x-speed.
        let tip = end_point(1.0, [s.a[0], s.a[1]], FRAC_PI_2).unwrap();
        let x = 0.08 + 0.32 * t / 5.0;
        prop_assert!((tip[0] - x).abs() < 1e-12 && (tip[1] - (0.4 * (5.0 * x).sin() + 0.2)).abs() < 1e-12);
        let p = path.point(t);
        prop_assert!((p[0] - x).abs() < 1e-15 && (p[1] - (0.4 * (5.0 * x).sin() + 0.2)).abs() < 1e-15);
        let on_branch = if positive { s.a[0] > 0.0 } else { s.a[0] < 0.0 };
        prop_assert!(on_branch);
        let (rate, accel) = finite_differences(&mut path, t, 1e-5);
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
        let mut path = CartesianPath::new(PathShape::Polyline(points.clone()), 3.0, 1.0, 1, BaseAngle::Fixed(1.2), Branch::Positive).unwrap();
        let s = at(&mut path, t);
        let tip = end_point(1.0, [s.a[0], s.a[1]], 1.2).unwrap();
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
            let (rate, accel) = finite_differences(&mut path, t, 1e-6);
            for i in 0..2 {
                prop_assert!((s.a_dot[i] - rate[i]).abs() < 1e-6 * (1.0 + s.a_dot[i].abs()));
                prop_assert!((s.a_ddot[i] - accel[i]).abs() < 1e-4 * (1.0 + s.a_ddot[i].abs()));
            }
        }
    }
}

#[test]
fn path_holds_its_ends() {
    let mut path = paper_path(Branch::Positive);
    for t in [5.0, 5.3, 100.0] {
        let s = at(&mut path, t);
        assert_eq!((s.a_dot, s.a_ddot), (vec![0.0; 2], vec![0.0; 2]));
        let tip = end_point(1.0, [s.a[0], s.a[1]], FRAC_PI_2).unwrap();
        assert!((tip[0] - 0.4).abs() < 1e-12);
    }
    let before = at(&mut path, -1.0);
    assert_eq!(before.a, at(&mut path, 0.0).a);
    assert_eq!(before.a_dot, [0.0; 2]);
    assert!(at(&mut path, 0.0).a_dot[0] != 0.0);
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
    let err = CartesianPath::new(
        sine(1.2),
        5.0,
        1.0,
        1,
        BaseAngle::Fixed(FRAC_PI_2),
        Branch::Positive,
    )
    .unwrap_err();
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
        1,
        BaseAngle::Fixed(FRAC_PI_2),
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
        let err = CartesianPath::new(
            shape,
            time,
            1.0,
            1,
            BaseAngle::Fixed(FRAC_PI_2),
            Branch::Positive,
        )
        .unwrap_err();
        assert!(matches!(err, SimError::InvalidSetting { .. }), "{err}");
    }
    // A sine turning through more than MAX_SINE_PHASE between its ends (its NaN acceleration
    // named no field): refused naming the wavenumber; just within, the path is built (a tiny
    // amplitude keeps it reachable).
    let fast = |wavenumber: f64| PathShape::Sine {
        amplitude: 1e-9,
        wavenumber,
        phase: 0.0,
        offset: 0.2,
        x_start: 0.08,
        x_end: 0.4,
    };
    let new = |shape| {
        CartesianPath::new(
            shape,
            5.0,
            1.0,
            1,
            BaseAngle::Fixed(FRAC_PI_2),
            Branch::Positive,
        )
    };
    let err = new(fast(1e300)).unwrap_err().to_string();
    assert_eq!(
        err,
        "reference.sine.wavenumber = 1e300 turns the sine through 3.200e299 rad from x_start \
         to x_end, more than 1e6: its slope and curvature leave double precision"
    );
    assert!(new(fast(MAX_SINE_PHASE / 0.32 * 1.001)).is_err());
    new(fast(1e3)).unwrap();
}

/// Parameters whose rates or accelerations double precision cannot hold are refused up front:
/// a travel time of `5e-324` s gave NaN rates, a frequency of `1e300` Hz a NaN acceleration.
#[test]
fn references_beyond_double_precision_are_refused() {
    let line = || PathShape::Polyline(vec![[0.3, 0.3], [0.2, 0.4]]);
    let base = BaseAngle::Fixed(FRAC_PI_2);
    for time in [5e-324, 1e-300, 9.9e-7] {
        let err = CartesianPath::new(line(), time, 1.0, 1, base, Branch::Positive).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("reference.travel_time must be finite and at least 1e-6 s, got"),
            "{err}"
        );
    }
    assert!(CartesianPath::new(line(), 1e-6, 1.0, 1, base, Branch::Positive).is_ok());
    let waypoints = sim_core::reference::Waypoints::new(&[vec![0.0], vec![1.0]], 1e-300);
    assert!(
        waypoints
            .unwrap_err()
            .to_string()
            .contains("at least 1e-6 s")
    );
    let spline = sim_core::reference::SplineMotion::new(&[vec![0.0], vec![1.0]], 5e-324);
    assert!(spline.unwrap_err().to_string().contains("at least 1e-6 s"));
    let err = Sinusoid::new(&[0.0; 2], &[0.1; 2], &[1e300, 1.0], &[0.0; 2]).unwrap_err();
    assert_eq!(
        err.to_string(),
        "reference.frequency_hz must be at most 1000000 Hz, got 1e300"
    );
    // The highest frequency: accelerations of 0.1 (2 pi 1e6)^2, finite.
    let mut sine = Sinusoid::new(&[0.0], &[0.1], &[1e6], &[0.5]).unwrap();
    let sample = at(&mut sine, 0.25);
    assert!(sample.a_ddot[0].is_finite() && sample.a_ddot[0].abs() > 1e11);
}

/// The paper's path for a family of `harmonics` harmonics with `alpha0` fixed at pi/2 or free.
fn family_path(harmonics: usize, free: bool) -> CartesianPath {
    let shape = PathShape::Sine {
        amplitude: 0.4,
        wavenumber: 5.0,
        phase: 0.0,
        offset: 0.2,
        x_start: 0.08,
        x_end: 0.4,
    };
    let base = if free {
        BaseAngle::Free
    } else {
        BaseAngle::Fixed(FRAC_PI_2)
    };
    CartesianPath::new(shape, 5.0, 1.0, harmonics, base, Branch::Positive).unwrap()
}

/// The end point of the family's curve at `a` (a free alpha0 last).
fn family_tip(a: &[f64], free: bool) -> [f64; 2] {
    let (modes, alpha0) = if free {
        (&a[..a.len() - 1], a[a.len() - 1])
    } else {
        (a, FRAC_PI_2)
    };
    BackboneCurve::new(1.0, modes, alpha0).unwrap().end_point()
}

#[test]
fn the_continuation_follows_the_path_without_branch_jumps() {
    for (harmonics, free) in [(2, false), (1, true), (2, true), (3, false)] {
        let mut path = family_path(harmonics, free);
        let m = 2 * harmonics + usize::from(free);
        assert_eq!(path.n_coords(), m);
        // Starts on the paper's K = 1 solution (higher harmonics zero, a free alpha0 at pi/2).
        let start = at(&mut path, 0.0);
        let closed = backbone_kin::inverse_kinematics(
            1.0,
            [0.08, 0.2 + 0.4 * 0.4f64.sin()],
            FRAC_PI_2,
            Branch::Positive,
        )
        .unwrap();
        assert!((start.a[0] - closed[0]).abs() < 1e-10 && (start.a[1] - closed[1]).abs() < 1e-10);
        assert!(start.a[2..2 * harmonics].iter().all(|a| a.abs() < 1e-10));
        let h = 1e-3;
        let mut previous = start;
        for k in 1..=5000 {
            let t = k as f64 * h;
            let s = at(&mut path, t);
            // On the path.
            let tip = family_tip(&s.a, free);
            let point = path.point(t);
            assert!(
                (tip[0] - point[0]).hypot(tip[1] - point[1]) < 1e-12,
                "K = {harmonics}, free = {free}, t = {t}: {tip:?} vs {point:?}"
            );
            // No jump: the step is the one the rates predict, to second order.
            for i in 0..m {
                let predicted =
                    previous.a[i] + h * previous.a_dot[i] + 0.5 * h * h * previous.a_ddot[i];
                assert!(
                    (s.a[i] - predicted).abs() < 1e-6,
                    "K = {harmonics}, free = {free}, t = {t}, coordinate {i}: {} vs {predicted}",
                    s.a[i]
                );
            }
            previous = s;
        }
        // A function of t alone: sampling backwards gives the same numbers.
        let forward = at(&mut path, 2.345_6);
        let _ = at(&mut path, 4.9);
        assert_eq!(at(&mut path, 2.345_6), forward);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn continuation_rates_match_finite_differences(
        t in 0.01f64..4.99,
        family in 0usize..3,
    ) {
        let (harmonics, free) = [(2, false), (1, true), (2, true)][family];
        let mut path = family_path(harmonics, free);
        let s = at(&mut path, t);
        let (rate, accel) = finite_differences(&mut path, t, 1e-5);
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        for i in 0..s.n_coords() {
            prop_assert!((s.a_dot[i] - rate[i]).abs() < 1e-6 * (1.0 + norm(&rate)), "{:?} vs {rate:?}", s.a_dot);
            prop_assert!((s.a_ddot[i] - accel[i]).abs() < 1e-4 * (1.0 + norm(&accel)), "{:?} vs {accel:?}", s.a_ddot);
        }
    }
}

/// A waypoint motion: rates and accelerations are the derivatives of the coordinates (central
/// differences), every shape lies on its segment, and the motion rests at every waypoint.
#[test]
fn waypoints_differentiate_and_stay_on_their_segments() {
    use sim_core::reference::Waypoints;
    let points = vec![
        vec![0.0, 0.0, 0.0],
        vec![0.6, -0.2, 0.1],
        vec![0.6, 0.4, -0.3],
    ];
    let mut motion = Waypoints::new(&points, 3.0).unwrap();
    let (mut s, mut lo, mut hi) = (
        ReferenceSample::zeros(3),
        ReferenceSample::zeros(3),
        ReferenceSample::zeros(3),
    );
    let h = 1e-6;
    for k in 1..300 {
        let t = 3.2 * f64::from(k) / 300.0;
        motion.sample(t, &mut s).unwrap();
        motion.sample(t - h, &mut lo).unwrap();
        motion.sample(t + h, &mut hi).unwrap();
        for i in 0..3 {
            let rate = (hi.a[i] - lo.a[i]) / (2.0 * h);
            let accel = (hi.a_dot[i] - lo.a_dot[i]) / (2.0 * h);
            assert!((rate - s.a_dot[i]).abs() < 1e-6, "t = {t}");
            assert!((accel - s.a_ddot[i]).abs() < 1e-4, "t = {t}");
        }
        // On the segment: a - w_k parallel to w_{k+1} - w_k.
        let on_segment = points.windows(2).any(|w| {
            let d: Vec<f64> = (0..3).map(|i| w[1][i] - w[0][i]).collect();
            let r: Vec<f64> = (0..3).map(|i| s.a[i] - w[0][i]).collect();
            let along =
                (0..3).map(|i| r[i] * d[i]).sum::<f64>() / (0..3).map(|i| d[i] * d[i]).sum::<f64>();
            (-1e-12..=1.0 + 1e-12).contains(&along)
                && (0..3).all(|i| (r[i] - along * d[i]).abs() < 1e-12)
        });
        assert!(on_segment, "t = {t}");
    }
    // Segments of 0.41^0.5 and 0.52^0.5 share the 3 s: the first ends at rest on w_1.
    let first = 3.0 * 0.41_f64.sqrt() / (0.41_f64.sqrt() + 0.52_f64.sqrt());
    motion.sample(first, &mut s).unwrap();
    assert!((0..3).all(|i| (s.a[i] - points[1][i]).abs() < 1e-12 && s.a_dot[i].abs() < 1e-12));
    motion.sample(3.0, &mut s).unwrap();
    assert_eq!(s.a, points[2]);
    assert!(s.a_dot.iter().chain(&s.a_ddot).all(|x| *x == 0.0));
    for (bad, text) in [
        (Waypoints::new(&[], 1.0).unwrap_err(), "between 1 and"),
        (
            Waypoints::new(&[vec![0.0], vec![0.0, 1.0]], 1.0).unwrap_err(),
            "has 2 entries",
        ),
        (
            Waypoints::new(&[vec![0.0]], 0.0).unwrap_err(),
            "travel time",
        ),
        (
            Waypoints::new(&[vec![f64::NAN]], 1.0).unwrap_err(),
            "finite",
        ),
    ] {
        assert!(bad.to_string().contains(text), "{bad}");
    }
}
