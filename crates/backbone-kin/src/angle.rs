//! Reduction of a base angle into `(-pi, pi]`.

use std::f64::consts::PI;

/// An angle in `(-pi, pi]` equal to `angle` modulo `2 pi`. Values already there are kept bit for
/// bit; larger ones are reduced through their sine and cosine, whose argument reduction is exact
/// (reducing by the double nearest `2 pi` would be off by `angle / 2 pi` times its rounding
/// error, thousands of radians at `angle = 1e20`). A base angle `alpha0` enters the curve and the
/// chain only through sines and cosines, but `theta_1 = alpha0 + ...` (eq 8) would lose the modal
/// part in rounding for a large one: callers reduce it first. A non-finite angle is returned as
/// it is, for the caller's check to name.
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
        assert!(reduce_angle(f64::NAN).is_nan());
    }
}
