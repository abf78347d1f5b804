//! The slice of a sweep's runs one shard takes (`K/N`, round robin), and the format tag and
//! bounds of the file a shard is written to.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Most shards a sweep splits into (one run each at most, so no more than
/// [`MAX_RUNS`](super::MAX_RUNS)).
pub const MAX_SHARDS: usize = 10_000_000;

/// The `format` tag of a shard file.
pub const FORMAT: &str = "hrm-sweep-shard/4";

/// Longest line of a shard file read (64 MiB: the header holds the scenario, whose file has at
/// most 16 MiB; a run's line has a few hundred bytes).
pub const MAX_SHARD_LINE_BYTES: usize = 64 << 20;

/// Largest metric a shard file may hold: ten million runs of it still sum to a finite mean.
pub const MAX_SHARD_METRIC: f64 = 1e300;

/// Shard `index` of `count` (1-based, written `K/N`): the runs whose index `i` has
/// `i % N == K - 1`. Round robin spreads every cell's costly and cheap runs over all shards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shard {
    /// `K`, from 1 to `count`.
    pub index: usize,
    /// `N`, the number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole sweep as one shard.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Whether run `i` belongs to this shard.
    pub fn contains(self, i: usize) -> bool {
        i % self.count == self.index - 1
    }

    /// The number of runs of this shard among `runs`.
    pub fn run_count(self, runs: usize) -> usize {
        if runs < self.index {
            0
        } else {
            (runs - self.index) / self.count + 1
        }
    }

    /// The run indices of this shard among `runs`, ascending.
    pub fn indices(self, runs: usize) -> impl Iterator<Item = usize> {
        (self.index - 1..runs).step_by(self.count)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// A shard's index or count out of `1 <= index <= count <= MAX_SHARDS`, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ShardRangeError {
    /// A count of 0 or beyond [`MAX_SHARDS`].
    #[error("count must be from 1 to {MAX_SHARDS}, got {0}")]
    Count(usize),
    /// An index of 0 or beyond the count.
    #[error("index must be from 1 to count ({count}), got {index}")]
    Index {
        /// The index given.
        index: usize,
        /// The count given.
        count: usize,
    },
}

impl Shard {
    /// Shard `index` of `count`, checked: `1 <= index <= count <= MAX_SHARDS`.
    pub fn new(index: usize, count: usize) -> Result<Self, ShardRangeError> {
        if !(1..=MAX_SHARDS).contains(&count) {
            return Err(ShardRangeError::Count(count));
        }
        if !(1..=count).contains(&index) {
            return Err(ShardRangeError::Index { index, count });
        }
        Ok(Shard { index, count })
    }
}

/// A shard written otherwise than `K/N` with `1 <= K <= N <= MAX_SHARDS`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("a shard is written K/N with 1 <= K <= N <= {MAX_SHARDS}, got '{text}'")]
pub struct ShardParseError {
    /// The text given.
    pub text: String,
}

impl FromStr for Shard {
    type Err = ShardParseError;

    /// Parses `K/N` with `1 <= K <= N <= MAX_SHARDS`.
    fn from_str(s: &str) -> Result<Self, ShardParseError> {
        let bad = || ShardParseError {
            text: s.to_string(),
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        Shard::new(index, count).map_err(|_| bad())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn shards_parse_and_refuse_bad_text() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2"] {
            assert!(
                bad.parse::<Shard>()
                    .unwrap_err()
                    .to_string()
                    .contains("K/N"),
                "{bad}"
            );
        }
        assert_eq!(Shard { index: 2, count: 3 }.to_string(), "2/3");
        // Checked from numbers, the one at fault named.
        assert_eq!(Shard::new(2, 3), Ok(Shard { index: 2, count: 3 }));
        for (index, count, message) in [
            (0, 2, "index must be from 1 to count (2), got 0"),
            (3, 2, "index must be from 1 to count (2), got 3"),
            (1, 0, "count must be from 1 to 10000000, got 0"),
            (
                1,
                MAX_SHARDS + 1,
                "count must be from 1 to 10000000, got 10000001",
            ),
        ] {
            assert_eq!(Shard::new(index, count).unwrap_err().to_string(), message);
        }
    }

    proptest! {
        #[test]
        fn shards_partition_the_runs(runs in 0usize..200, count in 1usize..12) {
            let mut seen = vec![0u32; runs];
            for index in 1..=count {
                let shard = Shard { index, count };
                prop_assert_eq!(shard.run_count(runs), shard.indices(runs).count());
                for i in shard.indices(runs) {
                    prop_assert!(shard.contains(i));
                    seen[i] += 1;
                }
            }
            prop_assert!(seen.iter().all(|&n| n == 1));
        }
    }
}
