//! Dynamics of planar serial chains (section 3 of the paper, eq 12):
//! `tau = M(theta) theta_ddot + C(theta, theta_dot) + G(theta)`.
//!
//! Follows Pinocchio's Model/Data split: a [`ChainModel`] is immutable, and every algorithm takes
//! it together with a reusable workspace so that per-step calls allocate nothing.
#![deny(missing_docs)]

pub mod error;
pub mod model;

pub use error::DynError;
pub use model::{ChainModel, Link};
