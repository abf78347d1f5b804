//! The restricted inverse of the Bessel function `J0` (the `J0^{-1}` of eq 6).
//!
//! On its first branch `[0, j_{0,1}]` the Bessel function `J0` falls monotonically from 1 to 0,
//! so every `y in [0, 1]` has exactly one preimage `A` there: the modal amplitude
//! `A = sqrt(a1^2 + a2^2)` of a curve whose end point lies at distance `r = l y` from the base
//! (eqs 3-4).

use crate::error::KinError;
use crate::validate::check_finite;

/// `j_{0,1}`, the first positive zero of `J0`: the end of the branch [`inverse_j0`] inverts.
pub const J0_FIRST_ZERO: f64 = 2.404_825_557_695_773;

/// Below this distance `d = 1 - y` from the top, the inverse comes from its power series alone.
const SERIES_ONLY_BELOW: f64 = 1e-2;

/// Most Newton-bisection steps; the iteration needs about four from the series start.
const MAX_STEPS: usize = 64;

/// The restricted inverse of `J0`: the unique `A in [0, J0_FIRST_ZERO]` with `J0(A) = value`.
///
/// Accuracy: `|J0(A) - value|` is at the rounding level of `libm::j0` (about `3e-16`, and well
/// under the `1e-14` the kinematics needs) over the whole domain. The amplitude itself is as
/// accurate as the problem's conditioning allows: a change `dy` in `value` moves `A` by
/// `dy / J1(A)`, which grows as `A -> 0` (where `J0'(0) = 0`).
///
/// Method: near `value = 1` the series inversion of `J0(A) = sum_k (-u)^k / (k!)^2`,
/// `u = A^2 / 4`, in `d = 1 - value`:
/// `u = d + d^2/4 + 7 d^3/72 + 13 d^4/288 + 997 d^5/43200 + 13001 d^6/1036800 + O(d^7)`,
/// which is used alone when `d < 1e-2` (its truncation error in `u` is then at most `7e-15`
/// relative, at `d = 1e-2`, which moves `J0(A)` by under `1e-16`: below the rounding of `libm::j0`)
/// and otherwise as the start of Newton's method with `J0' = -J1`, safeguarded by bisection on a
/// bracket that always contains the root.
///
/// ```
/// use backbone_kin::{inverse_j0, J0_FIRST_ZERO};
/// let amplitude = inverse_j0(0.5)?;
/// assert!((libm::j0(amplitude) - 0.5).abs() < 1e-15);
/// assert_eq!(inverse_j0(1.0)?, 0.0);
/// assert_eq!(inverse_j0(0.0)?, J0_FIRST_ZERO);
/// assert!(inverse_j0(1.5).is_err());
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn inverse_j0(value: f64) -> Result<f64, KinError> {
    check_finite("J0 value", value)?;
    if !(0.0..=1.0).contains(&value) {
        return Err(KinError::J0Domain { value });
    }
    if value == 0.0 {
        return Ok(J0_FIRST_ZERO);
    }
    // Exact for value >= 1/2 (Sterbenz), which covers the series region.
    let d = 1.0 - value;
    let u = d
        * (1.0
            + d * (1.0 / 4.0
                + d * (7.0 / 72.0
                    + d * (13.0 / 288.0 + d * (997.0 / 43200.0 + d * (13001.0 / 1036800.0))))));
    let start = (2.0 * u.sqrt()).min(J0_FIRST_ZERO);
    if d < SERIES_ONLY_BELOW {
        return Ok(start);
    }
    Ok(newton_bisection(value, start))
}

/// Solves `J0(A) = value` on `[0, J0_FIRST_ZERO]` from `start`, keeping a bracket `[lo, hi]`
/// with `J0(lo) >= value >= J0(hi)` and bisecting whenever a Newton step would leave it.
fn newton_bisection(value: f64, start: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, J0_FIRST_ZERO);
    let mut amplitude = start;
    let mut best = (f64::INFINITY, amplitude);
    for _ in 0..MAX_STEPS {
        let g = libm::j0(amplitude) - value;
        if g.abs() < best.0 {
            best = (g.abs(), amplitude);
        }
        if g == 0.0 {
            break;
        }
        if g > 0.0 {
            lo = amplitude;
        } else {
            hi = amplitude;
        }
        let newton = amplitude + g / libm::j1(amplitude);
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - amplitude).abs() <= 2.0 * f64::EPSILON * amplitude
            || hi - lo <= 2.0 * f64::EPSILON * hi
        {
            let g_next = (libm::j0(next) - value).abs();
            if g_next < best.0 {
                best = (g_next, next);
            }
            break;
        }
        amplitude = next;
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_zero_is_a_zero_of_j0() {
        assert!(libm::j0(J0_FIRST_ZERO).abs() < 1e-16);
        // and J0 has no other zero before it: it is positive on a fine grid of [0, j01).
        for i in 0..10_000 {
            assert!(libm::j0(J0_FIRST_ZERO * f64::from(i) / 10_000.0) > 0.0);
        }
    }

    #[test]
    fn series_and_newton_agree_at_the_switch() {
        // Both ways of computing the inverse near the switch point give the same amplitude.
        for value in [0.985, 0.99, 0.995] {
            let d: f64 = 1.0 - value;
            let start = 2.0 * (d + d * d / 4.0).sqrt();
            let newton = newton_bisection(value, start);
            let series = inverse_j0(value).unwrap();
            assert!(
                (newton - series).abs() < 1e-14,
                "{value}: {newton} vs {series}"
            );
        }
    }

    #[test]
    fn bisection_rescues_a_bad_start() {
        for start in [0.0, 1e-300, J0_FIRST_ZERO, 0.5] {
            let amplitude = newton_bisection(0.3, start);
            assert!(
                (libm::j0(amplitude) - 0.3).abs() < 1e-15,
                "start {start}: {amplitude}"
            );
        }
    }
}
