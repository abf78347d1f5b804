//! The main job's experiment set: every shipped scenario with every controller, in parallel.

use super::outcome::{RunOutcome, run_scenario};
use crate::{ControllerKind, Scenario, ScenarioError};
use rayon::prelude::*;

/// One finished (or stopped) run of a comparison: its scenario, controller, the names of its
/// modal coordinates and its outcome (the run, or why it could not be built or had to stop).
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonRun {
    /// The scenario's name.
    pub scenario: String,
    /// The controller.
    pub controller: ControllerKind,
    /// The names of the modal coordinates ([`Scenario::coordinate_names`]).
    pub coordinates: Vec<String>,
    /// The run, or why it stopped and what it recorded until then.
    pub result: RunOutcome,
}

/// Every shipped scenario ([`Scenario::builtin_names`]), in order.
pub fn builtin_scenarios() -> Result<Vec<Scenario>, ScenarioError> {
    Scenario::builtin_names().map(Scenario::builtin).collect()
}

/// Runs `scenario` with controller `kind`.
pub fn run_one(scenario: &Scenario, kind: ControllerKind) -> ComparisonRun {
    let mut scenario = scenario.clone();
    scenario.controller.kind = kind;
    let result = run_scenario(&scenario);
    ComparisonRun {
        scenario: scenario.name.clone(),
        controller: kind,
        coordinates: scenario.coordinate_names(),
        result,
    }
}

/// Runs every scenario with every controller ([`ControllerKind::ALL`]) in parallel (rayon), calling
/// `each` on every run as it finishes (e.g. to write its files), and returns the runs in a fixed
/// order: scenario by scenario, controllers in [`ControllerKind::ALL`] order. The first error of
/// `each` (of the caller's own type `E`) stops the comparison.
///
/// ```
/// use sim_study::study::{builtin_scenarios, compare};
/// let mut scenarios = builtin_scenarios()?;
/// scenarios.retain(|s| s.name == "paper-responses-step");
/// scenarios[0].duration = 0.2;
/// let runs = compare(&scenarios, |_| Ok::<(), std::convert::Infallible>(()))?;
/// assert_eq!(runs.len(), sim_study::ControllerKind::ALL.len());
/// assert!(runs.iter().all(|r| r.result.is_ok()));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn compare<E: Send>(
    scenarios: &[Scenario],
    each: impl Fn(&ComparisonRun) -> Result<(), E> + Sync,
) -> Result<Vec<ComparisonRun>, E> {
    let jobs: Vec<(&Scenario, ControllerKind)> = scenarios
        .iter()
        .flat_map(|scenario| ControllerKind::ALL.map(|kind| (scenario, kind)))
        .collect();
    jobs.par_iter()
        .map(|&(scenario, kind)| {
            let run = run_one(scenario, kind);
            each(&run)?;
            Ok(run)
        })
        .collect()
}
