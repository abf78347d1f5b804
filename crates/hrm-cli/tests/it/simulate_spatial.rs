//! `hrm simulate` and `hrm view` on a spatial modal arm: the run's files with the tip in space,
//! and the viewer's page of the folder.

use crate::common::{hrm, scratch};
use sim_study::Scenario;

#[test]
fn simulate_and_view_a_spatial_scenario() {
    let dir = scratch("simulate-spatial");
    let mut scenario = Scenario::builtin("spatial-tracking").unwrap();
    scenario.duration = 0.2;
    let file = dir.join("spatial.toml");
    std::fs::write(&file, scenario.to_toml()).unwrap();
    let out = dir.join("run");
    let run = hrm(&[
        "simulate",
        "--scenario",
        file.to_str().unwrap(),
        "--controller",
        "computed-torque",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for column in [
        "az1",
        "ay2_ref",
        "tau4",
        "tip_z",
        "tip_ref_z",
        "joint_tau20",
    ] {
        assert!(header.contains(&column), "{column} in {header:?}");
    }
    // The tip's z column holds the chain's tip: the start on the circle, in the x-y plane.
    let z = header.iter().position(|c| *c == "tip_ref_z").unwrap();
    let first: Vec<f64> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(first[z].abs() < 1e-9, "{}", first[z]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(
        summary["tip_error_rms_m"].as_f64().unwrap() < 1e-3,
        "{summary}"
    );
    let page = out.join("view.html");
    let view = hrm(&[
        "view",
        out.to_str().unwrap(),
        "--out",
        page.to_str().unwrap(),
    ]);
    assert!(
        view.status.success(),
        "{}",
        String::from_utf8_lossy(&view.stderr)
    );
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("\"dims\":3"), "a 3-D view");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn simulate_plans_spatial_clutter_and_its_links_keep_the_margin() {
    let dir = scratch("simulate-spatial-clutter");
    let out = dir.join("run");
    let run = hrm(&[
        "simulate",
        "--scenario",
        "spatial-clutter",
        "--controller",
        "computed-torque",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let scenario = Scenario::builtin("spatial-clutter").unwrap();
    let Some(sim_study::TaskSpec::Reach { target, .. }) = &scenario.task else {
        panic!("spatial-clutter has a reach task")
    };
    let obstacles = scenario.obstacles(sim_study::Workspace::Spatial).unwrap();
    let radius = scenario.arm.radius.unwrap();
    // links.csv: t, then x, y, z of the base and of every link's end.
    let csv = std::fs::read_to_string(out.join("links.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows[0].len(), 1 + 3 * 11);
    // The clearance of the drawn links, by sampling each link's axis against the obstacles'
    // distance functions: never below the loop's own minimum (over every controller sample,
    // a superset of the recorded ones) by more than the sampling's resolution, and above 5 mm.
    let mut smallest = f64::INFINITY;
    for row in &rows {
        for link in 0..10 {
            let (a, b) = (
                &row[1 + 3 * link..4 + 3 * link],
                &row[4 + 3 * link..7 + 3 * link],
            );
            for k in 0..=100 {
                let t = k as f64 / 100.0;
                let q: [f64; 3] = std::array::from_fn(|d| a[d] + t * (b[d] - a[d]));
                for o in &obstacles {
                    smallest = smallest.min(o.signed_distance(q) - radius);
                }
            }
        }
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let loop_min = summary["min_clearance_m"].as_f64().unwrap();
    assert!(
        smallest > 0.005 && loop_min > 0.005,
        "{smallest} {loop_min}"
    );
    assert!(smallest >= loop_min - 1e-9, "{smallest} < {loop_min}");
    assert!(smallest - loop_min < 2e-3, "{smallest} vs {loop_min}");
    // The tip (the last point) ends on the target.
    let last = rows.last().unwrap();
    let tip = &last[last.len() - 3..];
    let miss = (0..3)
        .map(|d| (tip[d] - target[d]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(miss < 3e-3, "{miss} m");
}
