//! Spatial serial chains: revolute and prismatic joints about or along any axis, each at a fixed
//! origin in its parent link, links with full rigid-body inertias, any gravity vector, a fixed
//! base; the algorithms of the planar chain and their analytic derivatives, on a small spatial
//! algebra (Featherstone's, in Pinocchio's layout).
//!
//! # The model
//!
//! A [`SpatialModel`] is `n` [`SpatialJoint`]s and `n` [`SpatialLink`]s: joint `i` joins link
//! `i - 1` (the base for `i = 0`) to link `i`. Link `i`'s frame is link `i - 1`'s frame moved by
//! the joint's `origin` (a [`Transform`]: rotation, then translation, child to parent), then by
//! the joint's motion: a rotation by `q_i` about its unit `axis` ([`JointKind::Revolute`]) or a
//! translation by `q_i` along it ([`JointKind::Prismatic`]), the axis in the joint frame. A link
//! is its mass, its centre of mass in its frame and its rotational inertia about the centre of
//! mass in its frame's axes. Gravity is a vector in the base frame.
//! [`SpatialModel::from_planar`] gives the planar [`ChainModel`](crate::ChainModel) as a spatial
//! chain (joints about `z`, links along `x`, gravity along `-y`).
//!
//! # The algorithms
//!
//! Each takes the model, a [`SpatialData`] workspace built once for it, and slices of `n` joint
//! values, rates, accelerations or efforts (torques for revolute joints, forces for prismatic
//! ones); each is one file, allocation-free. Spatial vectors store the linear part first:
//!
//! | function | computes |
//! |---|---|
//! | [`forward_kinematics`] | every link's pose in the base frame ([`SpatialData::link_pose`]) |
//! | [`jacobian`] | the `6 x n` geometric Jacobian of a point of a link (linear rows first) |
//! | [`rnea`] | inverse dynamics `tau = M qdd + C qd + G` (Newton-Euler) |
//! | [`mass_matrix`] | `M(q)` by the composite-rigid-body algorithm, into a faer matrix |
//! | [`nonlinear_effects`], [`coriolis`], [`gravity`] | `C qd + G`, `C qd`, `G` |
//! | [`kinetic_energy`], [`potential_energy`] | `1/2 qd^T M qd`, `-sum m_i g . c_i` |
//! | [`aba`] | forward dynamics `qdd` by the articulated-body algorithm, `O(n)` |
//! | [`aba_batch`] | [`aba`] of many states, SIMD across states, the same bits |
//! | [`rnea_derivatives`] | `tau`, `d tau / d q`, `d tau / d v`, `M` into a [`SpatialDerivativeData`] |
//! | [`aba_derivatives`] | `qdd`, `d qdd / d q`, `d qdd / d v`, `M^-1` (in `O(n^2)`) into a [`SpatialDerivativeData`] |
//!
//! [`symmetric_eigen`] gives the principal moments and axes of an inertia (cyclic Jacobi
//! rotations, accurate when two moments are equal): [`SpatialModel::new`] checks the triangle
//! inequalities on them, `robot-desc` its URDF inertias and MJCF principal frames.
//!
//! The `n x n` algorithms refuse chains of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
//! links; a model has at most [`MAX_LINKS`](crate::MAX_LINKS). The conventions and the derivative
//! algorithms are derived in `docs/theory.md` ("Spatial chains").

mod aba;
mod aba_batch;
mod aba_derivatives;
mod algebra;
mod bias;
mod crba;
mod data;
mod derivative_data;
mod eigen;
mod energy;
mod kinematics;
mod minv;
mod model;
mod rnea;
mod rnea_derivatives;

pub use aba::{aba, singular_joint};
pub use aba_batch::{SpatialBatchData, aba_batch};
pub use aba_derivatives::aba_derivatives;
pub use algebra::{Force, Mat3, Motion, Transform, Vec3};
pub use bias::{coriolis, gravity, nonlinear_effects};
pub use crba::mass_matrix;
pub use data::SpatialData;
pub use derivative_data::SpatialDerivativeData;
pub use eigen::{SymmetricEigen, symmetric_eigen};
pub use energy::{kinetic_energy, potential_energy};
pub use kinematics::{forward_kinematics, jacobian};
pub use model::{JointKind, MAX_PRISMATIC_POSITION, SpatialJoint, SpatialLink, SpatialModel};
pub use rnea::rnea;
pub use rnea_derivatives::rnea_derivatives;

use crate::check;
use crate::error::DynError;

/// The preamble of every algorithm: `data` built for `model`, each named input `n` finite
/// entries, and the positions `q` (the first input) of prismatic joints at most
/// [`MAX_PRISMATIC_POSITION`] in magnitude. Returns `n`.
fn check_inputs(
    model: &SpatialModel,
    data: &SpatialData,
    inputs: &[(&'static str, &[f64])],
) -> Result<usize, DynError> {
    let n = model.n_links();
    lane_math::check_len(
        "data (a SpatialData built for another model)",
        data.n_links(),
        n,
    )?;
    check::vectors(n, inputs)?;
    if let Some(&("q", q)) = inputs.first()
        && let Some((index, (_, &value))) =
            model
                .joints()
                .iter()
                .zip(q)
                .enumerate()
                .find(|(_, (joint, q))| {
                    joint.kind == JointKind::Prismatic && q.abs() > MAX_PRISMATIC_POSITION
                })
    {
        return Err(DynError::InvalidJoint {
            index,
            quantity: "position q",
            requirement: "at most 1e9 m in magnitude (a prismatic joint)",
            value,
        });
    }
    Ok(n)
}
