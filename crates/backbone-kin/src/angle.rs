//! Reduction of an angle into `(-pi, pi]`, the one the library uses (base angles, the closed-form
//! inverse, `hrm eval`).

use std::f64::consts::PI;

/// An angle in `(-pi, pi]` equal to `angle` modulo `2 pi`. Values already there are kept bit for
/// bit; larger ones are reduced through their sine and cosine, whose argument reduction is exact
/// (reducing by the double nearest `2 pi` would be off by `angle / 2 pi` times its rounding
/// error, thousands of radians at `angle = 1e20`). A base angle `alpha0` enters the curve and the
/// chain only through sines and cosines, but `theta_1 = alpha0 + ...` (eq 8) would lose the modal
/// part in rounding for a large one: callers reduce it first. A non-finite angle is returned as
/// it is, for the caller's check to name.
///
/// The range in doubles is `[-PI, PI]`: `PI` and `-PI` are the doubles nearest `pi` and `-pi`,
/// both strictly inside `(-pi, pi]` (`PI < pi`), and each is returned as it is.
///
/// ```
/// use backbone_kin::reduce_angle;
/// assert_eq!(reduce_angle(1.25), 1.25);
/// assert!((reduce_angle(1e15) - 1e15f64.sin().atan2(1e15f64.cos())).abs() == 0.0);
/// ```
pub fn reduce_angle(angle: f64) -> f64 {
    if (angle > -PI && angle <= PI) || !angle.is_finite() {
        angle
    } else {
        let (sin, cos) = angle.sin_cos();
        sin.atan2(cos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_angles_reduce_to_their_remainder() {
        assert_eq!(reduce_angle(PI), PI);
        assert_eq!(reduce_angle(-0.5), -0.5);
        // The remainder keeps the sine and cosine (which reduce their argument exactly).
        for x in [7.0, -7.0, 1e15, 1e17, 1e300, -1e300] {
            let r = reduce_angle(x);
            assert!(r > -PI && r <= PI, "{x}: {r}");
            assert!((r.sin() - x.sin()).abs() < 1e-15 && (r.cos() - x.cos()).abs() < 1e-15);
        }
        assert!((reduce_angle(7.0) - (7.0 - 2.0 * PI)).abs() < 1e-15);
        assert_eq!(reduce_angle(f64::INFINITY), f64::INFINITY);
        assert_eq!(reduce_angle(f64::NEG_INFINITY), f64::NEG_INFINITY);
        assert!(reduce_angle(f64::NAN).is_nan());
    }

    #[test]
    fn the_ends_of_the_range_are_the_doubles_next_to_plus_and_minus_pi() {
        // `PI` and `-PI` are the doubles nearest pi and -pi, both inside (-pi, pi]: kept.
        assert_eq!(reduce_angle(PI).to_bits(), PI.to_bits());
        assert_eq!(reduce_angle(-PI).to_bits(), (-PI).to_bits());
        // Just past either end, the other end.
        let above = f64::from_bits(PI.to_bits() + 1);
        assert!(reduce_angle(above) < -PI + 1e-15 && reduce_angle(above) >= -PI);
        let below = -above;
        assert!(reduce_angle(below) > PI - 1e-15 && reduce_angle(below) <= PI);
        // A difference of two angles in (-pi, pi], as the closed-form inverse forms, turned by a
        // whole turn and kept to the last bit otherwise.
        for (x, expected) in [(1.5 * PI, -0.5 * PI), (-1.5 * PI, 0.5 * PI), (-2.0, -2.0)] {
            let r = reduce_angle(x);
            assert!((r - expected).abs() < 1e-15, "{x}: {r}");
        }
        assert_eq!(reduce_angle(-1e-300), -1e-300);
        assert_eq!(reduce_angle(-0.0).to_bits(), (-0.0f64).to_bits());
    }
}
