//! The error type of this crate.

use lane_math::{Classify, ErrorClass, ShapeError, ShapeProblem};

/// Why a clearance model or computation was refused; every variant names the condition.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ClearanceError {
    /// An input that must be finite was NaN or infinite.
    #[error("{name} must be finite, got {}", lane_math::Compact(*.value))]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A radius or half-extent was negative (or, where zero is refused, zero).
    #[error("{name} must be {bound}, got {}", lane_math::Compact(*.value))]
    OutOfRange {
        /// Which input.
        name: &'static str,
        /// What it must be, as words: `"non-negative"`, `"positive"`.
        bound: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A model was asked for more links or obstacles than the crate allows.
    #[error("at most {max} {what} are supported, got {got}")]
    TooMany {
        /// `"links"` or `"obstacles"`.
        what: &'static str,
        /// The number asked for.
        got: usize,
        /// The limit.
        max: usize,
    },
    /// A slice had the wrong number of entries.
    #[error("{name} has {found} entries, expected {expected}")]
    Dimension {
        /// Which input.
        name: &'static str,
        /// The length the computation needs.
        expected: usize,
        /// The length it got.
        found: usize,
    },
    /// The chain's kinematics refused the input.
    #[error(transparent)]
    Kinematics(#[from] backbone_kin::KinError),
}

impl Classify for ClearanceError {
    /// A refused kinematics computation keeps its class; every other error is invalid input.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Kinematics(error) => error.class(),
            _ => ErrorClass::InvalidInput,
        }
    }
}

/// A refused shape or non-finite number as [`ClearanceError::Dimension`] or
/// [`ClearanceError::NonFinite`], with the same message. This crate checks single numbers for
/// finiteness (a point coordinate by coordinate), so its `NonFinite` carries no index.
impl From<ShapeError<'static>> for ClearanceError {
    fn from(error: ShapeError<'static>) -> Self {
        let name = error.name;
        match error.problem {
            ShapeProblem::Length { expected, found } => Self::Dimension {
                name,
                expected,
                found,
            },
            ShapeProblem::NonFinite { value, .. } => Self::NonFinite { name, value },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_error_keeps_its_message() {
        for error in [
            lane_math::check_len("joint axes", 3, 2).unwrap_err(),
            lane_math::check_finite("link radius", f64::NEG_INFINITY).unwrap_err(),
        ] {
            let clearance = ClearanceError::from(error);
            assert_eq!(clearance.to_string(), error.to_string());
            assert!(clearance.is_invalid_input());
        }
    }
}
