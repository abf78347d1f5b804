//! Backbone-curve kinematics of planar hyper-redundant manipulators.
//!
//! Implements sections 2-3 of *Modeling of Hyper-Redundant Manipulators
//! Dynamics and Design of Fuzzy Controller for the System*, with the corrections listed in the
//! project's model notes (`docs/theory.md`), and extends them to `K` harmonics:
//!
//! - [`BackboneCurve`]: curvature (eq 1), inclination (eq 2), any point of the curve by
//!   quadrature with a rigorous error bound ([`QUADRATURE_TOLERANCE`]), the end point (eqs 3-4).
//! - [`end_point`] and [`inverse_kinematics`]: the two-mode closed forms (eqs 3-6), through the
//!   restricted inverse of `J0`, [`inverse_j0`].
//! - [`ModalMap`]: joint angles from the curve (eq 7) and the constant modal Jacobian (eqs 8-11,
//!   eq 9 with its sign corrected), for `K` harmonics and arbitrary link lengths.
//! - [`joint_positions`] and [`tip_position`]: forward kinematics of the discrete chain.
//! - [`HarmonicIk`]: numerical inverse kinematics of the `K`-harmonic family.
//! - [`ChainIk`] and [`chain_inverse_kinematics`]: inverse kinematics of the discrete chain
//!   itself (any link lengths), the closed form polished by Newton's method on the chain's tip.
//!
//! Every fallible function returns a [`KinError`] that names the failed condition.
//!
//! ```
//! use backbone_kin::{end_point, inverse_kinematics, tip_position, Branch, ModalMap};
//!
//! // The paper's arm: 10 links of 0.1 m, base angle pi/2.
//! let (length, alpha0) = (1.0, std::f64::consts::FRAC_PI_2);
//! let a = inverse_kinematics(length, [0.3, 0.5], alpha0, Branch::Positive)?;
//! let tip = end_point(length, a, alpha0)?;
//! assert!((tip[0] - 0.3).abs() < 1e-12 && (tip[1] - 0.5).abs() < 1e-12);
//!
//! // The chain follows the curve: joint angles from the modal map, then the chain's tip.
//! let map = ModalMap::paper_fixed_alpha0(10, alpha0)?;
//! let mut theta = [0.0; 10];
//! map.joint_angles(&a, &mut theta)?;
//! let chain_tip = tip_position(&[0.1; 10], &theta)?;
//! assert!((chain_tip[0] - 0.3).abs() < 1e-6 && (chain_tip[1] - 0.5).abs() < 1e-6);
//! # Ok::<(), backbone_kin::KinError>(())
//! ```
#![deny(missing_docs)]

pub mod bessel;
pub mod chain;
pub mod chain_ik;
pub mod closed_form;
pub mod curve;
pub mod error;
pub mod harmonic_ik;
pub mod modal_map;
mod quadrature;
mod validate;

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

pub use bessel::{J0_FIRST_ZERO, inverse_j0};
pub use chain::{joint_positions, tip_position};
pub use chain_ik::{ChainIk, chain_inverse_kinematics};
pub use closed_form::{Branch, end_point, inverse_kinematics};
pub use curve::{BackboneCurve, MAX_QUADRATURE_NODES, QUADRATURE_TOLERANCE};
pub use error::KinError;
pub use harmonic_ik::{HarmonicIk, IkOptions, IkReport};
pub use modal_map::{
    BaseAngle, MAX_HARMONICS, MAX_LINKS, MAX_MAP_ENTRIES, ModalMap, harmonic_basis,
};
