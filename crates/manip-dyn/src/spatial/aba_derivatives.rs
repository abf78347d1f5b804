//! Analytic derivatives of forward dynamics: `d qdd / d q`, `d qdd / d v` and
//! `d qdd / d tau = M^-1`. Differentiating `M(q) qdd + b(q, v) = tau` at the ABA's `qdd` gives
//! `d qdd / d q = -M^-1 d tau / d q` and `d qdd / d v = -M^-1 d tau / d v` with the RNEA
//! derivatives taken at `(q, v, qdd)` (Carpentier and Mansard 2018, eq. 12; what Pinocchio's
//! `computeABADerivatives` returns); `M^-1` comes from the Cholesky factor of the `M` those
//! derivatives give, solved against `[d tau / d q | d tau / d v | E]` at once.

use faer::Par;
use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::llt;

use super::aba::aba;
use super::data::SpatialData;
use super::derivative_data::SpatialDerivativeData;
use super::model::SpatialModel;
use super::rnea_derivatives::rnea_derivatives;
use crate::check;
use crate::error::DynError;

/// Forward dynamics and its analytic derivatives at `(q, v, tau)`: `qdd` (as
/// [`aba`](super::aba())), `d qdd / d q`, `d qdd / d v` and `d qdd / d tau = M^-1`, into
/// `derivatives`. `O(n^3)` for the solve, allocation-free.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialDerivativeData, SpatialModel, aba_derivatives};
/// // A pendulum: qdd = (tau - m g c cos q) / J, so d qdd / d q = m g c sin q / J.
/// let pendulum = SpatialModel::from_planar(&ChainModel::uniform(1, 1.0, 2.0, 9.81)?);
/// let mut data = SpatialData::new(&pendulum);
/// let mut derivatives = SpatialDerivativeData::new(&pendulum);
/// aba_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// let j = 2.0 / 3.0;
/// assert!((derivatives.d_q()[(0, 0)] - 2.0 * 9.81 * 0.5 * 0.3_f64.sin() / j).abs() < 1e-12);
/// assert!((derivatives.d_input()[(0, 0)] - 1.0 / j).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// As [`rnea_derivatives`] and [`aba`](super::aba()) ([`DynError::NotPositiveDefinite`] if `M`
/// is not numerically positive definite).
pub fn aba_derivatives(
    model: &SpatialModel,
    data: &mut SpatialData,
    derivatives: &mut SpatialDerivativeData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<(), DynError> {
    check::dense_count("the ABA derivatives", model.n_links())?;
    let n = super::check_inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::length(
        "derivatives (a SpatialDerivativeData built for another model)",
        derivatives.n_links(),
        n,
    )?;
    let mut qdd = std::mem::take(&mut derivatives.accelerations);
    let solved = aba(model, data, q, v, tau, &mut qdd)
        .and_then(|()| rnea_derivatives(model, data, derivatives, q, v, &qdd));
    derivatives.value.copy_from_slice(&qdd);
    derivatives.accelerations = qdd;
    solved?;
    let SpatialDerivativeData {
        blocks,
        factor,
        stack,
        accelerations: diagonal,
        ..
    } = derivatives;
    let (_, mut mass) = blocks.as_mut().split_at_col_mut(2 * n);
    factor.copy_from(mass.as_ref());
    for (i, entry) in diagonal.iter_mut().enumerate() {
        *entry = mass[(i, i)];
    }
    mass.fill(0.0);
    mass.diagonal_mut().fill(1.0);
    let stack = MemStack::new(stack);
    llt::factor::cholesky_in_place(
        factor.as_mut(),
        Default::default(),
        Par::Seq,
        stack,
        Default::default(),
    )
    .map_err(|_| DynError::NotPositiveDefinite)?;
    for (i, entry) in diagonal.iter().enumerate() {
        // The pivots L_ii^2 against the diagonal entries of M they come from.
        check::pivot(factor[(i, i)].powi(2), *entry)?;
    }
    llt::solve::solve_in_place(factor.as_ref(), blocks.as_mut(), Par::Seq, stack);
    for j in 0..2 * n {
        for i in 0..n {
            blocks[(i, j)] = -blocks[(i, j)];
        }
    }
    check::finite_matrix("the derivatives", &blocks.as_mut())
}
