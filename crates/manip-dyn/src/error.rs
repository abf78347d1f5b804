//! The error type of this crate.

use lane_math::{Classify, Compact, EntryIndex, ErrorClass, OutOfMemory, ShapeError, ShapeProblem};

/// Why a dynamics computation was refused.
///
/// Every variant names the condition that failed. [`Classify::class`] sorts the variants into
/// the classes a caller acts on:
/// [`ErrorClass::Numerical`] (a computation on valid input failed in double precision) and
/// [`ErrorClass::InvalidInput`] (the input is malformed or outside the model's domain).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DynError {
    /// A chain was asked for with zero links.
    #[error("a chain needs at least one link")]
    NoLinks,
    /// A chain was asked for with more than [`MAX_LINKS`](crate::model::MAX_LINKS) links, or an
    /// `n x n` algorithm with more than [`MAX_DENSE_LINKS`](crate::model::MAX_DENSE_LINKS).
    #[error("{what} may have at most {max} links, got {got}")]
    TooManyLinks {
        /// `"a chain"`, or which `n x n` algorithm refused.
        what: &'static str,
        /// The number of links asked for.
        got: usize,
        /// The limit.
        max: usize,
    },
    /// A link parameter was out of its domain.
    #[error("link {index}: {quantity} must be {requirement}, got {}", Compact(*.value))]
    InvalidLink {
        /// 0-based link index.
        index: usize,
        /// Which parameter (`"length"`, `"mass"`, `"inertia"`, `"centre of mass"`, `"inertia
        /// about the joint (inertia + mass * com^2)"`).
        quantity: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A joint parameter of a spatial chain was out of its domain.
    #[error("joint {index}: {quantity} must be {requirement}, got {}", Compact(*.value))]
    InvalidJoint {
        /// 0-based joint index.
        index: usize,
        /// Which parameter (`"axis"`, `"axis (its norm)"`, `"origin"`, ...).
        quantity: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A link index named no link of the chain.
    #[error("link index {index} is out of range: the chain has {n_links} links")]
    NoSuchLink {
        /// The index asked for.
        index: usize,
        /// The chain's number of links.
        n_links: usize,
    },
    /// A parameter of a lone link (from [`Link::new`](crate::Link::new) or
    /// [`Link::uniform_beam`](crate::Link::uniform_beam), which know no index) was out of its
    /// domain; [`DynError::at_link`] names the link once the caller knows where it goes.
    #[error("link {quantity} must be {requirement}, got {}", Compact(*.value))]
    InvalidLinkParameter {
        /// Which parameter, as in [`DynError::InvalidLink`].
        quantity: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The chain's total mass, or its inertia bound (total mass x total length^2), or its
    /// gravity torque bound (total mass x |g| x total length), is beyond double precision: every
    /// link is valid, but the chain's dynamics would overflow.
    #[error(
        "the chain's total mass {} kg over its length {} m under gravity {} m/s^2 overflows \
         double precision (total mass, mass x length^2 and mass x g x length must be finite)",
        Compact(*total_mass),
        Compact(*total_length),
        Compact(*gravity)
    )]
    ChainOverflows {
        /// The sum of the link masses (kg).
        total_mass: f64,
        /// The sum of the link lengths (m).
        total_length: f64,
        /// The gravitational acceleration's magnitude (m/s^2).
        gravity: f64,
    },
    /// The gravitational acceleration (or a component of it) was not finite.
    #[error("gravity must be finite, got {}", Compact(*.0))]
    InvalidGravity(f64),
    /// A slice or matrix had the wrong size.
    #[error("{name} has {found} entries, expected {expected}")]
    Dimension {
        /// Which input or output.
        name: &'static str,
        /// The size the computation needs.
        expected: usize,
        /// The size it got.
        found: usize,
    },
    /// An input that must be finite was NaN or infinite.
    #[error("{name}{} must be finite, got {}", EntryIndex(*index), Compact(*.value))]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// 0-based index of the first offending entry of a slice; `None` for a scalar input.
        index: Option<usize>,
        /// The offending value.
        value: f64,
    },
    /// A computation on finite inputs overflowed (inputs too large for double precision).
    #[error("{name} is not finite: the inputs are too large for double precision")]
    NonFiniteResult {
        /// Which output.
        name: &'static str,
    },
    /// The mass matrix was not numerically positive definite: a pivot of its factorisation (a
    /// Cholesky pivot, or an articulated inertia about a joint axis) was not positive beyond
    /// rounding (at least about 2e-13 of the matching diagonal entry of `M`). `M` is positive
    /// definite for every valid chain, so this signals link parameters too disparate for double
    /// precision; the accelerations would have no reliable digits.
    #[error("the mass matrix is not numerically positive definite")]
    NotPositiveDefinite,
    /// A spatial chain's articulated inertia about joint `index`'s axis was not positive beyond
    /// rounding (as for [`NotPositiveDefinite`](DynError::NotPositiveDefinite)): the joint moves
    /// no mass or inertia, so `M` is singular. A massless link is valid as long as the links
    /// beyond it give its joint something to move; this names the joint where they do not (a
    /// massless link at the tip, a point mass on the axis of the last revolute joint).
    #[error(
        "joint {index}: the articulated inertia about its axis is not positive beyond rounding \
         (the joint moves no mass or inertia), so the mass matrix is singular"
    )]
    SingularJoint {
        /// 0-based joint index.
        index: usize,
    },
    /// The system refused the memory of a model's or a workspace's arrays.
    #[error(transparent)]
    OutOfMemory(#[from] OutOfMemory),
}

