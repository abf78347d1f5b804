//! Input checks shared by the modules: every public entry point validates before computing, so
//! bad input becomes a [`KinError`] instead of a panic or a silent NaN.

use crate::error::KinError;

/// Checks that `value` is finite.
pub(crate) fn check_finite(name: &'static str, value: f64) -> Result<(), KinError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(KinError::NonFinite { name, value })
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

/// Checks that `values` has `expected` entries, all finite.
pub(crate) fn check_len(
    name: &'static str,
    values: &[f64],
    expected: usize,
) -> Result<(), KinError> {
    if values.len() != expected {
        return Err(KinError::Dimension {
            name,
            expected,
            got: values.len(),
        });
    }
    values
        .iter()
        .try_for_each(|&value| check_finite(name, value))
}

/// Checks that an output buffer has room for exactly `expected` entries.
pub(crate) fn check_output_len(
    name: &'static str,
    got: usize,
    expected: usize,
) -> Result<(), KinError> {
    if got == expected {
        Ok(())
    } else {
        Err(KinError::Dimension {
            name,
            expected,
            got,
        })
    }
}
