//! Mean and spread of the runs' errors per (noise level, controller) cell, computed in index
//! order so that a merged sweep gives bit for bit the numbers of an unsharded one. The runs of
//! a cell are consecutive in that order, so the cells are built from a stream of runs holding
//! only the current cell's values.

use super::outcome::RunMetrics;
use super::plan::SweepConfig;
use super::shard_file::{RunResult, StoredOutcome};
use crate::ControllerKind;
use serde::Serialize;

/// Mean, sample standard deviation (`n - 1`; 0 for one value), minimum, median and maximum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Median (the mean of the two middle values for an even count).
    pub median: f64,
    /// Largest value.
    pub max: f64,
}

impl Stats {
    /// The statistics of `values` (summed in the given order), `None` for no values.
    pub fn of(values: &[f64]) -> Option<Stats> {
        let n = values.len();
        if n == 0 {
            return None;
        }
        // Deviations from the first value: exact zeros (so std 0, mean exact) for equal values,
        // and no cancellation when the spread is small against the values.
        let shift = values[0];
        // Deviations whose squares or sums could overflow (beyond 1e150) are divided by a power
        // of two, exactly: finite values of one sign always give finite statistics, and
        // ordinary values (scale 1) give the same bits as without scaling.
        let spread = values.iter().fold(0.0f64, |s, v| s.max((v - shift).abs()));
        let scale = if spread > 1e150 && spread.is_finite() {
            // The largest power of two not above the spread: its exponent bits alone.
            f64::from_bits(spread.to_bits() & 0x7FF0_0000_0000_0000)
        } else {
            1.0
        };
        let dev = |v: &f64| (v - shift) / scale;
        let mean_dev = values.iter().map(dev).sum::<f64>() / n as f64;
        let mean = shift + scale * mean_dev;
        let std = if n > 1 {
            let ss: f64 = values
                .iter()
                .map(|v| (dev(v) - mean_dev) * (dev(v) - mean_dev))
                .sum();
            scale * (ss / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let median = if n % 2 == 1 {
            sorted[n / 2]
        } else {
            // Halving is exact: the same bits as 0.5 (a + b), without its overflow.
            0.5 * sorted[n / 2 - 1] + 0.5 * sorted[n / 2]
        };
        Some(Stats {
            mean,
            std,
            min: sorted[0],
            median,
            max: sorted[n - 1],
        })
    }
}

/// A run that stopped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailedRun {
    /// Its index.
    pub index: usize,
    /// Its seed.
    pub seed: u64,
    /// Why and when it stopped.
    pub error: String,
}

/// The runs of one noise level and controller. The statistics are over the completed runs and
/// absent when none completed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// Noise level (rad).
    pub noise_level: f64,
    /// Controller.
    pub controller: ControllerKind,
    /// Runs in the cell.
    pub runs: usize,
    /// Runs that stopped before the end.
    pub failed: usize,
    /// Tip error RMS (mm).
    pub tip_error_rms_mm: Option<Stats>,
    /// Largest tip error (mm).
    pub tip_error_max_mm: Option<Stats>,
    /// Modal error RMS of each coordinate (rad), in the order of the scenario's coordinates
    /// ([`Scenario::coordinate_names`](crate::Scenario::coordinate_names)).
    pub modal_error_rms_rad: Vec<Option<Stats>>,
    /// Largest joint torque (N m).
    pub peak_joint_torque_nm: Option<Stats>,
    /// The failed runs, by index: the first [`MAX_LISTED_FAILURES`] (`failed` counts them all;
    /// the shard files hold every one).
    pub failures: Vec<FailedRun>,
}

/// Failed runs a cell lists (with their errors); the rest are counted.
pub const MAX_LISTED_FAILURES: usize = 100;

/// The cells of a whole sweep, noise level slowest then controller, from its runs in index
/// order (as [`merge`](super::merge) returns them).
pub fn cells(config: &SweepConfig, runs: &[RunResult]) -> Vec<Cell> {
    let mut builder = CellBuilder::new(config);
    runs.iter().for_each(|run| builder.add(run));
    builder.finish()
}

/// Builds the cells from a sweep's runs given one at a time in index order, keeping the values
/// of the current cell only: `8 (3 + m)` bytes per completed run of one cell (`m` modal
/// coordinates), whatever the number of runs.
#[derive(Debug)]
pub struct CellBuilder {
    seeds: usize,
    n_coords: usize,
    done: Vec<Cell>,
    current: Option<Values>,
}

/// The values of the runs of one cell so far.
#[derive(Debug)]
struct Values {
    noise_level: f64,
    controller: ControllerKind,
    runs: usize,
    failed: usize,
    tip_error_rms_mm: Vec<f64>,
    tip_error_max_mm: Vec<f64>,
    modal_error_rms_rad: Vec<Vec<f64>>,
    peak_joint_torque_nm: Vec<f64>,
    failures: Vec<FailedRun>,
}

impl Values {
    /// Adds a completed run's metrics.
    fn push(&mut self, m: &RunMetrics) {
        self.tip_error_rms_mm.push(m.tip_error_rms_m * 1e3);
        self.tip_error_max_mm.push(m.tip_error_max_m * 1e3);
        for (values, v) in self
            .modal_error_rms_rad
            .iter_mut()
            .zip(&m.modal_error_rms_rad)
        {
            values.push(*v);
        }
        self.peak_joint_torque_nm.push(m.peak_joint_torque_nm);
    }

