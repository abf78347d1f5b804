//! The joint torques that realise a modal motion of a spatial modal arm: `tau = M J a_dd + C + G`
//! (`2n` entries, `z` and `y` joint of each link in turn), by the Newton-Euler recursion in
//! `O(n)` after the map's `O(n m)` (`docs/theory.md`, section 8).
//!
//! Forward, [`link_step`] with the joint accelerations `J a_dd`; backward, from the tip, the force
//! `F_i = m_i (a_i - g) + F_{i+1}` and the moment about the joint point `p_{i-1}`,
//! `N_i = I_i w_dot_i + w_i x I_i w_i + (c_i - p_{i-1}) x m_i (a_i - g) + (p_i - p_{i-1}) x F_{i+1}
//! + N_{i+1}`, whose components along the two joint axes are the torques. `J^T tau = M* a_dd + C*
//! + G*` then holds (tested against [`spatial_reduced_terms`](super::spatial_reduced_terms)).

use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::motion::{Carried, link_step, link_wrench, world_inertia};
use super::terms::check_state;
use crate::error::{ReduceError, check_finite_result};
use backbone_kin::vec3::dot;
use lane_math::{check_len, check_values};

/// The joint torques `tau` (`2n`) of the modal motion `(a, a_dot, a_ddot)`. Allocation-free.
///
/// Errors: as [`spatial_reduced_terms`](super::spatial_reduced_terms), `a_ddot` or `tau` of the
/// wrong length, torques that are not finite.
pub fn spatial_joint_torques(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
    a_ddot: &[f64],
    tau: &mut [f64],
) -> Result<(), ReduceError> {
    check_state(model, data, a, a_dot)?;
    check_values("a_ddot", a_ddot, model.n_coords())?;
    check_len("joint torques", tau.len(), 2 * model.n_links())?;
    let map = model.map();
    map.joint_angles(a, &mut data.theta)?;
    map.joint_rates(a_dot, &mut data.theta_dot)?;
    map.joint_rates(a_ddot, &mut data.theta_ddot)?;
    let base = model.base();
    let mut carried = Carried::base((), base.rotation(), base.xyz);
    for (((motion, &length), angles), (rates, accels)) in data
        .links
        .iter_mut()
        .zip(map.link_lengths())
        .zip(data.theta.chunks_exact(2))
        .zip(
            data.theta_dot
                .chunks_exact(2)
                .zip(data.theta_ddot.chunks_exact(2)),
        )
    {
        *motion = link_step(
            (),
            &mut carried,
            length,
            [angles[0], angles[1]],
            [rates[0], rates[1]],
            [accels[0], accels[1]],
        );
    }
    let gravity = model.gravity();
    let (mut force, mut moment, mut next_joint) = ([0.0; 3], [0.0; 3], carried.point);
    for ((motion, inertia), pair) in data
        .links
        .iter()
        .zip(model.links())
        .zip(tau.chunks_exact_mut(2))
        .rev()
    {
        let world = world_inertia(&motion.rotation, inertia.principal);
        (force, moment) = link_wrench(
            motion,
            &world,
            inertia.mass,
            gravity,
            force,
            moment,
            next_joint,
        );
        next_joint = motion.joint;
        pair[0] = dot(motion.u_z, moment);
        pair[1] = dot(motion.u_y, moment);
    }
    check_finite_result("joint torques", tau)
}

/// The modal forces of joint torques: `tau_star = J^T tau` (`2n` joint torques, `z` and `y`
/// joint of each link in turn, to `m`). Allocation-free.
///
/// Errors: `tau` not `2n` finite values, `tau_star` not of length `m`.
pub fn spatial_project_torques(
    model: &SpatialReducedModel,
    tau: &[f64],
    tau_star: &mut [f64],
) -> Result<(), ReduceError> {
    let map = model.map();
    check_values("tau", tau, map.n_joints())?;
    check_len("tau_star", tau_star.len(), model.n_coords())?;
    tau_star.fill(0.0);
    for (j, &value) in tau.iter().enumerate() {
        for (out, &entry) in tau_star.iter_mut().zip(map.row(j)) {
            *out += entry * value;
        }
    }
    Ok(())
}
