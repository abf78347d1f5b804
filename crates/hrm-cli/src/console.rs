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
/// very long numbers in exponent form ([`lane_math::compact_numbers`]).
pub fn error_line(message: &str) -> String {
    format!(
        "hrm: {}",
        lane_math::compact_numbers(&escape_controls(message, &[]))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn error_lines_write_long_numbers_with_exponents() {
        let message = format!("weight must lie in [0, 1], got {}", -1.7e308);
        assert_eq!(
            error_line(&message),
            "hrm: weight must lie in [0, 1], got -1.7e308"
        );
    }
}
