//! The error type of this crate.

use lane_math::{Classify, EntryIndex, ErrorClass, ShapeError, ShapeProblem};

/// Why a kinematics computation was refused.
///
/// Every variant names the condition that failed, so a caller (or the `hrm` command line) can
/// print it as one readable line. [`Classify::class`] sorts the variants into the classes a caller
/// acts on: [`ErrorClass::Unreachable`] ("the
/// backbone curve cannot reach this target"), [`ErrorClass::Numerical`] (a numerical method
/// failed on valid input) and [`ErrorClass::InvalidInput`] (everything else: the input is
/// malformed or outside the model's domain).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum KinError {
    /// An input that must be a finite number was NaN or infinite.
    #[error("{name}{} must be finite, got {value}", EntryIndex(*index))]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// 0-based index of the first offending entry of a slice; `None` for a scalar input.
        index: Option<usize>,
        /// The offending value.
        value: f64,
    },
    /// A base position farther than [`MAX_BASE_OFFSET`](crate::MAX_BASE_OFFSET) from the origin
    /// in a coordinate: the arm's points would lose their digits to it.
    #[error(
        "base xyz must be at most {} m from the origin in each coordinate, got {}",
        lane_math::Compact(*max),
        lane_math::Compact(*value)
    )]
    BaseTooFar {
        /// The offending coordinate.
        value: f64,
        /// The bound.
        max: f64,
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
    /// A modal map or solver was asked for more links ([`MAX_LINKS`](crate::MAX_LINKS)),
    /// harmonics ([`MAX_HARMONICS`](crate::MAX_HARMONICS)) or modal Jacobian entries
    /// ([`MAX_MAP_ENTRIES`](crate::MAX_MAP_ENTRIES)) than the crate allows; it would otherwise
    /// allocate without bound.
    #[error("at most {max} {what} are supported, got {got}")]
    TooMany {
        /// `"links"`, `"harmonics"` or `"modal Jacobian entries (links x coordinates)"`.
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
    /// Modal coordinates of a curve must come in `(a_{2k-1}, a_{2k})` pairs, one per harmonic.
    #[error(
        "modal coordinates come in (sin, 1 - cos) pairs, one pair per harmonic: got an odd count {got}"
    )]
    UnpairedModes {
        /// The number of coordinates given.
        got: usize,
    },
    /// An arc length outside the curve `[0, l]`.
    #[error("arc length s = {s} is outside the curve [0, {length}]")]
    ArcLength {
        /// The requested arc length.
        s: f64,
        /// The curve length `l`.
        length: f64,
    },
    /// The curve's modal amplitudes are so large that quadrature to the documented accuracy
    /// would need more nodes than the crate allows.
    #[error(
        "the curve oscillates too fast for quadrature to the documented accuracy: {} nodes needed, at most {max} allowed",
        NodeCount(*needed)
    )]
    TooOscillatory {
        /// Quadrature nodes the error bound asks for over the whole curve.
        needed: f64,
        /// The allowed maximum.
        max: usize,
    },
    /// An inverse-kinematics guess entry beyond the solver's bound (`MAX_IK_GUESS` rad).
    #[error("guess entries must be at most {max} in magnitude, got {value}")]
    GuessTooLarge {
        /// 0-based index of the first offending entry.
        index: usize,
        /// The offending value.
        value: f64,
        /// The bound.
        max: f64,
    },
    /// Inverse kinematics converged to coordinates whose backbone curve turns too fast for the
    /// quadrature of its forward kinematics ([`KinError::TooOscillatory`] of the answer).
    #[error(
        "the solution's curve ({iterations} iterations, residual {residual:.1e} m) cannot be evaluated by fk: the curve oscillates too fast for quadrature to the documented accuracy: {} nodes needed, at most {max} allowed; start from a guess of smaller coordinates",
        NodeCount(*needed)
    )]
    AnswerTooOscillatory {
        /// Iterations the solve took.
        iterations: usize,
        /// Its end-point error (m).
        residual: f64,
        /// Quadrature nodes the answer's curve asks for.
        needed: f64,
        /// The allowed maximum.
        max: usize,
    },
    /// The restricted inverse of `J0` was asked for a value outside `J0`'s range `[0, 1]` on its
    /// first branch.
    #[error("the restricted inverse of J0 needs a value in [0, 1], got {value}")]
    J0Domain {
        /// The offending value.
        value: f64,
    },
    /// The target is farther from the base than the curve is long (`r > l`).
    #[error(
        "target out of reach: its distance from the base r = {} exceeds the curve length l = {}",
        lane_math::Compact(*r),
        lane_math::Compact(*length)
    )]
    OutOfReach {
        /// Distance of the target from the base.
        r: f64,
        /// The curve length `l`.
        length: f64,
    },
    /// The target coincides with the base (`r / l` below machine epsilon), so its direction, and
    /// with it `a2`, is undefined.
    #[error(
        "target at the base: its distance r = {r} is below the rounding level of the curve length l = {length}, so its direction (and a2) is undefined"
    )]
    AtBase {
        /// Distance of the target from the base.
        r: f64,
        /// The curve length `l`.
        length: f64,
    },
    /// With the given `alpha0` the target needs `|a2| > A` on the first branch of `J0`, so
    /// `a1 = ±sqrt(A^2 - a2^2)` is not real (eq 6). The closed form searches only amplitudes
    /// `A <= j_{0,1}` ([`inverse_j0`](crate::inverse_j0)); a curve with a larger amplitude, whose
    /// end point lies behind the base, may still reach the target (for example
    /// `a = [3.127, 0]` with `alpha0 = pi/2` reaches `(0, -0.3 l)`), and [`HarmonicIk`](crate::HarmonicIk)
    /// or [`ChainIk`](crate::ChainIk) with a guess finds such solutions.
    #[error(
        "target not reachable on the first branch of J0 with alpha0 = {alpha0}: it needs |a2| = {a2_abs} but the amplitude there is only A = {amplitude} (eq 6 needs |a2| <= A; amplitudes beyond the first zero of J0, A > 2.405, are not searched)"
    )]
    A2ExceedsAmplitude {
        /// `|a2|`, from the target's direction and `alpha0` (eq 5).
        a2_abs: f64,
        /// `A = J0^{-1}(r / l)` on the first branch.
        amplitude: f64,
        /// The base angle used.
        alpha0: f64,
    },
    /// A numerical inverse kinematics did not reach its tolerance.
    #[error(
        "numerical inverse kinematics did not converge: end-point error {residual:e} after {iterations} iterations (tolerance {tolerance:e}); from another guess it may"
    )]
    NotConverged {
        /// Iterations spent.
        iterations: usize,
        /// The smallest end-point error reached (distance to the target).
        residual: f64,
        /// The end-point error asked for.
        tolerance: f64,
    },
    /// A numerical inverse kinematics met coordinates where the end point does not move to
    /// first order (a zero Jacobian: the straight arm of modes that all integrate to zero, or
    /// an arm so small that the Jacobian's squares underflow), so no step is defined.
    #[error(
        "numerical inverse kinematics cannot move from {}: the end point does not change to first order with the coordinates there (a zero Jacobian, as at the straight arm), end-point error {residual:e}; start from another guess",
        stationary_point(*.iterations)
    )]
    Stationary {
        /// Iterations spent before it (0: the guess itself).
        iterations: usize,
        /// The end-point error there.
        residual: f64,
    },
    /// The system refused the memory of a map's or a solver's arrays.
    #[error(transparent)]
    OutOfMemory(#[from] lane_math::OutOfMemory),
}

