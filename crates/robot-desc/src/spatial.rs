//! A description as `manip-dyn`'s spatial chain.

use crate::error::DescError;
use crate::model::Robot;
use manip_dyn::spatial::{SpatialJoint, SpatialLink, SpatialModel, Transform};

/// The chain's dynamics model under gravity `[gx, gy, gz]` (m/s^2, base frame; URDF carries
/// none, ROS's convention is `[0, 0, -9.81]`): joint origins as `Transform::from_rpy`, each
/// body's inertia rotated from its `<inertial>` frame into the link frame (`R I R^T`), the
/// base's mass ignored (it does not move). A massless link (the middle of a universal joint
/// written as two revolute joints) is kept as it is: `manip-dyn`'s forward dynamics refuse, naming
/// the joint, only a joint that moves nothing with mass (`DynError::SingularJoint`).
pub fn to_spatial(robot: &Robot, gravity: [f64; 3]) -> Result<SpatialModel, DescError> {
    check_gravity(gravity)?;
    let mut joints = Vec::with_capacity(robot.n_joints());
    let mut links = Vec::with_capacity(robot.n_joints());
    for joint in &robot.joints {
        let origin = Transform::from_rpy(joint.origin.rpy, joint.origin.xyz);
        joints.push(if joint.kind.is_rotation() {
            SpatialJoint::revolute(joint.axis, origin)
        } else {
            SpatialJoint::prismatic(joint.axis, origin)
        });
        let (com, inertia) = joint.child.inertial.in_link_frame();
        links.push(SpatialLink {
            mass: joint.child.inertial.mass,
            com,
            inertia,
        });
    }
    SpatialModel::new(joints, links, gravity).map_err(|e| {
        let element = match &e {
            manip_dyn::DynError::InvalidLink { index, .. }
            | manip_dyn::DynError::InvalidJoint { index, .. } => robot
                .joints
                .get(*index)
                .map(|j| format!("joint '{}' and link '{}'", j.name, j.child.name)),
            _ => None,
        };
        DescError::invalid(
            element.unwrap_or_else(|| format!("robot '{}'", robot.name)),
            format!("not a dynamics model: {e}"),
        )
    })
}

/// Checks a gravity vector for [`to_spatial`]: three finite numbers of at most
/// [`MAX_MAGNITUDE`](crate::MAX_MAGNITUDE) (the bound of a URDF's numbers) in magnitude.
///
/// # Errors
/// [`DescError::Invalid`] naming `gravity`: "gravity: must be three finite numbers [gx, gy,
/// gz] of at most 1e9 in magnitude, got [0, 0, 1e308]".
///
/// ```
/// assert!(robot_desc::check_gravity([0.0, 0.0, -9.81]).is_ok());
/// let error = robot_desc::check_gravity([0.0, f64::NAN, 1e308]).unwrap_err();
/// assert_eq!(
///     error.to_string(),
///     "gravity: must be three finite numbers [gx, gy, gz] of at most 1e9 in magnitude, got \
///      [0, NaN, 1e308]"
/// );
/// ```
pub fn check_gravity(gravity: [f64; 3]) -> Result<(), DescError> {
    if gravity.iter().all(|g| g.abs() <= crate::MAX_MAGNITUDE) {
        Ok(())
    } else {
        Err(DescError::invalid(
            "gravity",
            format!(
                "must be three finite numbers [gx, gy, gz] of at most 1e9 in magnitude, got [{}]",
                gravity
                    .map(|g| lane_math::Compact(g).to_string())
                    .join(", ")
            ),
        ))
    }
}
