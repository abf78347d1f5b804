//! The restricted inverse of the Bessel function `J0` (the `J0^{-1}` of eq 6).
//!
//! On its first branch `[0, j_{0,1}]` the Bessel function `J0` falls monotonically from 1 to 0,
//! so every `y in [0, 1]` has exactly one preimage `A` there: the modal amplitude
//! `A = sqrt(a1^2 + a2^2)` of a curve whose end point lies at distance `r = l y` from the base
//! (eqs 3-4).

use std::sync::OnceLock;

use crate::error::KinError;
use lane_math::check_finite;

/// `j_{0,1}`, the first positive zero of `J0`: the end of the branch [`inverse_j0`] inverts.
pub const J0_FIRST_ZERO: f64 = 2.404_825_557_695_773;

/// Below this distance `d = 1 - y` from the top, the inverse comes from its power series alone.
const SERIES_ONLY_BELOW: f64 = 1e-2;

/// Most Newton-bisection steps; the iteration needs two from the tabulated start.
const MAX_STEPS: usize = 64;

/// Below this relative step the iteration keeps the last `J1` instead of evaluating it again:
/// the slope is then off by at most about this fraction (`|J1' / J1| A <= 2` beyond the series
/// region), so the next step cuts the remaining error by eight digits or more, to rounding
/// from the tabulated start: the same iterates, one Bessel evaluation fewer.
const CHORD_STEPS_BELOW: f64 = 1e-8;

/// Pieces of `s = sqrt(1 - value)` over `[sqrt(SERIES_ONLY_BELOW), 1]`, equal in length, on each
/// of which the start of Newton's method is a Chebyshev interpolant of the inverse.
const START_PIECES: usize = 16;

/// Chebyshev coefficients of each piece's interpolant (its degree plus one).
const START_TERMS: usize = 10;

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
/// and otherwise Newton's method with `J0' = -J1`, safeguarded by bisection on a bracket that
/// always contains the root, from a start tabulated once in `sqrt(d)` (piecewise Chebyshev
/// interpolants built from the series-started iteration) so close to the root that the
/// iteration ends after its second step, the second with the first's slope: four Bessel
/// evaluations, where the series start took seven to eleven beyond `d = 0.1`.
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
    if d < SERIES_ONLY_BELOW {
        return Ok(series_start(d));
    }
    Ok(newton_bisection(value, tabulated_start(d)))
}

/// The series inversion of `J0` at `d = 1 - value` (see [`inverse_j0`]).
fn series_start(d: f64) -> f64 {
    let u = d
        * (1.0
            + d * (1.0 / 4.0
                + d * (7.0 / 72.0
                    + d * (13.0 / 288.0 + d * (997.0 / 43200.0 + d * (13001.0 / 1036800.0))))));
    (2.0 * u.sqrt()).min(J0_FIRST_ZERO)
}

/// The inverse beyond the series region as a function of `s = sqrt(d)`, `d = 1 - value`, which
/// is analytic there (`A = 2 s (1 + s^2 / 8 + ...)` near the top; the nearest singularity, where
/// `J1(A) = 0`, lies at `s = 1.18`): on each of [`START_PIECES`] pieces the interpolant of degree
/// `START_TERMS - 1` at the piece's Chebyshev points, within `1e-11` of the inverse (a test
/// checks it), so that the first Newton step reaches the root to rounding and the second
/// confirms it. The table is built on first use from [`newton_bisection`] started from the
/// series: the Chebyshev coefficients of each piece, turned into powers of the piece's local
/// variable `t` so that the start is a short Estrin evaluation (a chain of four multiply-adds,
/// where Clenshaw's recurrence is a chain of nine).
fn tabulated_start(d: f64) -> f64 {
    static TABLE: OnceLock<[[f64; START_TERMS]; START_PIECES]> = OnceLock::new();
    let s_min = SERIES_ONLY_BELOW.sqrt();
    let half = 0.5 * (1.0 - s_min) / START_PIECES as f64;
    let centre = |piece: usize| s_min + (2 * piece + 1) as f64 * half;
    let table = TABLE.get_or_init(|| {
        let node = |j: usize| (std::f64::consts::PI * (j as f64 + 0.5) / START_TERMS as f64).cos();
        std::array::from_fn(|piece| {
            let inverse: [f64; START_TERMS] = std::array::from_fn(|j| {
                let s = centre(piece) + half * node(j);
                let d = s * s;
                newton_bisection(1.0 - d, series_start(d))
            });
            let chebyshev: [f64; START_TERMS] = std::array::from_fn(|k| {
                let sum: f64 = (0..START_TERMS)
                    .map(|j| {
                        let angle = std::f64::consts::PI * k as f64 * (j as f64 + 0.5);
                        inverse[j] * (angle / START_TERMS as f64).cos()
                    })
                    .sum();
                let scale = if k == 0 { 1.0 } else { 2.0 };
                scale * sum / START_TERMS as f64
            });
            monomial(&chebyshev)
        })
    });
    let s = d.sqrt();
    let piece = (((s - s_min) / (2.0 * half)) as usize).min(START_PIECES - 1);
    let t = (s - centre(piece)) / half;
    let [a0, a1, a2, a3, a4, a5, a6, a7, a8, a9] = table[piece];
    let (t2, t4) = (t * t, t * t * (t * t));
    let low = (a0 + a1 * t) + (a2 + a3 * t) * t2;
    let high = (a4 + a5 * t) + (a6 + a7 * t) * t2;
    (low + high * t4 + (a8 + a9 * t) * (t4 * t4)).clamp(0.0, J0_FIRST_ZERO)
}

