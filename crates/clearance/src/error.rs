//! The error type of this crate.

use lane_math::{Classify, ErrorClass};

/// Why a clearance model or computation was refused; every variant names the condition.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ClearanceError {
    /// An input that must be finite was NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A radius or half-extent was negative (or, where zero is refused, zero).
    #[error("{name} must be {bound}, got {value}")]
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

pub(crate) fn check_finite(name: &'static str, value: f64) -> Result<(), ClearanceError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ClearanceError::NonFinite { name, value })
    }
}

pub(crate) fn check_len(
    name: &'static str,
    found: usize,
    expected: usize,
) -> Result<(), ClearanceError> {
    if found == expected {
        Ok(())
    } else {
        Err(ClearanceError::Dimension {
            name,
            expected,
            found,
        })
    }
}
