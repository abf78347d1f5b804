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
            "obstacles[1].radius must be non-negative and finite (m), got -0.05",
        ),
        (
            &format!(
                "{circle}{circle}[[obstacles]]\nkind = \"circle\"\ncenter = [0.3, 0.6]\nradius = nan\n"
            ),
            Workspace::Planar,
            "obstacles[2].radius must be non-negative and finite (m), got NaN",
        ),
        (
            "[[obstacles]]\nkind = \"capsule\"\nfrom = [0.0, inf]\nto = [0.5, 1.0]\nradius = 0.02\n",
            Workspace::Planar,
            "obstacles[0].from must be finite (m), got inf",
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
        (
            "[arm]\nradius = -1.0\n",
            Workspace::Planar,
            "arm.radius must be non-negative and finite (m), got -1",
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
