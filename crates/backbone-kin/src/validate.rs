//! The input checks of this crate's own domain, shared by its modules: every public entry point
//! validates before computing, so bad input becomes a [`KinError`] instead of a panic or a silent
//! NaN. Shapes and finiteness are checked by [`lane_math::check_values`] and its siblings, whose
//! [`ShapeError`](lane_math::ShapeError) becomes a [`KinError`] through `From`.

use crate::error::KinError;

/// Checks that the length `value` is positive and finite. Beyond finiteness a length must be
/// positive, a rule of this crate's domain with its own message ([`KinError::NonPositiveLength`]).
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
