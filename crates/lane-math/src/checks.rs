//! The shape and finiteness checks every crate applies to its inputs, written once: each returns
//! a [`ShapeError`] naming the field and the problem, which each crate's error type takes in
//! through `From` (`?`), keeping its own variants and messages.

use std::fmt;

use crate::{Classify, ErrorClass};

/// A refused input: which field, and what is wrong with it.
///
/// Its message is `"{name} has {found} entries, expected {expected}"` or
/// `"{name}[{index}] must be finite, got {value}"` (no `[index]` for a single number), the text
/// the crates' own `Dimension` and `NonFinite` errors print.
///
/// ```
/// let error = lane_math::check_values("q", &[0.5, f64::NAN], 2).unwrap_err();
/// assert_eq!(error.to_string(), "q[1] must be finite, got NaN");
/// assert_eq!(lane_math::check_len("q", 3, 2).unwrap_err().to_string(), "q has 3 entries, expected 2");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeError<'a> {
    /// The field, as the caller names it to the user.
    pub name: &'a str,
    /// What is wrong with it.
    pub problem: ShapeProblem,
}

/// What is wrong with an input: the number of its entries or one of its values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeProblem {
    /// It has `found` entries where `expected` are needed.
    Length {
        /// The number of entries needed.
        expected: usize,
        /// The number given.
        found: usize,
    },
    /// A value is not finite (NaN or infinite).
    NonFinite {
        /// 0-based index of the first offending entry of an array; `None` for a single number.
        index: Option<usize>,
        /// The offending value.
        value: f64,
    },
}

/// `[i]` after an input's name when the offending value is entry `i` of an array, nothing for a
/// single number: `q[1] must be finite`, `alpha0 must be finite`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EntryIndex(pub Option<usize>);

impl fmt::Display for EntryIndex {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(index) => write!(f, "[{index}]"),
            None => Ok(()),
        }
    }
}

/// The problem without the field's name: `has 3 entries, expected 2`, `must be finite, got NaN`
/// (the index, if any, belongs after the name).
impl fmt::Display for ShapeProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Length { expected, found } => {
                write!(f, "has {found} entries, expected {expected}")
            }
            Self::NonFinite { value, .. } => write!(f, "must be finite, got {value}"),
        }
    }
}

impl fmt::Display for ShapeError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.problem {
            ShapeProblem::NonFinite { index, .. } => {
                write!(f, "{}{} {}", self.name, EntryIndex(index), self.problem)
            }
            ShapeProblem::Length { .. } => write!(f, "{} {}", self.name, self.problem),
        }
    }
}

impl std::error::Error for ShapeError<'_> {}

impl Classify for ShapeError<'_> {
    /// Always [`ErrorClass::InvalidInput`]: a wrong shape or a non-finite number given.
    fn class(&self) -> ErrorClass {
        ErrorClass::InvalidInput
    }
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

/// Whether every value is finite: one test of all of them, without the early exit that keeps a
/// search from vectorising (for a kernel's hot path; [`first_non_finite`] names the entry).
///
/// ```
/// assert!(lane_math::all_finite(&[1.0, -2.0]) && !lane_math::all_finite(&[1.0, f64::NAN]));
/// ```
#[inline(always)]
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |finite, v| finite & v.is_finite())
}

/// Checks that the field `name` has `expected` entries: it has `found`.
#[inline]
pub fn check_len(name: &str, found: usize, expected: usize) -> Result<(), ShapeError<'_>> {
    if found == expected {
        Ok(())
    } else {
        Err(ShapeError {
            name,
            problem: ShapeProblem::Length { expected, found },
        })
    }
}

/// Checks that the single number `value` of the field `name` is finite.
///
/// ```
/// assert_eq!(lane_math::check_finite("alpha0", 0.5), Ok(()));
/// let error = lane_math::check_finite("alpha0", f64::INFINITY).unwrap_err();
/// assert_eq!(error.to_string(), "alpha0 must be finite, got inf");
/// ```
pub fn check_finite(name: &str, value: f64) -> Result<(), ShapeError<'_>> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ShapeError {
            name,
            problem: ShapeProblem::NonFinite { index: None, value },
        })
    }
}

/// Checks that every entry of the field `name` is finite; the error names the first that is not.
#[inline]
pub fn check_all_finite<'a>(name: &'a str, values: &[f64]) -> Result<(), ShapeError<'a>> {
    if all_finite(values) {
        return Ok(());
    }
    match first_non_finite(values) {
        None => Ok(()),
        Some((index, value)) => Err(ShapeError {
            name,
            problem: ShapeProblem::NonFinite {
                index: Some(index),
                value,
            },
        }),
    }
}

/// Checks that the field `name` has `expected` entries (checked first), all finite.
///
/// ```
/// use lane_math::{ShapeProblem, check_values};
/// assert_eq!(check_values("q", &[1.0, 2.0], 2), Ok(()));
/// let error = check_values("q", &[1.0], 2).unwrap_err();
/// assert_eq!(error.problem, ShapeProblem::Length { expected: 2, found: 1 });
/// ```
#[inline]
pub fn check_values<'a>(
    name: &'a str,
    values: &[f64],
    expected: usize,
) -> Result<(), ShapeError<'a>> {
    check_len(name, values.len(), expected)?;
    check_all_finite(name, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_length_is_checked_before_the_values() {
        assert_eq!(
            check_values("q", &[f64::NAN], 2),
            Err(ShapeError {
                name: "q",
                problem: ShapeProblem::Length {
                    expected: 2,
                    found: 1
                }
            })
        );
        assert_eq!(check_values("q", &[], 0), Ok(()));
    }

    #[test]
    fn the_first_non_finite_entry_is_found_whatever_its_kind() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let values = [0.0, f64::MAX, bad, f64::NAN];
            let (index, value) = first_non_finite(&values).unwrap();
            assert_eq!(index, 2);
            assert_eq!(value.to_bits(), bad.to_bits());
            let error = check_all_finite("v", &values).unwrap_err();
            assert_eq!(error.to_string(), format!("v[2] must be finite, got {bad}"));
            let error = check_finite("x", bad).unwrap_err();
            assert_eq!(error.to_string(), format!("x must be finite, got {bad}"));
        }
        assert_eq!(first_non_finite(&[f64::MIN_POSITIVE, -f64::MAX]), None);
        assert_eq!(
            check_all_finite("v", &[f64::MIN_POSITIVE, -f64::MAX]),
            Ok(())
        );
        assert_eq!(check_finite("x", -f64::MAX), Ok(()));
    }

    #[test]
    fn a_shape_error_is_invalid_input() {
        assert!(check_len("q", 1, 2).unwrap_err().is_invalid_input());
        assert_eq!(
            check_len("q", 1, 2).unwrap_err().to_string(),
            "q has 1 entries, expected 2"
        );
    }
}
