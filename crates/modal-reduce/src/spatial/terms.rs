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
use crate::error::{ReduceError, check_terms_finite};
use backbone_kin::vec3::{add, cross, mat_vec};
use lane_math::Lane;
use lane_math::check_values;
use pulp::{Simd, WithSimd};

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
    let arch = data.arch;
    arch.dispatch(TermsOfOneState {
        model,
        data,
        a,
        a_dot,
    });
    check_terms_finite(&data.mass_matrix, &data.coriolis, &data.gravity)
}

/// [`spatial_reduced_terms`] after its checks, run by [`pulp::Arch::dispatch`] so that the
/// kernel's fused multiply-adds are compiled for the processor's instruction set.
struct TermsOfOneState<'a> {
    model: &'a SpatialReducedModel,
    data: &'a mut SpatialReducedData,
    a: &'a [f64],
    a_dot: &'a [f64],
}

impl WithSimd for TermsOfOneState<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let data = self.data;
        let work = TermsLanes {
            omega_jacobian: &mut data.omega_jacobian,
            origin_jacobian: &mut data.origin_jacobian,
            com_jacobian: &mut data.com_jacobian,
            momentum_jacobian: &mut data.momentum_jacobian,
            inertia_times_omega_jacobian: &mut data.inertia_times_omega_jacobian,
            mass_matrix: &mut data.mass_matrix,
            coriolis: &mut data.coriolis,
            gravity: &mut data.gravity,
        };
        // The sizes a batch runs SIMD across states, with the size known at compile time.
        match self.model.n_coords() {
            4 => accumulate::<f64>((), self.model, self.a, self.a_dot, 4, work),
            8 => accumulate::<f64>((), self.model, self.a, self.a_dot, 8, work),
            m => accumulate::<f64>((), self.model, self.a, self.a_dot, m, work),
        }
    }
}

/// The buffers of [`accumulate`], each of one state (`f64`) or one state per lane: `3 x m`
/// row-major Jacobians `Jw`, `Jo`, `Jv`, `m Jv` and `I Jw`, `M*` (`m x m`, row-major), `C*`, `G*`.
pub(crate) struct TermsLanes<'w, L> {
    pub(crate) omega_jacobian: &'w mut [L],
    pub(crate) origin_jacobian: &'w mut [L],
    pub(crate) com_jacobian: &'w mut [L],
    pub(crate) momentum_jacobian: &'w mut [L],
    pub(crate) inertia_times_omega_jacobian: &'w mut [L],
    pub(crate) mass_matrix: &'w mut [L],
    pub(crate) coriolis: &'w mut [L],
    pub(crate) gravity: &'w mut [L],
}

