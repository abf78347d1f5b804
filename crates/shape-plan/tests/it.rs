//! Plans checked by brute force: link surfaces sampled against the obstacles' own distances,
//! tips by the chain's own forward kinematics, motions sampled far more densely than planned.

use backbone_kin::{BaseAngle, Branch, ModalMap, chain_inverse_kinematics, joint_positions};
use clearance::{ClearanceModel, Obstacle};
use lane_math::Classify;
use shape_plan::{Arm, PlanError, PlanOptions, PlanarArm, Planner, check_segment};

const LINKS: usize = 10;
const LENGTH: f64 = 0.1;
const RADIUS: f64 = 0.01;
const ALPHA0: f64 = std::f64::consts::FRAC_PI_2;

/// The joint points of the planar chain of `lengths` for modal coordinates `a` of `map`.
fn points(map: &ModalMap, lengths: &[f64], a: &[f64]) -> Vec<[f64; 2]> {
    let mut theta = vec![0.0; lengths.len()];
    map.joint_angles(a, &mut theta).unwrap();
    let mut p = vec![[0.0; 2]; lengths.len() + 1];
    joint_positions(lengths, &theta, &mut p).unwrap();
    p
}

/// A circle obstacle as the test sees it.
#[derive(Clone, Copy)]
struct Circle {
    center: [f64; 2],
    radius: f64,
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn point_segment(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let t = (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]))
        .clamp(0.0, 1.0);
    dist(x, [a[0] + t * d[0], a[1] + t * d[1]])
}

/// Points on the boundary of every link's capsule (radius `RADIUS`): 100 stations along the
/// link, 48 directions around each.
fn surface(p: &[[f64; 2]]) -> Vec<(usize, [f64; 2])> {
    let mut out = Vec::new();
    for i in 0..p.len() - 1 {
        for s in 0..=100 {
            let t = f64::from(s) / 100.0;
            let c = [
                p[i][0] + t * (p[i + 1][0] - p[i][0]),
                p[i][1] + t * (p[i + 1][1] - p[i][1]),
            ];
            for k in 0..48 {
                let phi = std::f64::consts::TAU * f64::from(k) / 48.0;
                let x = [c[0] + RADIUS * phi.cos(), c[1] + RADIUS * phi.sin()];
                // Keep only points on the union's boundary: outside every other link's core.
                if (0..p.len() - 1)
                    .filter(|&j| j != i)
                    .all(|j| point_segment(x, p[j], p[j + 1]) >= RADIUS - 1e-12)
                {
                    out.push((i, x));
                }
            }
        }
    }
    out
}

/// The smallest clearance the sampled surface shows: to every circle, and between links that
/// share no joint (a surface point of one against the other's core).
fn sampled_clearance(p: &[[f64; 2]], circles: &[Circle]) -> f64 {
    let mut smallest = f64::INFINITY;
    for (i, x) in surface(p) {
        for c in circles {
            smallest = smallest.min(dist(x, c.center) - c.radius);
        }
        for k in 0..p.len() - 1 {
            if k + 1 < i || k > i + 1 {
                smallest = smallest.min(point_segment(x, p[k], p[k + 1]) - RADIUS);
            }
        }
    }
    smallest
}

fn lengths() -> Vec<f64> {
    vec![LENGTH; LINKS]
}

/// Circles on the fifth joint of both closed-form `K = 1` shapes that reach `target`.
fn blocking_circles(target: [f64; 2]) -> Vec<Circle> {
    let map = ModalMap::new(&lengths(), 1, BaseAngle::Fixed(ALPHA0)).unwrap();
    [Branch::Positive, Branch::Negative]
        .map(|branch| {
            let a = chain_inverse_kinematics(&lengths(), target, ALPHA0, branch).unwrap();
            Circle {
                center: points(&map, &lengths(), &a)[4],
                radius: 0.03,
            }
        })
        .to_vec()
}

fn planner(harmonics: usize, circles: &[Circle], options: PlanOptions) -> Planner<PlanarArm> {
    let obstacles = circles
        .iter()
        .map(|c| Obstacle::circle(c.center, c.radius).unwrap())
        .collect();
    let model = ClearanceModel::new(LINKS, RADIUS, obstacles).unwrap();
    let arm = PlanarArm::new(&lengths(), harmonics, BaseAngle::Fixed(ALPHA0)).unwrap();
    Planner::new(arm, model, options).unwrap()
}

