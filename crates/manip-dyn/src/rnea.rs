//! Inverse dynamics by the recursive Newton-Euler algorithm (RNEA), O(n): the joint torques of
//! eq 12, `tau = M(q) qdd + C(q, v) + G(q)`.

use crate::check;
use crate::data::{ChainData, LinkAcceleration, LinkFrame};
use crate::error::DynError;
use crate::kinematics::{cross, update_frames};
use crate::model::ChainModel;

/// Inverse dynamics: the joint torques `tau` that give the joint accelerations `qdd` at the state
/// `(q, v)` (eq 12).
///
/// Forward sweep: absolute angles, angular velocities and accelerations, and the acceleration of
/// each link's centre of mass, with gravity as an upward acceleration of the base. Backward sweep:
/// the force and moment each link receives from its parent, whose moment is the joint torque.
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, rnea};
/// let pendulum = ChainModel::uniform(1, 1.0, 2.0, 9.81)?;
/// let mut data = ChainData::new(&pendulum);
/// let mut tau = [0.0];
/// // Held horizontal and at rest: the torque balances gravity on the centre of mass.
/// rnea(&pendulum, &mut data, &[0.0], &[0.0], &[0.0], &mut tau)?;
/// assert!((tau[0] - 2.0 * 9.81 * 0.5).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::NonFiniteResult`] if
/// the torques overflow.
pub fn rnea(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("qdd", qdd)])?;
    check::output("tau", tau, n)?;
    newton_euler(model, data, q, Some(v), Some(qdd), model.gravity(), tau);
    check::finite_result("tau", tau)
}

/// The Newton-Euler recursion on validated inputs; `None` stands for a zero vector and `gravity`
/// may be 0, so that the bias terms come out of the same code.
pub(crate) fn newton_euler(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: Option<&[f64]>,
    qdd: Option<&[f64]>,
    gravity: f64,
    tau: &mut [f64],
) {
    update_frames(&mut data.frames, q, v);
    forward_sweep(model, &data.frames, &mut data.accelerations, qdd, gravity);
    backward_sweep(model, &data.frames, &data.accelerations, tau);
}

fn forward_sweep(
    model: &ChainModel,
    frames: &[LinkFrame],
    accelerations: &mut [LinkAcceleration],
    qdd: Option<&[f64]>,
    gravity: f64,
) {
    let mut alpha = 0.0;
    let mut joint = [0.0, gravity];
    for (i, ((link, frame), acc)) in model
        .links()
        .iter()
        .zip(frames)
        .zip(accelerations)
        .enumerate()
    {
        alpha += qdd.map_or(0.0, |qdd| qdd[i]);
        // Acceleration of a point at unit distance along the link, relative to the joint:
        // tangential alpha (e_z x u) plus centripetal -omega^2 u.
        let [ux, uy] = frame.axis;
        let [wx, wy] = frame.normal();
        let w2 = frame.omega * frame.omega;
        let rel = [alpha * wx - w2 * ux, alpha * wy - w2 * uy];
        *acc = LinkAcceleration {
            alpha,
            com: [joint[0] + link.com * rel[0], joint[1] + link.com * rel[1]],
        };
        joint = [
            joint[0] + link.length * rel[0],
            joint[1] + link.length * rel[1],
        ];
    }
}

fn backward_sweep(
    model: &ChainModel,
    frames: &[LinkFrame],
    accelerations: &[LinkAcceleration],
    tau: &mut [f64],
) {
    // Force and moment (about the joint) that link i + 1 receives from link i.
    let mut force = [0.0, 0.0];
    let mut moment = 0.0;
    for i in (0..model.n_links()).rev() {
        let link = &model.links()[i];
        let u = frames[i].axis;
        let acc = &accelerations[i];
        // Euler about joint i: the moment from the parent balances the link's angular momentum
        // rate, the moment of m * com acceleration, and what the child receives.
        moment += link.inertia * acc.alpha
            + link.mass * link.com * cross(u, acc.com)
            + link.length * cross(u, force);
        // Newton: the parent's force drives the link and, through it, the child.
        force = [
            force[0] + link.mass * acc.com[0],
            force[1] + link.mass * acc.com[1],
        ];
        tau[i] = moment;
    }
}
