//! Forward dynamics by the articulated-body algorithm (ABA), O(n).
//!
//! Planar spatial vectors, all in base-frame axes and each referred to a point: a motion
//! `(alpha, a_x, a_y)` is a body's angular acceleration and the acceleration of its material point
//! at the reference point; a force `(n, f_x, f_y)` is a moment about the reference point and a
//! force. Link `i`'s quantities are referred to its joint `p_i`. Moving a motion from `p_i` to
//! `p_{i+1} = p_i + d` multiplies it by `X(d) = [[1, 0, 0], [-d_y, 1, 0], [d_x, 0, 1]]`; moving a
//! force back from `p_{i+1}` to `p_i` multiplies it by `X(d)^T`. The joint's motion axis is
//! `S = (1, 0, 0)`.
//!
//! Link `i` obeys `f_i = H_i A_i + b_i + X_i^T f_{i+1}`, with `f_i` the force it receives from its
//! parent, `A_i` its acceleration, `H_i` its inertia about `p_i` and `b_i = (0, -m c omega^2 u)`
//! the centripetal bias; the child's acceleration is `A_{i+1} = X_i A_i + beta_i + S qdd_{i+1}`,
//! `beta_i = (0, -L omega^2 u)`, and `tau_i = S^T f_i`. Gravity is an upward acceleration of the
//! base. The backward sweep condenses the chain tip-first into articulated inertias
//! `f_i = IA_i A_i + pA_i`; the forward sweep then solves each joint's acceleration.

use crate::check;
use crate::crba::{Subtree, accumulate_subtrees};
use crate::data::ChainData;
use crate::error::DynError;
use crate::kinematics::{LinkFrame, dot, update_frames};
use crate::model::ChainModel;

/// What the forward sweep needs of joint `i`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ArticulatedLink {
    /// The translational part of `U_i = IA_i S` (its rotational part is `D_i`).
    pub(crate) u_lin: [f64; 2],
    /// `D_i = S^T IA_i S`: the articulated inertia about the joint axis.
    pub(crate) d: f64,
    /// `tau_i - S^T pA_i`: the joint torque left after the articulated bias force.
    residual: f64,
}

/// Forward dynamics by the articulated-body algorithm: the joint accelerations `qdd` that the
/// torques `tau` produce at the state `(q, v)`, solving eq 12 for `theta_ddot` in O(n).
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, aba};
/// let pendulum = ChainModel::uniform(1, 1.0, 3.0, 9.81)?;
/// let mut data = ChainData::new(&pendulum);
/// let mut qdd = [0.0];
/// aba(&pendulum, &mut data, &[0.0], &[0.0], &[0.0], &mut qdd)?;
/// // Released horizontally: qdd = -m g c / (m L^2 / 3) = -1.5 g / L.
/// assert!((qdd[0] + 1.5 * 9.81).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::NotPositiveDefinite`]
/// if an articulated inertia about a joint axis is not positive beyond rounding (link parameters
/// too disparate for double precision), [`DynError::NonFiniteResult`] if the accelerations
/// overflow.
pub fn aba(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::output("qdd", qdd, n)?;
    articulated_body(model, data, q, v, tau, qdd)?;
    check::finite_result("qdd", qdd)
}

/// The articulated-body algorithm on validated inputs. Leaves the link frames of `(q, v)` in
/// `data.frames` and each joint's articulated inertia in `data.articulated`.
pub(crate) fn articulated_body(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    update_frames(&mut data.frames, q, Some(v));
    // The composite inertias about each joint (the diagonal of M) are the scale of the pivots.
    accumulate_subtrees(model, &data.frames, &mut data.subtrees);
    backward_sweep(
        model,
        &data.frames,
        &data.subtrees,
        tau,
        &mut data.articulated,
    )?;
    forward_sweep(model, &data.frames, &data.articulated, qdd);
    Ok(())
}

