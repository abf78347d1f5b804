//! `M*`, `C*` and `G*` of a spatial modal arm in `O(n m^2)`, without the `2n x 2n` mass matrix
//! (`docs/theory.md`, section 8).
//!
//! The modal rates move link `i` with angular velocity `w_i = Jw_i a_dot` and its centre of mass
//! with velocity `v_i = Jv_i a_dot`, where `Jw_i = sum_j u_j J_j` and `Jv_i = Jo_i - [c_i]x Jw_i`,
//! `Jo_i = sum_j (o_j x u_j) J_j` (the velocity of the world origin moving with the link), sums
//! over the joints `j` up to link `i` (`u_j` the joint's axis, `o_j` its point, `J_j` its row of
//! the modal map): both `3 x m`, updated joint by joint in `O(m)`. Then, from the kinetic energy
//! `T = (1/2) sum_i m_i |v_i|^2 + w_i^T I_i w_i` and the potential `V = -sum_i m_i g . c_i`,
//!
//! - `M* = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i` (`I_i` the inertia about the centre of mass
//!   in the world frame),
//! - `C* = sum_i Jv_i^T (m_i a_i) + Jw_i^T (I_i w_dot_i + w_i x I_i w_i)`, with `a_i` and
//!   `w_dot_i` the accelerations at zero modal acceleration ([`motion`](super::motion)),
//! - `G* = -sum_i m_i Jv_i^T g`,
//!
//! `O(m^2)` a link for `M*`, `O(m)` for the others. The tests hold them against the joint torques
//! of the Newton-Euler recursion (`J^T tau`), the Lagrangian's finite differences, the planar
//! reduced model and Pinocchio through the URDF export.

use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::motion::{Carried, link_step, world_inertia};
use crate::error::{ReduceError, check_finite_result, check_input};
use backbone_kin::vec3::{cross, dot, mat_vec};

/// Computes `M*`, `C*` and `G*` at the modal state `(a, a_dot)` into `data` (read them with
/// [`SpatialReducedData::mass_matrix`], [`coriolis`](SpatialReducedData::coriolis) and
/// [`gravity`](SpatialReducedData::gravity)). Allocation-free.
///
/// Errors: a workspace of another model, inputs of the wrong length or not finite, and terms
/// that are not finite (inputs too large for double precision).
pub fn spatial_reduced_terms(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    check_state(model, data, a, a_dot)?;
    let m = model.n_coords();
    let map = model.map();
    map.joint_angles(a, &mut data.theta)?;
    map.joint_rates(a_dot, &mut data.theta_dot)?;
    data.omega_jacobian.fill(0.0);
    data.origin_jacobian.fill(0.0);
    data.mass_matrix.fill(0.0);
    data.coriolis.fill(0.0);
    data.gravity.fill(0.0);
    let gravity = model.gravity();
    let base = model.base();
    let mut carried = Carried::base(base.rotation(), base.xyz);
    for (i, ((&length, inertia), (angles, rates))) in map
        .link_lengths()
        .iter()
        .zip(model.links())
        .zip(
            data.theta
                .chunks_exact(2)
                .zip(data.theta_dot.chunks_exact(2)),
        )
        .enumerate()
    {
        let motion = link_step(
            &mut carried,
            length,
            [angles[0], angles[1]],
            [rates[0], rates[1]],
            [0.0; 2],
        );
        for (joint, axis) in [(2 * i, motion.u_z), (2 * i + 1, motion.u_y)] {
            let moment = cross(motion.joint, axis);
            let row = map.row(joint);
            for d in 0..3 {
                let (w, o) = (
                    &mut data.omega_jacobian[d * m..(d + 1) * m],
                    &mut data.origin_jacobian[d * m..(d + 1) * m],
                );
                for ((w, o), &r) in w.iter_mut().zip(o.iter_mut()).zip(row) {
                    *w += axis[d] * r;
                    *o += moment[d] * r;
                }
            }
        }
        // Jv = Jo + Jw x c, column by column; I Jw.
        let world = world_inertia(&motion.rotation, inertia.principal);
        for k in 0..m {
            let w = [0, 1, 2].map(|d| data.omega_jacobian[d * m + k]);
            let o = [0, 1, 2].map(|d| data.origin_jacobian[d * m + k]);
            let wc = cross(w, motion.com);
            let iw = mat_vec(&world, w);
            for d in 0..3 {
                data.com_jacobian[d * m + k] = o[d] + wc[d];
                data.inertia_times_omega_jacobian[d * m + k] = iw[d];
            }
        }
        let mass = inertia.mass;
        let force = motion.com_accel.map(|x| mass * x);
        let iw = mat_vec(&world, motion.omega);
        let torque = {
            let spin = cross(motion.omega, iw);
            let angular = mat_vec(&world, motion.omega_dot);
            [0, 1, 2].map(|d| angular[d] + spin[d])
        };
        let (jv, jw, ijw) = (
            &data.com_jacobian,
            &data.omega_jacobian,
            &data.inertia_times_omega_jacobian,
        );
        let column = |matrix: &[f64], k: usize| [0, 1, 2].map(|d| matrix[d * m + k]);
        for k in 0..m {
            let (jv_k, jw_k) = (column(jv, k), column(jw, k));
            data.coriolis[k] += dot(jv_k, force) + dot(jw_k, torque);
            data.gravity[k] -= mass * dot(jv_k, gravity);
            for l in 0..=k {
                let value = mass * dot(jv_k, column(jv, l)) + dot(jw_k, column(ijw, l));
                data.mass_matrix[k * m + l] += value;
            }
        }
    }
    for k in 0..m {
        for l in 0..k {
            data.mass_matrix[l * m + k] = data.mass_matrix[k * m + l];
        }
    }
    check_finite_result("reduced mass matrix M*", &data.mass_matrix)?;
    check_finite_result("reduced Coriolis vector C*", &data.coriolis)?;
    check_finite_result("reduced gravity vector G*", &data.gravity)
}

/// Checks that `data` was made for `model` and that `a` and `a_dot` are `m` finite values each.
pub(crate) fn check_state(
    model: &SpatialReducedModel,
    data: &SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_input("a", a, m)?;
    check_input("a_dot", a_dot, m)
}
