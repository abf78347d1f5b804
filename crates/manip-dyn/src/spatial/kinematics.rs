//! Forward kinematics: every link's placement relative to its parent and pose in the base frame,
//! and the geometric Jacobian of a point of a link.

use faer::MatMut;
use lane_math::{Lane, sin_cos};
use pulp::{Arch, Simd, WithSimd};

use super::algebra::{Transform, add, cross, mat_mul, mat_vec, scale, splat3, splat33, sub};
use super::data::SpatialData;
use super::model::{JointKind, SpatialJoint, SpatialModel};
use crate::check;
use crate::error::DynError;

/// Link `i`'s frame in its parent's at joint value `q` (with `sin q`, `cos q`):
/// `origin * J(q)`, `J(q)` the rotation by `q` about the axis (revolute) or the translation by
/// `q` along it (prismatic).
#[inline(always)]
pub(crate) fn joint_placement<T: Lane>(
    context: T::Context,
    joint: &SpatialJoint,
    q: T,
    sin: T,
    cos: T,
) -> Transform<T> {
    let rotation = splat33(context, &joint.origin.rotation);
    let translation = splat3(context, joint.origin.translation);
    match joint.kind {
        JointKind::Revolute => Transform {
            rotation: mat_mul(
                &rotation,
                &super::algebra::axis_rotation(context, joint.axis, sin, cos),
            ),
            translation,
        },
        JointKind::Prismatic => {
            let shift = mat_vec(&rotation, scale(splat3(context, joint.axis), q));
            Transform {
                rotation,
                translation: add(translation, shift),
            }
        }
    }
}

/// The sines and cosines of `q` ([`lane_math::sin_cos`], compiled for `arch`), then every
/// link's placement in its parent's frame. `q` finite, of `n` entries.
pub(crate) fn update_placements(model: &SpatialModel, data: &mut SpatialData, q: &[f64]) {
    sin_cos_dispatched(data.arch, q, &mut data.sin, &mut data.cos);
    for (i, (joint, placement)) in model
        .joints()
        .iter()
        .zip(data.placements.iter_mut())
        .enumerate()
    {
        *placement = joint_placement((), joint, q[i], data.sin[i], data.cos[i]);
    }
}

/// [`lane_math::sin_cos`] under [`Arch::dispatch`] (as the planar ABA runs it).
struct SinCos<'a> {
    angle: &'a [f64],
    sin: &'a mut [f64],
    cos: &'a mut [f64],
}

impl WithSimd for SinCos<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        sin_cos(self.angle, self.sin, self.cos);
    }
}

/// The one-state sines and cosines in `arch`'s dispatch (what [`update_placements`] and the
/// articulated-body algorithm share).
pub(crate) fn sin_cos_dispatched(arch: Arch, angle: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    arch.dispatch(SinCos { angle, sin, cos });
}

/// Placements, then poses `oM_i = oM_{i-1} * {i-1}M_i`, base first.
pub(crate) fn update_poses(model: &SpatialModel, data: &mut SpatialData, q: &[f64]) {
    update_placements(model, data, q);
    compose_poses(data);
}

/// Poses from the placements, base first: `oM_i = oM_{i-1} * {i-1}M_i`.
fn compose_poses(data: &mut SpatialData) {
    let mut parent = Transform::IDENTITY;
    for (pose, placement) in data.poses.iter_mut().zip(&data.placements) {
        parent = parent.compose(placement);
        *pose = parent;
    }
}

/// Link `i`'s placement as [`joint_placement`], the first joint's origin moved to the base
/// frame's origin (`i = 0`): the frame in which the derivatives sum their base-frame quantities.
/// A translation of the origin changes no joint-space quantity, and a first joint far from the
/// base (a URDF's `1e6` m offset) would otherwise leave those sums few correct digits (terms of
/// `m |p|^2` cancelling to `m L^2`).
#[inline(always)]
pub(crate) fn placement_about_first_joint(
    model: &SpatialModel,
    data: &SpatialData,
    q: &[f64],
    i: usize,
) -> Transform {
    let mut joint = model.joints()[i];
    if i == 0 {
        joint.origin.translation = [0.0; 3];
    }
    joint_placement((), &joint, q[i], data.sin[i], data.cos[i])
}

