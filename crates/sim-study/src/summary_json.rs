//! The `summary.json` documents of the `hrm` command, built here so that every front end (the
//! command, the Python package) writes the same keys and numbers.
//!
//! - [`run`]: one closed-loop run (`hrm simulate`, and each run of the main job): the fields of
//!   [`Summary`](sim_core::Summary); a run that stopped adds its `error` and the time it
//!   `stopped_at_s`; a scenario that could not be built has only its `error`.
//! - [`chain`]: a joint-space run on a URDF arm (`hrm simulate` with `[arm] urdf`);
//! - [`deploy`]: a deployment (`[deploy]`, `hrm simulate`, the main job, Python's
//!   `Scenario.run_deploy`): [`chain`]'s fields and the deployment metrics;
//! - [`stopped`]: either of those for a run that stopped, with its `error` and `stopped_at_s`;
//! - [`sweep`]: a whole sweep (`hrm sweep`, `hrm sweep merge`): `{"config": ..., "cells": [...]}`
//!   (`docs/sweep.md`).

use crate::study::{Cell, RunOutcome, Stopped, SweepConfig};
use crate::{DeployMetrics, DeployRun, Scenario};
use serde_json::{Value, json};
use sim_core::{ChainRun, SimError};

/// The `summary.json` of one run: its [`Summary`](sim_core::Summary)'s fields; for a run that
/// stopped, those of the data up to the stop (`null` for the statistics of a run that stopped
/// before its first recorded or controller sample) plus `error` (why and when) and
/// `stopped_at_s`; for a scenario that could not be built, `{"error": ...}` alone.
///
/// ```
/// use sim_study::study::run_one;
/// use sim_study::{ControllerKind, Scenario};
///
/// let mut scenario = Scenario::builtin("paper-responses-step")?;
/// scenario.duration = 0.05;
/// let summary = sim_study::summary_json::run(&run_one(&scenario, ControllerKind::Pd).result);
/// assert!(summary["tip_error_rms_m"].is_number() && summary.get("error").is_none());
/// scenario.duration = 0.15;
/// scenario.limits.max_modal_error = 1e-9; // stops at the step, t = 0.1 s
/// let summary = sim_study::summary_json::run(&run_one(&scenario, ControllerKind::Pd).result);
/// assert!(summary["error"].as_str().unwrap().contains("runaway"));
/// assert_eq!(summary["stopped_at_s"], summary["simulated_s"]);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run(result: &RunOutcome) -> Value {
    match result {
        Ok(run) => json!(run.summary),
        Err(Stopped {
            error,
            partial: None,
        }) => json!({ "error": error.to_string() }),
        Err(Stopped {
            error,
            partial: Some(run),
        }) => {
            let mut summary = json!(run.summary);
            if let Some(fields) = summary.as_object_mut() {
                // Statistics over no sample are not zeros: they are null.
                let empty = [
                    (run.summary.recorded_samples, &OVER_RECORDED_SAMPLES[..]),
                    (run.summary.controller_samples, &OVER_CONTROLLER_SAMPLES[..]),
                ];
                for (samples, keys) in empty {
                    if samples == 0 {
                        for key in keys {
                            if let Some(value) = fields.get_mut(*key) {
                                *value = Value::Null;
                            }
                        }
                    }
                }
                fields.insert("error".into(), json!(error.to_string()));
                fields.insert("stopped_at_s".into(), json!(run.summary.simulated_s));
            }
            summary
        }
    }
}

/// The [`Summary`](sim_core::Summary) fields taken over the recorded samples.
const OVER_RECORDED_SAMPLES: [&str; 4] = [
    "tip_error_rms_m",
    "tip_error_max_m",
    "modal_error_rms_rad",
    "modal_error_max_rad",
];

/// The [`Summary`](sim_core::Summary) fields taken over the controller samples.
const OVER_CONTROLLER_SAMPLES: [&str; 8] = [
    "peak_modal_torques_nm",
    "peak_joint_torque_nm",
    "peak_joint_torques_nm",
    "control_effort_n2m2s",
    "tau_star_clamped_fraction",
    "torque_projection_share",
    "min_clearance_m",
    "min_self_clearance_m",
];

/// The `summary.json` of a whole sweep: its configuration and its cells
/// ([`cells`](crate::study::cells) of the merged runs).
pub fn sweep(config: &SweepConfig, cells: &[Cell]) -> Value {
    json!({ "config": config, "cells": cells })
}

/// The `summary.json` fields of a joint-space run of `scenario` on an arm of kind `arm`
/// (`"urdf"`, `"deploy"`) under the scenario's controller.
pub fn chain(scenario: &Scenario, arm: &str, run: &ChainRun) -> Value {
    let summary = &run.summary;
    let mut fields = json!({
        "scenario": scenario.name,
        "controller": scenario.controller.kind.name(),
        "arm": arm,
        "joints": summary.joint_error_rms.len(),
        "controller_samples": summary.controller_samples,
        "steps": summary.steps,
        "joint_error_rms": summary.joint_error_rms,
        "joint_error_max": summary.joint_error_max,
        "final_error": summary.final_error,
        "peak_joint_efforts": summary.peak_joint_efforts,
    });
    // A URDF arm's actuators saturate at their `<limit effort>`: how often they did.
    if arm == "urdf" {
        fields["effort_limited_share"] = json!(summary.effort_limited_share);
    }
    fields
}

/// The `summary.json` of a deployment: [`chain`]'s fields, then `deploy_tip_error_m`,
/// `deploy_shape_deviation_pct`, `deploy_min_wall_clearance_m`, `deploy_min_self_clearance_m`
/// (`null` below three links) and `deploy_length_m` of the run (over every recorded sample, the
/// rows of its `links.csv`) and the same of the kinematic plan it tracked under `plan`.
pub fn deploy(scenario: &Scenario, run: &DeployRun) -> Value {
    let mut summary = chain(scenario, "deploy", &run.run);
    let metrics = |m: &DeployMetrics| {
        json!({
            "deploy_tip_error_m": m.tip_error,
            "deploy_shape_deviation_pct": m.shape_deviation_percent,
            "deploy_min_wall_clearance_m": m.min_wall_clearance,
            // `+inf` (no two links that share no joint) is written `null`.
            "deploy_min_self_clearance_m": m.min_self_clearance,
            "deploy_length_m": m.deployed_length,
        })
    };
    if let (Some(fields), Value::Object(own)) = (summary.as_object_mut(), metrics(&run.metrics)) {
        fields.extend(own);
        fields.insert("plan".into(), metrics(&run.plan));
    }
    summary
}

/// A [`chain`] or [`deploy`] document `summary` of `run`, a joint-space run that stopped with
/// `error`: its fields over the samples up to the stop, plus `error` and `stopped_at_s` (the time
/// of the run's last recorded sample), as [`run`] marks a modal run that stopped.
pub fn stopped(mut summary: Value, error: &SimError, run: &ChainRun) -> Value {
    if let Some(fields) = summary.as_object_mut() {
        fields.insert("error".into(), json!(error.to_string()));
        fields.insert("stopped_at_s".into(), json!(run.record.t.last()));
    }
    summary
}
