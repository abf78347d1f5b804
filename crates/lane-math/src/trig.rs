//! Sine and cosine of many angles at once, in a form the compiler vectorises.
//!
//! The default path needs `sin` and `cos` of every link's absolute angle, and a library call per
//! angle is half its cost. Here the whole batch goes through one branch-free loop:
//!
//! 1. Argument reduction (Cody-Waite): `x = k pi/2 + r` with `k` the integer nearest `x 2/pi`
//!    and `|r| <= pi/4`, subtracting `k pi/2` in three parts (`pi/2 = HI + MID + LO`, `HI` and
//!    `MID` with 33 significant bits, so `k HI` and `k MID` are exact for `|k| < 2^20`).
//! 2. Taylor polynomials on `|r| <= pi/4`: `sin` to `r^17`, `cos` to `r^16`; the first omitted
//!    terms are below `1e-19` and `3e-18`, so rounding (about one ulp) dominates.
//! 3. The quadrant `k mod 4` swaps and negates the pair.
//!
//! Angles beyond `2^19 pi` (where the exact products run out of bits) go to `libm::sincos`.
//! Accuracy: within a few units in the last place of `libm` (tested).

use std::f64::consts::FRAC_2_PI;

/// The three parts of `pi/2`: `HI` and `MID` have 33 significant bits.
const PIO2_HI: f64 = 1.5707963267341256;
const PIO2_MID: f64 = 6.077100506303966e-11;
const PIO2_LO: f64 = 2.0222662487959506e-21;

/// Largest `|x|` reduced here: `|k| < 2^20` keeps `k HI` and `k MID` exact.
const REDUCTION_LIMIT: f64 = 524288.0 * std::f64::consts::PI;

/// `1.5 2^52`: adding it rounds to an integer, which then sits in the low mantissa bits.
const ROUNDING_SHIFT: f64 = 6755399441055744.0;

/// `(-1)^j / (2j + 1)!` for `j = 1..=8`: the Taylor coefficients of `sin` after `r`.
const SIN: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362880.0,
    -1.0 / 39916800.0,
    1.0 / 6227020800.0,
    -1.0 / 1307674368000.0,
    1.0 / 355687428096000.0,
];

/// `(-1)^j / (2j)!` for `j = 2..=8`: the Taylor coefficients of `cos` after `1 - r^2/2`.
const COS: [f64; 7] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40320.0,
    -1.0 / 3628800.0,
    1.0 / 479001600.0,
    -1.0 / 87178291200.0,
    1.0 / 20922789888000.0,
];

/// `sin[i] = sin(angles[i])` and `cos[i] = cos(angles[i])` (slices of equal length). Inlined,
/// so that inside a batch it vectorises with the batch's instruction set.
#[inline(always)]
pub fn sin_cos(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    let (sin, cos) = (&mut sin[..angles.len()], &mut cos[..angles.len()]);
    let mut any_large = false;
    for ((&x, s), c) in angles.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
        any_large |= x.abs() > REDUCTION_LIMIT;
        (*s, *c) = sin_cos_reduced(x);
    }
    if any_large {
        sin_cos_large(angles, sin, cos);
    }
}

/// Redoes the angles beyond [`REDUCTION_LIMIT`] with `libm`.
#[cold]
fn sin_cos_large(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    for ((&x, s), c) in angles.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
        if x.abs() > REDUCTION_LIMIT {
            (*s, *c) = libm::sincos(x);
        }
    }
}

/// `(sin x, cos x)` for `|x| <= REDUCTION_LIMIT`, branch-free.
#[inline(always)]
fn sin_cos_reduced(x: f64) -> (f64, f64) {
    let shifted = x * FRAC_2_PI + ROUNDING_SHIFT;
    let k = shifted - ROUNDING_SHIFT;
    // The low mantissa bits of `shifted` hold k in two's complement: k mod 4.
    let quadrant = shifted.to_bits();
    let r = ((x - k * PIO2_HI) - k * PIO2_MID) - k * PIO2_LO;
    let r2 = r * r;
    let mut sin_tail = SIN[7];
    for &coefficient in SIN[..7].iter().rev() {
        sin_tail = sin_tail * r2 + coefficient;
    }
    let mut cos_tail = COS[6];
    for &coefficient in COS[..6].iter().rev() {
        cos_tail = cos_tail * r2 + coefficient;
    }
    let sin_r = r + r * r2 * sin_tail;
    let cos_r = 1.0 - 0.5 * r2 + r2 * r2 * cos_tail;
    // k mod 4 = 0: (s, c); 1: (c, -s); 2: (-s, -c); 3: (-c, s).
    // Bit masks rather than branches, so the loop over angles vectorises.
    let swap = (quadrant & 1).wrapping_neg();
    let (sin_bits, cos_bits) = (sin_r.to_bits(), cos_r.to_bits());
    let sin_x = (cos_bits & swap) | (sin_bits & !swap);
    let cos_x = (sin_bits & swap) | (cos_bits & !swap);
    let sin_sign = (quadrant & 2) << 62;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
    (
        f64::from_bits(sin_x ^ sin_sign),
        f64::from_bits(cos_x ^ cos_sign),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Both results against `libm` (within 1 ulp of the exact values) to 3e-16 absolute.
    fn check(angles: &[f64]) -> Result<(), TestCaseError> {
        let (mut sin, mut cos) = (vec![0.0; angles.len()], vec![0.0; angles.len()]);
        sin_cos(angles, &mut sin, &mut cos);
        for ((&x, s), c) in angles.iter().zip(&sin).zip(&cos) {
            let (s_ref, c_ref) = libm::sincos(x);
            prop_assert!((s - s_ref).abs() <= 3e-16, "sin({x}) = {s}, libm {s_ref}");
            prop_assert!((c - c_ref).abs() <= 3e-16, "cos({x}) = {c}, libm {c_ref}");
        }
        Ok(())
    }

    proptest! {
        #[test]
        fn matches_libm_on_ordinary_angles(angles in prop::collection::vec(-50.0..50.0f64, 1..40)) {
            check(&angles)?;
        }

        #[test]
        fn matches_libm_on_large_angles(angles in prop::collection::vec(-2e6..2e6f64, 1..40)) {
            check(&angles)?;
        }

        #[test]
        fn matches_libm_near_quadrant_boundaries(k in -100_000i64..100_000, offset in -1e-6..1e-6f64) {
            let x = k as f64 * std::f64::consts::FRAC_PI_2 + offset;
            check(&[x, x + std::f64::consts::FRAC_PI_4, x - std::f64::consts::FRAC_PI_4])?;
        }
    }

    #[test]
    fn special_values() {
        check(&[
            0.0,
            -0.0,
            1e-300,
            5e-324,
            REDUCTION_LIMIT,
            -REDUCTION_LIMIT,
            1e300,
        ])
        .unwrap();
        let (mut s, mut c) = ([0.0; 2], [0.0; 2]);
        sin_cos(&[f64::NAN, f64::INFINITY], &mut s, &mut c);
        assert!(s.iter().chain(&c).all(|v| v.is_nan()));
    }
}
