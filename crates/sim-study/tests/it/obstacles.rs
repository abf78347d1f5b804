//! `[[obstacles]]` and `[arm] radius`: what a scenario file may say, what it becomes
//! (`clearance::Obstacle`, checked against each shape's own signed distance), and every refusal
//! naming the obstacle's field.

use clearance::Obstacle;
use sim_study::{ObstacleSpec, Scenario, Workspace};

const HOLD: &str = "name = \"hold\"\nduration = 0.01\nalpha0 = 1.0\n\
    reference = { kind = \"constant\", a = [0.3, -0.2] }\n\
    integrator = { method = \"rk4\", dt = 1e-3 }\n";

fn with(extra: &str) -> Scenario {
    let text = format!("{HOLD}{extra}");
    Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn planar_obstacles_are_read_in_the_plane() {
    let scenario = with(
        "[arm]\nradius = 0.01\n\
         [[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = 0.05\n\
         [[obstacles]]\nkind = \"capsule\"\nfrom = [0.0, 1.0]\nto = [0.5, 1.0]\nradius = 0.02\n\
         [[obstacles]]\nkind = \"box\"\ncenter = [-0.4, 0.5]\nhalf_extents = [0.1, 0.2]\n\
         rpy = [0.0, 0.0, 0.5]\n",
    );
    assert_eq!(scenario.obstacles.len(), 3);
    // The text round-trips.
    assert_eq!(Scenario::from_toml(&scenario.to_toml()).unwrap(), scenario);
    let obstacles = scenario.obstacles(Workspace::Planar).unwrap();
    // The circle: distance from a point in the plane is |p - c| - r.
    assert!((obstacles[0].signed_distance([0.3, 0.8, 0.0]) - 0.15).abs() < 1e-15);
    // The capsule's axis at y = 1.
    assert!((obstacles[1].signed_distance([0.25, 0.9, 0.0]) - 0.08).abs() < 1e-15);
    // The rectangle turned by 0.5 rad: a point along its turned x axis at 0.3 from the centre
    // is 0.2 outside it, at any height (a planar rectangle is infinitely tall).
    let (s, c) = 0.5f64.sin_cos();
    for z in [0.0, 10.0] {
        let p = [-0.4 + 0.3 * c, 0.5 + 0.3 * s, z];
        assert!((obstacles[2].signed_distance(p) - 0.2).abs() < 1e-12);
    }
    let model = scenario
        .clearance_model(10, Workspace::Planar)
        .unwrap()
        .unwrap();
    assert_eq!(model.radius(), 0.01);
    assert_eq!(model.obstacles().len(), 3);
    assert_eq!(model.n_obstacle_pairs(), 30);
    // A scenario without either key measures nothing.
    assert!(
        with("")
            .clearance_model(10, Workspace::Planar)
            .unwrap()
            .is_none()
    );
}

#[test]
fn spatial_obstacles_are_read_in_space() {
    let scenario = with(
        "[[obstacles]]\nkind = \"sphere\"\ncenter = [0.3, 0.6, 0.1]\nradius = 0.05\n\
         [[obstacles]]\nkind = \"box\"\ncenter = [0.0, 0.0, 1.0]\nhalf_extents = [0.1, 0.2, 0.3]\n\
         rpy = [0.1, 0.2, 0.3]\n",
    );
    let obstacles = scenario.obstacles(Workspace::Spatial).unwrap();
    assert_eq!(
        obstacles[0],
        Obstacle::sphere([0.3, 0.6, 0.1], 0.05).unwrap()
    );
    assert_eq!(
        obstacles[1],
        Obstacle::cuboid([0.0, 0.0, 1.0], [0.1, 0.2, 0.3], [0.1, 0.2, 0.3]).unwrap()
    );
}

/// Every refusal is one line naming the obstacle's field and the problem.
#[test]
fn malformed_obstacles_are_refused_with_the_field_named() {
    let circle = "[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = 0.05\n";
    for (extra, workspace, expected) in [
        (
            "[[obstacles]]\nkind = \"sphere\"\ncenter = [0.3, 0.6, 0.0]\nradius = 0.05\n",
            Workspace::Planar,
            "obstacles[0].kind is \"sphere\", which needs a spatial arm",
        ),
        (
            circle,
            Workspace::Spatial,
            "obstacles[0].kind is \"circle\"",
        ),
        (
            "[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6, 0.0]\nradius = 0.05\n",
            Workspace::Planar,
            "obstacles[0].center must be a point [x, y] of the arm's plane, got 3 numbers",
        ),
        (
            &format!(
                "{circle}[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = -0.05\n"
            ),
            Workspace::Planar,
            "obstacles[1].radius must be non-negative, finite and at most 1e6 (m), got -0.05",
        ),
        (
            &format!(
                "{circle}{circle}[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = nan\n"
            ),
            Workspace::Planar,
            "obstacles[2].radius must be non-negative, finite and at most 1e6 (m), got NaN",
        ),
        (
            "[[obstacles]]\nkind = \"capsule\"\nfrom = [0.0, inf]\nto = [0.5, 1.0]\nradius = 0.02\n",
            Workspace::Planar,
            "obstacles[0].from must be finite and at most 1e6 in magnitude (m, the scale a run resolves), got inf",
        ),
        (
            "[[obstacles]]\nkind = \"capsule\"\nfrom = [0.0, 1.0, 0.0]\nto = [0.5, 1.0]\nradius = 0.02\n",
            Workspace::Spatial,
            "obstacles[0].to must be a point [x, y, z], got 2 numbers",
        ),
        (
            "[[obstacles]]\nkind = \"box\"\ncenter = [0.0, 1.0]\nhalf_extents = [0.0, 0.1]\n",
            Workspace::Planar,
            "obstacles[0].half_extents must be positive (m), got 0",
        ),
        (
            "[[obstacles]]\nkind = \"box\"\ncenter = [0.0, 1.0]\nhalf_extents = [0.1, 0.1]\nrpy = [0.1, 0.0, 0.0]\n",
            Workspace::Planar,
            "obstacles[0].rpy must be [0, 0, yaw] for a planar arm",
        ),
        (
            "[[obstacles]]\nkind = \"box\"\ncenter = [0.0, 1.0]\nhalf_extents = [0.1, 0.1]\nrpy = [0.5]\n",
            Workspace::Planar,
            "obstacles[0].rpy must be three angles [roll, pitch, yaw] (rad), got 1 number",
        ),
        // Beyond 1e6 m the closest points' rounding reaches the arm's millimetres.
        (
            "[[obstacles]]\nkind = \"circle\"\ncenter = [1e155, 0.0]\nradius = 0.05\n",
            Workspace::Planar,
            "obstacles[0].center must be finite and at most 1e6 in magnitude (m, the scale a run resolves), got 1e155",
        ),
        (
            "[[obstacles]]\nkind = \"capsule\"\nfrom = [-1e14, 1.03]\nto = [7e13, 1.03]\nradius = 0.01\n",
            Workspace::Planar,
            "obstacles[0].from must be finite and at most 1e6 in magnitude (m, the scale a run resolves), got -100000000000000",
        ),
        (
            "[[obstacles]]\nkind = \"box\"\ncenter = [0.0, 1.0]\nhalf_extents = [1e14, 0.1]\n",
            Workspace::Planar,
            "obstacles[0].half_extents must be finite and at most 1e6 in magnitude (m, the scale a run resolves), got 100000000000000",
        ),
        (
            "[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = 1e306\n",
            Workspace::Planar,
            "obstacles[0].radius must be non-negative, finite and at most 1e6 (m), got 1e306",
        ),
        (
            "[[obstacles]]\nkind = \"box\"\ncenter = [0.0, 1.0]\nhalf_extents = [0.1]\n",
            Workspace::Planar,
            "obstacles[0].half_extents must be [hx, hy], got 1 number",
        ),
        (
            "[arm]\nradius = -1.0\n",
            Workspace::Planar,
            "arm.radius must be non-negative and at most 1e6 (m, as an obstacle's extent), got -1",
        ),
        (
            "[arm]\nradius = 1e308\n",
            Workspace::Planar,
            "arm.radius must be non-negative and at most 1e6 (m, as an obstacle's extent), got 1e308",
        ),
    ] {
        let scenario = with(extra);
        let message = scenario
            .clearance_model(10, workspace)
            .expect_err(extra)
            .to_string();
        assert!(message.starts_with(expected), "{extra}: {message}");
        assert!(!message.contains('\n'), "{message}");
        if workspace == Workspace::Planar {
            // Building the planar scenario refuses it the same way.
            let built = scenario.build().err().expect(extra).to_string();
            assert_eq!(built, message);
        }
    }
}

#[test]
fn unknown_kinds_and_keys_and_too_many_obstacles_are_refused() {
    for extra in [
        "[[obstacles]]\nkind = \"cone\"\ncenter = [0.3, 0.6]\nradius = 0.05\n",
        "[[obstacles]]\nkind = \"circle\"\ncentre = [0.3, 0.6]\nradius = 0.05\n",
        "[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = 0.05\nrpy = [0.0, 0.0, 0.0]\n",
    ] {
        let message = Scenario::from_toml(&format!("{HOLD}{extra}"))
            .expect_err(extra)
            .to_string();
        assert!(message.contains("line "), "{message}");
        assert!(!message.contains('\n'), "{message}");
    }
    let mut scenario = with("");
    scenario.obstacles = vec![
        ObstacleSpec::Circle {
            center: vec![0.0, 2.0],
            radius: 0.1
        };
        sim_study::MAX_SCENARIO_OBSTACLES + 1
    ];
    let message = scenario.build().err().unwrap().to_string();
    assert_eq!(
        message,
        "obstacles holds 1025 obstacles, more than the 1024 a scenario may"
    );
}

/// The clearance of a segment's capsule of radius `r` to a circle, by this file's own
/// geometry: the distance from the centre to the closest point of the segment.
fn segment_circle(p: [f64; 3], q: [f64; 3], center: [f64; 2], radius: f64, r: f64) -> f64 {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let t =
        (((center[0] - p[0]) * dx + (center[1] - p[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    let (x, y) = (p[0] + t * dx, p[1] + t * dy);
    (x - center[0]).hypot(y - center[1]) - radius - r
}

/// The paper's arm straight up (`a = 0`, `alpha0 = pi/2`), held by computed torque.
fn straight(extra: &str) -> Scenario {
    with(&format!(
        "[controller]\nkind = \"computed-torque\"\n{extra}"
    ))
    .with_constant([0.0, 0.0])
}

trait Constant {
    fn with_constant(self, a: [f64; 2]) -> Self;
}

impl Constant for Scenario {
    fn with_constant(mut self, a: [f64; 2]) -> Self {
        self.reference = sim_study::ReferenceSpec::Constant { a: a.to_vec() };
        self.alpha0 = Some(sim_study::Alpha0::Fixed(std::f64::consts::FRAC_PI_2));
        self
    }
}

#[test]
fn the_clearance_of_a_straight_arm_is_its_closed_form() {
    // The arm lies on x = 0 from y = 0 to 1: a circle at (0.3, 0.5) of radius 0.05 is 0.25 from
    // its axis, and two links that share no joint are one link (0.1 m) apart along it.
    let r = 0.01;
    let scenario = straight(&format!(
        "[arm]\nradius = {r}\n[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.5]\nradius = 0.05\n"
    ));
    let run = scenario.build().unwrap().run().unwrap();
    let s = &run.summary;
    assert!(
        (s.min_clearance_m.unwrap() - (0.25 - r)).abs() < 1e-12,
        "{s:?}"
    );
    assert!((s.min_self_clearance_m.unwrap() - (0.1 - 2.0 * r)).abs() < 1e-12);
    assert_eq!(s.torque_projection_share, None);
    // Without either key the summary has neither field, and the run is the same bit for bit.
    let plain = straight("").build().unwrap().run().unwrap();
    assert_eq!(plain.summary.min_clearance_m, None);
    assert_eq!(plain.summary.min_self_clearance_m, None);
    assert_eq!(plain.record.a, run.record.a);
    assert_eq!(plain.record.joint_points, run.record.joint_points);
    // The recorded points are the chain's: the base at the origin, the tip the recorded tip.
    let points = run.record.joint_points_at(3);
    assert_eq!(points.len(), 11);
    assert_eq!(points[0], [0.0; 3]);
    assert_eq!([points[10][0], points[10][1]], run.record.tip[3]);
}

/// Computed torque drives the arm from straight to the shape `a = (0.3, -0.2)`; an obstacle
/// put where that shape's last link lies is hit: the unconstrained controller collides, which the
/// clearance shows (negative), and the clearance recomputed from the recorded points with this
/// file's own geometry is the summary's, the smallest over every sample.
#[test]
fn an_unconstrained_controller_collides_and_the_clearance_shows_it() {
    let target = [0.3, -0.2];
    let mut probe = straight("").with_constant(target);
    probe.duration = 0.01;
    let run = probe.build().unwrap().run().unwrap();
    let shape = run.record.joint_points_at(0).to_vec();
    // Start straight, step to the target at 0.05 s: the arm sweeps from x = 0 to the curved shape.
    let mid = [
        0.5 * (shape[9][0] + shape[10][0]),
        0.5 * (shape[9][1] + shape[10][1]),
    ];
    assert!(mid[0].abs() > 0.1, "{mid:?}");
    let (radius, r) = (0.02, 0.005);
    let mut scenario = with(&format!(
        "[controller]\nkind = \"computed-torque\"\n[arm]\nradius = {r}\n\
         [[obstacles]]\nkind = \"circle\"\ncenter = [{}, {}]\nradius = {radius}\n",
        mid[0], mid[1]
    ));
    scenario.alpha0 = Some(sim_study::Alpha0::Fixed(std::f64::consts::FRAC_PI_2));
    scenario.reference = sim_study::ReferenceSpec::Step {
        initial: Some(vec![0.0, 0.0]),
        target: target.to_vec(),
        time: 0.05,
    };
    scenario.duration = 0.5;
    let run = scenario.build().unwrap().run().unwrap();
    let least = run.summary.min_clearance_m.unwrap();
    assert!(
        least < -radius,
        "the arm goes through the obstacle: {least}"
    );
    // Every controller sample is recorded here, so the recorded minimum is the summary's.
    assert_eq!(run.summary.recorded_samples, run.summary.controller_samples);
    let mut recomputed = f64::INFINITY;
    for k in 0..run.record.len() {
        let p = run.record.joint_points_at(k);
        for link in 0..10 {
            recomputed = recomputed.min(segment_circle(p[link], p[link + 1], mid, radius, r));
        }
    }
    assert!(
        (recomputed - least).abs() < 1e-12,
        "{recomputed} vs {least}"
    );
    // At the start the straight arm is clear of it.
    let p = run.record.joint_points_at(0);
    assert!((0..10).all(|l| segment_circle(p[l], p[l + 1], mid, radius, r) > 0.0));
}
