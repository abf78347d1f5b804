//! Table-driven refusal tests: each row is a call on bad input, the error it returned, the error
//! expected (a pattern, as a predicate) and what the message must say. A crate's `bad_input`
//! module builds its rows and hands them to [`check`]; rows named after a `docs/bad-input.md`
//! row carry that row's test name.

use std::fmt::{Debug, Display};

/// What a refusal's message must say.
#[derive(Debug, Clone, Copy)]
pub enum Says {
    /// Exactly this line.
    Exactly(&'static str),
    /// A line starting with this.
    Starts(&'static str),
    /// These words, in any order (nothing beyond one line if empty).
    Words(&'static [&'static str]),
}

/// One refusal: its name, the error the call returned, the error expected and what its message
/// says.
pub struct Row<E> {
    /// The row's name: the test named in `docs/bad-input.md`, or what the row checks.
    pub name: &'static str,
    /// The error the call returned.
    pub error: E,
    /// Whether `error` is the one expected (usually a `matches!` pattern or an equality).
    pub expected: fn(&E) -> bool,
    /// What the message must say.
    pub says: Says,
}

/// A row whose message is checked only to be one line.
pub fn row<E>(name: &'static str, error: E, expected: fn(&E) -> bool) -> Row<E> {
    Row {
        name,
        error,
        expected,
        says: Says::Words(&[]),
    }
}

/// A row whose message contains `words`.
pub fn words<E>(
    name: &'static str,
    error: E,
    expected: fn(&E) -> bool,
    words: &'static [&'static str],
) -> Row<E> {
    Row {
        says: Says::Words(words),
        ..row(name, error, expected)
    }
}

/// A row whose message is exactly `line`.
pub fn exactly<E>(
    name: &'static str,
    error: E,
    expected: fn(&E) -> bool,
    line: &'static str,
) -> Row<E> {
    Row {
        says: Says::Exactly(line),
        ..row(name, error, expected)
    }
}

/// A row whose message starts with `start`.
pub fn starts<E>(
    name: &'static str,
    error: E,
    expected: fn(&E) -> bool,
    start: &'static str,
) -> Row<E> {
    Row {
        says: Says::Starts(start),
        ..row(name, error, expected)
    }
}

/// The error of `call` on `output`, which must be refused and leave `output` as it was (fill it
/// with a value no function writes, such as [`SENTINEL`]).
pub fn untouched<T: Clone + PartialEq + Debug, R: Debug, E: Debug>(
    mut output: T,
    call: impl FnOnce(&mut T) -> Result<R, E>,
) -> E {
    let before = output.clone();
    let error = call(&mut output).unwrap_err();
    assert_eq!(output, before, "{error:?}: the output was written");
    error
}

/// A value no function under test writes: an output still holding it was left untouched.
pub const SENTINEL: f64 = -12345.0;

/// The most digits a number in a message may have: the 17 significant digits of an `f64` and
/// the zeros of a plain decimal down to `1e-4` (`lane_math::Compact`); a count or an index has
/// fewer.
const MAX_MESSAGE_DIGITS: usize = 24;

/// The length of the longest run of digits and decimal points in `text`.
fn longest_digit_run(text: &str) -> usize {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .map(|run| run.bytes().filter(u8::is_ascii_digit).count())
        .max()
        .unwrap_or(0)
}

/// Checks every row: the error is the one expected, and its message is one line, with its
/// numbers written compactly (no number of more than 24 digits), that says what the row asks. Panics naming the first row that fails.
pub fn check<E: Debug + Display>(rows: &[Row<E>]) {
    for Row {
        name,
        error,
        expected,
        says,
    } in rows
    {
        assert!(expected(error), "{name}: unexpected {error:?}");
        let message = error.to_string();
        assert!(
            !message.contains('\n'),
            "{name}: {message:?} is not one line"
        );
        assert!(
            longest_digit_run(&message) <= MAX_MESSAGE_DIGITS,
            "{name}: {message:?} writes a number in full (lane_math::Compact writes it compactly)"
        );
        match *says {
            Says::Exactly(line) => assert_eq!(message, line, "{name}"),
            Says::Starts(start) => assert!(message.starts_with(start), "{name}: {message:?}"),
            Says::Words(words) => {
                for word in words {
                    assert!(message.contains(word), "{name}: {message:?} lacks {word:?}");
                }
            }
        }
    }
}