/// Poses as [`update_poses`] in the base frame moved to the first joint's origin (see
/// [`placement_about_first_joint`]).
pub(crate) fn update_poses_about_first_joint(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
) {
    update_placements(model, data, q);
    data.placements[0] = placement_about_first_joint(model, data, q, 0);
    compose_poses(data);
}

/// Forward kinematics at the joint values `q`: every link's pose in the base frame, read with
/// [`SpatialData::link_pose`].
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, forward_kinematics};
/// let arm = SpatialModel::from_planar(&ChainModel::uniform(2, 0.5, 1.0, 9.81)?);
/// let mut data = SpatialData::new(&arm);
/// forward_kinematics(&arm, &mut data, &[std::f64::consts::FRAC_PI_2, 0.0])?;
/// // The second joint sits 0.5 m up the y axis.
/// let pose = data.link_pose(1).unwrap();
/// assert!((pose.translation[1] - 0.5).abs() < 1e-15 && pose.translation[0].abs() < 1e-15);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if `q` does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite `q`.
pub fn forward_kinematics(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
) -> Result<(), DynError> {
    super::check_inputs(model, data, &[("q", q)])?;
    update_poses(model, data, q);
    Ok(())
}

/// The geometric Jacobian of the point `point` (in link `link`'s frame) at `q`, into `out`
/// (`6 x n`): column `k` is the base-frame linear velocity of the point (rows 0-2) and angular
/// velocity of the link (rows 3-5) per unit rate of joint `k`; zero for joints beyond `link`.
/// Runs [`forward_kinematics`] (the poses are left in `data`).
///
/// Column `k <= link`, with `a_k` joint `k`'s axis and `o_k` its origin in the base frame:
/// `(a_k x (p - o_k), a_k)` for a revolute joint, `(a_k, 0)` for a prismatic one.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, jacobian};
/// let arm = SpatialModel::from_planar(&ChainModel::uniform(2, 0.5, 1.0, 9.81)?);
/// let mut data = SpatialData::new(&arm);
/// let mut j = manip_dyn::faer::Mat::<f64>::zeros(6, 2);
/// jacobian(&arm, &mut data, &[0.0, 0.0], 1, [0.5, 0.0, 0.0], j.as_mut())?;
/// // The tip, 1 m out along x, moves along y at 1 m/s per rad/s of the first joint.
/// assert!((j[(1, 0)] - 1.0).abs() < 1e-15 && (j[(5, 1)] - 1.0).abs() < 1e-15);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// As [`forward_kinematics`], and [`DynError::NoSuchLink`] for `link >= n`,
/// [`DynError::NonFinite`] for a non-finite `point`, [`DynError::Dimension`] if `out` is not
/// `6 x n`.
pub fn jacobian(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    link: usize,
    point: [f64; 3],
    mut out: MatMut<'_, f64>,
) -> Result<(), DynError> {
    let n = super::check_inputs(model, data, &[("q", q)])?;
    check::vectors(3, &[("point", &point[..])])?;
    if link >= n {
        return Err(DynError::NoSuchLink {
            index: link,
            n_links: n,
        });
    }
    lane_math::check_len("out (rows)", out.nrows(), 6)?;
    lane_math::check_len("out (columns)", out.ncols(), n)?;
    update_poses(model, data, q);
    let target = data.poses[link].apply(point);
    for k in 0..n {
        let column = if k > link {
            [0.0; 6]
        } else {
            let pose = &data.poses[k];
            let axis = mat_vec(&pose.rotation, model.joints()[k].axis);
            match model.joints()[k].kind {
                JointKind::Revolute => {
                    let [x, y, z] = cross(axis, sub(target, pose.translation));
                    [x, y, z, axis[0], axis[1], axis[2]]
                }
                JointKind::Prismatic => [axis[0], axis[1], axis[2], 0.0, 0.0, 0.0],
            }
        };
        for (r, value) in column.into_iter().enumerate() {
            out[(r, k)] = value;
        }
    }
    Ok(())
}
