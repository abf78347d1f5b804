//! Studies as a library: the main job's comparison of every shipped scenario with every
//! controller, and Monte Carlo sweeps over noise levels and seeds with their plan, seeds,
//! sharding, parallel running (rayon), aggregation and merge (`docs/sweep.md`). The `hrm`
//! command is a thin layer of arguments and printing over these functions.
//!
//! A sweep in a few lines, whole or as shards merged back (bit for bit the same numbers):
//!
//! ```
//! use sim_study::study::{Shard, SweepConfig, SweepSettings, cells, merge, run_shard};
//! use sim_study::{ControllerKind, Scenario};
//!
//! let mut scenario = Scenario::builtin("paper-responses-step")?;
//! scenario.duration = 0.15;
//! let settings = SweepSettings {
//!     controllers: vec![ControllerKind::Pd],
//!     noise_levels: vec![0.0, 0.01],
//!     seeds: 2,
//!     base_seed: 7,
//!     ..SweepSettings::default()
//! };
//! let config = SweepConfig::new(scenario, settings)?;
//! let whole = run_shard(&config, Shard::WHOLE, || {})?;
//! let halves = (1..=2).map(|index| {
//!     let shard = Shard { index, count: 2 };
//!     let file = run_shard(&config, shard, || {})?;
//!     Ok((std::path::PathBuf::from(format!("shard-{index}")), file))
//! });
//! let merged = merge(halves.collect::<Result<_, sim_study::study::StudyError>>()?)?;
//! assert_eq!(merged, whole);
//! let table = cells(&config, &whole.runs);
//! assert_eq!(table.len(), 2); // one cell per noise level and controller
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod aggregate;
mod comparison;
mod error;
mod inputs;
mod outcome;
mod plan;
mod shard;
mod shard_file;

pub use aggregate::{Cell, CellBuilder, FailedRun, MAX_LISTED_FAILURES, Stats, cells};
pub use comparison::{
    ComparisonRun, builtin_scenarios, compare, run_one, run_one_with, run_prepared,
};
pub use error::SettingError;
pub use error::{MergeProblem, MetricError, ShardProblem, StudyError};
pub use inputs::{
    InputDigest, SCENARIO_INPUT, check_digests, check_json_safe, first_changed, input_digests,
};
pub use outcome::{RunError, RunMetrics, RunOutcome, Stopped, run_scenario};
pub use plan::{
    MAX_NOISE_LEVELS, MAX_RUNS, MAX_SEEDS, RunId, SweepConfig, SweepSettings, run_seed,
};
pub use shard::{
    FORMAT, MAX_SHARD_LINE_BYTES, MAX_SHARD_METRIC, MAX_SHARDS, Shard, ShardParseError,
    ShardRangeError,
};
pub use shard_file::{
    RunResult, ShardFile, ShardHeader, ShardInput, ShardReader, ShardSource, StoredOutcome, merge,
    merge_readers, shard_paths, write_json_line,
};

use crate::{ControllerKind, IntegratorSpec};
use rayon::prelude::*;
use sim_core::{Prepared, SimError};
use std::io::Write;

/// Runs run in parallel before their results are passed on in index order: enough to keep
/// every core busy, few enough that the batch's results take little memory (a few hundred
/// kilobytes).
const BATCH_RUNS: usize = 1024;

/// The most work one shard (or a whole sweep run as one) may take, in the units of
/// [`sim_core::MAX_RUN_WORK`] (which bounds a run at about ten minutes): about a day of
/// computing, so that a count typed `10000000` for `1000` is refused up front rather than
/// running for months; a larger study splits into shards (Slurm, Dask).
pub const MAX_SHARD_WORK: f64 = 1e14;

/// The toolkit version recorded in a sweep's configuration: shards merge only when theirs agree.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Runs run `id` of `config` alone and keeps its summary metrics (the time series are dropped at
/// once).
pub fn execute(config: &SweepConfig, id: &RunId) -> RunResult {
    let outcome = match config.prepare(id.controller) {
        Err(e) => StoredOutcome::of(Err(Stopped::not_built(e))),
        Ok(prepared) => run_alone(config, &prepared, id),
    };
    RunResult::new(id, outcome)
}

/// Runs run `id` of `config` alone from its controller's prepared simulation.
fn run_alone(config: &SweepConfig, prepared: &Prepared, id: &RunId) -> StoredOutcome {
    match config
        .run_noise(id)
        .and_then(|noise| prepared.simulation(&noise))
    {
        Err(e) => StoredOutcome::of(Err(Stopped::not_built(e))),
        Ok(mut simulation) => StoredOutcome::of(simulation.run().map_err(Stopped::from)),
    }
}

