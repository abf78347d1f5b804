//! Validation shared by every algorithm: sizes first, then finiteness, before any work is done.

use faer::MatMut;

use crate::data::ChainData;
use crate::derivative_data::DerivativeData;
use crate::error::DynError;
use crate::model::{ChainModel, MAX_DENSE_LINKS};

/// The workspace must have been built for a chain with as many links as `model`.
fn workspace(model: &ChainModel, data: &ChainData) -> Result<(), DynError> {
    lane_math::check_len(
        "data (a ChainData built for another model)",
        data.n_links(),
        model.n_links(),
    )?;
    Ok(())
}

/// A derivative workspace built for a chain of `n` links.
pub(crate) fn derivative_workspace(derivatives: &DerivativeData, n: usize) -> Result<(), DynError> {
    lane_math::check_len(
        "derivatives (a DerivativeData built for another model)",
        derivatives.n_links(),
        n,
    )?;
    Ok(())
}

/// The preamble of every algorithm: `data` built for `model` and each named input `n` finite
/// entries. Returns `n`; callers check their output's size next, before writing anything.
pub(crate) fn inputs(
    model: &ChainModel,
    data: &ChainData,
    inputs: &[(&'static str, &[f64])],
) -> Result<usize, DynError> {
    let n = model.n_links();
    workspace(model, data)?;
    vectors(n, inputs)?;
    Ok(n)
}

/// Each named input has `n` finite entries.
pub(crate) fn vectors(n: usize, inputs: &[(&'static str, &[f64])]) -> Result<(), DynError> {
    for &(name, x) in inputs {
        lane_math::check_values(name, x, n)?;
    }
    Ok(())
}

/// An output vector of `n` entries.
pub(crate) fn output(name: &'static str, x: &[f64], n: usize) -> Result<(), DynError> {
    Ok(lane_math::check_len(name, x.len(), n)?)
}

/// An `n x n` algorithm (named by `what`) accepts at most [`MAX_DENSE_LINKS`] links.
pub(crate) fn dense(what: &'static str, model: &ChainModel) -> Result<(), DynError> {
    dense_count(what, model.n_links())
}

/// An `n x n` algorithm (named by `what`) accepts at most [`MAX_DENSE_LINKS`] links: `got`.
pub(crate) fn dense_count(what: &'static str, got: usize) -> Result<(), DynError> {
    if got <= MAX_DENSE_LINKS {
        Ok(())
    } else {
        Err(DynError::TooManyLinks {
            what,
            got,
            max: MAX_DENSE_LINKS,
        })
    }
}

/// An `n x n` output matrix (always the parameter `out`).
pub(crate) fn square_output(m: &MatMut<'_, f64>, n: usize) -> Result<(), DynError> {
    lane_math::check_len("out (rows)", m.nrows(), n)?;
    Ok(lane_math::check_len("out (columns)", m.ncols(), n)?)
}

/// A computed vector must be finite (finite inputs can still overflow). Unlike an input's, a
/// result's non-finite value is a [`DynError::NonFiniteResult`] (numerical, not the caller's
/// fault), not the [`ShapeError`](lane_math::ShapeError) of an input.
pub(crate) fn finite_result(name: &'static str, x: &[f64]) -> Result<(), DynError> {
    lane_math::check_all_finite(name, x).map_err(|_| DynError::NonFiniteResult { name })
}

/// A computed matrix must be finite.
pub(crate) fn finite_matrix(name: &'static str, m: &MatMut<'_, f64>) -> Result<(), DynError> {
    // `0 x` is 0 for a finite `x` and NaN otherwise, so the sums are NaN if and only if an
    // entry is not finite: eight independent sums, a loop the compiler vectorises.
    let mut sums = [0.0; 8];
    for j in 0..m.ncols() {
        let column = m.as_ref().col(j);
        if let Some(column) = column.try_as_col_major() {
            let mut chunks = column.as_slice().chunks_exact(8);
            for chunk in &mut chunks {
                for (sum, &x) in sums.iter_mut().zip(chunk) {
                    *sum += x * 0.0;
                }
            }
            for (sum, &x) in sums.iter_mut().zip(chunks.remainder()) {
                *sum += x * 0.0;
            }
        } else {
            for i in 0..m.nrows() {
                sums[0] += column[i] * 0.0;
            }
        }
    }
    if sums.iter().all(|sum| *sum == 0.0) {
        Ok(())
    } else {
        Err(DynError::NonFiniteResult { name })
    }
}

/// Smallest admissible ratio of a factorisation pivot of `M` to the scale of its rounding (for a
/// Cholesky pivot, the diagonal entry of `M` it comes from; for an articulated inertia, the
/// magnitude of the terms it is summed from). Rounding perturbs a pivot by a few machine
/// epsilons of that scale, so below about 1e3 epsilons (2e-13) the pivot, and every acceleration
/// computed from it, has no reliable digits.
pub(crate) const PIVOT_FLOOR: f64 = 1e3 * f64::EPSILON;

/// A pivot of a factorisation of `M` (`name`: a Cholesky pivot `L_ii^2` of the "mass matrix",
/// or an "articulated inertia" about a joint axis) must be finite and positive beyond rounding
/// relative to `diagonal`, the scale of its rounding ([`PIVOT_FLOOR`]), and normal, so that its
/// reciprocal is finite (a link inertia of `1e-320` about its joint gave an infinite
/// acceleration).
pub(crate) fn pivot(name: &'static str, pivot: f64, diagonal: f64) -> Result<(), DynError> {
    if !(pivot.is_finite() && diagonal.is_finite()) {
        Err(DynError::NonFiniteResult { name })
    } else if pivot > PIVOT_FLOOR * diagonal && pivot >= f64::MIN_POSITIVE {
        Ok(())
    } else {
        Err(DynError::NotPositiveDefinite)
    }
}

/// A computed scalar must be finite.
pub(crate) fn finite_scalar(name: &'static str, x: f64) -> Result<f64, DynError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(DynError::NonFiniteResult { name })
    }
}
