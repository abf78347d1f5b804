//! Inverse dynamics by the recursive Newton-Euler algorithm (RNEA), `O(n)`, in link frames
//! (Featherstone 2008, table 5.1; Pinocchio's `rnea`).
//!
//! Base to tip, with `a_0 = -g` (gravity as an upward acceleration of the base):
//! `v_i = X_i^-1 v_{i-1} + S_i qd_i`, `a_i = X_i^-1 a_{i-1} + S_i qdd_i + v_i x S_i qd_i`,
//! `f_i = I_i a_i + v_i x* I_i v_i`. Tip to base: `tau_i = S_i^T f_i`,
//! `f_{i-1} += X_i^-T f_i`.

use super::algebra::{Force, Motion};
use super::data::SpatialData;
use super::kinematics::update_placements;
use super::model::SpatialModel;
use crate::check;
use crate::error::DynError;

/// Inverse dynamics: the joint efforts `tau = M(q) qdd + C(q, v) v + G(q)` (torques for revolute
/// joints, forces for prismatic ones) that give the accelerations `qdd` at the state `(q, v)`.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, rnea};
/// // A 1 kg point-like pendulum 1 m long, held horizontal: tau = m g L.
/// let pendulum = SpatialModel::from_planar(&ChainModel::uniform(1, 2.0, 1.0, 9.81)?);
/// let mut data = SpatialData::new(&pendulum);
/// let mut tau = [0.0];
/// rnea(&pendulum, &mut data, &[0.0], &[0.0], &[0.0], &mut tau)?;
/// assert!((tau[0] - 9.81).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::NonFiniteResult`] if
/// the efforts overflow.
pub fn rnea(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
) -> Result<(), DynError> {
    let n = super::check_inputs(model, data, &[("q", q), ("v", v), ("qdd", qdd)])?;
    check::output("tau", tau, n)?;
    update_placements(model, data, q);
    newton_euler(model, data, Some(v), Some(qdd), true, tau);
    check::finite_result("tau", tau)
}

/// The Newton-Euler sweeps on the placements already in `data`, with `v` and `qdd` zero where
/// `None` and gravity left out unless `with_gravity`. Leaves each link's velocity, acceleration
/// and the force from its parent in `data`.
pub(crate) fn newton_euler(
    model: &SpatialModel,
    data: &mut SpatialData,
    v: Option<&[f64]>,
    qdd: Option<&[f64]>,
    with_gravity: bool,
    tau: &mut [f64],
) {
    let g = if with_gravity {
        model.gravity()
    } else {
        [0.0; 3]
    };
    let mut velocity = Motion::default();
    let mut acceleration = Motion {
        linear: [-g[0], -g[1], -g[2]],
        angular: [0.0; 3],
    };
    for i in 0..model.n_links() {
        let placement = &data.placements[i];
        let axis = &model.axes[i];
        let joint_velocity = axis.times(v.map_or(0.0, |v| v[i]));
        velocity = placement.inv_act_motion(&velocity).plus(&joint_velocity);
        acceleration = placement
            .inv_act_motion(&acceleration)
            .plus(&axis.times(qdd.map_or(0.0, |qdd| qdd[i])))
            .plus(&velocity.cross_motion(&joint_velocity));
        // A massless link (the cross of a universal joint) needs no force.
        data.forces[i] = if model.massless[i] {
            Force::default()
        } else {
            let inertia = &model.inertias[i];
            let momentum = inertia.apply((), &velocity);
            inertia
                .apply((), &acceleration)
                .plus(&velocity.cross_force(&momentum))
        };
        data.velocities[i] = velocity;
        data.accelerations[i] = acceleration;
    }
    for i in (0..model.n_links()).rev() {
        tau[i] = model.axes[i].dot(&data.forces[i]);
        if i > 0 {
            let passed = data.placements[i].act_force(&data.forces[i]);
            data.forces[i - 1] = data.forces[i - 1].plus(&passed);
        }
    }
}
