//! The paper's two-mode closed forms (`K = 1`): the end point through `J0` (eqs 3-4) and its
//! inverse (eqs 5-6), with the corrections of the model notes.
//!
//! For `alpha(s) = alpha0 + a1 sin(2 pi s / l) + a2 (1 - cos(2 pi s / l))` the end point is
//! `(x, y) = l J0(A) (cos(alpha0 + a2), sin(alpha0 + a2))` with `A = sqrt(a1^2 + a2^2)` (the
//! paper puts `l` inside the Bessel argument, wrongly). Inverting: the direction of the target
//! fixes `a2`, its distance fixes `A`, and `a1 = ±sqrt(A^2 - a2^2)`.

use crate::angle::reduce_angle;
use crate::bessel::inverse_j0;
use crate::error::KinError;
use crate::validate::check_length;
use lane_math::check_finite;

/// The sign branch of `a1 = ±sqrt(A^2 - a2^2)` (eq 6): the two mirror-image curves that reach
/// the same target with the same `alpha0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Branch {
    /// `a1 >= 0` (the paper's choice, the square root of eq 6).
    Positive,
    /// `a1 <= 0`.
    Negative,
}

/// Relative uncertainty of `r / l` as the inverse sees it: the rounding of `hypot` and of the
/// division, and the error of `libm::j0` in a round trip.
const RATIO_UNCERTAINTY: f64 = 4.0 * f64::EPSILON;

/// Refuses a target at distance `r` from the base beyond the arm's `length` by more than
/// [`RATIO_UNCERTAINTY`]: the reach of every inverse kinematics, closed-form and numerical, so
/// that a target at the nominal length (the length is a rounded sum of the links') is reached
/// whatever the method.
pub(crate) fn check_reach(r: f64, length: f64) -> Result<(), KinError> {
    if r > length * (1.0 + RATIO_UNCERTAINTY) {
        return Err(KinError::OutOfReach { r, length });
    }
    Ok(())
}

/// The end point of the two-mode backbone curve of length `length` (eqs 3-4, corrected):
/// `l J0(A) (cos(alpha0 + a2), sin(alpha0 + a2))`, `a = [a1, a2]`, `A = |a|`.
///
/// Exact up to the rounding of `libm::j0` (about `2e-16 l`). Any amplitude is allowed; past
/// `A = j_{0,1}` the factor `J0(A)` turns negative and the end point lies behind the base.
///
/// ```
/// use backbone_kin::end_point;
/// let tip = end_point(1.0, [0.0, 0.0], 0.3)?;
/// assert!((tip[0] - 0.3f64.cos()).abs() < 1e-15 && (tip[1] - 0.3f64.sin()).abs() < 1e-15);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn end_point(length: f64, a: [f64; 2], alpha0: f64) -> Result<[f64; 2], KinError> {
    check_length("curve length", length)?;
    check_finite("a1", a[0])?;
    check_finite("a2", a[1])?;
    check_finite("alpha0", alpha0)?;
    Ok(bessel_end_point(length, a, alpha0))
}

/// [`end_point`] without input checks, for callers that validated already.
pub(crate) fn bessel_end_point(length: f64, a: [f64; 2], alpha0: f64) -> [f64; 2] {
    let reach = length * libm::j0(a[0].hypot(a[1]));
    let (sin, cos) = (alpha0 + a[1]).sin_cos();
    [reach * cos, reach * sin]
}

/// The closed-form inverse kinematics (eqs 5-6, corrected): the two-mode coordinates `[a1, a2]`
/// whose curve of length `length`, leaving the base at `alpha0`, ends at `target`.
///
/// `a2 = atan2(y, x) - alpha0` wrapped to `(-pi, pi]`, `A = J0^{-1}(r / l)` on the first branch
/// ([`inverse_j0`]), and `a1 = ±sqrt(A^2 - a2^2)` with the sign chosen by `branch`.
///
/// Errors, each naming its condition: [`KinError::OutOfReach`] when `r > l`;
/// [`KinError::AtBase`] when `r <= l * f64::EPSILON`, where the target's direction (and so `a2`)
/// is lost in rounding; [`KinError::A2ExceedsAmplitude`] when `|a2| > A` for this `alpha0`
/// (the target is then not reachable on the first branch of `J0`; a curve with `A > j_{0,1}`
/// may still reach it, and [`HarmonicIk`](crate::HarmonicIk) finds it from a guess there);
/// [`KinError::NonFinite`] and [`KinError::NonPositiveLength`] for bad input.
///
/// Rounding at the edges of the reachable set is absorbed rather than reported: `r` up to
/// `l (1 + 4 eps)` counts as `r = l`, and `|a2|` exceeding `A` by less than the uncertainty of
/// `A` (`4 eps / J1(A)`, at most `4 sqrt(eps)` near `A = 0`) gives `a1 = 0`. So the inverse of
/// every end point of [`end_point`] with `|a2| <= A <= j_{0,1}` succeeds.
///
/// ```
/// use backbone_kin::{end_point, inverse_kinematics, Branch};
/// let target = end_point(1.0, [0.8, -0.4], 0.5)?;
/// let a = inverse_kinematics(1.0, target, 0.5, Branch::Positive)?;
/// assert!((a[0] - 0.8).abs() < 1e-12 && (a[1] + 0.4).abs() < 1e-12);
/// // A target beyond the curve's length is refused, with the reason:
/// let err = inverse_kinematics(1.0, [2.0, 0.0], 0.0, Branch::Positive).unwrap_err();
/// assert!(err.to_string().contains("out of reach"));
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn inverse_kinematics(
    length: f64,
    target: [f64; 2],
    alpha0: f64,
    branch: Branch,
) -> Result<[f64; 2], KinError> {
    check_length("curve length", length)?;
    check_finite("target x", target[0])?;
    check_finite("target y", target[1])?;
    check_finite("alpha0", alpha0)?;
    let r = target[0].hypot(target[1]);
    check_reach(r, length)?;
    if r <= length * f64::EPSILON {
        return Err(KinError::AtBase { r, length });
    }
    let a2 = reduce_angle(target[1].atan2(target[0]) - alpha0);
    let amplitude = inverse_j0((r / length).min(1.0))?;
    // The slack (never negative) is only needed, and its J1 only evaluated, past the amplitude.
    if a2.abs() > amplitude {
        let slack = (RATIO_UNCERTAINTY / libm::j1(amplitude)).min(2.0 * RATIO_UNCERTAINTY.sqrt());
        if a2.abs() > amplitude + slack {
            return Err(KinError::A2ExceedsAmplitude {
                a2_abs: a2.abs(),
                amplitude,
                alpha0,
            });
        }
    }
    // (A - a2)(A + a2) keeps relative accuracy when |a2| is close to A.
    let a1 = ((amplitude - a2.abs()).max(0.0) * (amplitude + a2.abs())).sqrt();
    Ok(match branch {
        Branch::Positive => [a1, a2],
        Branch::Negative => [-a1, a2],
    })
}
