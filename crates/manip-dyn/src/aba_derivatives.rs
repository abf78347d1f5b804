//! Analytic derivatives of forward dynamics: `d qdd / d q`, `d qdd / d v` and
//! `d qdd / d tau = M^-1`, in `O(n^2)`.
//!
//! Differentiating `M(q) qdd + C(q, v) + G(q) = tau` at fixed `tau` gives
//! `d qdd / d q = -M^-1 (d tau / d q)` and `d qdd / d v = -M^-1 (d tau / d v)`, the inverse-
//! dynamics partials taken at the forward-dynamics solution `qdd` (as Pinocchio does). The
//! partials come in closed form from [`rnea_derivatives`](crate::rnea_derivatives()); the `3n`
//! right-hand sides `[-d tau / d q | -d tau / d v | 1]` are then solved together by the
//! articulated-body factorisation of `M` that [`aba`](crate::aba()) has just built: with no
//! velocity and no gravity, the bias sweep of the ABA computes `M^-1 b` in `O(n)` for any `b`,
//! so the `3n` solves cost `O(n^2)` and never form `M`. The sweeps run over the links outside
//! and the right-hand sides inside, along contiguous rows.

use crate::aba::articulated_body;
use crate::check;
use crate::data::ChainData;
use crate::derivative_data::DerivativeData;
use crate::error::DynError;
use crate::model::ChainModel;
use crate::rnea_derivatives::fill_partials;

/// Forward dynamics and its analytic derivatives at `(q, v, tau)`: `qdd` (as [`aba`]),
/// `d qdd / d q`, `d qdd / d v` and `d qdd / d tau = M^-1`, into `derivatives` (read them with
/// [`DerivativeData::value`], [`d_q`](DerivativeData::d_q), [`d_v`](DerivativeData::d_v) and
/// [`d_input`](DerivativeData::d_input)). `O(n^2)` and allocation-free; the method is in the
/// module documentation of `src/aba_derivatives.rs`.
///
/// [`aba`]: crate::aba()
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, DerivativeData, aba_derivatives};
/// // A pendulum: qdd = (tau - m g c cos q) / (m L^2 / 3).
/// let pendulum = ChainModel::uniform(1, 1.0, 3.0, 9.81)?;
/// let (mut data, mut derivatives) = (ChainData::new(&pendulum), DerivativeData::new(&pendulum));
/// aba_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// let inertia = 3.0 / 3.0;
/// assert!((derivatives.d_q()[(0, 0)] - 3.0 * 9.81 * 0.5 * 0.3_f64.sin() / inertia).abs() < 1e-12);
/// assert_eq!(derivatives.d_v()[(0, 0)], 0.0);
/// assert!((derivatives.d_input()[(0, 0)] - 1.0 / inertia).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` or `derivatives` was
/// built for another chain, [`DynError::NonFinite`] for a NaN or infinite input,
/// [`DynError::NotPositiveDefinite`] if an articulated inertia is not positive beyond rounding
/// (as in [`aba`]), [`DynError::NonFiniteResult`] if a result overflows.
pub fn aba_derivatives(
    model: &ChainModel,
    data: &mut ChainData,
    derivatives: &mut DerivativeData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<(), DynError> {
    check::dense("the ABA derivatives", model)?;
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::derivative_workspace(derivatives, n)?;
    articulated_body(model, data, q, v, tau, &mut derivatives.value)?;
    check::finite_result("qdd", &derivatives.value)?;
    let DerivativeData {
        value: qdd,
        blocks,
        links,
        sweep,
        ..
    } = derivatives;
    fill_partials(model, &data.frames, qdd, -1.0, links, blocks);
    for (i, row) in blocks.chunks_exact_mut(3 * n).enumerate() {
        let identity = &mut row[2 * n..];
        identity.fill(0.0);
        identity[i] = 1.0;
    }
    solve_in_place(model, data, blocks, sweep);
    check::finite_result("qdd derivatives", blocks)
}

/// Overwrites the row-major `n x p` matrix `rhs` with `M^-1 rhs`, by the bias and acceleration
/// sweeps of the ABA at zero velocity and gravity, on the articulated inertias that
/// [`articulated_body`] left in `data`. `sweep` holds three scratch vectors of at least `p`
/// entries.
fn solve_in_place(
    model: &ChainModel,
    data: &ChainData,
    rhs: &mut [f64],
    sweep: &mut [Vec<f64>; 3],
) {
    let n = model.n_links();
    let p = rhs.len() / n;
    let [first, second, third] = sweep;
    let (first, second, third) = (&mut first[..p], &mut second[..p], &mut third[..p]);
    // From the tip: each column's condensed force (x, y) and joint torque, and in place of b_i
    // the residual b_i - S^T pA_i (see `aba`).
    first.fill(0.0);
    second.fill(0.0);
    third.fill(0.0);
    for ((link, frame), (joint, row)) in model
        .links()
        .iter()
        .zip(&data.frames)
        .zip(data.articulated.iter().zip(rhs.chunks_exact_mut(p)))
        .rev()
    {
        let [ux, uy] = [link.length * frame.axis[0], link.length * frame.axis[1]];
        let gain = [joint.u_lin[0] / joint.d, joint.u_lin[1] / joint.d];
        for (((b, fx), fy), torque) in row
            .iter_mut()
            .zip(first.iter_mut())
            .zip(second.iter_mut())
            .zip(third.iter_mut())
        {
            let residual = *b - (*torque + ux * *fy - uy * *fx);
            *torque = *b;
            *b = residual;
            *fx += gain[0] * residual;
            *fy += gain[1] * residual;
        }
    }
    // From the base: each column's parent acceleration (angular, x, y) moved to the joint.
    first.fill(0.0);
    second.fill(0.0);
    third.fill(0.0);
    for ((link, frame), (joint, row)) in model
        .links()
        .iter()
        .zip(&data.frames)
        .zip(data.articulated.iter().zip(rhs.chunks_exact_mut(p)))
    {
        let [dx, dy] = [link.length * frame.axis[0], link.length * frame.axis[1]];
        let inverse = 1.0 / joint.d;
        let [gx, gy] = joint.u_lin;
        for (((x, angular), ax), ay) in row
            .iter_mut()
            .zip(first.iter_mut())
            .zip(second.iter_mut())
            .zip(third.iter_mut())
        {
            let own = (*x - *ax * gx - *ay * gy) * inverse;
            *x = own - *angular;
            *angular = own;
            *ax -= dy * own;
            *ay += dx * own;
        }
    }
}
