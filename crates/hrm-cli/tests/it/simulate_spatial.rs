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
