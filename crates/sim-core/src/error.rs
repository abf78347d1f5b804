//! The error types of this crate.

use crate::ode::OdeError;
use backbone_kin::KinError;
use modal_reduce::ReduceError;

/// Why a simulation could not be built or had to stop.
///
/// Every variant names the condition that failed; the ones raised during a run say when.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A setting was out of its domain.
    #[error("{name} {requirement}")]
    InvalidSetting {
        /// Which setting (as it is spelled in a scenario file).
        name: String,
        /// What was wrong with it, e.g. "must be positive and finite, got -1".
        requirement: String,
    },
    /// A point of a Cartesian reference path cannot be reached by the backbone curve.
    #[error("the reference path point ({x:.6}, {y:.6}) at t = {t} s is unreachable: {source}")]
    Unreachable {
        /// Time on the path (s).
        t: f64,
        /// The point's `x` (m).
        x: f64,
        /// The point's `y` (m).
        y: f64,
        /// Which reachability condition failed.
        source: KinError,
    },
    /// A Cartesian reference path passes through a singular point of the inverse kinematics:
    /// the branch point `a1 = 0` of eq 6 or the straight curve `A = 0` (`r = l`), where the rate
    /// of the modal reference is undefined.
    #[error(
        "the reference path passes through a singular point of the inverse kinematics near \
         t = {t} s at ({x:.6}, {y:.6}): {what}, where the modal reference rate is undefined; move \
         the path or change alpha0"
    )]
    SingularPoint {
        /// Which singularity: the branch point or the straight curve.
        what: &'static str,
        /// Time on the path (s).
        t: f64,
        /// The point's `x` (m).
        x: f64,
        /// The point's `y` (m).
        y: f64,
    },
    /// The kinematics refused a computation.
    #[error("kinematics: {0}")]
    Kinematics(#[from] KinError),
    /// The reduced dynamics refused a computation (outside of the integrator).
    #[error("reduced dynamics at t = {t} s: {source}")]
    Dynamics {
        /// When (s).
        t: f64,
        /// The refusal.
        source: ReduceError,
    },
    /// The arm or the modal map could not be built.
    #[error("model: {0}")]
    Model(ReduceError),
    /// The fuzzy system could not be built, loaded or evaluated.
    #[error("fuzzy controller: {0}")]
    Fuzzy(#[from] fuzzy_sugeno::FuzzyError),
    /// The integrator stopped: the dynamics failed or the state blew up between two samples.
    #[error("integration diverged: {0}")]
    Integration(OdeError<ReduceError>),
    /// The controller produced a NaN or infinite torque.
    #[error("the controller produced a non-finite modal torque {tau_star:?} at t = {t} s")]
    NonFiniteControl {
        /// When (s).
        t: f64,
        /// The torque it produced.
        tau_star: [f64; 2],
    },
    /// A modal tracking error grew beyond the configured bound.
    #[error(
        "runaway tracking error at t = {t} s: |a{coordinate} - a{coordinate}_ref| = {error:.4} rad \
         exceeds the bound {bound} rad"
    )]
    RunawayError {
        /// When (s).
        t: f64,
        /// Which coordinate (1 or 2).
        coordinate: usize,
        /// The error's magnitude (rad).
        error: f64,
        /// The bound in force (rad).
        bound: f64,
    },
}

impl SimError {
    /// An [`InvalidSetting`](Self::InvalidSetting) error.
    pub(crate) fn setting(name: impl Into<String>, requirement: impl Into<String>) -> Self {
        Self::InvalidSetting {
            name: name.into(),
            requirement: requirement.into(),
        }
    }
}

/// Checks that `value` is positive and finite.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!("must be positive and finite, got {}", Readable(value)),
        ))
    }
}

/// Checks that `value` is non-negative and finite.
pub(crate) fn check_non_negative(name: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!("must be non-negative and finite, got {}", Readable(value)),
        ))
    }
}

/// Checks that every entry of `values` is finite.
pub(crate) fn check_finite(name: &str, values: &[f64]) -> Result<(), SimError> {
    match values.iter().find(|v| !v.is_finite()) {
        None => Ok(()),
        Some(v) => Err(SimError::setting(name, format!("must be finite, got {v}"))),
    }
}

/// A number in an error message as a person reads it: plain decimals from `1e-4` up to `1e15`
/// (`0.001`, `-0.5`, `250`), exponents beyond (`1e-300`, `1e300`), never a 300-digit decimal.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Readable(pub f64);

impl std::fmt::Display for Readable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let magnitude = self.0.abs();
        if self.0 == 0.0 || !self.0.is_finite() || (1e-4..1e15).contains(&magnitude) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Readable;

    #[test]
    fn numbers_are_readable() {
        for (x, text) in [
            (0.0, "0"),
            (-0.5, "-0.5"),
            (0.001, "0.001"),
            (250.0, "250"),
            (1e-300, "1e-300"),
            (-1e300, "-1e300"),
            (f64::MAX, "1.7976931348623157e308"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(Readable(x).to_string(), text);
        }
    }
}
