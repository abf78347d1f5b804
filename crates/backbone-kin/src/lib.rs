#![doc = include_str!("../README.md")]

pub mod angle;
pub mod bessel;
pub mod chain;
pub mod chain_ik;
pub mod closed_form;
pub mod curve;
pub mod error;
pub mod harmonic_ik;
pub mod modal_map;
mod quadrature;
pub mod spatial_chain;
pub mod spatial_curve;
pub mod spatial_ik;
pub mod spatial_map;
mod validate;
pub mod vec3;

pub use angle::reduce_angle;
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
pub use spatial_chain::{
    BasePose, MAX_BASE_OFFSET, spatial_joint_positions, spatial_tip_jacobian, spatial_tip_position,
};
pub use spatial_curve::{CurveTip, MAX_CURVE_STEPS, SPATIAL_CURVE_TOLERANCE, SpatialCurve};
pub use spatial_ik::{MAX_IK_GUESS, SpatialIk};
pub use spatial_map::SpatialModalMap;
pub use vec3::Rotation;
