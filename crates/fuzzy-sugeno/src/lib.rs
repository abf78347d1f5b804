//! Takagi-Sugeno fuzzy inference (section 4 of *Modeling of Hyper-Redundant Manipulators
//! Dynamics and Design of Fuzzy Controller for the System*), grown into a general engine:
//!
//! - zero- and first-order Sugeno systems with any number of inputs and outputs, singleton
//!   fuzzifier, product or minimum AND, probabilistic-sum or maximum OR, rule weights, negated
//!   and "don't care" antecedents, centre-average (eq 21) or weighted-sum defuzzification;
//! - MATLAB's membership functions, validated when a system is built ([`MembershipFn`]);
//! - allocation-free evaluation with explicit policies for out-of-range inputs and for outputs
//!   on which no rule fires, per-rule firing strengths and a batch API ([`Evaluator`]);
//! - MATLAB `.fis` read and write ([`FuzzySystem::from_fis`], [`FuzzySystem::to_fis`]),
//!   reading the habits of files from older MATLAB releases, Octave and fuzzylite, with notes of
//!   what was accepted but ignored ([`FuzzySystem::from_fis_with_notes`], [`FisNote`]);
//! - export as self-contained C99 ([`FuzzySystem::to_c`]); IEC 61131-7 FCL read and write
//!   ([`FuzzySystem::from_fcl`], [`FuzzySystem::to_fcl`]);
//! - systems learned from data, `genfis` and ANFIS training ([`learn`]);
//! - Wang's completeness, consistency and continuity checks ([`FuzzySystem::analyze`]);
//! - the paper's controller as a preset ([`paper_controller`], [`PaperController`]).
//!
//! ```
//! use fuzzy_sugeno::{paper_controller, Evaluator};
//!
//! let mut controller = Evaluator::new(paper_controller());
//! let mut tau = [0.0; 2];
//! // Both errors and rates at zero: no action (eq 21 with symmetric constants).
//! controller.eval(&[0.0, 0.0, 0.0, 0.0], &mut tau)?;
//! assert_eq!(tau, [0.0, 0.0]);
//! // Which rules fired, and how strongly (all 16 at 1/16 at the origin).
//! assert!(controller.firing_strengths().iter().all(|&w| w == 0.0625));
//! # Ok::<(), fuzzy_sugeno::FuzzyError>(())
//! ```
#![deny(missing_docs)]

pub mod analysis;
mod builder;
mod error;
mod eval;
mod export_c;
mod fcl;
mod fis;
pub mod learn;
mod membership;
mod paper;
mod system;

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

pub use analysis::{AnalysisOptions, AnalysisReport};
pub use builder::SystemBuilder;
pub use error::{FuzzyError, SystemProblem};
pub use eval::{EvalOptions, Evaluator, NoRuleFired, OutOfRange};
pub use export_c::CSource;
pub use fis::FisNote;
pub use membership::MembershipFn;
pub use paper::{PaperController, paper_controller};
pub use system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable,
    Methods, OrMethod, OutputFn, OutputTerm, OutputVariable, Rule,
};
