//! Buffers sized by the user, allocated so that a refusal by the system is an error
//! ([`OutOfMemory`], class [`ErrorClass::OutOfMemory`]) rather than an abort of the process.

use crate::{Classify, ErrorClass};

/// The system refused the memory of a buffer: `what` and its size in bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutOfMemory {
    /// The buffer (e.g. `"the workspace of the recursive algorithms"`).
    pub what: &'static str,
    /// Its size in bytes.
    pub bytes: usize,
}

impl std::fmt::Display for OutOfMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: the system refused {} bytes ({} MiB)",
            self.what,
            self.bytes,
            self.bytes >> 20
        )
    }
}

impl std::error::Error for OutOfMemory {}

impl Classify for OutOfMemory {
    /// Always [`OutOfMemory`](ErrorClass::OutOfMemory).
    fn class(&self) -> ErrorClass {
        ErrorClass::OutOfMemory
    }
}

/// `len` copies of `value`, or [`OutOfMemory`] naming `what` when the system refuses the
/// memory (or its size overflows `usize`).
///
/// ```
/// let zeros = lane_math::try_filled(3, 0.0, "x")?;
/// assert_eq!(zeros, [0.0; 3]);
/// let refused = lane_math::try_filled(usize::MAX / 8, 0.0, "the record").unwrap_err();
/// assert!(refused.to_string().starts_with("the record: the system refused"));
/// # Ok::<(), lane_math::OutOfMemory>(())
/// ```
pub fn try_filled<T: Clone>(
    len: usize,
    value: T,
    what: &'static str,
) -> Result<Vec<T>, OutOfMemory> {
    let mut values = try_with_capacity(len, what)?;
    values.resize(len, value);
    Ok(values)
}

/// A copy of `values`, or [`OutOfMemory`] naming `what` when the system refuses the memory.
///
/// ```
/// assert_eq!(lane_math::try_copied(&[1.0, 2.0], "x")?, [1.0, 2.0]);
/// # Ok::<(), lane_math::OutOfMemory>(())
/// ```
pub fn try_copied<T: Clone>(values: &[T], what: &'static str) -> Result<Vec<T>, OutOfMemory> {
    let mut copy = try_with_capacity(values.len(), what)?;
    copy.extend_from_slice(values);
    Ok(copy)
}

/// An empty vector with room for exactly `capacity` values, or [`OutOfMemory`] naming `what`.
pub fn try_with_capacity<T>(capacity: usize, what: &'static str) -> Result<Vec<T>, OutOfMemory> {
    let mut values = Vec::new();
    try_reserve(&mut values, capacity, what)?;
    Ok(values)
}

/// Room for exactly `additional` more values in `values`, or [`OutOfMemory`] naming `what`.
pub fn try_reserve<T>(
    values: &mut Vec<T>,
    additional: usize,
    what: &'static str,
) -> Result<(), OutOfMemory> {
    values
        .try_reserve_exact(additional)
        .map_err(|_| OutOfMemory {
            what,
            bytes: additional.saturating_mul(size_of::<T>()),
        })
}