    /// The statistics of the cell.
    fn cell(self) -> Cell {
        Cell {
            noise_level: self.noise_level,
            controller: self.controller,
            runs: self.runs,
            failed: self.failed,
            tip_error_rms_mm: Stats::of(&self.tip_error_rms_mm),
            tip_error_max_mm: Stats::of(&self.tip_error_max_mm),
            modal_error_rms_rad: self
                .modal_error_rms_rad
                .iter()
                .map(|v| Stats::of(v))
                .collect(),
            peak_joint_torque_nm: Stats::of(&self.peak_joint_torque_nm),
            failures: self.failures,
        }
    }
}

impl CellBuilder {
    /// A builder for the cells of `config`.
    pub fn new(config: &SweepConfig) -> Self {
        CellBuilder {
            seeds: config.settings.seeds.max(1),
            n_coords: config.scenario.n_coords(),
            done: Vec::new(),
            current: None,
        }
    }

    /// Adds the next run in index order; the first run of a cell (an index that is a multiple
    /// of the seeds) closes the cell before it.
    pub fn add(&mut self, run: &RunResult) {
        let first_of_cell = run.index.is_multiple_of(self.seeds);
        if first_of_cell && let Some(values) = self.current.take() {
            self.done.push(values.cell());
        }
        let m = self.n_coords;
        let values = self.current.get_or_insert_with(|| Values {
            noise_level: run.noise_level,
            controller: run.controller,
            runs: 0,
            failed: 0,
            tip_error_rms_mm: Vec::new(),
            tip_error_max_mm: Vec::new(),
            modal_error_rms_rad: vec![Vec::new(); m],
            peak_joint_torque_nm: Vec::new(),
            failures: Vec::new(),
        });
        values.runs += 1;
        match &run.outcome {
            StoredOutcome::Completed(metrics) => values.push(metrics),
            StoredOutcome::Failed { error, .. } => {
                values.failed += 1;
                if values.failures.len() < MAX_LISTED_FAILURES {
                    values.failures.push(FailedRun {
                        index: run.index,
                        seed: run.seed,
                        error: error.clone(),
                    });
                }
            }
        }
    }

    /// The cells of the runs added.
    pub fn finish(mut self) -> Vec<Cell> {
        if let Some(values) = self.current.take() {
            self.done.push(values.cell());
        }
        self.done
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn statistics_of_known_samples() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, sum of squared deviations 32, so std sqrt(32/7).
        let s = Stats::of(&[9.0, 2.0, 4.0, 4.0, 5.0, 5.0, 7.0, 4.0]).unwrap();
        assert_eq!((s.mean, s.min, s.median, s.max), (5.0, 2.0, 4.5, 9.0));
        assert!((s.std - (32.0f64 / 7.0).sqrt()).abs() < 1e-15);
        // Equal values: the naive sum of ten 0.1 is 0.9999999999999999, not 1.
        let same = Stats::of(&[0.1; 10]).unwrap();
        assert_eq!((same.mean, same.std, same.median), (0.1, 0.0, 0.1));
        let one = Stats::of(&[3.5]).unwrap();
        assert_eq!((one.mean, one.std, one.median), (3.5, 0.0, 3.5));
        assert_eq!(Stats::of(&[1.0, 10.0, 2.0]).unwrap().median, 2.0);
        assert!(Stats::of(&[]).is_none());
    }

    /// Issue 11: what a summary holds must be JSON, so finite values (of one sign) give finite
    /// statistics even near the largest double: `[0, M, M]` has mean `2M/3`, std `M/sqrt(3)`.
    #[test]
    fn statistics_of_huge_values_are_finite() {
        let m = f64::MAX;
        let s = Stats::of(&[0.0, m, m]).unwrap();
        assert_eq!((s.min, s.median, s.max), (0.0, m, m));
        assert!((s.mean / (2.0 * (m / 3.0)) - 1.0).abs() < 1e-15, "{s:?}");
        assert!((s.std / (m / 3f64.sqrt()) - 1.0).abs() < 1e-15, "{s:?}");
        let pair = Stats::of(&[m, m]).unwrap();
        assert_eq!((pair.mean, pair.std, pair.median), (m, 0.0, m));
        let many = Stats::of(&vec![1e300; 100_000]).unwrap();
        assert_eq!((many.mean, many.std), (1e300, 0.0));
    }

    proptest! {
        #[test]
        fn statistics_are_shift_and_scale_equivariant(
            values in proptest::collection::vec(-1e3f64..1e3, 1..40),
            shift in -1e3f64..1e3,
            scale in 0.1f64..10.0,
        ) {
            let s = Stats::of(&values).unwrap();
            let moved: Vec<f64> = values.iter().map(|v| scale * v + shift).collect();
            let t = Stats::of(&moved).unwrap();
            let tol = 1e-9 * (1e3 * scale + shift.abs());
            prop_assert!((t.mean - (scale * s.mean + shift)).abs() <= tol);
            prop_assert!((t.std - scale * s.std).abs() <= tol);
            prop_assert!((t.median - (scale * s.median + shift)).abs() <= tol);
            prop_assert!(s.min <= s.median && s.median <= s.max);
            prop_assert!(s.min <= s.mean && s.mean <= s.max);
            // Half the values lie on each side of the median.
            let below = values.iter().filter(|&&v| v <= s.median).count();
            prop_assert!(2 * below >= values.len());
        }
    }
}
