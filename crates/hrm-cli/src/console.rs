//! What `hrm` prints: text on standard output that ends quietly when the reader goes away
//! (`hrm ... | head`), and error lines with the control characters of untrusted text escaped
//! and very long numbers written with exponents.

use std::io::Write;

/// Writes `text` to standard output, with the control characters other than newline and tab
/// escaped. A reader that has gone away (a broken pipe) is not an error: the rest of the
/// output is dropped and the command goes on.
pub fn print(text: &str) -> Result<(), String> {
    let mut out = std::io::stdout().lock();
    match out
        .write_all(escape_controls(text, &['\n', '\t']).as_bytes())
        .and_then(|()| out.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// `text` with every control character except those in `keep`, and every bidirectional
/// formatting character (U+202E reverses the text after it), written as a Rust escape (`\n`,
/// `\u{1b}`, `\u{202e}`), so that a message quoting a file cannot move the cursor, recolour
/// the terminal, break into several lines or read backwards.
pub fn escape_controls(text: &str, keep: &[char]) -> String {
    let mut escaped = String::with_capacity(text.len());
    for c in text.chars() {
        if (c.is_control() || is_bidi_control(c)) && !keep.contains(&c) {
            escaped.extend(c.escape_default());
        } else {
            escaped.push(c);
        }
    }
    escaped
}

/// Whether `c` is a bidirectional formatting character of Unicode (UAX #9): the marks, the
/// embeddings and overrides, the isolates.
fn is_bidi_control(c: char) -> bool {
    matches!(
        c,
        '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}'
    )
}

/// Escapes the characters of a user's text (a scenario name, a CSV header) that would break a
/// table row or reorder it: newline and tab too, besides what [`escape_controls`] escapes.
pub fn escape_field(text: &str) -> String {
    escape_controls(text, &[])
}

/// The one line `hrm` writes to standard error for a failure: control characters escaped and
/// very long numbers in exponent form.
pub fn error_line(message: &str) -> String {
    format!("hrm: {}", readable_numbers(&escape_controls(message, &[])))
}

/// Digits beyond which a number is written with an exponent: more than any integer option
/// (`u128::MAX` has 39 digits), so exact integers such as seeds are kept as they are.
const MAX_DIGITS: usize = 39;

/// `text` with every decimal number of more than [`MAX_DIGITS`] digits (a value near `1e300`
/// or `1e-300` written out by `{}`, as some library messages do) in exponent form: `1e300`,
/// `1.7e308`, `1e-300`.
pub fn readable_numbers(text: &str) -> String {
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

/// A number as written to a CSV field: Rust's shortest round-trip form, in exponent form when
/// the plain decimal would be longer than [`CsvNumber::MAX_PLAIN`] characters (`1e308`, not 309
/// digits; `1e-300`, not 302). Both forms read back to the same `f64`.
#[derive(Debug, Clone, Copy)]
pub struct CsvNumber(pub f64);

impl CsvNumber {
    /// The longest plain decimal written as it is.
    const MAX_PLAIN: usize = 24;
}

impl std::fmt::Display for CsvNumber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plain = self.0.to_string();
        if plain.len() > Self::MAX_PLAIN {
            write!(f, "{:e}", self.0)
        } else {
            f.write_str(&plain)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_numbers_near_the_float_limits_are_short_and_round_trip() {
        for value in [
            1e308,
            -1.7976931348623157e308,
            1e-300,
            5e-324,
            0.1,
            -250.0,
            0.0,
        ] {
            let text = CsvNumber(value).to_string();
            assert!(text.len() < 40, "{text}");
            assert_eq!(text.parse::<f64>().unwrap(), value);
        }
        assert_eq!(CsvNumber(1e308).to_string(), "1e308");
        assert_eq!(CsvNumber(0.001).to_string(), "0.001");
    }

    #[test]
    fn control_characters_are_escaped_and_text_kept() {
        assert_eq!(
            error_line("line 2: found `\u{1b}[31mred\r\nx` in é"),
            "hrm: line 2: found `\\u{1b}[31mred\\r\\nx` in é"
        );
        assert_eq!(
            escape_controls("a\tb\nc\u{7}", &['\n', '\t']),
            "a\tb\nc\\u{7}"
        );
    }

    #[test]
    fn bidirectional_overrides_are_escaped() {
        assert_eq!(
            error_line("scenario \u{202e}gnirts\u{2066}x\u{200f}"),
            "hrm: scenario \\u{202e}gnirts\\u{2066}x\\u{200f}"
        );
        assert_eq!(escape_field("name\nwith\tbreaks"), "name\\nwith\\tbreaks");
    }

    #[test]
    fn numbers_of_hundreds_of_digits_get_exponents() {
        let (huge, tiny) = (format!("{}", -1.7e308), format!("{}", 1e-300));
        assert!(huge.len() > 300 && tiny.len() > 300);
        assert_eq!(
            error_line(&format!(
                "weight must lie in [0, 1], got {huge}; bound {tiny}."
            )),
            "hrm: weight must lie in [0, 1], got -1.7e308; bound 1e-300."
        );
        // Integers up to 39 digits (seeds, counts) and ordinary decimals stay as written.
        let text = "seed 340282366920938463463374607431768211455, t = 0.25 s, v1.2.3.";
        assert_eq!(readable_numbers(text), text);
    }
}
