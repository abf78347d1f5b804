#![doc = include_str!("../README.md")]

mod chain_loop;
pub mod controller;
mod error;
mod noise;
pub mod ode;
mod record;
pub mod reference;
mod simulation;

/// The most modal coordinates a loop may have: `2K + 1` for the most harmonics a modal map may
/// have ([`backbone_kin::MAX_HARMONICS`]).
pub const MAX_COORDINATES: usize = 2 * backbone_kin::MAX_HARMONICS + 1;

pub use chain_loop::{
    ChainFailure, ChainLoopSettings, ChainRecord, ChainRun, ChainSummary, run_chain_loop,
    run_chain_loop_mpc,
};
pub use error::{ControllerFailure, SimError, StoppedRun, check_non_negative};
pub use ode::MAX_RK4_STEPS;
pub use record::{Record, Summary, TorqueLimitExceeded};
pub use simulation::{
    ControlSample, ControllerFactory, Integrator, JOINT_ANGLE_APPROACH_S, Lockstep, LoopHooks,
    LoopSettings, MAX_CONTROLLER_SAMPLES, MAX_LOOP_WORK, MAX_MODAL_MAGNITUDE, MAX_RECORDED_VALUES,
    MAX_RUN_WORK, MIN_JOINT_TORQUE_LIMIT_NM, NoHooks, Observation, Prepared, RATE_NAMES,
    ReferenceFactory, Run, RunFailure, RunNoise, Simulation, check_coordinates, check_loop_work,
    check_rates,
};
