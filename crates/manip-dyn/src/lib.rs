//! Dynamics of planar serial chains (section 3 of the paper, eq 12):
//! `tau = M(theta) theta_ddot + C(theta, theta_dot) + G(theta)`.
//!
//! Follows Pinocchio's Model/Data split: a [`ChainModel`] is immutable, and every algorithm takes
//! it together with a reusable [`ChainData`] workspace, built once, so that per-step calls
//! allocate nothing. Every algorithm validates the sizes and finiteness of its inputs.
//!
//! A chain may have up to [`MAX_LINKS`] (10^6) links, and the `O(n)` algorithms accept them all;
//! the `O(n^2)` and `O(n^3)` ones below, which fill or factorise `n x n` matrices, accept up to
//! [`MAX_DENSE_LINKS`] (4096).
//!
//! | quantity | function | cost |
//! |---|---|---|
//! | inverse dynamics `tau` | [`rnea`] | O(n) |
//! | `C(q, v)`, `G(q)`, `C + G` | [`coriolis`], [`gravity`], [`nonlinear_effects`] | O(n) |
//! | mass matrix `M(q)` (faer) | [`mass_matrix`] | O(n^2) |
//! | Coriolis matrix (Christoffel symbols) | [`coriolis_matrix`] | O(n^2) |
//! | forward dynamics | [`aba`] / [`forward_dynamics`] (Cholesky) | O(n) / O(n^3) |
//! | energies | [`kinetic_energy`], [`potential_energy`] | O(n) |
//! | `d tau / d (q, v, qdd)` (analytic) | [`rnea_derivatives`] into [`DerivativeData`] | O(n^2) |
//! | `d qdd / d (q, v, tau)` (analytic) | [`aba_derivatives`] into [`DerivativeData`] | O(n^2) |
//!
//! ```
//! use manip_dyn::{ChainData, ChainModel, aba, rnea};
//! // The paper's arm: ten 0.1 m, 0.1 kg uniform links.
//! let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
//! let mut data = ChainData::new(&arm);
//! let (q, v) = ([0.1; 10], [0.2; 10]);
//! let mut qdd = [0.0; 10];
//! aba(&arm, &mut data, &q, &v, &[0.0; 10], &mut qdd)?; // falling freely
//! let mut tau = [0.0; 10];
//! rnea(&arm, &mut data, &q, &v, &qdd, &mut tau)?; // ...needs no torque
//! assert!(tau.iter().all(|t| t.abs() < 1e-12));
//! # Ok::<(), manip_dyn::DynError>(())
//! ```
#![deny(missing_docs)]

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod aba;
mod aba_derivatives;
mod bias;
mod check;
mod coriolis_matrix;
mod crba;
mod data;
mod derivative_data;
mod energy;
pub mod error;
mod forward_dynamics;
mod kinematics;
pub mod model;
mod rnea;
mod rnea_derivatives;

/// The faer version whose matrices [`mass_matrix`] and [`coriolis_matrix`] fill.
pub use faer;

pub use aba::aba;
pub use aba_derivatives::aba_derivatives;
pub use bias::{coriolis, gravity, nonlinear_effects};
pub use coriolis_matrix::coriolis_matrix;
pub use crba::mass_matrix;
pub use data::ChainData;
pub use derivative_data::DerivativeData;
pub use energy::{kinetic_energy, potential_energy};
pub use error::DynError;
pub use forward_dynamics::forward_dynamics;
pub use model::{ChainModel, Link, MAX_DENSE_LINKS, MAX_LINKS};
pub use rnea::rnea;
pub use rnea_derivatives::rnea_derivatives;
