//! `hrm simulate` of a scenario on a URDF arm (`[arm] urdf`): computed torque on the full
//! spatial chain in joint space ([`Scenario::run_chain`]), written as `scenario.toml`,
//! `summary.json` and `timeseries.csv` (`t`, then `q_i`, `q_ref_i`, `tau_i` per joint).

use crate::console;
use crate::output_dir::OutputDir;
use lane_math::Compact;
use sim_core::{ChainFailure, ChainRun};
use sim_study::Scenario;
use std::fmt::Write as _;
use std::path::Path;

/// Runs `scenario` (its arm a URDF chain) and writes its files into `out`; a run that stops
/// writes them up to the stop (`summary.json` with its `error` and `stopped_at_s`) and fails with
/// its error, one that fails before its first recorded sample writes nothing.
pub fn simulate(scenario: &Scenario, out: &Path) -> Result<(), String> {
    let (run, stop) = ChainFailure::split(scenario.run_chain()).map_err(|e| e.to_string())?;
    let summary = &run.summary;
    let n = summary.joint_error_rms.len();
    let staging = OutputDir::create(out, "simulate")?;
    let dir = staging.path();
    let mut json = sim_study::summary_json::chain(scenario, "urdf", &run);
    let mut stopped = String::new();
    if let Some(error) = &stop {
        json = sim_study::summary_json::stopped(json, error, &run);
        stopped = format!("stopped: {error}\n");
    }
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n";
    write(&dir.join("summary.json"), &text)?;
    write(&dir.join("scenario.toml"), &scenario.to_toml())?;
    write(&dir.join("timeseries.csv"), &chain_timeseries(&run))?;
    staging.commit()?;
    let rms = |values: &[f64]| (values.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    console::print(&format!(
        "{}: computed torque on a {n}-joint URDF chain: joint error RMS {:.3e} (over joints and \
         time), max {:.3e}, final |q - q_ref| {:.3e}\n{stopped}wrote {}\n",
        scenario.name,
        rms(&summary.joint_error_rms),
        summary
            .joint_error_max
            .iter()
            .fold(0.0f64, |m, e| m.max(*e)),
        summary.final_error,
        console::shown(out)
    ))?;
    stop.map_or(Ok(()), |error| Err(error.to_string()))
}

/// The `timeseries.csv` of a joint-space run: `t`, then `q_i`, `q_ref_i`, `tau_i` per joint.
pub fn chain_timeseries(run: &ChainRun) -> String {
    let record = &run.record;
    let n = run.summary.joint_error_rms.len();
    let mut csv = String::from("t");
    for series in ["q", "q_ref", "tau"] {
        for i in 1..=n {
            let _ = write!(csv, ",{series}_{i}");
        }
    }
    csv.push('\n');
    for (k, t) in record.t.iter().enumerate() {
        let _ = write!(csv, "{}", Compact(*t));
        for series in [&record.q, &record.q_ref, &record.tau] {
            for value in &series[k * n..(k + 1) * n] {
                let _ = write!(csv, ",{}", Compact(*value));
            }
        }
        csv.push('\n');
    }
    csv
}

pub(crate) fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_urdf_example_writes_its_summary_and_time_series() {
        let example =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/urdf-arm/step.toml");
        let scenario = Scenario::load(&example).unwrap();
        let dir = std::env::temp_dir().join(format!("hrm-chain-simulate-{}", std::process::id()));
        simulate(&scenario, &dir).unwrap();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["joints"], 7);
        assert!(summary["final_error"].as_f64().unwrap() < 1e-5);
        let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 1001);
        assert_eq!(csv.lines().next().unwrap().split(',').count(), 1 + 21);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
