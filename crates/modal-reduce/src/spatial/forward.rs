//! Reduced forward dynamics of a spatial modal arm: `a_dd = M*^{-1} (tau* - C* - G*)` (eq 15).

use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::terms::spatial_reduced_terms;
use crate::error::{ReduceError, check_finite_result};
use crate::forward::right_hand_side;
use lane_math::dense::{ldlt_in_place, ldlt_solve_in_place};
use lane_math::{check_len, check_values};

/// The modal accelerations `a_ddot` (`m`) under the modal forces `tau_star` at `(a, a_dot)`:
/// [`spatial_reduced_terms`], then an `L D L^T` solve of `M*`. Allocation-free.
///
/// Errors: as [`spatial_reduced_terms`], `tau_star` or `a_ddot` of the wrong length,
/// [`ReduceError::NotPositiveDefinite`] where `M*` is not numerically positive definite.
pub fn spatial_forward_dynamics(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), ReduceError> {
    let m = model.n_coords();
    check_values("tau_star", tau_star, m)?;
    check_len("a_ddot", a_ddot.len(), m)?;
    spatial_reduced_terms(model, data, a, a_dot)?;
    data.factor.copy_from_slice(&data.mass_matrix);
    if !ldlt_in_place::<f64>((), &mut data.factor, m) {
        return Err(ReduceError::NotPositiveDefinite);
    }
    right_hand_side(tau_star, &data.coriolis, &data.gravity, a_ddot);
    ldlt_solve_in_place(&data.factor, m, a_ddot);
    check_finite_result("modal acceleration a_ddot", a_ddot)
}
