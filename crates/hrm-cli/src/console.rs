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
/// the message [`shown`].
pub fn error_line(message: &str) -> String {
    format!("hrm: {}", shown(&escape_controls(message, &[])))
}

/// Characters of a message shown whole: an error quoting a user's list (a shard header's
/// 100,000 noise levels) is cut after them.
const MAX_MESSAGE_CHARS: usize = 2000;

/// A failure's message as `hrm` shows it (on standard error and in `hrm eval`'s answers): very
/// long numbers in exponent form ([`lane_math::compact_numbers`]) and at most
/// [`MAX_MESSAGE_CHARS`] characters, a longer one cut with the count of what was left out.
pub fn shown(message: &str) -> String {
    let compact = lane_math::compact_numbers(message);
    match compact.char_indices().nth(MAX_MESSAGE_CHARS) {
        None => compact,
        Some((cut, _)) => format!(
            "{} ... ({} more characters)",
            &compact[..cut],
            compact[cut..].chars().count()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_messages_are_cut() {
        let list = vec!["0.5"; 100_000].join(", ");
        let line = error_line(&format!("noise levels [{list}] differ"));
        assert!(line.len() < 2100, "{}", line.len());
        assert!(line.ends_with(" ... (498020 more characters)"), "{line}");
        assert_eq!(shown("short"), "short");
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
    fn error_lines_write_long_numbers_with_exponents() {
        let message = format!("weight must lie in [0, 1], got {}", -1.7e308);
        assert_eq!(
            error_line(&message),
            "hrm: weight must lie in [0, 1], got -1.7e308"
        );
    }
}
