//! Joint torques that realise a modal motion, and their projection onto the modal coordinates.

use backbone_kin::ModalMap;

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::model::ReducedModel;
use lane_math::{check_len, check_values};

/// The joint torques `tau = M J a_ddot + C + G` (eq 13) that make the full chain follow the modal
/// motion `(a, a_dot, a_ddot)`: what the actuators of the real arm must deliver. Written into
/// `tau` (length `n`).
///
/// Computed by the full chain's recursive Newton-Euler algorithm at `theta = J a + theta_0`,
/// `theta_dot = J a_dot`, `theta_ddot = J a_ddot` (eqs 8, 10, 11). They satisfy
/// `J^T tau = tau*` when `a_ddot` solves `M* a_ddot = tau* - C* - G*` (see [`project_torques`]).
/// Allocation-free.
pub fn joint_torques(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
    a_ddot: &[f64],
    tau: &mut [f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_values("a", a, m)?;
    check_values("a_dot", a_dot, m)?;
    check_values("a_ddot", a_ddot, m)?;
    check_len("tau", tau.len(), model.n_links())?;
    let map = model.map();
    map.joint_angles(a, &mut data.theta)?;
    map.joint_rates(a_dot, &mut data.theta_dot)?;
    map.joint_rates(a_ddot, &mut data.theta_ddot)?;
    // Finite coordinates can overflow in the map: the joints' dynamics would then name their
    // own input; the overflow is numerical.
    check_finite_result("theta = J a + theta_0", &data.theta)?;
    check_finite_result("theta_dot = J a_dot", &data.theta_dot)?;
    check_finite_result("theta_ddot = J a_ddot", &data.theta_ddot)?;
    manip_dyn::rnea(
        model.chain(),
        &mut data.chain,
        &data.theta,
        &data.theta_dot,
        &data.theta_ddot,
        tau,
    )?;
    Ok(())
}

/// The modal generalised forces `tau* = J^T tau` (eqs 14-15) of joint torques `tau` (length `n`),
/// written into `tau_star` (length `m`). Allocation-free.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedModel, project_torques};
///
/// let model = ReducedModel::new(ChainModel::uniform(4, 0.25, 0.1, 9.81)?, ModalMap::paper(4)?)?;
/// let mut tau_star = [0.0; 3];
/// // A unit torque at the base joint only: tau* is the first row of J.
/// project_torques(&model, &[1.0, 0.0, 0.0, 0.0], &mut tau_star)?;
/// assert_eq!(tau_star.as_slice(), model.map().row(0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn project_torques(
    model: &ReducedModel,
    tau: &[f64],
    tau_star: &mut [f64],
) -> Result<(), ReduceError> {
    check_values("tau", tau, model.n_links())?;
    check_len("tau_star", tau_star.len(), model.n_coords())?;
    project(model.map(), tau, tau_star);
    Ok(())
}

/// `out = J^T v` for a joint-space vector `v` (sizes already checked).
pub(crate) fn project(map: &ModalMap, v: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (i, &value) in v.iter().enumerate() {
        for (o, &entry) in out.iter_mut().zip(map.row(i)) {
            *o += entry * value;
        }
    }
}
