//! Forward kinematics of the discrete planar chain, for arbitrary link lengths.
//!
//! Joint `i` sits at the proximal end of link `i`, the base joint at the origin; `theta_i` is the
//! angle of link `i` relative to link `i - 1` (`theta_1` from the `x` axis), so link `i` points
//! along `phi_i = theta_1 + ... + theta_i` and joint `i + 1` is at
//! `p_{i+1} = p_i + L_i (cos phi_i, sin phi_i)`. With `theta` from the modal map (eq 8) the tip
//! is the midpoint rule applied to the end-point integral of eqs 3-4.

use crate::error::KinError;
use crate::validate::check_link_lengths;
use lane_math::{check_len, check_values};

/// Every joint position from the base to the tip: `positions[0]` is the base (the origin),
/// `positions[i]` the distal end of link `i` (0-based: of `link_lengths[i - 1]`), and
/// `positions[n]` the tip. `positions` must hold `n + 1` points. Allocation-free.
///
/// # Errors
/// [`KinError`] for link lengths that are not positive and finite, joint angles that are not
/// `n` finite numbers, or finite ones whose running sum (a link's absolute angle) overflows.
///
/// ```
/// use backbone_kin::joint_positions;
/// use std::f64::consts::FRAC_PI_2;
/// let mut points = [[0.0; 2]; 3];
/// joint_positions(&[1.0, 0.5], &[FRAC_PI_2, -FRAC_PI_2], &mut points)?;
/// assert!((points[1][1] - 1.0).abs() < 1e-15 && (points[2][0] - 0.5).abs() < 1e-15);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn joint_positions(
    link_lengths: &[f64],
    theta: &[f64],
    positions: &mut [[f64; 2]],
) -> Result<(), KinError> {
    check_chain(link_lengths, theta)?;
    check_len("joint positions", positions.len(), link_lengths.len() + 1)?;
    positions[0] = [0.0; 2];
    let mut i = 0;
    walk(link_lengths, theta, |point| {
        i += 1;
        positions[i] = point;
    })
}

/// The tip (the distal end of the last link) of the chain with joint angles `theta`.
///
/// # Errors
/// As [`joint_positions`].
///
/// ```
/// use backbone_kin::tip_position;
/// let tip = tip_position(&[0.5, 0.5], &[0.0, 0.0])?;
/// assert_eq!(tip, [1.0, 0.0]);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn tip_position(link_lengths: &[f64], theta: &[f64]) -> Result<[f64; 2], KinError> {
    check_chain(link_lengths, theta)?;
    let mut tip = [0.0; 2];
    walk(link_lengths, theta, |point| tip = point)?;
    Ok(tip)
}

/// Visits the distal end of every link, base to tip; refuses joint angles whose running sum
/// (a link's absolute angle) overflows.
fn walk(
    link_lengths: &[f64],
    theta: &[f64],
    mut visit: impl FnMut([f64; 2]),
) -> Result<(), KinError> {
    let (mut phi, mut point) = (0.0, [0.0; 2]);
    for (i, (&length, &angle)) in link_lengths.iter().zip(theta).enumerate() {
        phi += angle;
        if !phi.is_finite() {
            return Err(KinError::NonFinite {
                name: "absolute link angles (running sums of the joint angles)",
                index: Some(i),
                value: phi,
            });
        }
        let (sin, cos) = phi.sin_cos();
        point = [point[0] + length * cos, point[1] + length * sin];
        visit(point);
    }
    Ok(())
}

fn check_chain(link_lengths: &[f64], theta: &[f64]) -> Result<(), KinError> {
    check_link_lengths(link_lengths)?;
    check_values("joint angles", theta, link_lengths.len())?;
    Ok(())
}
