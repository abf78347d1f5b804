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
        .write_all(lane_math::escape_controls(text, &['\n', '\t']).as_bytes())
        .and_then(|()| out.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// Writes `line` and a newline to standard error. A standard error that cannot be written
/// (closed by the reader, `2>/dev/full`) drops the line rather than stop the command: a warning
/// is not worth a crash, and a failure's exit status still tells.
pub fn to_stderr(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Escapes the characters of a user's text (a scenario name, a CSV header) that would break a
/// table row or reorder it: newline and tab too, besides what [`lane_math::escape_controls`] escapes.
pub fn escape_field(text: &str) -> String {
    lane_math::escape_controls(text, &[])
}

/// A path as the reports name it: on one line, its control characters escaped as in
/// [`escape_field`] (`--out $'a\nb'` is shown `a\nb`).
pub fn shown(path: &std::path::Path) -> String {
    escape_field(&path.display().to_string())
}

/// The one line `hrm` writes to standard error for a failure: the message as
/// [`lane_math::one_line`] shows it (control characters escaped, long numbers with exponents,
/// cut to 2,000 characters).
pub fn error_line(message: &str) -> String {
    format!("hrm: {}", lane_math::one_line(message))
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
    }

    #[test]
    fn bidirectional_overrides_are_escaped() {
        assert_eq!(
            error_line("scenario \u{202e}gnirts\u{2066}x\u{200f}"),
            "hrm: scenario \\u{202e}gnirts\\u{2066}x\\u{200f}"
        );
        assert_eq!(escape_field("name\nwith\tbreaks"), "name\\nwith\\tbreaks");
        // The paths of the `wrote` lines likewise (`--out $'mm\nx'`).
        assert_eq!(shown(std::path::Path::new("mm\nx")), "mm\\nx");
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
