//! The projection path of spatial modal arms: form the universal-joint chain's `2n x 2n` mass
//! matrix by the spatial composite-rigid-body algorithm (`manip_dyn::spatial`), its Coriolis and
//! gravity efforts by Newton-Euler, and project them onto the modal coordinates with faer:
//! `M* = J^T M J`, `C* = J^T C`, `G* = J^T G` (eq 14), `O(n^2 m)`. The reference against which
//! the default [`spatial_reduced_terms`](super::spatial_reduced_terms) is tested.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use manip_dyn::spatial::{SpatialData, SpatialJoint, SpatialLink, SpatialModel, Transform};
use manip_dyn::{DynError, MAX_DENSE_LINKS};

use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::terms::check_state;
use super::torques::spatial_project_torques;
use crate::error::{ReduceError, check_terms_finite};

/// The chain of the spatial modal arm `model` as a `manip_dyn` spatial chain of `2n` revolute
/// joints in the order of `theta = [z_1, y_1, z_2, y_2, ...]`: joint `z_i` about the parent
/// frame's `z` axis at the end of link `i - 1` (the first at the base pose), moving a massless
/// cross, then joint `y_i` about the cross's `y` axis at the same point, moving link `i` (its
/// mass at the midpoint, its principal moments in the link frame), under the arm's gravity.
/// The same chain as `robot_desc::from_spatial_arm`'s URDF.
///
/// Errors: more than `MAX_LINKS` joints ([`DynError::TooManyLinks`]).
pub fn spatial_chain(model: &SpatialReducedModel) -> Result<SpatialModel, ReduceError> {
    let n = model.n_links();
    let (mut joints, mut links) = (Vec::with_capacity(2 * n), Vec::with_capacity(2 * n));
    let base = model.base();
    let mut origin = Transform::from_rpy(base.rpy, base.xyz);
    for (&length, link) in model.map().link_lengths().iter().zip(model.links()) {
        joints.push(SpatialJoint::revolute([0.0, 0.0, 1.0], origin));
        links.push(SpatialLink {
            mass: 0.0,
            com: [0.0; 3],
            inertia: [[0.0; 3]; 3],
        });
        joints.push(SpatialJoint::revolute([0.0, 1.0, 0.0], Transform::IDENTITY));
        let [xx, yy, zz] = link.principal;
        links.push(SpatialLink {
            mass: link.mass,
            com: [0.5 * length, 0.0, 0.0],
            inertia: [[xx, 0.0, 0.0], [0.0, yy, 0.0], [0.0, 0.0, zz]],
        });
        origin = Transform::translation([length, 0.0, 0.0]);
    }
    Ok(SpatialModel::new(joints, links, model.gravity())?)
}

/// The arm, its chain ([`spatial_chain`]) and the dense workspace of
/// [`spatial_reduced_terms_by_projection`]: `O(n^2)` memory, built once.
#[derive(Debug, Clone)]
pub struct SpatialProjection {
    model: SpatialReducedModel,
    chain: SpatialModel,
    chain_data: SpatialData,
    joint_mass: Mat<f64>,
    mass_times_jacobian: Mat<f64>,
    joint_torque: Vec<f64>,
}

impl SpatialProjection {
    /// The projection of `model`.
    ///
    /// Errors: a chain of more than [`MAX_DENSE_LINKS`] joints ([`DynError::TooManyLinks`]: the
    /// `2n x 2n` mass matrix), as [`spatial_chain`].
    pub fn new(model: &SpatialReducedModel) -> Result<Self, ReduceError> {
        let joints = 2 * model.n_links();
        if joints > MAX_DENSE_LINKS {
            return Err(ReduceError::Dyn(DynError::TooManyLinks {
                what: "the projection J^T M J (joints)",
                got: joints,
                max: MAX_DENSE_LINKS,
            }));
        }
        let chain = spatial_chain(model)?;
        Ok(Self {
            model: model.clone(),
            chain_data: SpatialData::new(&chain),
            chain,
            joint_mass: Mat::zeros(joints, joints),
            mass_times_jacobian: Mat::zeros(joints, model.n_coords()),
            joint_torque: vec![0.0; joints],
        })
    }

    /// The arm projected.
    pub fn model(&self) -> &SpatialReducedModel {
        &self.model
    }

    /// Its universal-joint chain.
    pub fn chain(&self) -> &SpatialModel {
        &self.chain
    }
}

/// Computes `M* = J^T M J`, `C* = J^T C(theta, J a_dot)` and `G* = J^T G(theta)` at
/// `theta = J a` (eq 14) into `data` (a workspace of `projection.model()`), forming the chain's
/// full mass matrix by CRBA and multiplying with faer (sequential). Allocation-free.
///
/// Gives the same terms as [`spatial_reduced_terms`](super::spatial_reduced_terms) up to
/// rounding, at `O(n^2 m)` instead of `O(n m^2)` cost.
///
/// Errors: as [`spatial_reduced_terms`](super::spatial_reduced_terms).
pub fn spatial_reduced_terms_by_projection(
    projection: &mut SpatialProjection,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    let SpatialProjection {
        model,
        chain,
        chain_data,
        joint_mass,
        mass_times_jacobian,
        joint_torque,
    } = projection;
    check_state(model, data, a, a_dot)?;
    let (map, m) = (model.map(), model.n_coords());
    map.joint_angles(a, &mut data.theta)?;
    map.joint_rates(a_dot, &mut data.theta_dot)?;
    let jacobian = MatRef::from_row_major_slice(map.jacobian(), map.n_joints(), m);

    manip_dyn::spatial::mass_matrix(chain, chain_data, &data.theta, joint_mass.as_mut())?;
    matmul(
        mass_times_jacobian.as_mut(),
        Accum::Replace,
        joint_mass.as_ref(),
        jacobian,
        1.0,
        Par::Seq,
    );
    matmul(
        MatMut::from_row_major_slice_mut(&mut data.mass_matrix, m, m),
        Accum::Replace,
        jacobian.transpose(),
        mass_times_jacobian.as_ref(),
        1.0,
        Par::Seq,
    );
    // J^T (M J) is symmetric up to rounding: make it exactly so.
    for j in 0..m {
        for k in 0..j {
            let mean = 0.5 * (data.mass_matrix[j * m + k] + data.mass_matrix[k * m + j]);
            data.mass_matrix[j * m + k] = mean;
            data.mass_matrix[k * m + j] = mean;
        }
    }

    manip_dyn::spatial::coriolis(
        chain,
        chain_data,
        &data.theta,
        &data.theta_dot,
        joint_torque,
    )?;
    spatial_project_torques(model, joint_torque, &mut data.coriolis)?;
    manip_dyn::spatial::gravity(chain, chain_data, &data.theta, joint_torque)?;
    spatial_project_torques(model, joint_torque, &mut data.gravity)?;
    check_terms_finite(&data.mass_matrix, &data.coriolis, &data.gravity)
}
