//! Messages as a person reads them: one line (control and bidirectional formatting characters
//! escaped), long numbers with exponents ([`compact_numbers`]), at most a few thousand
//! characters. The CLI's error lines and answers and the Python package's exceptions show
//! every message this way.

use crate::compact_numbers;

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

/// Characters of a message shown whole: an error quoting a user's list (a shard header's
/// 100,000 noise levels) is cut after them.
const MAX_MESSAGE_CHARS: usize = 2000;

/// `message` as one line a person reads: control and bidirectional characters escaped
/// ([`escape_controls`]), very long numbers in exponent form ([`compact_numbers`]), and at most
/// 2,000 characters, a longer one cut with the count of what was left out.
pub fn one_line(message: &str) -> String {
    let compact = compact_numbers(&escape_controls(message, &[]));
    match compact.char_indices().nth(MAX_MESSAGE_CHARS) {
        None => compact,
        Some((cut, _)) => format!(
            "{} ... ({} more characters)",
            &compact[..cut],
            compact[cut..].chars().count()
        ),
    }
}

/// Whether `text` could be a message [`one_line`] gave: no control or bidirectional formatting
/// character, and no longer than a cut message (what a file that claims to hold such a message
/// must meet before it is shown).
pub fn is_one_line(text: &str) -> bool {
    // A cut message: the kept characters, then " ... (N more characters)".
    const CUT_SUFFIX_CHARS: usize = 64;
    text.chars().count() <= MAX_MESSAGE_CHARS + CUT_SUFFIX_CHARS
        && !text.chars().any(|c| c.is_control() || is_bidi_control(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_gives_one_line_messages() {
        for text in [
            "short",
            "a\nb\u{1b}[31m\u{202e}",
            &"9".repeat(5000),
            &"x".repeat(10_000),
        ] {
            assert!(is_one_line(&one_line(text)), "{text}");
        }
        assert!(!is_one_line("a\nb"));
        assert!(!is_one_line("a\u{202e}b"));
        assert!(!is_one_line(&"x".repeat(3000)));
    }

    #[test]
    fn long_messages_are_cut() {
        let list = vec!["0.5"; 100_000].join(", ");
        let line = one_line(&format!("noise levels [{list}] differ"));
        assert!(line.len() < 2100, "{}", line.len());
        assert!(line.ends_with(" ... (498020 more characters)"), "{line}");
        assert_eq!(one_line("short"), "short");
    }

    #[test]
    fn control_characters_are_escaped_and_text_kept() {
        assert_eq!(
            escape_controls("a\tb\nc\u{7}", &['\n', '\t']),
            "a\tb\nc\\u{7}"
        );
        assert_eq!(one_line("x\u{0}y\nz"), "x\\u{0}y\\nz");
    }
}
