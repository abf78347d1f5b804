//! `[task]` scenarios: planned first, then tracked. `narrow-gap` (planar) and `spatial-clutter`
//! (spatial) end on their targets and hold them with computed torque and with MPC, keeping the
//! clearance the plan promised up to the tracking error, while the free-space shapes a
//! controller would be given without a plan (the closed-form `K = 1` shapes, the spatial
//! inverse kinematics') collide.

use backbone_kin::{
    BaseAngle, Branch, ModalMap, SpatialIk, chain_inverse_kinematics, joint_positions,
    spatial_joint_positions,
};
use sim_study::study::run_one;
use sim_study::{
    AngleLimit, ControllerKind, ObstacleSpec, ReferenceSpec, Scenario, TaskSpec, Workspace,
};

fn target(scenario: &Scenario) -> [f64; 2] {
    let Some(TaskSpec::Reach { target, .. }) = &scenario.task else {
        panic!("narrow-gap has a reach task")
    };
    [target[0], target[1]]
}

#[test]
fn narrow_gap_is_planned_then_reached_and_held() {
    let scenario = Scenario::builtin("narrow-gap").unwrap();
    let target = target(&scenario);
    let plan = scenario.plan().unwrap().unwrap();
    assert!(plan.goal_clearance >= 0.01 && plan.tip_error <= 1e-6);
    for kind in [ControllerKind::ComputedTorque, ControllerKind::Mpc] {
        let run = run_one(&scenario, kind)
            .result
            .unwrap_or_else(|f| panic!("{kind}: {}", f.error));
        let record = &run.record;
        let last = record.len() - 1;
        let miss = |k: usize| (record.tip[k][0] - target[0]).hypot(record.tip[k][1] - target[1]);
        // On target at the end, and held over the last half second.
        let hold_from = record
            .t
            .iter()
            .position(|&t| t >= scenario.duration - 0.5)
            .unwrap();
        let worst_hold = (hold_from..=last).map(miss).fold(0.0, f64::max);
        assert!(miss(last) < 3e-3, "{kind}: {} m", miss(last));
        assert!(worst_hold < 3e-3, "{kind}: {} m while holding", worst_hold);
        // The loop's own clearance over every controller sample: the margin less what the
        // tracking error costs, never a collision.
        let clearance = run.summary.min_clearance_m.unwrap();
        assert!(clearance > 0.005, "{kind}: {clearance} m");
    }
}

#[test]
fn without_a_plan_the_closed_form_shapes_collide() {
    let scenario = Scenario::builtin("narrow-gap").unwrap();
    let target = target(&scenario);
    let lengths = [0.1; 10];
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let obstacles = scenario.obstacles(Workspace::Planar).unwrap();
    let map = ModalMap::new(&lengths, 1, BaseAngle::Fixed(alpha0)).unwrap();
    for branch in [Branch::Positive, Branch::Negative] {
        let a = chain_inverse_kinematics(&lengths, target, alpha0, branch).unwrap();
        let mut theta = [0.0; 10];
        map.joint_angles(&a, &mut theta).unwrap();
        let mut p = [[0.0; 2]; 11];
        joint_positions(&lengths, &theta, &mut p).unwrap();
        // Some joint of the shape lies inside an obstacle (signed distance below the radius).
        let inside = p.iter().any(|q| {
            obstacles
                .iter()
                .any(|o| o.signed_distance([q[0], q[1], 0.0]) < 0.01)
        });
        assert!(inside, "{branch:?}");
    }
}

