#![doc = include_str!("../README.md")]

mod aba;
mod aba_batch;
mod aba_derivatives;
mod batch_driver;
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
pub mod spatial;

/// The faer version whose matrices [`mass_matrix`] and [`coriolis_matrix`] fill.
pub use faer;

pub use aba::aba;
pub use aba_batch::{AbaBatchData, aba_batch};
pub use aba_derivatives::aba_derivatives;
pub use batch_driver::{BatchError, MAX_BATCH_LINKS};
pub use bias::{coriolis, gravity, nonlinear_effects};
pub use coriolis_matrix::coriolis_matrix;
pub use crba::mass_matrix;
pub use data::ChainData;
pub use derivative_data::DerivativeData;
pub use energy::{kinetic_energy, potential_energy};
pub use error::DynError;
pub use forward_dynamics::forward_dynamics;
pub use model::{ChainModel, Link, MAX_DENSE_LINKS, MAX_LINKS, MIN_LINK_SCALE};
pub use rnea::rnea;
pub use rnea_derivatives::rnea_derivatives;
