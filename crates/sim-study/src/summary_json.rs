//! The `summary.json` documents of the `hrm` command, built here so that every front end (the
//! command, the Python package) writes the same keys and numbers.
//!
//! - [`run`]: one closed-loop run (`hrm simulate`, and each run of the main job): the fields of
//!   [`Summary`](sim_core::Summary); a run that stopped adds its `error` and the time it
//!   `stopped_at_s`; a scenario that could not be built has only its `error`.
//! - [`sweep`]: a whole sweep (`hrm sweep`, `hrm sweep merge`): `{"config": ..., "cells": [...]}`
//!   (`docs/sweep.md`).

use crate::study::{Cell, RunOutcome, Stopped, SweepConfig};
use serde_json::{Value, json};

/// The `summary.json` of one run: its [`Summary`](sim_core::Summary)'s fields; for a run that
/// stopped, those of the data up to the stop plus `error` (why and when) and `stopped_at_s`;
/// for a scenario that could not be built, `{"error": ...}` alone.
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
                fields.insert("error".into(), json!(error.to_string()));
                fields.insert("stopped_at_s".into(), json!(run.summary.simulated_s));
            }
            summary
        }
    }
}

/// The `summary.json` of a whole sweep: its configuration and its cells
/// ([`cells`](crate::study::cells) of the merged runs).
pub fn sweep(config: &SweepConfig, cells: &[Cell]) -> Value {
    json!({ "config": config, "cells": cells })
}