const TARGET: [f64; 2] = [0.35, 0.55];

fn options() -> PlanOptions {
    PlanOptions {
        clearance: 0.01,
        ..PlanOptions::default()
    }
}

#[test]
fn both_closed_form_k1_shapes_are_blocked() {
    let circles = blocking_circles(TARGET);
    let map = ModalMap::new(&lengths(), 1, BaseAngle::Fixed(ALPHA0)).unwrap();
    for branch in [Branch::Positive, Branch::Negative] {
        let a = chain_inverse_kinematics(&lengths(), TARGET, ALPHA0, branch).unwrap();
        let p = points(&map, &lengths(), &a);
        assert!(sampled_clearance(&p, &circles) < 0.0, "{branch:?}");
    }
}

#[test]
fn two_harmonics_reach_between_the_blocked_shapes_and_keep_the_margin() {
    let circles = blocking_circles(TARGET);
    let options = options();
    let mut planner = planner(2, &circles, options);
    let plan = planner.plan(&[0.0; 4], &TARGET).unwrap();
    let map = planner.arm().map().clone();
    // The tip by the chain's own forward kinematics.
    let p = points(&map, &lengths(), &plan.goal);
    assert!(dist(p[LINKS], TARGET) <= options.tip_tolerance);
    // The goal's clearance by sampling the surfaces: at least c, and the planner's own
    // distance agrees within the sampling's resolution.
    let sampled = sampled_clearance(&p, &circles);
    assert!(sampled >= options.clearance, "{sampled}");
    assert!(
        (sampled - plan.goal_clearance).abs() < 2e-4,
        "{sampled} vs {}",
        plan.goal_clearance
    );
    // The motion: 200 shapes a segment, sampled by brute force, keep c.
    assert_eq!(plan.path.first().unwrap(), &vec![0.0; 4]);
    assert_eq!(plan.path.last().unwrap(), &plan.goal);
    let mut smallest = f64::INFINITY;
    for pair in plan.path.windows(2) {
        for s in 0..=200 {
            let t = f64::from(s) / 200.0;
            let a: Vec<f64> = pair[0]
                .iter()
                .zip(&pair[1])
                .map(|(x, y)| x + t * (y - x))
                .collect();
            smallest = smallest.min(sampled_clearance(&points(&map, &lengths(), &a), &circles));
        }
    }
    assert!(smallest >= options.clearance, "{smallest}");
}

#[test]
fn a_distant_obstacle_changes_no_plan() {
    // A circle 1e15 m away is never near: its pairs' linearised rows, whose bounds are about
    // 1.4e15 m, must not swamp the projection's tolerance and leave the near pairs unheld.
    let circles = blocking_circles(TARGET);
    let mut far = circles.clone();
    far.push(Circle {
        center: [1e15, 1e15],
        radius: 0.03,
    });
    let near_plan = planner(2, &circles, options())
        .plan(&[0.0; 4], &TARGET)
        .unwrap();
    let far_plan = planner(2, &far, options())
        .plan(&[0.0; 4], &TARGET)
        .unwrap();
    assert_eq!(far_plan.goal, near_plan.goal);
    assert_eq!(far_plan.path, near_plan.path);
}

#[test]
fn one_harmonic_cannot_pass_and_says_so() {
    let circles = blocking_circles(TARGET);
    let mut planner = planner(1, &circles, options());
    let error = planner.plan(&[0.0; 2], &TARGET).unwrap_err();
    let PlanError::NoCollisionFreeShape {
        best_clearance,
        needed,
        tip_error,
        starts,
    } = error
    else {
        panic!("{error}")
    };
    assert!(error.is_unreachable());
    assert!(starts == 3 + options().samples, "{starts}");
    assert!(best_clearance < needed || tip_error > options().tip_tolerance);
    let opening = if best_clearance < needed {
        "no collision-free shape found"
    } else {
        "no shape found that reaches the target"
    };
    assert!(error.to_string().starts_with(opening), "{error}");
}

