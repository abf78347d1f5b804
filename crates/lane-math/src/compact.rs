//! Numbers in messages and text files written compactly: plain decimals for ordinary
//! magnitudes, exponent form for tiny and huge ones (`1e-300`, not 302 characters), always
//! Rust's shortest form that reads back to the same `f64`. Every crate's messages print their
//! numbers through [`Compact`]; [`compact_numbers`] rewrites a message built elsewhere.

use std::fmt;

/// A number written compactly: plain (`0.25`, `-250`, `0.001`) when its magnitude lies in
/// `[1e-4, 1e15)`, `0`, `inf` and `NaN` as they are, otherwise in exponent form (`1e-300`,
/// `-1.7976931348623157e308`, `5e-5`). Both forms are the shortest that read back to the same
/// `f64`, so a CSV field written this way loses nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compact(pub f64);

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let magnitude = self.0.abs();
        if self.0 == 0.0 || !self.0.is_finite() || (1e-4..1e15).contains(&magnitude) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// Digits beyond which [`compact_numbers`] writes a number with an exponent: more than any
/// integer a message holds (`u128::MAX` has 39 digits), so exact integers such as seeds are
/// kept as they are.
const MAX_DIGITS: usize = 39;

/// `text` with every decimal number of more than 39 digits (a value near `1e300` or `1e-300`
/// written out by `{}`) in exponent form: `1e300`, `-1.7e308`, `1e-300`. For messages that
/// come from outside (a wrapped error, a front end's own text) before they are shown.
pub fn compact_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let mut dot = false;
        let end = rest
            .char_indices()
            .find(|&(_, c)| {
                let part = c.is_ascii_digit() || (c == '.' && !dot);
                dot |= c == '.';
                !part
            })
            .map_or(rest.len(), |(i, _)| i);
        let number = rest[..end].trim_end_matches('.');
        let digits = number.bytes().filter(u8::is_ascii_digit).count();
        match number.parse::<f64>() {
            Ok(value) if digits > MAX_DIGITS => out.push_str(&format!("{value:e}")),
            _ => out.push_str(number),
        }
        rest = &rest[number.len()..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn numbers_are_compact() {
        for (x, text) in [
            (0.0, "0"),
            (-0.5, "-0.5"),
            (0.001, "0.001"),
            (1e-4, "0.0001"),
            (5e-5, "5e-5"),
            (250.0, "250"),
            (1e-300, "1e-300"),
            (-1e300, "-1e300"),
            (f64::MAX, "1.7976931348623157e308"),
            (5e-324, "5e-324"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(Compact(x).to_string(), text);
        }
    }

    #[test]
    fn numbers_of_hundreds_of_digits_in_a_text_get_exponents() {
        let (huge, tiny) = (format!("{}", -1.7e308), format!("{}", 1e-300));
        assert!(huge.len() > 300 && tiny.len() > 300);
        assert_eq!(
            compact_numbers(&format!(
                "weight must lie in [0, 1], got {huge}; bound {tiny}."
            )),
            "weight must lie in [0, 1], got -1.7e308; bound 1e-300."
        );
        // Integers up to 39 digits (seeds, counts) and ordinary decimals stay as written.
        let text = "seed 340282366920938463463374607431768211455, t = 0.25 s, v1.2.3.";
        assert_eq!(compact_numbers(text), text);
    }

    proptest! {
        #[test]
        fn every_number_reads_back_exactly_in_at_most_24_characters(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            let text = Compact(x).to_string();
            prop_assert!(text.len() <= 24, "{}", text);
            if x.is_nan() {
                prop_assert_eq!(text, "NaN");
            } else {
                prop_assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits());
            }
        }
    }
}
