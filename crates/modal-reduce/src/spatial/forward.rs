//! Reduced forward dynamics of a spatial modal arm: `a_dd = M*^{-1} (tau* - C* - G*)` (eq 15).

use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::terms::{TermsOfOneState, check_shapes, check_state, check_terms};
use crate::error::ReduceError;
use lane_math::{check_all_finite, check_len};

/// The modal accelerations `a_ddot` (`m`) under the modal forces `tau_star` at `(a, a_dot)`:
/// [`spatial_reduced_terms`](super::spatial_reduced_terms), then an `L D L^T` solve of `M*`, in
/// one dispatch to the processor's instruction set. Allocation-free.
///
/// Errors: as [`spatial_reduced_terms`](super::spatial_reduced_terms), `tau_star` or `a_ddot` of
/// the wrong length, [`ReduceError::NotPositiveDefinite`] where `M*` is not numerically positive
/// definite. On an error `a_ddot` is left as it was.
pub fn spatial_forward_dynamics(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), ReduceError> {
    let m = model.n_coords();
    check_len("tau_star", tau_star.len(), m)?;
    check_len("a_ddot", a_ddot.len(), m)?;
    check_shapes(model, data, a, a_dot)?;
    let outcome = TermsOfOneState {
        model,
        data: &mut *data,
        a,
        a_dot,
        solve: Some((tau_star, &mut *a_ddot)),
    }
    .run();
    if outcome.positive_definite && outcome.finite {
        return Ok(());
    }
    // Name the first problem, the inputs' values first (one test of the results stood for their
    // checks, see `TermsOfOneState`).
    check_all_finite("tau_star", tau_star)?;
    check_state(model, data, a, a_dot)?;
    check_terms(data)?;
    if !outcome.positive_definite {
        return Err(ReduceError::NotPositiveDefinite);
    }
    Err(ReduceError::NonFiniteResult {
        name: "modal acceleration a_ddot",
    })
}