#[test]
fn tasks_and_planned_references_come_together_and_name_their_fields() {
    let base = Scenario::builtin("narrow-gap").unwrap();
    let mut no_task = base.clone();
    no_task.task = None;
    let e = no_task.build().err().unwrap().to_string();
    assert!(e.contains("reference") && e.contains("[task]"), "{e}");
    let mut no_planned = base.clone();
    no_planned.reference = ReferenceSpec::Constant { a: vec![0.0; 4] };
    let e = no_planned.build().err().unwrap().to_string();
    assert!(e.starts_with("task"), "{e}");
    let with = |f: &dyn Fn(&mut Scenario)| {
        let mut s = base.clone();
        f(&mut s);
        s.build().err().unwrap().to_string()
    };
    let set = |s: &mut Scenario, target: Vec<f64>, clearance: f64| {
        s.task = Some(TaskSpec::Reach {
            target,
            clearance,
            check_slack: None,
            samples: None,
            max_iterations: None,
        });
    };
    let e = with(&|s| set(s, vec![0.3], 0.01));
    assert!(e.starts_with("task.target must be a point [x, y]"), "{e}");
    let e = with(&|s| set(s, vec![2.0, 0.0], 0.01));
    assert!(
        e.starts_with("task.target cannot be met: target is 2 m"),
        "{e}"
    );
    let e = with(&|s| set(s, vec![0.35, 0.55], -0.1));
    assert!(
        e.starts_with("task.clearance cannot be met: clearance must be non-negative"),
        "{e}"
    );
    // A clearance the start (a = 0, no [initial]) cannot keep names the clearance.
    let e = with(&|s| set(s, vec![0.35, 0.55], 10.0));
    assert!(
        e.starts_with("task.clearance cannot be met from the arm's start (a = 0, no [initial])"),
        "{e}"
    );
    // One beyond any workspace is refused as such.
    let e = with(&|s| set(s, vec![0.35, 0.55], 1e300));
    assert!(
        e.starts_with("task.clearance cannot be met: clearance must be at most 1e6 m, got 1e300"),
        "{e}"
    );
    // The planner keeps clearance, not joint angles: a plan beyond limits.joint_angle_rad is
    // refused by name, one within them builds.
    let e = with(&|s| {
        let mut limits = vec![0.3; 10];
        limits[0] = 3.0;
        s.limits.joint_angle_rad = Some(AngleLimit::PerJoint(limits));
    });
    assert!(
        e.starts_with("limits.joint_angle_rad cannot be kept by the [task]'s plan")
            && e.contains("beyond 0.3 rad"),
        "{e}"
    );
    // A run of hours is refused before its plan (which would refuse this target as out of
    // reach, after planning over the 1,000 links).
    let e = with(&|s| {
        s.arm.links = Some(1000);
        s.arm.link_length = Some(0.001);
        s.arm.link_mass = Some(0.001);
        s.arm.radius = Some(1e-4);
        set(s, vec![5.0, 5.0], 0.0);
    });
    assert!(
        e.starts_with("duration = 4 s would take an estimated") && e.contains("clearance measures"),
        "{e}"
    );
    // A limit out of its domain is named as without a [task].
    let e = with(&|s| {
        let mut limits = vec![2.0; 10];
        limits[8] = -1.0;
        s.limits.joint_angle_rad = Some(AngleLimit::PerJoint(limits));
    });
    assert_eq!(
        e,
        "limits.joint_angle_rad[8] must be positive and finite, got -1"
    );
    let e = with(&|s| s.limits.joint_angle_rad = Some(AngleLimit::All(0.0)));
    assert_eq!(
        e,
        "limits.joint_angle_rad must be positive and finite, got 0"
    );
    let mut roomy = base.clone();
    roomy.limits.joint_angle_rad = Some(AngleLimit::All(3.0));
    assert!(roomy.build().is_ok());
    // A target inside an obstacle, or within its margin: refused before any start, naming the
    // obstacle.
    let e = with(&|s| set(s, vec![-0.14, 0.36], 0.01));
    assert!(
        e.starts_with("task.target cannot be met: target is within obstacles[")
            && e.ends_with("less than the 0.011 m every link must keep"),
        "{e}"
    );
    // A start a plan cannot move from, and zero iterations, are refused by their keys.
    let e = with(&|s| {
        s.initial = Some(sim_study::InitialSpec {
            a: vec![1e300, 0.0, 0.0, 0.0],
            a_dot: None,
        })
    });
    assert!(
        e.starts_with("initial.a must be finite and within 1000 rad with a [task]")
            && e.ends_with("got 1e300"),
        "{e}"
    );
    let e = with(&|s| {
        if let Some(TaskSpec::Reach { max_iterations, .. }) = &mut s.task {
            *max_iterations = Some(0);
        }
    });
    assert!(
        e.starts_with("task.max_iterations cannot be met: max iterations must be at least 1"),
        "{e}"
    );
    // A spatial arm's target is a point in space: the plane's [x, y] is refused by name.
    let mut spatial = Scenario::builtin("spatial-clutter").unwrap();
    spatial.task = base.task.clone();
    let e = spatial.build().err().unwrap().to_string();
    assert!(
        e.starts_with("task.target must be a point [x, y, z], got 2 numbers"),
        "{e}"
    );
    let e = {
        let mut s = spatial.clone();
        set(&mut s, vec![1.5, 0.0, 0.0], 0.01);
        s.build().err().unwrap().to_string()
    };
    assert!(
        e.starts_with("task.target cannot be met: target is 1.5 m"),
        "{e}"
    );
    // A spatial target inside an obstacle (the first sphere's centre).
    let centre = match &spatial.obstacles[0] {
        ObstacleSpec::Sphere { center, .. } => center.clone(),
        other => panic!("spatial-clutter's first obstacle is a sphere, got {other:?}"),
    };
    let e = {
        let mut s = spatial.clone();
        set(&mut s, centre, 0.01);
        s.build().err().unwrap().to_string()
    };
    assert!(
        e.starts_with("task.target cannot be met: target is within obstacles[0]'s margin"),
        "{e}"
    );
    let text = base.to_toml();
    assert_eq!(Scenario::from_toml(&text).unwrap(), base);
}

