//! The error type of this crate.

/// Why a dynamics computation was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DynError {
    /// A chain was asked for with zero links.
    #[error("a chain needs at least one link")]
    NoLinks,
    /// A chain was asked for with more than [`MAX_LINKS`](crate::model::MAX_LINKS) links.
    #[error("a chain may have at most {max} links, got {got}")]
    TooManyLinks {
        /// The number of links asked for.
        got: usize,
        /// The limit.
        max: usize,
    },
    /// A link parameter was out of its domain.
    #[error("link {index}: {quantity} must be {requirement}, got {value}")]
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
    /// The gravitational acceleration was not finite.
    #[error("gravity must be finite, got {0}")]
    InvalidGravity(f64),
    /// A slice or matrix had the wrong size.
    #[error("{name} has {got} entries, expected {expected}")]
    Dimension {
        /// Which input or output.
        name: &'static str,
        /// The size the computation needs.
        expected: usize,
        /// The size it got.
        got: usize,
    },
    /// An input that must be finite was NaN or infinite.
    #[error("{name}[{index}] must be finite, got {value}")]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// 0-based index of the first offending entry.
        index: usize,
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
}
