//! Reduced dynamics of spatial modal arms: the universal-joint chain of
//! [`SpatialModalMap`](backbone_kin::SpatialModalMap) projected onto its `m = 4K` modal
//! coordinates, `M* a_dd + C* + G* = tau*` with `M* = J^T M J`, `C* = J^T C`, `G* = J^T G`
//! (eqs 13-14 for the spatial chain; `docs/theory.md`, section 8).
//!
//! - [`model`]: [`SpatialReducedModel`], the arm (links, base pose, gravity) and its map;
//!   [`data`]: [`SpatialReducedData`], the workspace.
//! - [`motion`]: one link's step of the forward recursion in the world frame (frames, joint axes,
//!   angular velocity and acceleration, the acceleration of its centre of mass) for the joint
//!   torques and the derivatives; [`terms`] runs its own in the links' frames.
//! - [`terms`]: `M*`, `C*`, `G*` in `O(n m^2)` without the `2n x 2n` mass matrix; `carried`:
//!   the motion its pass carries from link to link.
//! - [`projection`]: the same terms by projecting the chain's CRBA mass matrix and Newton-Euler
//!   efforts (`J^T M J`, `O(n^2 m)`), the cross-check of [`terms`].
//! - [`torques`]: the joint torques that realise a modal motion (Newton-Euler, `O(n)`).
//! - [`forward`]: reduced forward dynamics; [`batch`]: the same for many states at once, SIMD
//!   across states, each state's bits those of [`forward`].
//! - [`tangent`]: the tangent of the Newton-Euler recursion along one direction;
//!   [`derivatives`]: the analytic derivatives of the reduced forward dynamics, `O(n m^2)`.

pub mod batch;
mod carried;
pub mod data;
pub mod derivatives;
pub mod forward;
pub mod model;
pub mod motion;
pub mod projection;
pub mod tangent;
pub mod terms;
pub mod torques;

pub use batch::{
    MAX_SPATIAL_BATCH_COORDS, SpatialReducedBatchData, spatial_batch_lanes,
    spatial_forward_dynamics_batch,
};
pub use data::SpatialReducedData;
pub use derivatives::{SpatialReducedDerivatives, spatial_reduced_derivatives};
pub use forward::spatial_forward_dynamics;
pub use model::{SpatialLinkInertia, SpatialReducedModel};
pub use projection::{SpatialProjection, spatial_chain, spatial_reduced_terms_by_projection};
pub use terms::spatial_reduced_terms;
pub use torques::{spatial_joint_torques, spatial_project_torques};