#[test]
fn a_controller_given_the_closed_form_goal_collides_where_the_planned_run_keeps_the_margin() {
    let planned = Scenario::builtin("narrow-gap").unwrap();
    let target = target(&planned);
    let lengths = [0.1; 10];
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let k1 = ModalMap::new(&lengths, 1, BaseAngle::Fixed(alpha0)).unwrap();
    let k2 = ModalMap::new(&lengths, 2, BaseAngle::Fixed(alpha0)).unwrap();
    for branch in [Branch::Positive, Branch::Negative] {
        // The closed-form K = 1 goal in the scenario's K = 2 coordinates (second harmonic zero),
        // checked to be the same shape: its tip is on the target.
        let a = chain_inverse_kinematics(&lengths, target, alpha0, branch).unwrap();
        let goal = vec![a[0], a[1], 0.0, 0.0];
        let (mut theta1, mut theta2) = ([0.0; 10], [0.0; 10]);
        k1.joint_angles(&a, &mut theta1).unwrap();
        k2.joint_angles(&goal, &mut theta2).unwrap();
        assert!(
            theta1
                .iter()
                .zip(&theta2)
                .all(|(x, y)| (x - y).abs() < 1e-12)
        );
        // The same arm, obstacles and controller with that goal as a constant reference and
        // no plan: computed torque drives the arm into an obstacle.
        let mut unplanned = planned.clone();
        unplanned.task = None;
        unplanned.reference = ReferenceSpec::Constant { a: goal };
        let run = run_one(&unplanned, ControllerKind::ComputedTorque)
            .result
            .unwrap_or_else(|f| panic!("{branch:?}: {}", f.error));
        let clearance = run.summary.min_clearance_m.unwrap();
        assert!(clearance < 0.0, "{branch:?}: {clearance} m");
    }
    // Planned and tracked, the same controller keeps the margin less the tracking error.
    let run = run_one(&planned, ControllerKind::ComputedTorque)
        .result
        .unwrap();
    assert!(run.summary.min_clearance_m.unwrap() > 0.005);
}

/// The target of `spatial-clutter`, `[x, y, z]`.
fn spatial_target(scenario: &Scenario) -> [f64; 3] {
    let Some(TaskSpec::Reach { target, .. }) = &scenario.task else {
        panic!("spatial-clutter has a reach task")
    };
    [target[0], target[1], target[2]]
}