/// Where [`KinError::Stationary`] stopped.
fn stationary_point(iterations: usize) -> String {
    if iterations == 0 {
        "the guess".to_string()
    } else {
        format!("its iterate after {iterations} iterations")
    }
}

impl Classify for KinError {
    /// [`Unreachable`](ErrorClass::Unreachable) when the closed form cannot reach the target
    /// ([`OutOfReach`]: no curve of this length can; [`AtBase`]: its direction is undefined;
    /// [`A2ExceedsAmplitude`]: not on the first branch of `J0` with this `alpha0`);
    /// [`Numerical`](ErrorClass::Numerical) when a numerical inverse kinematics did not reach its
    /// tolerance ([`NotConverged`](KinError::NotConverged)), met coordinates where no step is
    /// defined ([`Stationary`](KinError::Stationary)) or converged to coordinates its
    /// forward kinematics cannot evaluate ([`AnswerTooOscillatory`](KinError::AnswerTooOscillatory));
    /// [`OutOfMemory`](ErrorClass::OutOfMemory) for memory the system refused;
    /// otherwise the input was malformed or
    /// outside the model's domain.
    ///
    /// [`OutOfReach`]: KinError::OutOfReach
    /// [`AtBase`]: KinError::AtBase
    /// [`A2ExceedsAmplitude`]: KinError::A2ExceedsAmplitude
    fn class(&self) -> ErrorClass {
        match self {
            Self::OutOfReach { .. } | Self::AtBase { .. } | Self::A2ExceedsAmplitude { .. } => {
                ErrorClass::Unreachable
            }
            Self::NotConverged { .. }
            | Self::Stationary { .. }
            | Self::AnswerTooOscillatory { .. } => ErrorClass::Numerical,
            Self::OutOfMemory(e) => e.class(),
            _ => ErrorClass::InvalidInput,
        }
    }
}

/// A number of quadrature nodes in a message: compact, and "an overflowing number of" where the
/// estimate overflowed (the bound's terms exceed `f64`'s range long before the count does).
struct NodeCount(f64);

impl std::fmt::Display for NodeCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_finite() {
            write!(f, "{}", lane_math::Compact(self.0))
        } else {
            f.write_str("an overflowing number of")
        }
    }
}

/// A refused shape or non-finite input as [`KinError::Dimension`] or [`KinError::NonFinite`],
/// with the same message.
impl From<ShapeError<'static>> for KinError {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_error_keeps_its_message() {
        for error in [
            lane_math::check_len("joint output", 3, 2).unwrap_err(),
            lane_math::check_finite("alpha0", f64::NAN).unwrap_err(),
            lane_math::check_values("joint angles", &[0.0, f64::INFINITY], 2).unwrap_err(),
        ] {
            let kin = KinError::from(error);
            assert_eq!(kin.to_string(), error.to_string());
            assert!(kin.is_invalid_input());
        }
    }
}
