//! Kinetic and potential energy of the chain at a modal state.

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::model::ReducedModel;
use lane_math::check_values;

/// The chain's kinetic energy at `theta = J a + theta_0`, `theta_dot = J a_dot`; it equals
/// `1/2 a_dot^T M*(a) a_dot`. Allocation-free.
pub fn kinetic_energy(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<f64, ReduceError> {
    data.check_model(model)?;
    check_values("a_dot", a_dot, model.n_coords())?;
    model.map().joint_rates(a_dot, &mut data.theta_dot)?;
    check_finite_result("theta_dot = J a_dot", &data.theta_dot)?;
    joint_angles(model, data, a)?;
    Ok(manip_dyn::kinetic_energy(
        model.chain(),
        &mut data.chain,
        &data.theta,
        &data.theta_dot,
    )?)
}

/// The chain's potential energy `V = g sum_i m_i y_i` at `theta = J a + theta_0`, with `y_i` the
/// height of link `i`'s centre of mass above the base joint; its gradient with respect to `a` is
/// `G*(a)`. Allocation-free.
pub fn potential_energy(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
) -> Result<f64, ReduceError> {
    data.check_model(model)?;
    joint_angles(model, data, a)?;
    Ok(manip_dyn::potential_energy(
        model.chain(),
        &mut data.chain,
        &data.theta,
    )?)
}

/// Fills `data.theta` with `J a + theta_0` after checking `a`; an overflow in the map is a
/// [`ReduceError::NonFiniteResult`].
fn joint_angles(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
) -> Result<(), ReduceError> {
    check_values("a", a, model.n_coords())?;
    model.map().joint_angles(a, &mut data.theta)?;
    check_finite_result("theta = J a + theta_0", &data.theta)
}