/// What link `i` sees of the links beyond it once their joint accelerations are solved out,
/// referred to joint `i + 1`: `f = IA' A + pA'` with `IA' = [[0, 0], [0, K]]` and
/// `pA' = (tau_{i+1}, force)`. The rotational row of `IA'` vanishes and the moment of `pA'` is
/// the joint torque because a revolute joint transmits no other moment.
#[derive(Debug, Clone, Copy, Default)]
struct Condensed {
    /// `K`, the symmetric 2 x 2 resistance to translating the joint, as `[k_xx, k_xy, k_yy]`.
    inertia: [f64; 3],
    /// The bias force at the joint.
    force: [f64; 2],
    /// The joint torque.
    torque: f64,
}

/// Condenses the chain from the tip: the articulated inertia and bias force of each joint.
fn backward_sweep(
    model: &ChainModel,
    frames: &[LinkFrame],
    subtrees: &[Subtree],
    tau: &[f64],
    articulated: &mut [ArticulatedLink],
) -> Result<(), DynError> {
    let mut child = Condensed::default();
    for i in (0..model.n_links()).rev() {
        let link = &model.links()[i];
        let frame = &frames[i];
        let u = frame.axis;
        let w = frame.normal();
        let w2 = frame.omega * frame.omega;
        // Joint i + 1 is at d = L u; X(d) moves the child's quantities to joint i, where the
        // child's acceleration gains the centripetal bias beta = (0, -omega^2 d).
        let d = [link.length * u[0], link.length * u[1]];
        let r = [-d[1], d[0]];
        let [kxx, kxy, kyy] = child.inertia;
        let k_mul = |x: [f64; 2]| [kxx * x[0] + kxy * x[1], kxy * x[0] + kyy * x[1]];
        let k_beta = k_mul([-w2 * d[0], -w2 * d[1]]);
        let force = [child.force[0] + k_beta[0], child.force[1] + k_beta[1]];
        let k_r = k_mul(r);

        // IA_i = H_i + X^T IA' X and pA_i = b_i + X^T (pA' + IA' beta), with the link's inertia
        // about its joint H_i = [[I + m c^2, m c w^T], [m c w, m 1]] and centripetal bias
        // b_i = (0, -m c omega^2 u).
        let mc = link.mass * link.com;
        let d_axis = link.inertia + mc * link.com + dot(r, k_r);
        let u_lin = [mc * w[0] + k_r[0], mc * w[1] + k_r[1]];
        let bias_moment = child.torque + dot(r, force);
        let bias_force = [force[0] - mc * w2 * u[0], force[1] - mc * w2 * u[1]];
        check::pivot(d_axis, subtrees[i].second_moment)?;
        let residual = tau[i] - bias_moment;
        articulated[i] = ArticulatedLink {
            u_lin,
            d: d_axis,
            residual,
        };
        // Solve the joint acceleration out: IA - U U^T / D and pA + U residual / D.
        let gain = [u_lin[0] / d_axis, u_lin[1] / d_axis];
        child = Condensed {
            inertia: [
                link.mass + kxx - gain[0] * u_lin[0],
                kxy - gain[0] * u_lin[1],
                link.mass + kyy - gain[1] * u_lin[1],
            ],
            force: [
                bias_force[0] + gain[0] * residual,
                bias_force[1] + gain[1] * residual,
            ],
            torque: tau[i],
        };
    }
    Ok(())
}

/// Solves the joint accelerations from the base out.
fn forward_sweep(
    model: &ChainModel,
    frames: &[LinkFrame],
    articulated: &[ArticulatedLink],
    qdd: &mut [f64],
) {
    // Acceleration of link i's parent, moved to joint i (gravity as an upward base acceleration).
    let mut parent = [0.0, 0.0, model.gravity()];
    for (i, (link, (frame, joint))) in model
        .links()
        .iter()
        .zip(frames.iter().zip(articulated))
        .enumerate()
    {
        // qdd_i = (tau_i - S^T pA_i - U_i^T A_i^-) / D_i.
        let acc = (joint.residual - dot([parent[1], parent[2]], joint.u_lin)) / joint.d - parent[0];
        qdd[i] = acc;
        let own = [parent[0] + acc, parent[1], parent[2]];
        let w2 = frame.omega * frame.omega;
        let d = [link.length * frame.axis[0], link.length * frame.axis[1]];
        parent = [
            own[0],
            own[1] - d[1] * own[0] - w2 * d[0],
            own[2] + d[0] * own[0] - w2 * d[1],
        ];
    }
}
