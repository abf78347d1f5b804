//! `hrm`: planar hyper-redundant manipulators in one crate. It re-exports the toolkit's five
//! crates and a [`prelude`] of what a first program needs:
//!
//! - [`backbone_kin`]: the backbone curve (eqs 1-6), the modal map `theta = J a + theta_0`
//!   (eqs 7-11) for `K` harmonics and a fixed or free `alpha0`, numerical inverse kinematics.
//! - [`manip_dyn`]: the Lagrangian chain dynamics `M`, `C`, `G` (eq 13), ABA and RNEA.
//! - [`modal_reduce`]: the reduced dynamics `M* a_dd + C* + G* = tau*` (eqs 14-15).
//! - [`fuzzy_sugeno`]: Takagi-Sugeno systems, `.fis` files, the paper's controller (eqs 19-24).
//! - [`sim_core`]: the closed loop (controllers, references, integrators, scenarios).
//!
//! The first program (also `examples/custom_controller.rs`, which CI runs): a 20-link arm, its
//! reduced forward dynamics at a state, the paper's fuzzy controller evaluated once, and a closed
//! loop with a controller written on the spot.
//!
//! ```
//! use hrm::prelude::*;
//!
//! // A 20-link arm of 5 cm and 50 g links, the paper's modal family with alpha0 = pi/2.
//! let arm = ChainModel::uniform(20, 0.05, 0.05, 9.81)?;
//! let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(20, std::f64::consts::FRAC_PI_2)?)?;
//!
//! // The reduced forward dynamics at a state, without torque.
//! let mut data = ReducedData::new(&model);
//! let mut a_ddot = [0.0; 2];
//! forward_dynamics(&model, &mut data, &[0.3, -0.2], &[0.1, 0.0], &[0.0, 0.0], &mut a_ddot)?;
//!
//! // The paper's fuzzy controller, evaluated once.
//! let mut fuzzy = FuzzyController::new(paper_controller(), 2)?;
//! let (measured, reference) = (ModalState::new(&[0.1, 0.0], &[0.0, 0.0])?, ReferenceSample::zeros(2));
//! let ctx = ControlContext {
//!     t: 0.0,
//!     measured: &measured,
//!     reference: &reference,
//!     model: &model,
//!     tau_star_limits: None,
//! };
//! let mut tau = [0.0; 2];
//! fuzzy.control(&ctx, &mut tau)?;
//! assert!(tau[0] < 0.0);
//!
//! // A controller of one's own: gravity compensation plus a PD law, for any number of coordinates.
//! struct Mine(ReducedData);
//! impl Controller for Mine {
//!     fn control(&mut self, ctx: &ControlContext<'_>, tau: &mut [f64]) -> Result<(), ControllerError> {
//!         let (s, r) = (ctx.measured, ctx.reference);
//!         reduced_terms(ctx.model, &mut self.0, &s.a, &s.a_dot)?;
//!         for i in 0..tau.len() {
//!             tau[i] = self.0.gravity()[i] - 40.0 * (s.a[i] - r.a[i]) - 4.0 * s.a_dot[i];
//!         }
//!         Ok(())
//!     }
//! }
//! let mine = Mine(ReducedData::new(&model));
//! let step = Step::new(&[0.0, 0.0], &[0.2, -0.1], 0.0)?;
//! let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-4, 0.5);
//! let mut simulation = Simulation::new(model, Box::new(step), Box::new(mine), settings, None)?;
//! let run = simulation.run()?;
//! assert!(run.summary.modal_error_max[0] <= 0.2 + 1e-12);
//! # Ok::<(), Box<dyn std::error::Error + Send + Sync>>(())
//! ```
#![deny(missing_docs)]

pub use backbone_kin;
pub use fuzzy_sugeno;
pub use manip_dyn;
pub use modal_reduce;
pub use sim_core;

/// What a first program needs, in one `use hrm::prelude::*;`.
pub mod prelude {
    pub use backbone_kin::{BackboneCurve, BaseAngle, Branch, HarmonicIk, ModalMap};
    pub use fuzzy_sugeno::{Evaluator, FuzzySystem, PaperController, paper_controller};
    pub use manip_dyn::{ChainModel, Link};
    pub use modal_reduce::{
        ReducedData, ReducedModel, forward_dynamics, joint_torques, reduced_terms,
    };
    pub use sim_core::controller::{
        ComputedTorque, ControlContext, Controller, ControllerError, FuzzyController, ModalState,
        PdController,
    };
    pub use sim_core::reference::{
        CartesianPath, PathShape, Reference, ReferenceSample, Sinusoid, Step,
    };
    pub use sim_core::{
        ControllerKind, Integrator, LoopSettings, Run, Scenario, SimError, Simulation,
    };
}
