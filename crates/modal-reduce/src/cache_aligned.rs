//! Per-link buffers that start on a cache line, so that a register of eight lanes (AVX-512) is
//! read and written as one line rather than split across two (which costs a split load or
//! store each time: about a tenth of a batch's time when they were unaligned).

use lane_math::{OutOfMemory, try_filled};

/// The bytes of a cache line, and of an AVX-512 register.
const LINE: usize = 64;

/// `len` values starting on a 64-byte boundary, inside a vector with the room to find one.
/// Correct at any alignment; the alignment is for speed only.
#[derive(Debug)]
pub(crate) struct CacheAligned {
    values: Vec<f64>,
    len: usize,
}

impl CacheAligned {
    /// `len` zeros.
    ///
    /// # Panics
    /// When the system refuses the memory; [`CacheAligned::try_zeros`] returns the error.
    pub(crate) fn zeros(len: usize) -> Self {
        Self::try_zeros(len, "a per-link buffer").unwrap_or_else(|e| panic!("{e}"))
    }

    /// `len` zeros, or [`OutOfMemory`] naming `what` when the system refuses the memory.
    pub(crate) fn try_zeros(len: usize, what: &'static str) -> Result<Self, OutOfMemory> {
        let room = LINE / size_of::<f64>() - 1;
        Ok(Self {
            values: try_filled(len.saturating_add(room), 0.0, what)?,
            len,
        })
    }

    /// Where the aligned values start in `values` (recomputed on each access: a clone's
    /// allocation has its own).
    fn offset(&self) -> usize {
        let room = self.values.len() - self.len;
        self.values.as_ptr().align_offset(LINE).min(room)
    }

    /// The values.
    pub(crate) fn get(&self) -> &[f64] {
        let offset = self.offset();
        &self.values[offset..offset + self.len]
    }

    /// The values, to write.
    pub(crate) fn get_mut(&mut self) -> &mut [f64] {
        let offset = self.offset();
        &mut self.values[offset..offset + self.len]
    }
}

impl Clone for CacheAligned {
    /// The same values, on a cache line of the new allocation.
    fn clone(&self) -> Self {
        let mut copy = Self::zeros(self.len);
        copy.get_mut().copy_from_slice(self.get());
        copy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_start_on_a_cache_line_and_keep_their_length_when_cloned() {
        for len in [0, 1, 7, 8, 80, 1001] {
            let mut buffer = CacheAligned::zeros(len);
            buffer
                .get_mut()
                .iter_mut()
                .enumerate()
                .for_each(|(i, x)| *x = i as f64);
            let copy = buffer.clone();
            for values in [buffer.get(), copy.get()] {
                assert_eq!(values.len(), len);
                assert_eq!(values.as_ptr() as usize % LINE, 0, "len {len}");
                assert!(values.iter().enumerate().all(|(i, &x)| x == i as f64));
            }
        }
    }
}
