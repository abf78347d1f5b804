//! Studies as a library: the main job's comparison of every shipped scenario with every
//! controller, and Monte Carlo sweeps over noise levels and seeds with their plan, seeds,
//! sharding, parallel running (rayon), aggregation and merge (`docs/sweep.md`). The `hrm`
//! command is a thin layer of arguments and printing over these functions.
//!
//! A sweep in a few lines, whole or as shards merged back (bit for bit the same numbers):
//!
//! ```
//! use sim_core::study::{Shard, SweepConfig, cells, merge, run_shard};
//! use sim_core::{ControllerKind, Scenario};
//!
//! let mut scenario = Scenario::builtin("paper-responses-step")?;
//! scenario.duration = 0.15;
//! let config = SweepConfig::new(scenario, vec![ControllerKind::Pd], vec![0.0, 0.01], 2, 7)?;
//! let whole = run_shard(&config, Shard::WHOLE, || {});
//! let halves = (1..=2).map(|index| {
//!     let shard = Shard { index, count: 2 };
//!     (std::path::PathBuf::from(format!("shard-{index}")), run_shard(&config, shard, || {}))
//! });
//! let merged = merge(halves.collect())?;
//! assert_eq!(merged, whole);
//! let table = cells(&config, &whole.runs);
//! assert_eq!(table.len(), 2); // one cell per noise level and controller
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod aggregate;
mod comparison;
mod plan;
mod shard_file;

pub use aggregate::{Cell, FailedRun, Stats, cells};
pub use comparison::{ComparisonRun, Stopped, builtin_scenarios, compare, run_one};
pub use plan::{MAX_RUNS, MAX_SHARDS, RunId, Shard, SweepConfig, run_seed};
pub use shard_file::{FORMAT, Outcome, RunMetrics, RunResult, ShardFile, merge, shard_paths};

use rayon::prelude::*;

/// The toolkit version recorded in a sweep's configuration: shards merge only when theirs agree.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Runs run `id` of `config` and keeps its summary metrics (the time series are dropped at once).
pub fn execute(config: &SweepConfig, id: &RunId) -> RunResult {
    let outcome = match config.scenario_for(id).build() {
        Err(e) => Outcome::Failed {
            error: e.to_string(),
            simulated_s: 0.0,
        },
        Ok(mut simulation) => match simulation.run() {
            Ok(run) => match RunMetrics::from_summary(&run.summary) {
                Ok(metrics) => Outcome::Completed(metrics),
                Err(error) => Outcome::Failed {
                    error,
                    simulated_s: run.summary.simulated_s,
                },
            },
            Err(failure) => Outcome::Failed {
                error: failure.error.to_string(),
                simulated_s: failure.summary.simulated_s,
            },
        },
    };
    RunResult::new(id, outcome)
}

/// Runs the runs of `shard` in parallel (rayon), calling `progress` after each; the results are
/// in index order. [`Shard::WHOLE`] runs the whole sweep.
pub fn run_shard(config: &SweepConfig, shard: Shard, progress: impl Fn() + Sync) -> ShardFile {
    let total = config.runs().unwrap_or(0);
    let indices: Vec<usize> = shard.indices(total).collect();
    let runs = indices
        .par_iter()
        .map(|&i| {
            let result = execute(config, &config.run_at(i));
            progress();
            result
        })
        .collect();
    ShardFile {
        format: FORMAT.into(),
        config: config.clone(),
        shard,
        runs,
    }
}
