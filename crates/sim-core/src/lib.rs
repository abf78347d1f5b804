#![doc = include_str!("../README.md")]

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
pub use input_file::{MAX_INPUT_FILE_BYTES, open_regular_file, read_text_file};
pub use record::{Record, Summary, TorqueLimitExceeded};
pub use scenario::{
    Alpha0, ArmSpec, BranchSpec, CONTROLLERS, ControllerEntry, ControllerKind, ControllerSetup,
    ControllerSpec, FuzzyInputRange, InitialSpec, IntegratorSpec, LimitsSpec, ModalSpec,
    ModalTorqueLimit, NoiseSpec, ReferenceSpec, Scenario, ScenarioError, SineSpec, TorqueLimit,
};
pub use simulation::{
    ControlSample, Integrator, Lockstep, LoopSettings, MAX_CONTROLLER_SAMPLES, MAX_RECORDED_VALUES,
    MAX_RK4_STEPS, Observation, Run, RunFailure, Simulation,
};
