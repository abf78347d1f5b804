//! Kinetic and potential energy of a spatial chain.

use super::algebra::{Motion, dot};
use super::data::SpatialData;
use super::kinematics::{update_placements, update_poses};
use super::model::SpatialModel;
use crate::check;
use crate::error::DynError;

/// Kinetic energy `T = 1/2 qd^T M(q) qd = 1/2 sum_i v_i . I_i v_i` (`v_i` link `i`'s spatial
/// velocity in its frame).
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, kinetic_energy};
/// // A rod of 3 kg, 1 m, spinning at 2 rad/s about its end: 1/2 (m L^2 / 3) w^2 = 2 J.
/// let rod = SpatialModel::from_planar(&ChainModel::uniform(1, 1.0, 3.0, 9.81)?);
/// let energy = kinetic_energy(&rod, &mut SpatialData::new(&rod), &[0.4], &[2.0])?;
/// assert!((energy - 2.0).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::NonFiniteResult`] on
/// overflow.
pub fn kinetic_energy(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: &[f64],
) -> Result<f64, DynError> {
    super::check_inputs(model, data, &[("q", q), ("v", v)])?;
    update_placements(model, data, q);
    let mut velocity = Motion::default();
    let mut twice = 0.0;
    for (i, (placement, rate)) in data.placements.iter().zip(v).enumerate() {
        velocity = placement
            .inv_act_motion(&velocity)
            .plus(&model.axes[i].times(*rate));
        twice += velocity.dot(&model.inertias[i].apply((), &velocity));
    }
    check::finite_scalar("kinetic energy", 0.5 * twice)
}

/// Potential energy `V = -sum_i m_i g . c_i`, with `c_i` link `i`'s centre of mass in the base
/// frame (zero when every centre of mass is at the base's origin). Leaves the poses in `data`.
///
/// # Errors
/// As [`kinetic_energy`].
pub fn potential_energy(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
) -> Result<f64, DynError> {
    super::check_inputs(model, data, &[("q", q)])?;
    update_poses(model, data, q);
    let g = model.gravity();
    let energy = model
        .inertias
        .iter()
        .zip(&data.poses)
        .map(|(inertia, pose)| -inertia.mass * dot(g, pose.apply(inertia.com)))
        .sum();
    check::finite_scalar("potential energy", energy)
}
