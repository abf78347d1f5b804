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

/// Characters kept from the end of a cut message: what a message says last (serde's
/// "expected one of ..." after a 100 kB field name) survives the cut.
const KEPT_TAIL_CHARS: usize = 400;

/// `message` as one line a person reads: control and bidirectional characters escaped
/// ([`escape_controls`]), very long numbers in exponent form ([`compact_numbers`]), and at most
/// 2,000 characters: a longer one keeps its start and its last 400 characters around the count
/// of what was left out.
pub fn one_line(message: &str) -> String {
    let compact = compact_numbers(&escape_controls(message, &[]));
    let total = compact.chars().count();
    if total <= MAX_MESSAGE_CHARS {
        return compact;
    }
    let marker = |left_out: usize| format!(" ... ({left_out} characters left out) ... ");
    // The marker's length for the largest count it can show.
    let head = MAX_MESSAGE_CHARS - KEPT_TAIL_CHARS - marker(total).chars().count();
    let left_out = total - head - KEPT_TAIL_CHARS;
    let at = |chars: usize| {
        compact
            .char_indices()
            .nth(chars)
            .map_or(compact.len(), |(i, _)| i)
    };
    format!(
        "{}{}{}",
        &compact[..at(head)],
        marker(left_out),
        &compact[at(total - KEPT_TAIL_CHARS)..]
    )
}

/// Whether `text` could be a message [`one_line`] gave: no control or bidirectional formatting
/// character, and no longer than a cut message (what a file that claims to hold such a message
/// must meet before it is shown).
pub fn is_one_line(text: &str) -> bool {
    // With room for the marker of an earlier version's cut (" ... (N more characters)" after
    // the first 2,000), as shard files written before keep.
    const EARLIER_CUT_CHARS: usize = 64;
    text.chars().count() <= MAX_MESSAGE_CHARS + EARLIER_CUT_CHARS
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
        // A cut message is at most 2,000 characters and keeps both ends.
        let long = format!(
            "unknown field `{}`, expected `arm` or `format`",
            "é".repeat(100_000)
        );
        let cut = one_line(&long);
        assert!(cut.chars().count() <= MAX_MESSAGE_CHARS);
        assert!(cut.starts_with("unknown field `éé"), "{cut}");
        assert!(cut.ends_with("éé`, expected `arm` or `format`"), "{cut}");
        assert!(cut.contains(" characters left out) ... "), "{cut}");
        assert_eq!(one_line(&"x".repeat(2000)), "x".repeat(2000));
        assert!(!is_one_line("a\nb"));
        assert!(!is_one_line("a\u{202e}b"));
        assert!(!is_one_line(&"x".repeat(3000)));
    }

    #[test]
    fn long_messages_are_cut() {
        let list = vec!["0.5"; 100_000].join(", ");
        let line = one_line(&format!("noise levels [{list}] differ"));
        assert!(line.chars().count() <= 2000, "{}", line.len());
        assert!(line.starts_with("noise levels [0.5, 0.5"), "{line}");
        assert!(line.contains(" characters left out) ... "), "{line}");
        assert!(line.ends_with("0.5, 0.5] differ"), "{line}");
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
