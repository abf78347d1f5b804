//! Controllers of the `m` modal coordinates, behind one trait: the paper's fuzzy controller
//! (eqs 19-24, Figure 8) applied per coordinate pair or any `.fis` system with `2m` inputs and
//! `m` outputs, its linearisation at the origin (PD), computed torque with the exact reduced
//! model, the fuzzy controller plus gravity compensation `G*`, the LQR about the reference,
//! re-linearised along it ([`LqrController`]), and model-predictive control under `tau*` limits,
//! and within joint limits and clearance ([`MpcController`], [`MpcLimits`]).
//!
//! The closed loop samples a controller at its own period and holds its output in between
//! (zero-order hold). At each sample it hands the controller a [`ControlContext`] that borrows
//! the time, the measured state, the reference sample and the [`Plant`] being simulated (a planar
//! or a spatial modal arm), so no controller needs its own copy of the model.
//!
//! A controller written elsewhere implements [`Controller`] and may fail with an error of its
//! own; the run reports it as [`SimError::Controller`] with the error
//! as its source:
//!
//! ```
//! use sim_core::controller::{ControlContext, Controller, ControllerError};
//!
//! /// A spring towards the reference in every coordinate.
//! struct Spring(f64);
//!
//! impl Controller for Spring {
//!     fn control(&mut self, ctx: &ControlContext<'_>, tau: &mut [f64]) -> Result<(), ControllerError> {
//!         if ctx.t > 10.0 {
//!             return Err("the spring is tired".into());
//!         }
//!         for ((tau, a), a_ref) in tau.iter_mut().zip(&ctx.measured.a).zip(&ctx.reference.a) {
//!             *tau = -self.0 * (a - a_ref);
//!         }
//!         Ok(())
//!     }
//! }
//! ```

mod chain_mpc;
mod computed_torque;
mod fuzzy;
mod lqr;
mod mpc;
mod mpc_limits;
mod pd;

pub use chain_mpc::ChainMpcController;
pub use computed_torque::ComputedTorque;
pub use fuzzy::FuzzyController;
pub use fuzzy::{SCHEDULED_INPUTS_PER_COORDINATE, scheduled_inputs};
pub use lqr::LqrController;
pub use mpc::MpcController;
pub(crate) use mpc_limits::joint_jacobian;
pub use mpc_limits::{
    ANGLE_ACTIVATION_RAD, BoundConstraints, CLEARANCE_ACTIVATION_M, CLEARANCE_APPROACH_S,
    CLEARANCE_LOOKAHEAD_M, MAX_CLEARANCE_MARGIN_M, MAX_CLEARANCE_ROWS, MpcConstraints, MpcLimits,
};
pub use pd::PdController;

pub use crate::error::ControllerError;
use crate::error::SimError;
use crate::reference::ReferenceSample;
use modal_reduce::Plant;

/// A modal state: the coordinates `a` and their rates `a_dot`, `m` entries each.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModalState {
    /// The modal coordinates (rad).
    pub a: Vec<f64>,
    /// Their rates (rad/s).
    pub a_dot: Vec<f64>,
}

impl ModalState {
    /// The state `a = 0`, `a_dot = 0` of `m` coordinates.
    pub fn zeros(m: usize) -> Self {
        Self {
            a: vec![0.0; m],
            a_dot: vec![0.0; m],
        }
    }

    /// The state `(a, a_dot)`; both must have the same length.
    ///
    /// ```
    /// let state = sim_core::controller::ModalState::new(&[0.1, 0.0, -0.2], &[0.0; 3])?;
    /// assert_eq!(state.n_coords(), 3);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(a: &[f64], a_dot: &[f64]) -> Result<Self, SimError> {
        if a.len() != a_dot.len() {
            return Err(SimError::setting(
                "initial.a_dot",
                format!("has {} entries, initial.a has {}", a_dot.len(), a.len()),
            ));
        }
        Ok(Self {
            a: a.to_vec(),
            a_dot: a_dot.to_vec(),
        })
    }

    /// The number of coordinates `m`.
    pub fn n_coords(&self) -> usize {
        self.a.len()
    }
}

/// What a controller may look at when it is sampled: borrowed from the loop, nothing copied.
#[derive(Debug, Clone, Copy)]
pub struct ControlContext<'a> {
    /// The sample time (s).
    pub t: f64,
    /// The state as the controller measures it (sensor noise included).
    pub measured: &'a ModalState,
    /// The reference as the controller receives it (reference noise included in `a`).
    pub reference: &'a ReferenceSample,
    /// The reduced model being simulated, planar or spatial.
    pub model: Plant<'a>,
    /// The actuator limits on `tau*` (N m, `m` entries) if the loop has any: the loop clamps
    /// whatever the controller asks for to `[-limit_i, limit_i]`, so a controller that plans
    /// (e.g. model-predictive control) can respect them itself. `None` without limits.
    pub tau_star_limits: Option<&'a [f64]>,
}

/// A feedback law producing the modal generalized forces `tau*` (N m), one per coordinate.
pub trait Controller: Send {
    /// Writes the modal torques for `ctx` into `tau_star` (`m` entries, where `m` is
    /// `ctx.model.n_coords()`). `&mut self`, so a controller may keep a workspace (sized when it
    /// is built) or a state between samples.
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError>;

    /// The number of coordinates the controller is built for, if it is built for one:
    /// [`Simulation::new`](crate::Simulation::new) refuses a model with another number. The
    /// default, `None`, accepts any.
    fn n_coords(&self) -> Option<usize> {
        None
    }

    /// An estimate of the controller's own work over `duration` seconds of a run of an arm of
    /// `n_joints` joints, in the units of [`MAX_RUN_WORK`](crate::MAX_RUN_WORK) (multiply-adds
    /// of the reduced dynamics): [`Simulation::new`](crate::Simulation::new) counts it in the
    /// run's work bound. The default, 0, suits a law of a few operations a sample (its cost is
    /// within the loop's own); a controller that plans (an MPC) counts its solves.
    fn work(&self, duration: f64, n_joints: usize) -> f64 {
        let _ = (duration, n_joints);
        0.0
    }
}

/// Checks that `ctx` has the `m` coordinates a controller was built for, and that `tau_star`
/// has room for them.
fn check_context(ctx: &ControlContext<'_>, m: usize, tau_star: &[f64]) -> Result<(), SimError> {
    let lengths = [
        ("model coordinates", ctx.model.n_coords()),
        ("measured a", ctx.measured.a.len()),
        ("measured a_dot", ctx.measured.a_dot.len()),
        ("reference a", ctx.reference.a.len()),
        ("reference a_dot", ctx.reference.a_dot.len()),
        ("reference a_ddot", ctx.reference.a_ddot.len()),
        ("tau_star", tau_star.len()),
    ];
    match lengths.iter().find(|(_, len)| *len != m) {
        None => Ok(()),
        Some((name, len)) => Err(SimError::setting(
            "controller",
            format!("is built for {m} modal coordinates, but {name} has {len}"),
        )),
    }
}

/// Checks that `m` is a number of modal coordinates a controller can be built for.
fn check_coordinate_count(name: &str, m: usize) -> Result<(), SimError> {
    if (1..=crate::MAX_COORDINATES).contains(&m) {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!(
                "must have between 1 and {} modal coordinates, got {m}",
                crate::MAX_COORDINATES
            ),
        ))
    }
}
