//! Projection of planar chain dynamics onto constant modal coordinates (eqs 13-18 of the paper).
//!
//! A hyper-redundant arm whose joint angles follow a backbone curve, `theta = J a + theta_0`
//! with a constant modal Jacobian `J` (`n x m`, from [`backbone_kin::ModalMap`]), is an exactly
//! constrained Lagrangian system in the modal coordinates `a`:
//!
//! ```text
//! M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau*        (eq 15)
//! M* = J^T M J,  C* = J^T C(theta, J a_dot),  G* = J^T G(theta),  tau* = J^T tau   (eq 14)
//! ```
//!
//! - [`ReducedModel`] (immutable) and [`ReducedData`] (reusable workspace): nothing allocates
//!   per call, and both take `O(n m)` memory, so chains of up to [`manip_dyn::MAX_LINKS`]
//!   (10^6) links reduce; only the faer path, which forms the `n x n` mass matrix, stops at
//!   [`manip_dyn::MAX_DENSE_LINKS`] (4096).
//! - [`reduced_terms`]: `M*`, `C*`, `G*` in `O(n m^2)` from prefix sums along the chain in
//!   absolute link angles, never forming `M` (the default; derivation in [`terms`]). [`reduced_terms_faer`]: the same by forming `M`
//!   and projecting it with faer, `O(n^2 m)` (the reference).
//! - [`forward_dynamics`] / [`forward_dynamics_faer`]: solve eq 15 for `a_ddot` by Cholesky.
//! - [`forward_dynamics_batch`]: the same for many states at once, SIMD across states (AVX-512 or
//!   AVX2 when the processor has them), into a [`ReducedBatchData`] workspace.
//! - [`reduced_derivatives`]: the analytic derivatives of eq 15, `d a_ddot / d (a, a_dot, tau*)`,
//!   in `O(n m^2)` into a [`ReducedDerivatives`] workspace.
//! - [`jacobi_forward_dynamics`]: the paper's eq 16-18 iteration, which reports divergence
//!   instead of returning garbage (see [`jacobi`]).
//! - [`joint_torques`]: `tau = M J a_ddot + C + G` for the real arm's actuators (eq 13), and
//!   [`project_torques`]: `tau* = J^T tau`.
//! - [`kinetic_energy`], [`potential_energy`]: the chain's energy at a modal state.
//!
//! ```
//! use backbone_kin::ModalMap;
//! use manip_dyn::ChainModel;
//! use modal_reduce::{ReducedData, ReducedModel, forward_dynamics, joint_torques, project_torques};
//!
//! // The paper's arm: 10 links of 0.1 m and 0.1 kg, coordinates (a1, a2, alpha0).
//! let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
//! let mut data = ReducedData::new(&model);
//! let (a, a_dot, tau_star) = ([0.4, -0.3, 1.2], [0.5, 0.2, -0.1], [1.0, -0.5, 0.2]);
//! let mut a_ddot = [0.0; 3];
//! forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot)?;
//! // The joint torques that realise this motion project back onto tau*.
//! let mut tau = [0.0; 10];
//! joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau)?;
//! let mut projected = [0.0; 3];
//! project_torques(&model, &tau, &mut projected)?;
//! for (p, t) in projected.iter().zip(&tau_star) {
//!     assert!((p - t).abs() < 1e-9);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod batch;
mod data;
mod derivatives;
mod energy;
mod error;
mod forward;
pub mod jacobi;
mod lanes;
mod model;
mod projection;
mod small_linalg;
pub mod terms;
mod torques;
mod trig;

pub use batch::{BatchError, MAX_BATCH_COORDS, ReducedBatchData, forward_dynamics_batch};
pub use data::ReducedData;
pub use derivatives::{ReducedDerivatives, reduced_derivatives};
pub use energy::{kinetic_energy, potential_energy};
pub use error::ReduceError;
pub use forward::{forward_dynamics, forward_dynamics_faer};
pub use jacobi::{JacobiReport, JacobiSettings, jacobi_forward_dynamics};
pub use model::ReducedModel;
pub use projection::reduced_terms_faer;
pub use terms::reduced_terms;
pub use torques::{joint_torques, project_torques};