/// Runs the runs `ids` of `config` side by side in a [`Lockstep`](sim_core::Lockstep) group, their dynamics
/// evaluated together (SIMD across runs) at every integrator stage, and keeps their summary
/// metrics: the results in the order of `ids`, each the same, bit for bit, as [`execute`]'s.
/// The runs must share the controller (they may differ in noise level and seed); a run that
/// stops leaves the others running.
pub fn execute_group(config: &SweepConfig, ids: &[RunId]) -> Vec<RunResult> {
    match ids.first() {
        None => Vec::new(),
        Some(first) => execute_prepared(config, &config.prepare(first.controller), ids),
    }
}

/// [`execute_group`] of runs whose controller's simulation is `prepared` (or could not be).
fn execute_prepared(
    config: &SweepConfig,
    prepared: &Result<Prepared, SimError>,
    ids: &[RunId],
) -> Vec<RunResult> {
    let prepared = match prepared {
        Ok(prepared) => prepared,
        Err(e) => {
            return ids
                .iter()
                .map(|id| RunResult::new(id, StoredOutcome::of(Err(Stopped::not_built(e.clone())))))
                .collect();
        }
    };
    let group = ids
        .iter()
        .map(|id| config.run_noise(id))
        .collect::<Result<Vec<_>, _>>()
        .and_then(|noises| prepared.lockstep(&noises));
    match group {
        Ok(mut group) => ids
            .iter()
            .zip(group.run())
            .map(|(id, run)| RunResult::new(id, StoredOutcome::of(run.map_err(Stopped::from))))
            .collect(),
        // A run that cannot be built fails alone.
        Err(_) => ids
            .iter()
            .map(|id| RunResult::new(id, run_alone(config, prepared, id)))
            .collect(),
    }
}

/// How many runs of a sweep go into one lock-step group: the states the reduced dynamics'
/// batch evaluates in one SIMD group ([`modal_reduce::batch_lanes`]) for an RK4 scenario, one
/// (each run alone) for an adaptive integrator, whose runs choose their own steps.
pub fn lockstep_size(config: &SweepConfig) -> usize {
    match (&config.scenario.integrator, config.scenario.model()) {
        (IntegratorSpec::Rk4 { .. }, Ok(model)) => modal_reduce::batch_lanes(&model),
        _ => 1,
    }
}

/// The runs `indices` (ascending) of `config` in lock-step groups of at most `size` runs of one
/// controller, each group in index order.
fn lockstep_groups(config: &SweepConfig, indices: &[usize], size: usize) -> Vec<Vec<RunId>> {
    let mut groups = Vec::new();
    for (c, controller) in config.settings.controllers.iter().enumerate() {
        if config.settings.controllers[..c].contains(controller) {
            continue;
        }
        let ids: Vec<RunId> = indices
            .iter()
            .map(|&i| config.run_at(i))
            .filter(|id| id.controller == *controller)
            .collect();
        groups.extend(ids.chunks(size.max(1)).map(<[RunId]>::to_vec));
    }
    groups
}

/// Runs the runs of `shard` in lock-step groups ([`execute_group`], [`lockstep_size`] runs of
/// one controller each, whose simulation is prepared once for the shard), the groups in
/// parallel (rayon), in batches of `BATCH_RUNS` (1024) runs, calling `progress` after each run
/// and `sink` with each result in index order; stops at the first error of `sink`. Only one
/// batch of results is held at a time.
pub fn for_each_run(
    config: &SweepConfig,
    shard: Shard,
    progress: impl Fn() + Sync,
    sink: impl FnMut(RunResult) -> Result<(), StudyError>,
) -> Result<(), StudyError> {
    for_each_run_until(config, shard, progress, || false, sink)
}

/// [`for_each_run`], checking `stop` before each lock-step group: once it returns true, no
/// further group starts and the call fails with [`StudyError::Stopped`] (a Python caller's
/// Ctrl-C). A configuration another `hrm` version made is refused before any run
/// ([`StudyError::OtherVersion`]).
pub fn for_each_run_until(
    config: &SweepConfig,
    shard: Shard,
    progress: impl Fn() + Sync,
    stop: impl Fn() -> bool + Sync,
    mut sink: impl FnMut(RunResult) -> Result<(), StudyError>,
) -> Result<(), StudyError> {
    if config.hrm_version != VERSION {
        return Err(StudyError::OtherVersion {
            configured: config.hrm_version.clone(),
            running: VERSION,
        });
    }
    let mut indices = shard.indices(config.runs().unwrap_or(0));
    let size = lockstep_size(config);
    // Each controller's simulation, prepared once for all of its runs.
    let mut prepared: Vec<(ControllerKind, Result<Prepared, SimError>)> = Vec::new();
    for &kind in &config.settings.controllers {
        if prepared.iter().all(|(k, _)| *k != kind) {
            prepared.push((kind, config.prepare(kind)));
        }
    }
    check_shard_work(config, shard, &prepared)?;
    loop {
        let batch: Vec<usize> = indices.by_ref().take(BATCH_RUNS).collect();
        if batch.is_empty() {
            return Ok(());
        }
        let groups = lockstep_groups(config, &batch, size);
        let mut results: Vec<RunResult> = groups
            .par_iter()
            .flat_map_iter(|ids| {
                if stop() {
                    return Vec::new();
                }
                let (_, prepared) = prepared
                    .iter()
                    .find(|(kind, _)| *kind == ids[0].controller)
                    .expect("every controller of the sweep is prepared");
                let results = execute_prepared(config, prepared, ids);
                results.iter().for_each(|_| progress());
                results
            })
            .collect();
        if stop() {
            return Err(StudyError::Stopped);
        }
        results.sort_unstable_by_key(|run| run.index);
        results.into_iter().try_for_each(&mut sink)?;
    }
}