/// `M*`, `C*` and `G*` (the module's sums) at `(a, a_dot)` into `work`, `m` coordinates: the
/// kernel of [`spatial_reduced_terms`] (`L = f64`) and of the batch across states
/// ([`spatial_forward_dynamics_batch`](super::spatial_forward_dynamics_batch), `L` a SIMD
/// register of states), the same operations in the same order for both.
///
/// The joint angles and rates are formed link by link from the rows of the planar map, so
/// nothing of size `n` is written: row `2i` of `J` is `[P_i, 0]` and row `2i + 1` is
/// `[0, P_i]` (`P_i` row `i` of the planar map, `2K` entries), so the `z` joint moves only the
/// first `2K` columns of the Jacobians and the `y` joint the last `2K`.
#[inline(always)]
pub(crate) fn accumulate<L: Lane>(
    context: L::Context,
    model: &SpatialReducedModel,
    a: &[L],
    a_dot: &[L],
    m: usize,
    work: TermsLanes<'_, L>,
) {
    // No closures: a closure is compiled without the instruction set of the SIMD dispatch that
    // inlines this function, and would call its intrinsics.
    let zero = L::splat(context, 0.0);
    let TermsLanes {
        omega_jacobian,
        origin_jacobian,
        com_jacobian,
        momentum_jacobian,
        inertia_times_omega_jacobian,
        mass_matrix,
        coriolis,
        gravity: gravity_terms,
    } = work;
    let (omega_jacobian, origin_jacobian) =
        (&mut omega_jacobian[..3 * m], &mut origin_jacobian[..3 * m]);
    let (com_jacobian, momentum_jacobian, inertia_times_omega_jacobian) = (
        &mut com_jacobian[..3 * m],
        &mut momentum_jacobian[..3 * m],
        &mut inertia_times_omega_jacobian[..3 * m],
    );
    let (mass_matrix, coriolis, gravity_terms) = (
        &mut mass_matrix[..m * m],
        &mut coriolis[..m],
        &mut gravity_terms[..m],
    );
    for buffer in [
        &mut *omega_jacobian,
        &mut *origin_jacobian,
        &mut *mass_matrix,
        &mut *coriolis,
        &mut *gravity_terms,
    ] {
        buffer.fill(zero);
    }
    let half = m / 2;
    let (a_z, a_y) = a[..m].split_at(half);
    let (rate_z, rate_y) = a_dot[..m].split_at(half);
    let map = model.map();
    let planar = map.planar();
    let gravity = model.gravity();
    let mut carried = Carried::<L>::base(context, model.base_rotation(), model.base().xyz);
    for (i, (&length, inertia)) in map.link_lengths().iter().zip(model.links()).enumerate() {
        let row = &planar.row(i)[..half];
        // theta = J a and theta_dot = J a_dot for this link's two joints.
        let (mut angles, mut rates) = ([zero; 2], [zero; 2]);
        for (k, &r) in row.iter().enumerate() {
            let r = L::splat(context, r);
            angles = [a_z[k].mul_add(r, angles[0]), a_y[k].mul_add(r, angles[1])];
            rates = [
                rate_z[k].mul_add(r, rates[0]),
                rate_y[k].mul_add(r, rates[1]),
            ];
        }
        let motion = link_step(context, &mut carried, length, angles, rates, [zero; 2]);
        // Jw += u J_row and Jo += (o x u) J_row for both joints.
        let (moment_z, moment_y) = (
            cross(motion.joint, motion.u_z),
            cross(motion.joint, motion.u_y),
        );
        for d in 0..3 {
            let (w, o) = (
                &mut omega_jacobian[d * m..(d + 1) * m],
                &mut origin_jacobian[d * m..(d + 1) * m],
            );
            let (w_z, w_y) = w.split_at_mut(half);
            let (o_z, o_y) = o.split_at_mut(half);
            for (k, &r) in row.iter().enumerate() {
                let r = L::splat(context, r);
                w_z[k] = motion.u_z[d].mul_add(r, w_z[k]);
                o_z[k] = moment_z[d].mul_add(r, o_z[k]);
                w_y[k] = motion.u_y[d].mul_add(r, w_y[k]);
                o_y[k] = moment_y[d].mul_add(r, o_y[k]);
            }
        }
        // Jv = Jo + Jw x c, the momentum Jacobian m Jv and I Jw, column by column.
        let world = world_inertia(&motion.rotation, inertia.principal);
        let mass = L::splat(context, inertia.mass);
        let c = motion.com;
        for k in 0..m {
            let (w, o) = (column(omega_jacobian, m, k), column(origin_jacobian, m, k));
            let v = [
                w[2].neg_mul_add(c[1], w[1].mul_add(c[2], o[0])),
                w[0].neg_mul_add(c[2], w[2].mul_add(c[0], o[1])),
                w[1].neg_mul_add(c[0], w[0].mul_add(c[1], o[2])),
            ];
            let iw = [
                dot_add(world[0], w, zero),
                dot_add(world[1], w, zero),
                dot_add(world[2], w, zero),
            ];
            for d in 0..3 {
                com_jacobian[d * m + k] = v[d];
                momentum_jacobian[d * m + k] = v[d] * mass;
                inertia_times_omega_jacobian[d * m + k] = iw[d];
            }
        }
        let weight = [
            L::splat(context, gravity[0]),
            L::splat(context, gravity[1]),
            L::splat(context, gravity[2]),
        ];
        let torque = add(
            mat_vec(&world, motion.omega_dot),
            cross(motion.omega, mat_vec(&world, motion.omega)),
        );
        // C* += (m Jv)^T a_c + Jw^T torque, G* -= (m Jv)^T g, M* += (m Jv)^T Jv + Jw^T I Jw.
        for k in 0..m {
            let (p_k, w_k) = (
                column(momentum_jacobian, m, k),
                column(omega_jacobian, m, k),
            );
            coriolis[k] = dot_add(w_k, torque, dot_add(p_k, motion.com_accel, coriolis[k]));
            gravity_terms[k] = gravity_terms[k] - dot_add(p_k, weight, zero);
            for l in 0..=k {
                let (v_l, iw_l) = (
                    column(com_jacobian, m, l),
                    column(inertia_times_omega_jacobian, m, l),
                );
                let entry = &mut mass_matrix[k * m + l];
                *entry = dot_add(w_k, iw_l, dot_add(p_k, v_l, *entry));
            }
        }
    }
    for k in 0..m {
        for l in 0..k {
            mass_matrix[l * m + k] = mass_matrix[k * m + l];
        }
    }
}

/// `acc + a . b` in fused multiply-adds, `a[0] b[0]` first.
#[inline(always)]
fn dot_add<L: Lane>(a: [L; 3], b: [L; 3], acc: L) -> L {
    a[2].mul_add(b[2], a[1].mul_add(b[1], a[0].mul_add(b[0], acc)))
}

/// Column `k` of a `3 x m` row-major matrix.
#[inline(always)]
fn column<L: Lane>(matrix: &[L], m: usize, k: usize) -> [L; 3] {
    [matrix[k], matrix[m + k], matrix[2 * m + k]]
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
    check_values("a", a, m)?;
    check_values("a_dot", a_dot, m)?;
    Ok(())
}
