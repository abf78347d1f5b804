//! The error type of this crate.

/// Why a kinematics computation was refused.
///
/// Every variant names the condition that failed, so a caller (or the `hrm` command line) can
/// print it as one readable line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinError {
    /// An input that must be a finite number was NaN or infinite.
    #[error("{name} must be finite, got {value}")]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A length (a link, the whole curve) was zero, negative or non-finite.
    #[error("{name} must be positive and finite, got {value}")]
    NonPositiveLength {
        /// Which length.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A chain or map was asked for with zero links.
    #[error("a manipulator needs at least one link")]
    NoLinks,
    /// A modal family was asked for with zero harmonics.
    #[error("a modal family needs at least one harmonic")]
    NoHarmonics,
    /// A slice had the wrong number of entries.
    #[error("{name} has {got} entries, expected {expected}")]
    Dimension {
        /// Which input.
        name: &'static str,
        /// The length the computation needs.
        expected: usize,
        /// The length it got.
        got: usize,
    },
}
