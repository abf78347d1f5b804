//! Backbone-curve kinematics of planar hyper-redundant manipulators.
//!
//! Implements sections 2-3 of *Modeling of Hyper-Redundant Manipulators
//! Dynamics and Design of Fuzzy Controller for the System*, with the corrections listed in
//! `docs/theory.md`: the modal backbone curve (eqs 1-4), its closed-form end point, and the
//! constant modal Jacobian that maps curve coordinates to joint angles (eqs 7-11).
#![deny(missing_docs)]

pub mod error;
pub mod modal_map;

pub use error::KinError;
pub use modal_map::{BaseAngle, ModalMap};