/// A refused shape or non-finite input as [`DynError::Dimension`] or [`DynError::NonFinite`],
/// with the same message.
impl From<ShapeError<'static>> for DynError {
    fn from(error: ShapeError<'static>) -> Self {
        let name = error.name;
        match error.problem {
            ShapeProblem::Length { expected, found } => Self::Dimension {
                name,
                expected,
                found,
            },
            ShapeProblem::NonFinite { index, value } => Self::NonFinite { name, index, value },
        }
    }
}

impl Classify for DynError {
    /// [`Numerical`](ErrorClass::Numerical) when a computation on valid input failed in double
    /// precision: a mass matrix that is not numerically positive definite, or a result that
    /// overflowed ([`NotPositiveDefinite`](DynError::NotPositiveDefinite),
    /// [`SingularJoint`](DynError::SingularJoint),
    /// [`NonFiniteResult`](DynError::NonFiniteResult)); [`OutOfMemory`](ErrorClass::OutOfMemory)
    /// when the system refused an allocation; otherwise the input was malformed or
    /// outside the model's domain.
    fn class(&self) -> ErrorClass {
        match self {
            Self::NotPositiveDefinite
            | Self::SingularJoint { .. }
            | Self::NonFiniteResult { .. } => ErrorClass::Numerical,
            Self::OutOfMemory(e) => e.class(),
            _ => ErrorClass::InvalidInput,
        }
    }
}

impl DynError {
    /// Names the link of a [`DynError::InvalidLinkParameter`]: it becomes
    /// [`DynError::InvalidLink`] with this 0-based `index`. Every other error is returned as is.
    ///
    /// ```
    /// let err = manip_dyn::Link::new(0.1, -1.0, 0.05, 0.0).unwrap_err();
    /// assert_eq!(err.to_string(), "link mass must be positive and finite, got -1");
    /// assert_eq!(err.at_link(3).to_string(), "link 3: mass must be positive and finite, got -1");
    /// ```
    pub fn at_link(self, index: usize) -> Self {
        match self {
            Self::InvalidLinkParameter {
                quantity,
                requirement,
                value,
            } => Self::InvalidLink {
                index,
                quantity,
                requirement,
                value,
            },
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_error_keeps_its_message() {
        for error in [
            lane_math::check_len("qdd", 3, 2).unwrap_err(),
            lane_math::check_values("v", &[0.0, f64::NAN], 2).unwrap_err(),
        ] {
            let dynamics = DynError::from(error);
            assert_eq!(dynamics.to_string(), error.to_string());
            assert!(dynamics.is_invalid_input());
        }
    }
}