/// Refuses a shard whose runs' estimated work exceeds [`MAX_SHARD_WORK`]: each run's
/// [`Simulation::work`](sim_core::Simulation::work), built from its controller's `prepared`
/// simulation at the noise of the shard's first run of that controller (a controller that
/// cannot be built makes runs that fail at once: no work).
fn check_shard_work(
    config: &SweepConfig,
    shard: Shard,
    prepared: &[(ControllerKind, Result<Prepared, SimError>)],
) -> Result<(), StudyError> {
    let runs = config.runs().unwrap_or(0);
    let mut work_of = Vec::with_capacity(prepared.len());
    for (kind, prepared) in prepared {
        let first = shard
            .indices(runs)
            .map(|i| config.run_at(i))
            .find(|id| id.controller == *kind);
        let work = match (first, prepared) {
            (Some(id), Ok(prepared)) => config
                .run_noise(&id)
                .and_then(|noise| prepared.simulation(&noise))
                .map_or(0.0, |simulation| simulation.work()),
            _ => 0.0,
        };
        work_of.push((*kind, work));
    }
    let work: f64 = shard
        .indices(runs)
        .map(|i| {
            let controller = config.run_at(i).controller;
            work_of
                .iter()
                .find(|(kind, _)| *kind == controller)
                .map_or(0.0, |(_, work)| *work)
        })
        .sum();
    if work > MAX_SHARD_WORK {
        return Err(StudyError::TooMuchWork {
            shard,
            runs: shard.run_count(runs),
            work,
            max: MAX_SHARD_WORK,
        });
    }
    Ok(())
}

/// Runs the runs of `shard` and keeps them in memory (see [`write_shard`] to stream them to a
/// file); the results are in index order. [`Shard::WHOLE`] runs the whole sweep.
///
/// # Errors
/// [`StudyError::TooMuchWork`] for a shard of more than [`MAX_SHARD_WORK`].
pub fn run_shard(
    config: &SweepConfig,
    shard: Shard,
    progress: impl Fn() + Sync,
) -> Result<ShardFile, StudyError> {
    run_shard_until(config, shard, progress, || false)
}

/// [`run_shard`], checking `stop` before each lock-step group ([`for_each_run_until`]):
/// [`StudyError::Stopped`] once it returned true.
pub fn run_shard_until(
    config: &SweepConfig,
    shard: Shard,
    progress: impl Fn() + Sync,
    stop: impl Fn() -> bool + Sync,
) -> Result<ShardFile, StudyError> {
    let runs_in_shard = shard.run_count(config.runs().unwrap_or(0));
    let mut runs = Vec::with_capacity(runs_in_shard.min(BATCH_RUNS));
    for_each_run_until(config, shard, progress, stop, |run| {
        runs.push(run);
        Ok(())
    })?;
    Ok(ShardFile {
        format: FORMAT.into(),
        config: config.clone(),
        shard,
        runs,
    })
}

/// The first file the scenario references whose contents no longer have the SHA-256 that the
/// sweep's configuration records ([`SweepConfig::inputs`]), described; `None` if none changed.
///
/// # Errors
/// [`StudyError::Io`] for a file that cannot be read.
pub fn changed_input(config: &SweepConfig) -> Result<Option<String>, StudyError> {
    let now = input_digests(&config.scenario)?;
    Ok(first_changed(&config.inputs, &now).map(|(input, _)| input.describe()))
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
) -> Result<(usize, usize), StudyError> {
    write_json_line(out, &ShardHeader::new(config, shard))?;
    let (mut runs, mut stopped) = (0, 0);
    for_each_run(config, shard, progress, |run| {
        runs += 1;
        stopped += usize::from(matches!(run.outcome, StoredOutcome::Failed { .. }));
        write_json_line(out, &run)
    })?;
    if let Some(input) = changed_input(config)? {
        return Err(StudyError::InputChanged { input });
    }
    out.flush().map_err(|e| StudyError::Write {
        cause: e.to_string(),
    })?;
    Ok((runs, stopped))
}