#[test]
fn a_target_the_family_cannot_reach_is_not_called_a_collision() {
    // Nearly at the arm's length, 0.8 rad off the base's direction, in empty space: one
    // harmonic's shapes about ALPHA0 reach the distance only straight up, so the best shape is
    // clear of everything and short of the target, and the message says so.
    let r = 0.999 * LENGTH * LINKS as f64;
    let target = [r * (ALPHA0 - 0.8).cos(), r * (ALPHA0 - 0.8).sin()];
    let options = PlanOptions {
        samples: 8,
        ..options()
    };
    let error = planner(1, &[], options)
        .plan(&[0.0; 2], &target)
        .unwrap_err();
    let PlanError::NoCollisionFreeShape {
        best_clearance,
        needed,
        tip_error,
        ..
    } = error
    else {
        panic!("{error}")
    };
    assert!(best_clearance >= needed && tip_error > 0.01, "{error}");
    assert!(
        error
            .to_string()
            .starts_with("no shape found that reaches the target"),
        "{error}"
    );
}

#[test]
fn a_target_inside_an_obstacle_is_refused_naming_it_before_any_start() {
    // The target at a circle's centre: a link ending there keeps minus the circle's radius and
    // its own from it.
    let circles = [Circle {
        center: TARGET,
        radius: 0.05,
    }];
    let options = PlanOptions {
        samples: 8,
        ..options()
    };
    let error = planner(2, &circles, options)
        .plan(&[0.0; 4], &TARGET)
        .unwrap_err();
    assert_eq!(
        error,
        PlanError::TargetTooClose {
            obstacle: 0,
            radius: RADIUS,
            clearance: -0.05 - RADIUS,
            needed: options.clearance + options.check_slack,
        }
    );
}

