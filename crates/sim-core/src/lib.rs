//! Closed-loop simulation of modal-coordinate controllers on hyper-redundant manipulators:
//! section 5 of the paper *Modeling of Hyper-Redundant Manipulators Dynamics and Design
//! of Fuzzy Controller for the System*, made reproducible.
//!
//! The loop of the paper's Figures 6 and 8: a [`reference`](mod@reference) for the modal
//! coordinates `(a1, a2)` (alpha0 held fixed), a [`controller`] sampled at its own period with a
//! zero-order hold, the reduced dynamics `M* a_dd + C* + G* = tau*` (eq 15, from `modal-reduce`)
//! integrated by fixed-step RK4 or adaptive Dormand-Prince 5(4) ([`ode`]), and a [`Record`] of
//! the time series with [`Summary`] metrics (tip and modal errors, modal and joint torques,
//! control effort). Divergence stops a run with a [`RunFailure`] that keeps the data so far.
//!
//! Experiments are [`Scenario`]s, TOML files; the paper's are shipped with the crate
//! ([`Scenario::builtin_names`]): `paper-tracking` (Figures 10-11) and the
//! `paper-responses-{step,sine,noise}` responses (Figure 9). [`imitation`] learns a fuzzy
//! controller from a better teacher (computed torque) on such scenarios.
//!
//! ```
//! use sim_core::{ControllerKind, Scenario};
//!
//! let mut scenario = Scenario::builtin("paper-tracking")?;
//! scenario.duration = 0.5; // the first half second of the paper's path
//! for kind in [ControllerKind::Fuzzy, ControllerKind::ComputedTorque] {
//!     scenario.controller.kind = kind;
//!     let run = scenario.build()?.run()?;
//!     assert!(run.summary.tip_error_rms_m < 0.01, "{kind}");
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

pub mod controller;
mod error;
pub mod imitation;
mod input_file;
mod noise;
pub mod ode;
pub mod optimal;
mod record;
pub mod reference;
mod scenario;
mod simulation;
pub mod study;
pub mod summary_json;

/// The most modal coordinates a loop may have: `2K + 1` for the most harmonics a modal map may
/// have ([`backbone_kin::MAX_HARMONICS`]).
pub const MAX_COORDINATES: usize = 2 * backbone_kin::MAX_HARMONICS + 1;

pub use error::{ControllerFailure, SimError};
pub use input_file::{MAX_INPUT_FILE_BYTES, read_text_file};
pub use record::{Record, Summary, TorqueLimitExceeded};
pub use scenario::{
    Alpha0, ArmSpec, BranchSpec, CONTROLLERS, ControllerEntry, ControllerKind, ControllerSetup,
    ControllerSpec, InitialSpec, IntegratorSpec, LimitsSpec, ModalSpec, NoiseSpec, ReferenceSpec,
    Scenario, ScenarioError, SineSpec, TorqueLimit,
};
pub use simulation::{
    ControlSample, Integrator, LoopSettings, MAX_CONTROLLER_SAMPLES, MAX_RECORDED_VALUES,
    MAX_RK4_STEPS, Observation, Run, RunFailure, Simulation,
};
