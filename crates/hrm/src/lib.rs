#![doc = include_str!("../README.md")]

pub use backbone_kin;
pub use fuzzy_sugeno;
pub use manip_dyn;
pub use modal_reduce;
pub use optimal_ctl;
pub use sim_core;
pub use sim_study;

/// What a first program needs, in one `use hrm::prelude::*;`.
pub mod prelude {
    pub use backbone_kin::{BackboneCurve, BaseAngle, Branch, HarmonicIk, ModalMap};
    pub use fuzzy_sugeno::{Evaluator, FuzzySystem, PaperController, paper_controller};
    pub use manip_dyn::{ChainModel, Link};
    pub use modal_reduce::{
        Plant, PlantData, ReducedData, ReducedModel, forward_dynamics, joint_torques, reduced_terms,
    };
    pub use sim_core::controller::{
        ComputedTorque, ControlContext, Controller, ControllerError, FuzzyController, ModalState,
        PdController,
    };
    pub use sim_core::reference::{
        CartesianPath, PathShape, Reference, ReferenceSample, Sinusoid, Step,
    };
    pub use sim_core::{Integrator, LoopSettings, Run, SimError, Simulation};
    pub use sim_study::{ControllerKind, Scenario};
}
