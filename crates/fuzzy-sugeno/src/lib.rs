#![doc = include_str!("../README.md")]

pub mod analysis;
mod batch;
mod builder;
mod error;
mod eval;
mod export_c;
mod fcl;
mod fis;
mod kernel;
pub mod learn;
mod membership;
mod paper;
mod system;

pub use analysis::{AnalysisOptions, AnalysisReport, COVERAGE_ROUNDING};
pub use builder::SystemBuilder;
pub use error::{ConsequentParameter, FuzzyError, LearningProblem, SystemProblem};
pub use eval::{EvalOptions, Evaluator, NoRuleFired, OutOfRange, OutsideRange};
pub use export_c::CSource;
pub use fis::FisNote;
pub use membership::MembershipFn;
pub use paper::{PaperController, paper_controller};
pub use system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable,
    Methods, OrMethod, OutputFn, OutputTerm, OutputVariable, Rule,
};