#[test]
fn refusals_name_the_problem() {
    let circles = blocking_circles(TARGET);
    let mut p = planner(2, &circles, options());
    let far = p.plan(&[0.0; 4], &[1.5, 0.0]).unwrap_err();
    assert!(
        matches!(far, PlanError::OutOfReach { .. }) && far.is_unreachable(),
        "{far}"
    );
    // A target within an obstacle's margin (the second circle's surface plus the links' radius
    // and half the clearance): no link can end there, and the message says which obstacle.
    let [_, second] = [circles[0], circles[1]];
    let gap = RADIUS + 0.5 * options().clearance;
    let near = [second.center[0] + second.radius + gap, second.center[1]];
    let close = p.plan(&[0.0; 4], &near).unwrap_err();
    let PlanError::TargetTooClose {
        obstacle,
        clearance,
        needed,
        ..
    } = close
    else {
        panic!("{close}")
    };
    assert_eq!(obstacle, 1);
    assert!(
        (clearance - 0.5 * options().clearance).abs() < 1e-15,
        "{clearance}"
    );
    assert_eq!(needed, options().needed());
    assert!(close.is_unreachable());
    assert!(
        close
            .to_string()
            .starts_with("target is within obstacles[1]'s margin: a link ending there (radius "),
        "{close}"
    );
    // A target whose squared distance overflows is still that far in the message.
    let very_far = p.plan(&[0.0; 4], &[1e300, -1e300]).unwrap_err();
    assert!(
        very_far
            .to_string()
            .starts_with("target is 1.4142135623730952e300 m from the base"),
        "{very_far}"
    );
    // The straight arm's own tip, at the arm's length (its links' sum rounds below it): in
    // reach, and the start is already there.
    let length: f64 = lengths().iter().sum();
    assert!(length < 1.0);
    let tip = [ALPHA0.cos(), ALPHA0.sin()];
    let mut clear = planner(2, &[], options());
    let plan = clear.plan(&[0.0; 4], &tip).unwrap();
    assert!(plan.tip_error <= 1e-9, "{}", plan.tip_error);
    let wrong = p.plan(&[0.0; 3], &TARGET).unwrap_err();
    assert!(
        wrong.is_invalid_input() && wrong.to_string().contains("initial shape"),
        "{wrong}"
    );
    let nan = p.plan(&[0.0; 4], &[f64::NAN, 0.5]).unwrap_err();
    assert!(
        nan.to_string().contains("target coordinate must be finite"),
        "{nan}"
    );
    let dims = p.plan(&[0.0; 4], &[0.3, 0.5, 0.0]).unwrap_err();
    assert!(
        dims.to_string()
            .contains("target has 3 entries, expected 2"),
        "{dims}"
    );
    // An initial shape through an obstacle: the motion could not keep the margin.
    let close = planner(
        2,
        &[Circle {
            center: [0.0, 0.5],
            radius: 0.02,
        }],
        options(),
    )
    .plan(&[0.0; 4], &TARGET)
    .unwrap_err();
    assert!(
        matches!(close, PlanError::InitialTooClose { .. }),
        "{close}"
    );
    for (bad, field) in [
        (
            PlanOptions {
                clearance: -1.0,
                ..options()
            },
            "clearance must be non-negative",
        ),
        (
            PlanOptions {
                check_slack: f64::NAN,
                ..options()
            },
            "check slack must be finite",
        ),
        (
            PlanOptions {
                samples: usize::MAX,
                ..options()
            },
            "samples must be at most",
        ),
        (
            PlanOptions {
                max_checks: 0,
                ..options()
            },
            "max checks must be at least 1",
        ),
        (
            PlanOptions {
                check_slack: 1e300,
                ..options()
            },
            "check slack must be at most 1e6 m, got 1e300",
        ),
        (
            PlanOptions {
                max_iterations: 0,
                ..options()
            },
            "max iterations must be at least 1",
        ),
    ] {
        let model = ClearanceModel::new(LINKS, RADIUS, vec![]).unwrap();
        let arm = PlanarArm::new(&lengths(), 2, BaseAngle::Fixed(ALPHA0)).unwrap();
        let error = Planner::new(arm, model, bad).unwrap_err();
        assert!(error.to_string().contains(field), "{error}");
    }
    // Counts within their limits whose product is hours of shape solves.
    let ring: Vec<Obstacle> = (0..16)
        .map(|i| {
            let angle = f64::from(i) * std::f64::consts::TAU / 16.0;
            Obstacle::circle([0.5 * angle.cos(), 0.5 * angle.sin()], 0.01).unwrap()
        })
        .collect();
    let model = ClearanceModel::new(LINKS, RADIUS, ring).unwrap();
    let arm = PlanarArm::new(&lengths(), 2, BaseAngle::Fixed(ALPHA0)).unwrap();
    let heavy = PlanOptions {
        samples: 100_000,
        max_iterations: 100_000,
        ..options()
    };
    let error = Planner::new(arm, model, heavy).unwrap_err();
    assert!(
        matches!(error, PlanError::TooMuchWork { .. })
            && error
                .to_string()
                .contains("more than the 1e11 a plan may take"),
        "{error}"
    );
    // A clearance model of another chain.
    let model = ClearanceModel::new(LINKS + 1, RADIUS, vec![]).unwrap();
    let arm = PlanarArm::new(&lengths(), 2, BaseAngle::Fixed(ALPHA0)).unwrap();
    assert!(Planner::new(arm, model, options()).is_err());
}

#[test]
fn the_lipschitz_bound_holds_on_random_pairs_of_shapes() {
    use rand::{RngExt, SeedableRng};
    let tapered: Vec<f64> = (0..12).map(|i| 0.12 - 0.005 * f64::from(i)).collect();
    for harmonics in [1, 2, 3] {
        let arm = PlanarArm::new(&tapered, harmonics, BaseAngle::Free).unwrap();
        let map = arm.map().clone();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(harmonics as u64);
        let mut worst: f64 = 0.0;
        for _ in 0..400 {
            let a: Vec<f64> = (0..map.n_coords())
                .map(|_| rng.random_range(-2.0..2.0))
                .collect();
            let b: Vec<f64> = a
                .iter()
                .map(|x| x + rng.random_range(-0.05..0.05))
                .collect();
            let (pa, pb) = (points(&map, &tapered, &a), points(&map, &tapered, &b));
            let step = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).powi(2))
                .sum::<f64>()
                .sqrt();
            // Points along every link at 11 stations.
            for i in 0..tapered.len() {
                for s in 0..=10 {
                    let t = f64::from(s) / 10.0;
                    let at = |p: &[[f64; 2]]| {
                        [
                            p[i][0] + t * (p[i + 1][0] - p[i][0]),
                            p[i][1] + t * (p[i + 1][1] - p[i][1]),
                        ]
                    };
                    worst = worst.max(dist(at(&pa), at(&pb)) / step);
                }
            }
        }
        assert!(
            worst <= arm.lipschitz(),
            "K = {harmonics}: {worst} > {}",
            arm.lipschitz()
        );
        // Not vacuous: the bound is within a small factor of what random moves show.
        assert!(
            worst > 0.1 * arm.lipschitz(),
            "K = {harmonics}: {worst} vs {}",
            arm.lipschitz()
        );
    }
}

