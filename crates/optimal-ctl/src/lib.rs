#![doc = include_str!("../README.md")]

mod box_qp;
mod chain_euler;
mod chain_mpc;
mod discrete;
mod ilqr;
mod joint_torque_rows;
mod linear_qp;
mod linearise;
mod lqr;
mod mpc;
mod polytope;
mod step_constraints;

pub use box_qp::{BoxQp, BoxQpReport, BoxQpSettings};
pub use chain_euler::ChainEuler;
pub use chain_mpc::ChainMpc;
pub use discrete::{DiscreteDynamics, ReducedEuler};
pub use ilqr::{Ilqr, IlqrReport, IlqrSettings, MAX_HORIZON, MAX_WORKSPACE, TrackingCost};
pub use joint_torque_rows::{JointTorqueLimits, JointTorqueRows};
pub use linear_qp::{LinearQp, LinearQpFailure};
pub use linearise::Linearisation;
pub use lqr::{Lqr, LqrSettings};
pub use mpc::{MAX_MPC_HORIZON, Mpc, MpcSettings};
pub use polytope::{PolytopeProjection, ProjectionFailure};
pub use step_constraints::StepConstraints;

use lane_math::{Classify, ErrorClass};
use modal_reduce::ReduceError;

/// Why an optimal-control computation was refused or failed.
///
/// [`ErrorClass::Numerical`] and [`ErrorClass::InvalidInput`] are the two classes
/// ([`Classify::class`]) its variants fall into.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OptimalError {
    /// The reduced dynamics refused the state (sizes, non-finite values, or a singular `M*`).
    #[error("reduced dynamics: {0}")]
    Dynamics(#[from] ReduceError),
    /// The joint-space dynamics of a chain ([`ChainEuler`], [`ChainMpc`]) refused the state.
    #[error("chain dynamics: {0}")]
    ChainDynamics(#[from] manip_dyn::DynError),
    /// A setting was out of its domain.
    #[error("{name} must be {requirement}, got {}", lane_math::Compact(*.value))]
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
    /// A term of a solve left double precision: costs or constraint penalties so large (a
    /// margin no motion keeps, say) that the backward pass's gradient overflowed.
    #[error("{0} is not finite: the costs or constraint penalties left double precision")]
    NonFinite(&'static str),
}

impl Classify for OptimalError {
    /// [`Numerical`](ErrorClass::Numerical) when a computation on valid input failed: a Riccati
    /// recursion that did not converge, a matrix that is not numerically positive definite, or
    /// a backward pass that left double precision; a
    /// wrapped [`ReduceError`] keeps its own class; otherwise the input was malformed or outside
    /// its domain.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Dynamics(e) => e.class(),
            Self::ChainDynamics(e) => e.class(),
            Self::NoConvergence { .. } | Self::NotPositiveDefinite(_) | Self::NonFinite(_) => {
                ErrorClass::Numerical
            }
            _ => ErrorClass::InvalidInput,
        }
    }
}
