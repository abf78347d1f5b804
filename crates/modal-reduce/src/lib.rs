#![doc = include_str!("../README.md")]

mod batch;
mod batch_driver;
mod batch_group;
mod cache_aligned;
mod data;
mod derivatives;
mod derivatives_batch;
mod energy;
mod error;
mod forward;
pub mod jacobi;
mod model;
mod plant;
mod projection;
pub mod spatial;
pub mod terms;
mod torques;

pub use batch::{MAX_BATCH_COORDS, ReducedBatchData, forward_dynamics_batch};
pub use batch_driver::BatchError;
pub use batch_group::batch_lanes;
pub use data::ReducedData;
pub use derivatives::{ReducedDerivatives, reduced_derivatives};
pub use derivatives_batch::{ReducedDerivativesBatch, reduced_derivatives_batch};
pub use energy::{kinetic_energy, potential_energy};
pub use error::ReduceError;
pub use forward::{forward_dynamics, forward_dynamics_by_projection};
pub use jacobi::{JacobiReport, JacobiSettings, jacobi_forward_dynamics};
pub use model::ReducedModel;
pub use plant::{Plant, PlantBatchData, PlantData, PlantDerivatives, PlantModel};
pub use projection::reduced_terms_by_projection;
pub use terms::reduced_terms;
pub use torques::{joint_torques, project_torques};