/// The power-series coefficients of `sum_k c_k T_k(t)`, `T_k` the Chebyshev polynomials (their
/// integer coefficients, by `T_{k+1} = 2 t T_k - T_{k-1}`, are exact in `f64`).
fn monomial(chebyshev: &[f64; START_TERMS]) -> [f64; START_TERMS] {
    let mut powers = [0.0; START_TERMS];
    let (mut previous, mut current) = ([0.0; START_TERMS], [0.0; START_TERMS]);
    previous[0] = 1.0;
    current[1] = 1.0;
    for (k, &c) in chebyshev.iter().enumerate() {
        let t_k = if k == 0 { previous } else { current };
        for (p, t) in powers.iter_mut().zip(t_k) {
            *p += c * t;
        }
        if k >= 1 {
            let mut next = [0.0; START_TERMS];
            for j in 0..START_TERMS {
                let shifted = if j > 0 { 2.0 * current[j - 1] } else { 0.0 };
                next[j] = shifted - previous[j];
            }
            (previous, current) = (current, next);
        }
    }
    powers
}

/// Solves `J0(A) = value` on `[0, J0_FIRST_ZERO]` from `start`, keeping a bracket `[lo, hi]`
/// with `J0(lo) >= value >= J0(hi)` and bisecting whenever a Newton step would leave it.
fn newton_bisection(value: f64, start: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, J0_FIRST_ZERO);
    let mut amplitude = start;
    let mut best = (f64::INFINITY, amplitude);
    // J1 at the last point where the iterate still moved by more than CHORD_STEPS_BELOW: past
    // it, steps with this slope (chord steps) gain eight digits or more each.
    let mut slope = None;
    let mut last_step = f64::INFINITY;
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
        let derivative = match slope {
            Some(slope) if last_step <= CHORD_STEPS_BELOW * amplitude => slope,
            _ => *slope.insert(libm::j1(amplitude)),
        };
        let newton = amplitude + g / derivative;
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
        last_step = (next - amplitude).abs();
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
    fn the_tabulated_start_is_one_short_newton_step_from_the_root() {
        // Dense in s = sqrt(1 - value), the variable of the table, over the whole region.
        let s_min = SERIES_ONLY_BELOW.sqrt();
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let s = s_min + (1.0 - s_min) * f64::from(i) / 20_000.0;
            let d = s * s;
            let start = tabulated_start(d);
            let root = slow_newton(1.0 - d);
            worst = worst.max((start - root).abs());
        }
        assert!(worst < 1e-11, "largest start error {worst:e}");
    }

    /// The root by Newton's method from the series start, stopped only when the step reaches
    /// rounding: a second algorithm for the tabulated start and the polished result.
    fn slow_newton(value: f64) -> f64 {
        let mut amplitude = series_start(1.0 - value);
        for _ in 0..100 {
            let step = (libm::j0(amplitude) - value) / libm::j1(amplitude);
            amplitude += step;
            if step.abs() <= 4.0 * f64::EPSILON * amplitude {
                break;
            }
        }
        amplitude
    }

    #[test]
    fn the_polished_root_is_the_slowly_converged_root() {
        for i in 1..2_000 {
            let value = f64::from(i) / 2_000.0;
            let root = slow_newton(value);
            let polished = inverse_j0(value).unwrap();
            // As close as the rounding of J0 (a few 1e-16) lets two roots be, dy / J1(A) ...
            let conditioning = 4.0 * f64::EPSILON / libm::j1(root);
            assert!(
                (polished - root).abs() <= conditioning,
                "{value}: {polished} vs {root}"
            );
            // ... and as good a root: J0 there is the value to its rounding.
            assert!(
                (libm::j0(polished) - value).abs() <= 3e-16,
                "{value}: residual {:e}",
                libm::j0(polished) - value
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
