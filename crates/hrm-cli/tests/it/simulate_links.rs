//! `hrm simulate` with obstacles: `links.csv` holds the chain's points at every recorded sample,
//! and an independent recomputation of the clearance from it (this file's own geometry: the
//! distance from a circle's centre to each link's segment) gives the summary's
//! `min_clearance_m` when every sample is recorded.

use crate::common::{hrm, scratch};

/// Computed torque steps the paper's arm from straight up to `a = (0.3, -0.2)` with a disc near
/// its path, every controller sample recorded.
const SCENARIO: &str = r#"name = "obstacle"
duration = 0.3
alpha0 = 1.5707963267948966
[arm]
radius = 0.01
[[obstacles]]
kind = "circle"
center = [0.25, 0.85]
radius = 0.05
[reference]
kind = "step"
initial = [0.0, 0.0]
target = [0.3, -0.2]
time = 0.05
[controller]
kind = "computed-torque"
period = 0.001
[integrator]
method = "rk4"
dt = 0.001
"#;

/// `hrm simulate --scenario SCENARIO --out OUT`.
fn simulate(scenario: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    hrm(&[
        "simulate",
        "--scenario",
        scenario.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn links_csv_holds_the_points_the_clearance_is_measured_from() {
    let dir = scratch("simulate-links");
    let scenario = dir.join("obstacle.toml");
    std::fs::write(&scenario, SCENARIO).unwrap();
    let out = dir.join("out");
    let output = simulate(&scenario, &out);
    assert!(output.status.success(), "{output:?}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let run = if summary.get("runs").is_some() {
        summary["runs"][0].clone()
    } else {
        summary.clone()
    };
    let least = run["min_clearance_m"]
        .as_f64()
        .unwrap_or_else(|| panic!("{summary}"));
    let least_self = run["min_self_clearance_m"].as_f64().unwrap();
    let csv = std::fs::read_to_string(out.join("links.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 1 + 2 * 11);
    assert_eq!(&header[..5], ["t", "x0", "y0", "x1", "y1"]);
    assert_eq!(header[22], "y10");
    let (center, radius, r) = ([0.25, 0.85], 0.05, 0.01);
    let mut recomputed = f64::INFINITY;
    let mut rows = 0;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let points: Vec<[f64; 2]> = (0..11).map(|j| [v[1 + 2 * j], v[2 + 2 * j]]).collect();
        assert_eq!(points[0], [0.0, 0.0]);
        for link in 0..10 {
            let (p, q) = (points[link], points[link + 1]);
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            let t = (((center[0] - p[0]) * dx + (center[1] - p[1]) * dy) / (dx * dx + dy * dy))
                .clamp(0.0, 1.0);
            let d = (p[0] + t * dx - center[0]).hypot(p[1] + t * dy - center[1]) - radius - r;
            recomputed = recomputed.min(d);
        }
        rows += 1;
    }
    assert_eq!(rows, 301);
    // The numbers are written in shortest round-trip form: the same points, the same minimum.
    assert!(
        (recomputed - least).abs() < 1e-12,
        "{recomputed} vs {least}"
    );
    assert!(least < 0.05, "the arm passes near the disc: {least}");
    assert!(
        least_self > 0.0 && least_self <= 0.1 - 2.0 * r + 1e-12,
        "{least_self}"
    );
}

/// The same step with the disc on the arm's final tip: the run enters it, and says so on
/// standard error (it reports a collision rather than refuses it).
#[test]
fn a_run_that_enters_an_obstacle_warns() {
    let dir = scratch("simulate-collision");
    let scenario = dir.join("collision.toml");
    std::fs::write(
        &scenario,
        SCENARIO.replace("center = [0.25, 0.85]", "center = [0.19, 0.95]"),
    )
    .unwrap();
    let out = dir.join("out");
    let output = simulate(&scenario, &out);
    assert!(output.status.success(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with("warning: the arm reaches ") && stderr.contains(" mm into an obstacle"),
        "{stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    // Clear of the disc, nothing is said.
    std::fs::write(&scenario, SCENARIO).unwrap();
    let output = simulate(&scenario, &out);
    assert!(
        output.status.success() && output.stderr.is_empty(),
        "{output:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
