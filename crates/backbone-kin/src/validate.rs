//! Input checks shared by the modules: every public entry point validates before computing, so
//! bad input becomes a [`KinError`] instead of a panic or a silent NaN.

use crate::error::KinError;
use lane_math::ShapeProblem;

/// Checks that the scalar `value` is finite.
pub(crate) fn check_finite(name: &'static str, value: f64) -> Result<(), KinError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(KinError::NonFinite {
            name,
            index: None,
            value,
        })
    }
}

/// Checks that the length `value` is positive and finite.
pub(crate) fn check_length(name: &'static str, value: f64) -> Result<(), KinError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(KinError::NonPositiveLength { name, value })
    }
}

/// Checks a chain's link lengths: at least one, each positive and finite, and a finite total
/// (the curve length), which is returned.
pub(crate) fn check_link_lengths(link_lengths: &[f64]) -> Result<f64, KinError> {
    if link_lengths.is_empty() {
        return Err(KinError::NoLinks);
    }
    for &length in link_lengths {
        check_length("link length", length)?;
    }
    let total = link_lengths.iter().sum();
    check_length("curve length (the sum of the link lengths)", total)?;
    Ok(total)
}

/// Checks that `got` does not exceed `max`: `what` is `"links"`, `"harmonics"` or `"modal Jacobian
/// entries (links x coordinates)"`.
pub(crate) fn check_count(what: &'static str, got: usize, max: usize) -> Result<(), KinError> {
    if got <= max {
        Ok(())
    } else {
        Err(KinError::TooMany { what, got, max })
    }
}

/// Checks that `values` has `expected` entries, all finite.
pub(crate) fn check_len(
    name: &'static str,
    values: &[f64],
    expected: usize,
) -> Result<(), KinError> {
    lane_math::check_values(values, expected).map_err(|problem| match problem {
        ShapeProblem::Length { expected, found } => KinError::Dimension {
            name,
            expected,
            found,
        },
        ShapeProblem::NonFinite { index, value } => KinError::NonFinite {
            name,
            index: Some(index),
            value,
        },
    })
}

/// Checks that an output buffer has room for exactly `expected` entries.
pub(crate) fn check_output_len(
    name: &'static str,
    found: usize,
    expected: usize,
) -> Result<(), KinError> {
    if found == expected {
        Ok(())
    } else {
        Err(KinError::Dimension {
            name,
            expected,
            found,
        })
    }
}