/// The smallest signed distance between the capsules of radius `radius` around the chain of
/// joint points `p` and the obstacles, by sampling each link's axis densely (an independent
/// check of the clearance crate's closed forms: a capsule's distance is its axis' less the
/// radius).
fn sampled_clearance(p: &[[f64; 3]], radius: f64, obstacles: &[clearance::Obstacle]) -> f64 {
    let mut smallest = f64::INFINITY;
    for link in p.windows(2) {
        for k in 0..=200 {
            let t = k as f64 / 200.0;
            let q: [f64; 3] = std::array::from_fn(|d| link[0][d] + t * (link[1][d] - link[0][d]));
            for o in obstacles {
                smallest = smallest.min(o.signed_distance(q) - radius);
            }
        }
    }
    smallest
}

#[test]
fn spatial_clutter_is_planned_then_reached_and_held() {
    let scenario = Scenario::builtin("spatial-clutter").unwrap();
    let target = spatial_target(&scenario);
    let plan = scenario.plan().unwrap().unwrap();
    assert!(plan.goal_clearance >= 0.01 && plan.tip_error <= 1e-6);
    // The goal shape's tip and clearance, recomputed from the chain's own kinematics and by
    // sampling the links against the obstacles' distance functions.
    let model = scenario.spatial_model().unwrap();
    let map = model.map();
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&plan.goal, &mut theta).unwrap();
    let mut p = vec![[0.0; 3]; model.n_links() + 1];
    spatial_joint_positions(map.link_lengths(), model.base(), &theta, &mut p).unwrap();
    let tip = p[model.n_links()];
    assert!((0..3).all(|d| (tip[d] - target[d]).abs() < 1e-6), "{tip:?}");
    let obstacles = scenario.obstacles(Workspace::Spatial).unwrap();
    let radius = scenario.arm.radius.unwrap();
    assert!(sampled_clearance(&p, radius, &obstacles) >= 0.01 - 1e-9);
    for kind in [ControllerKind::ComputedTorque, ControllerKind::Mpc] {
        let run = run_one(&scenario, kind)
            .result
            .unwrap_or_else(|f| panic!("{kind}: {}", f.error));
        let record = &run.record;
        let last = record.len() - 1;
        let miss = |k: usize| {
            let d = [
                record.tip[k][0] - target[0],
                record.tip[k][1] - target[1],
                record.tip_z[k] - target[2],
            ];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        };
        let hold_from = record
            .t
            .iter()
            .position(|&t| t >= scenario.duration - 0.5)
            .unwrap();
        let worst_hold = (hold_from..=last).map(miss).fold(0.0, f64::max);
        assert!(miss(last) < 3e-3, "{kind}: {} m", miss(last));
        assert!(worst_hold < 3e-3, "{kind}: {} m while holding", worst_hold);
        let clearance = run.summary.min_clearance_m.unwrap();
        assert!(clearance > 0.005, "{kind}: {clearance} m");
    }
}

