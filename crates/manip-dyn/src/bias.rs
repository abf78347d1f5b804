//! The velocity and gravity terms of eq 12, each one Newton-Euler pass (O(n)).

use crate::check;
use crate::data::ChainData;
use crate::error::DynError;
use crate::model::ChainModel;
use crate::rnea::newton_euler;

/// The Coriolis/centrifugal torque vector `C(q, v)` of eq 12: the inverse dynamics with zero
/// acceleration and zero gravity. It equals `coriolis_matrix(q, v) * v`.
///
/// # Errors
/// As [`rnea`](crate::rnea()).
pub fn coriolis(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q), ("v", v)])?;
    check::output("out", out, n)?;
    newton_euler(model, data, q, Some(v), None, 0.0, out);
    check::finite_result("coriolis", out)
}

/// The gravity torque vector `G(q)` of eq 12, the gradient of the potential energy: the inverse
/// dynamics at rest.
///
/// # Errors
/// As [`rnea`](crate::rnea()).
pub fn gravity(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q)])?;
    check::output("out", out, n)?;
    newton_euler(model, data, q, None, None, model.gravity(), out);
    check::finite_result("gravity", out)
}

/// The non-linear effects `C(q, v) + G(q)`: the inverse dynamics with zero acceleration, in one
/// pass.
///
/// # Errors
/// As [`rnea`](crate::rnea()).
pub fn nonlinear_effects(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q), ("v", v)])?;
    check::output("out", out, n)?;
    newton_euler(model, data, q, Some(v), None, model.gravity(), out);
    check::finite_result("nonlinear effects", out)
}
