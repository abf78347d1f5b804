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
mod inputs;
mod plan;
mod shard_file;

pub use aggregate::{Cell, CellBuilder, FailedRun, MAX_LISTED_FAILURES, Stats, cells};
pub use comparison::{ComparisonRun, Stopped, builtin_scenarios, compare, run_one};
pub use inputs::{
    InputDigest, SCENARIO_INPUT, check_digests, check_json_safe, first_changed, input_digests,
};
pub use plan::{MAX_RUNS, MAX_SHARDS, RunId, Shard, SweepConfig, run_seed};
pub use shard_file::{
    FORMAT, MAX_SHARD_LINE_BYTES, Outcome, RunMetrics, RunResult, ShardFile, ShardHeader,
    ShardInput, ShardReader, ShardSource, merge, merge_readers, shard_paths, write_json_line,
};

use rayon::prelude::*;
use std::io::Write;

/// Runs run in parallel before their results are passed on in index order: enough to keep
/// every core busy, few enough that the batch's results take little memory (a few hundred
/// kilobytes).
const BATCH_RUNS: usize = 1024;

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

/// Runs the runs of `shard` in parallel (rayon), in batches of `BATCH_RUNS` (1024), calling
/// `progress` after each run and `sink` with each result in index order; stops at the first
/// error of `sink`. Only one batch of results is held at a time.
pub fn for_each_run(
    config: &SweepConfig,
    shard: Shard,
    progress: impl Fn() + Sync,
    mut sink: impl FnMut(RunResult) -> Result<(), String>,
) -> Result<(), String> {
    let mut indices = shard.indices(config.runs().unwrap_or(0));
    loop {
        let batch: Vec<usize> = indices.by_ref().take(BATCH_RUNS).collect();
        if batch.is_empty() {
            return Ok(());
        }
        let results: Vec<RunResult> = batch
            .par_iter()
            .map(|&i| {
                let result = execute(config, &config.run_at(i));
                progress();
                result
            })
            .collect();
        results.into_iter().try_for_each(&mut sink)?;
    }
}

/// Runs the runs of `shard` and keeps them in memory (see [`write_shard`] to stream them to a
/// file); the results are in index order. [`Shard::WHOLE`] runs the whole sweep.
pub fn run_shard(config: &SweepConfig, shard: Shard, progress: impl Fn() + Sync) -> ShardFile {
    let mut runs = Vec::with_capacity(shard.run_count(config.runs().unwrap_or(0)));
    let pushed: Result<(), String> = for_each_run(config, shard, progress, |run| {
        runs.push(run);
        Ok(())
    });
    debug_assert!(pushed.is_ok(), "pushing to a vector cannot fail");
    ShardFile {
        format: FORMAT.into(),
        config: config.clone(),
        shard,
        runs,
    }
}

/// Runs the runs of `shard` and writes its shard file to `out` as they finish (the header, then
/// one line per run, in index order), so that memory does not grow with the number of runs.
/// Afterwards the files the scenario references are read again: if one changed while the
/// sweep ran (its runs could mix two contents), the shard is refused. Returns the number of
/// runs and of those that stopped.
pub fn write_shard<W: Write + ?Sized>(
    config: &SweepConfig,
    shard: Shard,
    out: &mut W,
    progress: impl Fn() + Sync,
) -> Result<(usize, usize), String> {
    write_json_line(out, &ShardHeader::new(config, shard))?;
    let (mut runs, mut stopped) = (0, 0);
    for_each_run(config, shard, progress, |run| {
        runs += 1;
        stopped += usize::from(matches!(run.outcome, Outcome::Failed { .. }));
        write_json_line(out, &run)
    })?;
    let now = input_digests(&config.scenario)?;
    if let Some((input, _)) = first_changed(&config.inputs, &now) {
        return Err(format!(
            "{} changed while the sweep ran, so its runs may mix two contents: run the sweep \
             again",
            input.describe()
        ));
    }
    out.flush().map_err(|e| e.to_string())?;
    Ok((runs, stopped))
}
