//! The main job (`hrm` with no arguments) and `hrm simulate`: closed-loop runs of the shipped
//! scenarios (section 5 of the paper), a comparison table, and per-run output files.

use serde_json::json;
use sim_core::{ControllerKind, Run, Scenario};
use std::fmt::Write as _;
use std::path::Path;

/// One finished (or stopped) run: its scenario, controller and outcome.
struct Outcome {
    scenario: String,
    controller: ControllerKind,
    result: Result<Run, String>,
}

/// Runs `scenario` with `controller` (or the scenario's own) and writes its files into `out`.
pub fn simulate(name_or_path: &str, controller: Option<&str>, out: &Path) -> Result<(), String> {
    let mut scenario = Scenario::resolve(name_or_path).map_err(|e| e.to_string())?;
    if let Some(kind) = controller {
        scenario.controller.kind = kind
            .parse()
            .map_err(|e: sim_core::SimError| e.to_string())?;
    }
    let outcome = run_one(&scenario, scenario.controller.kind);
    write_outcome(&outcome, out)?;
    print!("{}", table(std::slice::from_ref(&outcome)));
    println!("wrote {}", out.display());
    match outcome.result {
        Ok(_) => Ok(()),
        Err(message) => Err(message),
    }
}

/// The main job: every shipped scenario with every controller.
pub fn main_job(out: &Path) -> Result<(), String> {
    let mut outcomes = Vec::new();
    for name in Scenario::builtin_names() {
        let scenario = Scenario::builtin(name).map_err(|e| e.to_string())?;
        for kind in ControllerKind::ALL {
            eprintln!("hrm: running {name} with {kind}");
            let outcome = run_one(&scenario, kind);
            write_outcome(&outcome, &out.join(name).join(kind.name()))?;
            outcomes.push(outcome);
        }
    }
    let summaries: Vec<_> = outcomes.iter().map(outcome_json).collect();
    write(&out.join("summary.json"), &pretty(&json!(summaries))?)?;
    let table = table(&outcomes);
    write(&out.join("comparison.txt"), &table)?;
    print!("{table}");
    println!(
        "wrote {} (summary.json, comparison.txt, one folder per run)",
        out.display()
    );
    Ok(())
}

fn run_one(scenario: &Scenario, kind: ControllerKind) -> Outcome {
    let mut scenario = scenario.clone();
    scenario.controller.kind = kind;
    let result = scenario
        .build()
        .map_err(|e| e.to_string())
        .and_then(|mut sim| sim.run().map_err(|failure| failure.error.to_string()));
    Outcome {
        scenario: scenario.name.clone(),
        controller: kind,
        result,
    }
}

fn outcome_json(outcome: &Outcome) -> serde_json::Value {
    match &outcome.result {
        Ok(run) => {
            json!({"scenario": outcome.scenario, "controller": outcome.controller.name(), "summary": run.summary})
        }
        Err(e) => {
            json!({"scenario": outcome.scenario, "controller": outcome.controller.name(), "error": e})
        }
    }
}

/// Writes `summary.json` and `timeseries.csv` of one run into `dir`.
fn write_outcome(outcome: &Outcome, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let summary = match &outcome.result {
        Ok(run) => serde_json::to_value(&run.summary).map_err(|e| e.to_string())?,
        Err(e) => json!({"error": e}),
    };
    write(&dir.join("summary.json"), &pretty(&summary)?)?;
    if let Ok(run) = &outcome.result {
        let r = &run.record;
        let mut csv = String::from(
            "t,a1,a2,a1_dot,a2_dot,a1_ref,a2_ref,tau1,tau2,tip_x,tip_y,tip_ref_x,tip_ref_y\n",
        );
        for k in 0..r.len() {
            let row = [
                r.t[k],
                r.a[k][0],
                r.a[k][1],
                r.a_dot[k][0],
                r.a_dot[k][1],
                r.a_ref[k][0],
                r.a_ref[k][1],
                r.tau_star[k][0],
                r.tau_star[k][1],
                r.tip[k][0],
                r.tip[k][1],
                r.tip_ref[k][0],
                r.tip_ref[k][1],
            ];
            let line: Vec<String> = row.iter().map(f64::to_string).collect();
            let _ = writeln!(csv, "{}", line.join(","));
        }
        write(&dir.join("timeseries.csv"), &csv)?;
    }
    Ok(())
}

/// The comparison table: tip error RMS and maximum (mm), modal error RMS, peak torques, effort.
fn table(outcomes: &[Outcome]) -> String {
    let mut s = format!(
        "{:<24} {:<16} {:>12} {:>12} {:>20} {:>20} {:>13} {:>12}\n",
        "scenario",
        "controller",
        "tip rms mm",
        "tip max mm",
        "modal rms (rad)",
        "peak tau* (N m)",
        "peak tau N m",
        "effort"
    );
    for o in outcomes {
        let _ = match &o.result {
            Ok(run) => {
                let m = &run.summary;
                writeln!(
                    s,
                    "{:<24} {:<16} {:>12.4} {:>12.4} {:>9.2e},{:>9.2e} {:>9.2},{:>9.2} {:>13.3} {:>12.4e}",
                    o.scenario,
                    o.controller.name(),
                    m.tip_error_rms_m * 1e3,
                    m.tip_error_max_m * 1e3,
                    m.modal_error_rms[0],
                    m.modal_error_rms[1],
                    m.peak_modal_torque[0],
                    m.peak_modal_torque[1],
                    m.peak_joint_torque_nm,
                    m.control_effort
                )
            }
            Err(e) => writeln!(
                s,
                "{:<24} {:<16} stopped: {e}",
                o.scenario,
                o.controller.name()
            ),
        };
    }
    s
}

fn pretty(value: &serde_json::Value) -> Result<String, String> {
    serde_json::to_string_pretty(value)
        .map(|s| s + "\n")
        .map_err(|e| e.to_string())
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simulate_writes_the_summary_keys_and_a_time_series() {
        let dir = std::env::temp_dir().join(format!("hrm-simulate-test-{}", std::process::id()));
        let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
        scenario.duration = 0.2;
        let outcome = run_one(&scenario, ControllerKind::ComputedTorque);
        write_outcome(&outcome, &dir).unwrap();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        for key in [
            "tip_error_rms_m",
            "tip_error_max_m",
            "modal_error_rms",
            "peak_modal_torque",
            "peak_joint_torque_nm",
            "steps",
        ] {
            assert!(
                summary.get(key).is_some(),
                "summary.json lacks {key}: {summary}"
            );
        }
        let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
        assert_eq!(
            csv.lines().count(),
            outcome.result.as_ref().unwrap().record.len() + 1
        );
        assert!(table(&[outcome]).contains("computed-torque"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unknown_scenario_and_controller_are_refused() {
        let dir = std::env::temp_dir();
        assert!(simulate("no-such-scenario", None, &dir).is_err());
        let err = simulate("paper-responses-step", Some("bang-bang"), &dir).unwrap_err();
        assert!(
            err.contains("fuzzy, pd, computed-torque, fuzzy-gc"),
            "{err}"
        );
    }
}