#[test]
fn a_segment_through_an_obstacle_is_caught_and_a_clear_one_passes() {
    let circles = [Circle {
        center: [0.0, 0.9],
        radius: 0.02,
    }];
    let p = planner(1, &circles, options());
    let map = p.arm().map().clone();
    let mut data = shape_plan::PlanData::new(p.arm(), p.clearance()).unwrap();
    let brute_force_clear = |from: [f64; 2], to: [f64; 2]| {
        (0..=400).all(|s| {
            let t = f64::from(s) / 400.0;
            let a = [
                from[0] + t * (to[0] - from[0]),
                from[1] + t * (to[1] - from[1]),
            ];
            sampled_clearance(&points(&map, &lengths(), &a), &circles) >= options().clearance
        })
    };
    // From bent one way to bent the other, through the straight arm and the circle.
    let check = check_segment(
        p.arm(),
        p.clearance(),
        p.options(),
        &mut data,
        &[1.2, 0.0],
        &[-1.2, 0.0],
    )
    .unwrap();
    assert!(!brute_force_clear([1.2, 0.0], [-1.2, 0.0]));
    assert!(!check.clear && check.clearance < options().needed());
    // Bending further one way keeps the margin.
    let to = [2.0, 0.0];
    let away = check_segment(
        p.arm(),
        p.clearance(),
        p.options(),
        &mut data,
        &[1.2, 0.0],
        &to,
    )
    .unwrap();
    assert!(brute_force_clear([1.2, 0.0], to));
    assert!(away.clear && away.clearance >= options().needed());
    // A check budget too small is refused, not exceeded.
    let tight = PlanOptions {
        max_checks: 3,
        ..options()
    };
    let error =
        check_segment(p.arm(), p.clearance(), &tight, &mut data, &[1.2, 0.0], &to).unwrap_err();
    assert!(error.to_string().contains("max checks"), "{error}");
    // Options the planner refuses are refused here too, before any check point.
    let unbounded = PlanOptions {
        max_checks: usize::MAX,
        check_slack: -1.0,
        ..options()
    };
    let error = check_segment(
        p.arm(),
        p.clearance(),
        &unbounded,
        &mut data,
        &[1.2, 0.0],
        &to,
    )
    .unwrap_err();
    assert!(error.to_string().contains("check slack"), "{error}");
    // Plan data sized for another clearance model is refused, not read as this one's.
    let other = planner(1, &[circles[0], circles[0], circles[0]], options());
    let error = check_segment(
        p.arm(),
        other.clearance(),
        p.options(),
        &mut data,
        &[1.2, 0.0],
        &to,
    )
    .unwrap_err();
    assert!(
        error.to_string().contains("made for another model"),
        "{error}"
    );
    // A target that is not a point of space is refused by the shape solve.
    for target in [[f64::NAN, 0.5, 0.0], [1e300, 0.0, 0.0]] {
        let mut a = [0.0; 2];
        let error = shape_plan::solve_shape(
            p.arm(),
            p.clearance(),
            p.options(),
            &mut data,
            target,
            &mut a,
        )
        .unwrap_err();
        assert!(error.to_string().contains("target coordinate"), "{error}");
    }
}

#[test]
fn plans_are_reproducible() {
    let circles = blocking_circles(TARGET);
    let a = planner(2, &circles, options())
        .plan(&[0.0; 4], &TARGET)
        .unwrap();
    let b = planner(2, &circles, options())
        .plan(&[0.0; 4], &TARGET)
        .unwrap();
    assert_eq!(a, b);
}
