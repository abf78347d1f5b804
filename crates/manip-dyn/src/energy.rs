//! Kinetic and potential energy, summed link by link from centre-of-mass velocities and heights
//! (not from `M` or `G`, so they check both independently).

use crate::check;
use crate::data::ChainData;
use crate::error::DynError;
use crate::kinematics::update_frames;
use crate::model::ChainModel;

/// Kinetic energy `T = sum_i (m_i |r_i_dot|^2 + I_i omega_i^2) / 2`, from each link's
/// centre-of-mass velocity `r_i_dot` and absolute angular velocity `omega_i`. It equals
/// `v^T M(q) v / 2`.
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, kinetic_energy};
/// let rod = ChainModel::uniform(1, 2.0, 3.0, 9.81)?;
/// let mut data = ChainData::new(&rod);
/// // A rod turning about its end: T = (m L^2 / 3) omega^2 / 2.
/// let t = kinetic_energy(&rod, &mut data, &[0.4], &[2.0])?;
/// assert!((t - 3.0 * 4.0 / 3.0 * 4.0 / 2.0).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if `q` or `v` does not have `n` entries or `data` was built for
/// another chain, [`DynError::NonFinite`] for a NaN or infinite input,
/// [`DynError::NonFiniteResult`] if the energy overflows.
pub fn kinetic_energy(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
) -> Result<f64, DynError> {
    check::inputs(model, data, &[("q", q), ("v", v)])?;
    update_frames(&mut data.frames, q, Some(v));
    let mut joint_velocity = [0.0, 0.0];
    let mut energy = 0.0;
    for (link, frame) in model.links().iter().zip(&data.frames) {
        let normal = frame.normal();
        let com_velocity = [
            joint_velocity[0] + link.com * frame.omega * normal[0],
            joint_velocity[1] + link.com * frame.omega * normal[1],
        ];
        energy += 0.5
            * (link.mass * (com_velocity[0].powi(2) + com_velocity[1].powi(2))
                + link.inertia * frame.omega.powi(2));
        joint_velocity[0] += link.length * frame.omega * normal[0];
        joint_velocity[1] += link.length * frame.omega * normal[1];
    }
    check::finite_scalar("kinetic energy", energy)
}

/// Potential energy `V = g sum_i m_i y_i`, with `y_i` the height of link `i`'s centre of mass
/// above the base joint. Its gradient is [`gravity`](crate::gravity()).
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, potential_energy};
/// let arm = ChainModel::uniform(2, 1.0, 1.0, 10.0)?;
/// let mut data = ChainData::new(&arm);
/// // Pointing straight up: centres of mass at heights 0.5 and 1.5.
/// let v = potential_energy(&arm, &mut data, &[std::f64::consts::FRAC_PI_2, 0.0])?;
/// assert!((v - 20.0).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if `q` does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite angle, [`DynError::NonFiniteResult`] if
/// the energy overflows.
pub fn potential_energy(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
) -> Result<f64, DynError> {
    check::inputs(model, data, &[("q", q)])?;
    update_frames(&mut data.frames, q, None);
    let mut joint_height = 0.0;
    let mut weighted_height = 0.0;
    for (link, frame) in model.links().iter().zip(&data.frames) {
        weighted_height += link.mass * (joint_height + link.com * frame.axis[1]);
        joint_height += link.length * frame.axis[1];
    }
    check::finite_scalar("potential energy", model.gravity() * weighted_height)
}
