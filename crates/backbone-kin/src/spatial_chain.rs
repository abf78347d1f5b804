//! Forward kinematics of the discrete universal-joint chain of the spatial modal family
//! ([`SpatialModalMap`](crate::SpatialModalMap)), for arbitrary link lengths and base pose.
//!
//! Link `i`'s frame is its parent's turned about the parent's `z` axis by `z_i`, then about the
//! resulting `y` axis by `y_i`: `R_i = R_{i-1} Rz(z_i) Ry(y_i)`, `R_0` the base rotation. Both
//! joints of link `i` sit at its proximal end `p_{i-1}` (`p_0` the base position), and the link
//! runs along its frame's `x` axis: `p_i = p_{i-1} + L_i R_i e_x`. With `y = 0` and the base the
//! identity this is the planar chain of [`joint_positions`](crate::joint_positions) in the `x-y`
//! plane.

use crate::error::KinError;
use crate::validate::check_link_lengths;
use crate::vec3::{Rotation, column, cross, mat_mul, rot_x, rot_y, rot_z, sub};
use lane_math::{check_finite, check_len, check_values};

/// The pose of the arm's base: its position and its orientation as roll, pitch and yaw about the
/// fixed `x`, `y` and `z` axes (URDF's convention: `R = Rz(yaw) Ry(pitch) Rx(roll)`). The
/// default is the identity, so that the straight arm lies along the base's `x` axis.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BasePose {
    /// Position of the first joint in the world frame (m).
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw (rad).
    pub rpy: [f64; 3],
}

/// The farthest a base sits from the origin in each coordinate (m), as a URDF's numbers
/// (`robot_desc::MAX_MAGNITUDE`): a base at `1e308` would leave the arm's points no digits.
pub const MAX_BASE_OFFSET: f64 = 1e9;

impl BasePose {
    /// Checks that every number is finite and the position within [`MAX_BASE_OFFSET`].
    pub fn validate(&self) -> Result<(), KinError> {
        for (name, values) in [("base xyz", self.xyz), ("base rpy", self.rpy)] {
            for value in values {
                check_finite(name, value)?;
            }
        }
        if let Some(&value) = self.xyz.iter().find(|v| v.abs() > MAX_BASE_OFFSET) {
            return Err(KinError::BaseTooFar {
                value,
                max: MAX_BASE_OFFSET,
            });
        }
        Ok(())
    }

    /// The base rotation `Rz(yaw) Ry(pitch) Rx(roll)`.
    pub fn rotation(&self) -> Rotation {
        let [roll, pitch, yaw] = self.rpy;
        mat_mul(mat_mul(rot_z(yaw), rot_y(pitch)), rot_x(roll))
    }
}

/// Every joint position from the base to the tip: `positions[0]` is the base position,
/// `positions[i]` the distal end of link `i`, `positions[n]` the tip (`n + 1` points).
/// `theta` holds `2n` interleaved angles `[z_1, y_1, ...]`. Allocation-free.
///
/// ```
/// use backbone_kin::{BasePose, spatial_joint_positions};
/// use std::f64::consts::FRAC_PI_2;
/// let mut points = [[0.0; 3]; 2];
/// // One link pitched down by y_1 = pi/2 (about the base's y axis) points along -z.
/// spatial_joint_positions(&[1.0], &BasePose::default(), &[0.0, FRAC_PI_2], &mut points)?;
/// assert!(points[1][0].abs() < 1e-15 && (points[1][2] + 1.0).abs() < 1e-15);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn spatial_joint_positions(
    link_lengths: &[f64],
    base: &BasePose,
    theta: &[f64],
    positions: &mut [[f64; 3]],
) -> Result<(), KinError> {
    check_chain(link_lengths, base, theta)?;
    check_len("joint positions", positions.len(), link_lengths.len() + 1)?;
    positions[0] = base.xyz;
    walk(link_lengths, base, theta, |i, link| {
        positions[i + 1] = link.end
    });
    Ok(())
}

/// The tip (the distal end of the last link) of the chain with joint angles `theta` (`2n`).
pub fn spatial_tip_position(
    link_lengths: &[f64],
    base: &BasePose,
    theta: &[f64],
) -> Result<[f64; 3], KinError> {
    check_chain(link_lengths, base, theta)?;
    let mut tip = base.xyz;
    walk(link_lengths, base, theta, |_, link| tip = link.end);
    Ok(tip)
}

/// The tip and its Jacobian with respect to the joint angles, `d tip / d theta_j = u_j x (tip -
/// o_j)` (`u_j` the joint's axis in the world frame, `o_j` its position), written row-major into
/// `jacobian` (`3 x 2n`). Allocation-free.
pub fn spatial_tip_jacobian(
    link_lengths: &[f64],
    base: &BasePose,
    theta: &[f64],
    jacobian: &mut [f64],
) -> Result<[f64; 3], KinError> {
    let tip = spatial_tip_position(link_lengths, base, theta)?;
    let n2 = theta.len();
    check_len("tip Jacobian", jacobian.len(), 3 * n2)?;
    walk(link_lengths, base, theta, |i, link| {
        let arm = sub(tip, link.start);
        for (j, axis) in [(2 * i, link.z_axis), (2 * i + 1, link.y_axis)] {
            let column = cross(axis, arm);
            for (d, value) in column.into_iter().enumerate() {
                jacobian[d * n2 + j] = value;
            }
        }
    });
    Ok(tip)
}

/// One link of the walk: its joints' point and axes (world frame) and its distal end.
struct LinkPose {
    start: [f64; 3],
    z_axis: [f64; 3],
    y_axis: [f64; 3],
    end: [f64; 3],
}

/// Visits every link, base to tip, with its index (0-based) and pose.
fn walk(
    link_lengths: &[f64],
    base: &BasePose,
    theta: &[f64],
    mut visit: impl FnMut(usize, LinkPose),
) {
    let mut rotation = base.rotation();
    let mut point = base.xyz;
    for (i, (&length, angles)) in link_lengths.iter().zip(theta.chunks_exact(2)).enumerate() {
        let z_axis = column(&rotation, 2);
        let after_z = mat_mul(rotation, rot_z(angles[0]));
        let y_axis = column(&after_z, 1);
        rotation = mat_mul(after_z, rot_y(angles[1]));
        let start = point;
        let x_axis = column(&rotation, 0);
        point = std::array::from_fn(|d| start[d] + length * x_axis[d]);
        visit(
            i,
            LinkPose {
                start,
                z_axis,
                y_axis,
                end: point,
            },
        );
    }
}

fn check_chain(link_lengths: &[f64], base: &BasePose, theta: &[f64]) -> Result<(), KinError> {
    check_link_lengths(link_lengths)?;
    base.validate()?;
    check_values("joint angles", theta, 2 * link_lengths.len())?;
    Ok(())
}
