//! The shape and finiteness checks every crate applies to user-sized arrays of numbers, written
//! once: each crate's error type names the field and carries what [`check_values`] or
//! [`first_non_finite`] found.

/// What is wrong with an array of numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeProblem {
    /// It has `found` entries where `expected` are needed.
    Length {
        /// The number of entries needed.
        expected: usize,
        /// The number given.
        found: usize,
    },
    /// Entry `index` is `value`, which is not finite (NaN or infinite).
    NonFinite {
        /// The entry's index.
        index: usize,
        /// The entry.
        value: f64,
    },
}

/// The first entry of `values` that is not finite, with its index.
///
/// ```
/// assert_eq!(lane_math::first_non_finite(&[1.0, f64::NAN, f64::INFINITY]).map(|(i, _)| i), Some(1));
/// assert_eq!(lane_math::first_non_finite(&[1.0, -2.0]), None);
/// ```
pub fn first_non_finite(values: &[f64]) -> Option<(usize, f64)> {
    values
        .iter()
        .copied()
        .enumerate()
        .find(|(_, value)| !value.is_finite())
}

/// Checks that `values` has `expected` entries (checked first), all finite.
///
/// ```
/// use lane_math::{ShapeProblem, check_values};
/// assert_eq!(check_values(&[1.0, 2.0], 2), Ok(()));
/// assert_eq!(check_values(&[1.0], 2), Err(ShapeProblem::Length { expected: 2, found: 1 }));
/// assert!(matches!(check_values(&[1.0, f64::NAN], 2), Err(ShapeProblem::NonFinite { index: 1, .. })));
/// ```
pub fn check_values(values: &[f64], expected: usize) -> Result<(), ShapeProblem> {
    if values.len() != expected {
        return Err(ShapeProblem::Length {
            expected,
            found: values.len(),
        });
    }
    match first_non_finite(values) {
        Some((index, value)) => Err(ShapeProblem::NonFinite { index, value }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_length_is_checked_before_the_values() {
        assert_eq!(
            check_values(&[f64::NAN], 2),
            Err(ShapeProblem::Length {
                expected: 2,
                found: 1
            })
        );
        assert_eq!(check_values(&[], 0), Ok(()));
    }

    #[test]
    fn the_first_non_finite_entry_is_found_whatever_its_kind() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let values = [0.0, f64::MAX, bad, f64::NAN];
            let (index, value) = first_non_finite(&values).unwrap();
            assert_eq!(index, 2);
            assert_eq!(value.to_bits(), bad.to_bits());
        }
        assert_eq!(first_non_finite(&[f64::MIN_POSITIVE, -f64::MAX]), None);
    }
}
