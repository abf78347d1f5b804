//! The velocity and gravity terms of the equations of motion, `C(q, v) v + G(q)`, `C(q, v) v` and
//! `G(q)`, each one Newton-Euler pass with `qdd = 0` (and `v = 0` or gravity off).

use super::data::SpatialData;
use super::kinematics::update_placements;
use super::model::SpatialModel;
use super::rnea::newton_euler;
use crate::check;
use crate::error::DynError;

/// `C(q, v) v + G(q)`: the efforts that hold the chain at zero acceleration ([`rnea`] with
/// `qdd = 0`).
///
/// [`rnea`]: super::rnea()
///
/// # Errors
/// As [`rnea`](super::rnea()).
pub fn nonlinear_effects(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    bias_terms(model, data, q, Some(v), true, out)
}

/// `C(q, v) v`: the Coriolis and centrifugal efforts, without gravity.
///
/// # Errors
/// As [`rnea`](super::rnea()).
pub fn coriolis(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    bias_terms(model, data, q, Some(v), false, out)
}

/// `G(q)`: the efforts that hold the chain still against gravity.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, gravity};
/// let arm = SpatialModel::from_planar(&ChainModel::uniform(2, 0.5, 1.0, 9.81)?);
/// let mut g = [0.0; 2];
/// gravity(&arm, &mut SpatialData::new(&arm), &[0.0, 0.0], &mut g)?;
/// // Held out straight: the base carries 2 kg at 0.5 m, the elbow 1 kg at 0.25 m.
/// assert!((g[0] - 9.81).abs() < 1e-12 && (g[1] - 9.81 * 0.25).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// As [`rnea`](super::rnea()).
pub fn gravity(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    out: &mut [f64],
) -> Result<(), DynError> {
    bias_terms(model, data, q, None, true, out)
}

fn bias_terms(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: Option<&[f64]>,
    with_gravity: bool,
    out: &mut [f64],
) -> Result<(), DynError> {
    let n = super::check_inputs(model, data, &[("q", q), ("v", v.unwrap_or(q))])?;
    check::output("out", out, n)?;
    update_placements(model, data, q);
    newton_euler(model, data, v, None, with_gravity, out);
    let name = match (v, with_gravity) {
        (Some(_), true) => "nonlinear effects",
        (Some(_), false) => "coriolis",
        (None, _) => "gravity",
    };
    check::finite_result(name, out)
}
