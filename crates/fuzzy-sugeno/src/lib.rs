#![doc = include_str!("../README.md")]

pub mod analysis;
mod batch;
mod builder;
mod compiled_mf;
mod error;
mod eval;
#[cfg(feature = "formats")]
mod export_c;
#[cfg(feature = "formats")]
mod fcl;
#[cfg(feature = "formats")]
mod fis;
mod kernel;
#[cfg(feature = "learn")]
pub mod learn;
mod membership;
mod options;
mod paper;
mod rules;
mod separable;
mod system;

pub use analysis::{AnalysisOptions, AnalysisReport, COVERAGE_ROUNDING, MAX_SAMPLES_PER_INPUT};
pub use builder::SystemBuilder;
pub use error::{ConsequentParameter, FuzzyError, LearningProblem, SystemProblem};
pub use eval::{Evaluator, OutsideRange};
#[cfg(feature = "formats")]
pub use export_c::CSource;
#[cfg(feature = "formats")]
pub use fis::FisNote;
pub use membership::MembershipFn;
pub use options::{EvalOptions, NoRuleFired, OutOfRange};
pub use paper::{PaperController, paper_controller};
pub use system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable,
    Methods, OrMethod, OutputFn, OutputTerm, OutputVariable, Rule,
};
