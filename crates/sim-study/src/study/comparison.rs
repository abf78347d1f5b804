//! The main job's experiment set: every shipped scenario with every controller, in parallel.

use super::outcome::{RunOutcome, Stopped};
use crate::{ControllerKind, Scenario, ScenarioError};
use rayon::prelude::*;
use sim_core::{LoopHooks, NoHooks, Prepared, SimError};

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
    run_one_with(scenario, kind, &mut NoHooks)
}

/// [`run_one`] with `hooks` passed to the loop ([`sim_core::Simulation::run_with`]): their
/// observer sees every controller sample, for example to show a long run's progress.
///
/// ```
/// use sim_core::{ControlSample, LoopHooks};
/// use sim_study::{ControllerKind, Scenario, study::run_one_with};
///
/// struct Count(usize);
/// impl LoopHooks for Count {
///     fn observe(&mut self, _: &ControlSample) {
///         self.0 += 1;
///     }
/// }
/// let mut scenario = Scenario::builtin("paper-responses-step")?;
/// scenario.duration = 0.001; // ten controller periods of 0.1 ms: eleven samples
/// let mut count = Count(0);
/// let run = run_one_with(&scenario, ControllerKind::Pd, &mut count);
/// assert!(run.result.is_ok());
/// assert_eq!(count.0, 11);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run_one_with(
    scenario: &Scenario,
    kind: ControllerKind,
    hooks: &mut dyn LoopHooks,
) -> ComparisonRun {
    let mut scenario = scenario.clone();
    scenario.controller.kind = kind;
    let prepared = scenario.prepare();
    run_prepared_with(&scenario, prepared, hooks)
}

/// Runs `scenario` (with its own controller, seed and noise) from `prepared`, its simulation
/// prepared by [`Scenario::prepare`] or [`Scenario::prepare_with_system`], or the error that
/// refused it.
pub fn run_prepared(scenario: &Scenario, prepared: Result<Prepared, SimError>) -> ComparisonRun {
    run_prepared_with(scenario, prepared, &mut NoHooks)
}

/// [`run_prepared`] with `hooks` passed to the loop, as [`run_one_with`].
fn run_prepared_with(
    scenario: &Scenario,
    prepared: Result<Prepared, SimError>,
    hooks: &mut dyn LoopHooks,
) -> ComparisonRun {
    let result =
        match prepared.and_then(|prepared| prepared.simulation(&prepared.settings().noise())) {
            Err(error) => Err(Stopped::not_built(error)),
            Ok(mut simulation) => simulation.run_with(hooks).map_err(Stopped::from),
        };
    ComparisonRun {
        scenario: scenario.name.clone(),
        controller: scenario.controller.kind,
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
