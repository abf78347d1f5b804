//! Model-based optimal control in modal coordinates, on the analytic derivatives of the reduced
//! dynamics (`modal_reduce::reduced_derivatives`): the state is `x = (a, a_dot)` (`2m` entries)
//! and the control `u = tau*` (`m` entries), for any modal family.
//!
//! - [`Linearisation`]: the continuous `(A, B)` of `x_dot = f(x, u)` about a state and control,
//!   and the discrete `(A_d, B_d)` of a zero-order hold over a sampling period (matrix
//!   exponential).
//! - [`Lqr`]: the discrete infinite-horizon LQR gain by the Riccati recursion, for regulating
//!   about a reference (`u = u_ref - K (x - x_ref)`).
//! - [`Ilqr`]: control-limited iterative LQR (Tassa, Mansard and Todorov 2014) over a finite
//!   horizon of any [`DiscreteDynamics`], with the box limits on the controls handled in the
//!   solver by a [`BoxQp`] per step; [`ReducedEuler`] is the reduced model discretised by
//!   semi-implicit Euler with its exact Jacobians.
//! - [`Mpc`]: receding-horizon model-predictive control on [`Ilqr`], tracking a reference under
//!   `tau*` limits, warm-started from its previous plan.
//!
//! These depend only on `modal-reduce`; the closed loop wraps them as controllers
//! ([`crate::controller`]). Every type is built once for a model and then allocates nothing.

mod box_qp;
pub(crate) mod dense;
mod discrete;
mod ilqr;
mod linearise;
mod lqr;
mod mpc;

pub use box_qp::{BoxQp, BoxQpReport, BoxQpSettings};
pub use discrete::{DiscreteDynamics, ReducedEuler};
pub use ilqr::{Ilqr, IlqrReport, IlqrSettings, MAX_HORIZON, MAX_WORKSPACE, TrackingCost};
pub use linearise::Linearisation;
pub use lqr::{Lqr, LqrSettings};
pub use mpc::{MAX_MPC_HORIZON, Mpc, MpcSettings};

use modal_reduce::ReduceError;

/// Why an optimal-control computation was refused or failed.
///
/// [`OptimalError::is_numerical`] and [`OptimalError::is_invalid_input`] sort the variants into
/// the two classes a caller acts on; exactly one holds for every error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OptimalError {
    /// The reduced dynamics refused the state (sizes, non-finite values, or a singular `M*`).
    #[error("reduced dynamics: {0}")]
    Dynamics(#[from] ReduceError),
    /// A setting was out of its domain.
    #[error("{name} must be {requirement}, got {value}")]
    InvalidSetting {
        /// Which setting.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A matrix had the wrong size.
    #[error("{name} has {found} entries, expected {expected}")]
    Dimension {
        /// Which matrix.
        name: &'static str,
        /// The size expected.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// The Riccati recursion did not converge within its iteration limit (the pair `(A, B)` is
    /// not stabilisable, or the weights make it too slow).
    #[error(
        "the Riccati recursion did not converge in {iterations} iterations (last change {change:e})"
    )]
    NoConvergence {
        /// Iterations run.
        iterations: usize,
        /// The relative change of `P` in the last iteration.
        change: f64,
    },
    /// A matrix that must be positive definite (`R + B^T P B`) was not, numerically.
    #[error("{0} is not numerically positive definite")]
    NotPositiveDefinite(&'static str),
}

impl OptimalError {
    /// Whether a computation on valid input failed numerically: the reduced dynamics' numerical
    /// failures ([`ReduceError::is_numerical`]), a Riccati recursion that did not converge, or a
    /// matrix that is not numerically positive definite.
    pub fn is_numerical(&self) -> bool {
        match self {
            Self::Dynamics(e) => e.is_numerical(),
            Self::NoConvergence { .. } | Self::NotPositiveDefinite(_) => true,
            _ => false,
        }
    }

    /// Whether the input was malformed or outside its domain (every error that is not
    /// [`is_numerical`](Self::is_numerical)).
    pub fn is_invalid_input(&self) -> bool {
        !self.is_numerical()
    }
}
