//! How one run of a study ended: [`RunOutcome`], the one outcome the comparison, the sweeps, the
//! shards, the command line and the Python package share, with its typed error [`RunError`].

use crate::Scenario;
use lane_math::{Classify, ErrorClass};
use serde::{Deserialize, Serialize};
use sim_core::{Run, RunFailure, SimError, Summary};

/// How a run ended: the [`Run`] (record and summary) if it ran to the end, or [`Stopped`]: why it
/// did not, with what it recorded until then. A sweep keeps of it the metrics
/// ([`StoredOutcome::of`](super::StoredOutcome::of)).
pub type RunOutcome = Result<Run, Stopped>;

/// Why a run of a study did not complete.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The scenario could not be built into a simulation, or the simulation stopped (divergence,
    /// a runaway tracking error, a non-finite control, ...).
    #[error(transparent)]
    Simulation(#[from] SimError),
    /// The run completed, but a summary metric came out non-finite (a sweep keeps finite
    /// metrics only).
    #[error("the run's summary metric {name} came out {value}, not finite")]
    NonFiniteMetric {
        /// The metric's key (`summary.json`'s).
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

impl Classify for RunError {
    /// A simulation's error keeps its class; non-finite metrics are
    /// [`Numerical`](ErrorClass::Numerical).
    fn class(&self) -> ErrorClass {
        match self {
            Self::Simulation(error) => error.class(),
            Self::NonFiniteMetric { .. } => ErrorClass::Numerical,
        }
    }
}

/// A run that did not complete: why, and what it recorded until then.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error}")]
pub struct Stopped {
    /// The error that stopped the run, or refused to build it.
    pub error: RunError,
    /// The record and the summary up to the stop (what [`RunFailure`] keeps); `None` if the
    /// scenario could not be built.
    pub partial: Option<Box<Run>>,
}

impl Stopped {
    /// A run that could not be built: `error`, and nothing recorded.
    pub fn not_built(error: impl Into<RunError>) -> Self {
        Self {
            error: error.into(),
            partial: None,
        }
    }

    /// Simulated time reached (s): the partial run's, 0 for a run that was not built.
    pub fn simulated_s(&self) -> f64 {
        self.partial
            .as_ref()
            .map_or(0.0, |run| run.summary.simulated_s)
    }
}

impl From<Box<RunFailure>> for Stopped {
    fn from(failure: Box<RunFailure>) -> Self {
        let RunFailure {
            error,
            record,
            summary,
        } = *failure;
        Self {
            error: error.into(),
            partial: Some(Box::new(Run { record, summary })),
        }
    }
}

/// Builds `scenario` and runs it to the end or to the stop.
///
/// ```
/// use sim_study::Scenario;
/// use sim_study::study::run_scenario;
///
/// let mut scenario = Scenario::builtin("paper-responses-step")?;
/// scenario.duration = 0.15;
/// scenario.limits.max_modal_error = 1e-9; // stops at the step, t = 0.1 s
/// let stopped = run_scenario(&scenario).unwrap_err();
/// assert!(stopped.to_string().contains("runaway"));
/// assert!(stopped.simulated_s() > 0.0 && stopped.partial.is_some());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn run_scenario(scenario: &Scenario) -> RunOutcome {
    let mut simulation = scenario.build().map_err(Stopped::not_built)?;
    Ok(simulation.run()?)
}

/// The summary metrics a sweep keeps of a run (see [`Summary`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunMetrics {
    /// Tip error RMS (m).
    pub tip_error_rms_m: f64,
    /// Largest tip error (m).
    pub tip_error_max_m: f64,
    /// Modal error RMS per coordinate (rad).
    pub modal_error_rms_rad: Vec<f64>,
    /// Largest joint torque (N m).
    pub peak_joint_torque_nm: f64,
    /// Control effort (N^2 m^2 s).
    pub control_effort_n2m2s: f64,
}

impl RunMetrics {
    /// The kept metrics of `summary`, or [`RunError::NonFiniteMetric`] naming the first that is
    /// not finite.
    pub fn from_summary(s: &Summary) -> Result<Self, RunError> {
        let m = RunMetrics {
            tip_error_rms_m: s.tip_error_rms_m,
            tip_error_max_m: s.tip_error_max_m,
            modal_error_rms_rad: s.modal_error_rms_rad.clone(),
            peak_joint_torque_nm: s.peak_joint_torque_nm,
            control_effort_n2m2s: s.control_effort_n2m2s,
        };
        let non_finite = m.named().find(|(_, value)| !value.is_finite());
        match non_finite {
            None => Ok(m),
            Some((name, value)) => Err(RunError::NonFiniteMetric { name, value }),
        }
    }

    /// Every metric with its key, in `summary.json`'s order of fields (the modal RMS one a
    /// coordinate).
    pub(crate) fn named(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        let named = [
            ("tip_error_rms_m", self.tip_error_rms_m),
            ("tip_error_max_m", self.tip_error_max_m),
            ("peak_joint_torque_nm", self.peak_joint_torque_nm),
            ("control_effort_n2m2s", self.control_effort_n2m2s),
        ];
        let modal = (self.modal_error_rms_rad.iter()).map(|&v| ("modal_error_rms_rad", v));
        named.into_iter().chain(modal)
    }
}