/// `spatial-clutter` with one more sphere, on the straight motion of its plan (at joint 6 of the
/// shape 30% of the way), is planned through a via point at large coordinates, where the MPC's
/// Euler model is unstable open loop: MPC tracks it (its warm starts follow the previous plan's
/// feedback) and ends on the target with the margin kept.
#[test]
fn mpc_tracks_a_spatial_plan_through_its_via_point() {
    let mut scenario = Scenario::builtin("spatial-clutter").unwrap();
    scenario.duration = 3.5;
    let target = spatial_target(&scenario);
    let straight = scenario.plan().unwrap().unwrap();
    assert_eq!(straight.path.len(), 2);
    let model = scenario.spatial_model().unwrap();
    let map = model.map();
    let (start, goal) = (&straight.path[0], &straight.path[1]);
    let on_the_way: Vec<f64> = start
        .iter()
        .zip(goal)
        .map(|(a, b)| a + 0.3 * (b - a))
        .collect();
    let mut theta = vec![0.0; map.n_joints()];
    let mut p = vec![[0.0; 3]; model.n_links() + 1];
    map.joint_angles(&on_the_way, &mut theta).unwrap();
    spatial_joint_positions(map.link_lengths(), model.base(), &theta, &mut p).unwrap();
    scenario.obstacles.push(ObstacleSpec::Sphere {
        center: p[6].to_vec(),
        radius: 0.02,
    });
    let plan = scenario.plan().unwrap().unwrap();
    assert!(plan.path.len() > 2, "{} waypoints", plan.path.len());
    let largest = plan.path[1].iter().fold(0.0_f64, |s, x| s.max(x.abs()));
    assert!(largest > 1.5, "{:?}", plan.path[1]);
    let run = run_one(&scenario, ControllerKind::Mpc)
        .result
        .unwrap_or_else(|f| panic!("{}", f.error));
    let record = &run.record;
    let last = record.len() - 1;
    let miss = [
        record.tip[last][0] - target[0],
        record.tip[last][1] - target[1],
        record.tip_z[last] - target[2],
    ];
    let miss = (miss[0] * miss[0] + miss[1] * miss[1] + miss[2] * miss[2]).sqrt();
    assert!(miss < 3e-3, "{miss} m");
    let clearance = run.summary.min_clearance_m.unwrap();
    assert!(clearance > 0.005, "{clearance} m");
}

#[test]
fn a_controller_given_the_free_space_ik_shape_collides_where_the_planned_spatial_run_keeps_the_margin()
 {
    let planned = Scenario::builtin("spatial-clutter").unwrap();
    let target = spatial_target(&planned);
    let model = planned.spatial_model().unwrap();
    let map = model.map();
    let obstacles = planned.obstacles(Workspace::Spatial).unwrap();
    let radius = planned.arm.radius.unwrap();
    let mut ik = SpatialIk::new(map.clone(), *model.base()).unwrap();
    // The free-space inverse kinematics from the guesses bent in both planes that the planner
    // starts from (the straight arm is singular for the solver).
    let mut shapes: Vec<Vec<f64>> = Vec::new();
    for (z, y) in [(0.5, 0.5), (-0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)] {
        let mut a = vec![z, 0.0, y, 0.0];
        let solved = ik.solve(target, &mut a).is_ok();
        if solved
            && shapes
                .iter()
                .all(|s| s.iter().zip(&a).any(|(x, y)| (x - y).abs() > 1e-6))
        {
            shapes.push(a);
        }
    }
    assert!(shapes.len() >= 2, "{shapes:?}");
    let mut theta = vec![0.0; map.n_joints()];
    let mut p = vec![[0.0; 3]; model.n_links() + 1];
    for a in &shapes {
        // The shape reaches the target but runs a link into an obstacle.
        map.joint_angles(a, &mut theta).unwrap();
        spatial_joint_positions(map.link_lengths(), model.base(), &theta, &mut p).unwrap();
        let tip = p[model.n_links()];
        assert!((0..3).all(|d| (tip[d] - target[d]).abs() < 1e-6), "{a:?}");
        assert!(sampled_clearance(&p, radius, &obstacles) < 0.0, "{a:?}");
        // Given that shape as a constant reference and no plan, computed torque drives the arm
        // into the obstacle.
        let mut unplanned = planned.clone();
        unplanned.task = None;
        unplanned.reference = ReferenceSpec::Constant { a: a.clone() };
        let run = run_one(&unplanned, ControllerKind::ComputedTorque)
            .result
            .unwrap_or_else(|f| panic!("{a:?}: {}", f.error));
        let clearance = run.summary.min_clearance_m.unwrap();
        assert!(clearance < 0.0, "{a:?}: {clearance} m");
    }
    // Planned and tracked, the same controller keeps the margin less the tracking error.
    let run = run_one(&planned, ControllerKind::ComputedTorque)
        .result
        .unwrap();
    assert!(run.summary.min_clearance_m.unwrap() > 0.005);
}
