//! `hrm sweep`: Monte Carlo over noise levels and seeds, in parallel on all cores, reporting the
//! mean and spread of the errors per controller and noise level (docs/sweep.md).
//!
//! - `hrm sweep [--scenario S] [--controllers C,..] [--noise L,..] [--seeds N] [--base-seed B]
//!   [--duration T] [--out DIR]` runs every run and writes `runs.json`, `summary.json`,
//!   `table.txt` and `tip_error_rms.svg` into `DIR`.
//! - `hrm sweep --shard K/N ...` runs the runs `i` with `i % N == K - 1` and writes
//!   `DIR/shard-K-of-N.json`.
//! - `hrm sweep merge --out DIR SHARDS...` combines shard files into the report of the whole
//!   sweep, the same as an unsharded run's.

mod report;

use crate::console;
use crate::output_dir::{self, OutputDir};
use clap::{Args, Subcommand};
use sim_study::study::{
    self, Cell, CellBuilder, Shard, ShardHeader, ShardReader, SweepConfig, SweepSettings,
};
use sim_study::{ControllerKind, Scenario};
use std::path::{Path, PathBuf};

/// The arguments of `hrm sweep`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, args_override_self = true)]
pub struct SweepCli {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    #[command(flatten)]
    sweep: SweepArgs,
}

#[derive(Debug, Subcommand)]
enum SweepCommand {
    /// Combine shard files (or directories of `shard-*.json`) into the report of the whole sweep.
    Merge {
        /// Output folder.
        #[arg(long, default_value = "hrm-output/sweep")]
        out: PathBuf,
        /// Shard files, or directories holding them.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
}

/// What to sweep.
#[derive(Debug, Clone, Args)]
struct SweepArgs {
    /// Scenario name or TOML file. The default, the paper's tracking task, is the experiment whose
    /// tip error the paper reports and where the controllers differ most.
    #[arg(long, default_value = "paper-tracking")]
    scenario: String,
    /// Controllers to compare, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        action = clap::ArgAction::Set,
        default_value = crate::args::ALL_CONTROLLERS.as_str()
    )]
    controllers: Vec<ControllerKind>,
    /// Noise levels L, comma-separated: the sensor noise std on every modal coordinate in rad.
    #[arg(
        long,
        value_delimiter = ',',
        action = clap::ArgAction::Set,
        allow_negative_numbers = true,
        default_value = "0,0.005,0.01,0.02,0.05,0.1"
    )]
    noise: Vec<f64>,
    /// Sensor noise std on every modal rate per unit of L (rad/s per rad).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    rate_noise_ratio: f64,
    /// Noise std on every coordinate of the reference per unit of L.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    reference_noise_ratio: f64,
    /// Noise realisations (seeds) per noise level and controller (at most 1000000).
    #[arg(long, default_value_t = 10, allow_negative_numbers = true)]
    seeds: i128,
    /// The seed the runs' seeds derive from (SplitMix64), from 0 to 2^64 - 1.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    base_seed: i128,
    /// Override the scenario's duration (s).
    #[arg(long, allow_negative_numbers = true)]
    duration: Option<f64>,
    /// Run only shard K of N (the runs i with i % N == K - 1) and write DIR/shard-K-of-N.json.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Output folder.
    #[arg(long, default_value = "hrm-output/sweep")]
    out: PathBuf,
}

/// How a shard file hrm wrote begins: the first key of its header line.
const SHARD_START: &[u8] = b"{\"format\":\"hrm-sweep-shard/";

/// Runs `hrm sweep` or `hrm sweep merge`.
pub fn run(cli: SweepCli) -> Result<(), String> {
    match cli.command {
        Some(SweepCommand::Merge { out, shards }) => {
            let staging = OutputDir::create(&out, "sweep merge")?;
            let table = merge_files(&shards, staging.path(), &out).map_err(|e| staging.named(e))?;
            let wrote = wrote(&out, staging.path());
            staging.commit()?;
            console::print(&format!("{table}{wrote}"))
        }
        None => {
            let args = cli.sweep;
            let config = configure(&args)?;
            match args.shard {
                Some(shard) => {
                    let path = args
                        .out
                        .join(format!("shard-{}-of-{}.json", shard.index, shard.count));
                    // Shards share a folder of their own, and replace only shard files.
                    output_dir::refuse_marked_folder(&args.out, "sweep --shard", "the shard file")?;
                    output_dir::refuse_foreign_file(&path, SHARD_START.len(), |start| {
                        start == SHARD_START
                    })?;
                    let mut counts = (0, 0);
                    output_dir::write_file_with(&path, "sweep --shard", |out| {
                        counts = write_shard(&config, shard, out)?;
                        Ok(())
                    })?;
                    let (runs, stopped) = counts;
                    console::print(&format!(
                        "wrote {} ({runs} runs, {stopped} stopped)\n",
                        console::shown(&path)
                    ))
                }
                None => {
                    let staging = OutputDir::create(&args.out, "sweep")?;
                    let table =
                        sweep_whole(&config, staging.path()).map_err(|e| staging.named(e))?;
                    let wrote = wrote(&args.out, staging.path());
                    staging.commit()?;
                    console::print(&format!("{table}{wrote}"))
                }
            }
        }
    }
}

/// The command line's counts checked before anything is built: `--seeds` and `--base-seed` in
/// range, at most [`study::MAX_NOISE_LEVELS`] noise levels, at most [`study::MAX_RUNS`] runs.
fn check_counts(args: &SweepArgs) -> Result<(usize, u64), String> {
    let seeds = crate::args::count("--seeds", args.seeds, 1, study::MAX_SEEDS)?;
    let base_seed = crate::args::count("--base-seed", args.base_seed, 0, usize::MAX)? as u64;
    if args.noise.len() > study::MAX_NOISE_LEVELS {
        return Err(format!(
            "--noise lists {} levels, more than the {} a sweep takes",
            args.noise.len(),
            study::MAX_NOISE_LEVELS
        ));
    }
    let runs = args.noise.len() * args.controllers.len() * seeds;
    if runs > study::MAX_RUNS {
        return Err(format!(
            "the sweep would make {} noise levels x {} controllers x {seeds} seeds = {runs} runs, \
             more than the {} allowed: lower --seeds or use fewer noise levels",
            args.noise.len(),
            args.controllers.len(),
            study::MAX_RUNS
        ));
    }
    Ok((seeds, base_seed))
}

/// Each [`SweepSettings`] field with the option of `hrm sweep` that sets it.
const OPTIONS: [(&str, &str); 6] = [
    ("controllers", "--controllers"),
    ("noise_levels", "--noise"),
    ("rate_noise_ratio", "--rate-noise-ratio"),
    ("reference_noise_ratio", "--reference-noise-ratio"),
    ("seeds", "--seeds"),
    ("base_seed", "--base-seed"),
];

/// The option of `hrm sweep` that sets a [`SweepSettings`] field.
fn option(setting: &str) -> &str {
    OPTIONS
        .iter()
        .find(|(name, _)| *name == setting)
        .map_or(setting, |(_, option)| option)
}

/// A refusal of the settings in the options' words: the setting named by its option, and a
/// setting the problem cites (`rate_noise_ratio = 10`) too (`--rate-noise-ratio 10`).
fn in_options(e: &study::SettingError) -> String {
    let problem = OPTIONS
        .iter()
        .fold(e.problem.clone(), |text, (name, option)| {
            text.replace(&format!("{name} = "), &format!("{option} "))
        });
    format!("{} {problem}", option(e.setting))
}

/// The sweep's configuration ([`SweepConfig::new`]): the scenario resolved, the duration
/// applied, everything checked (a refused setting named by its option), and every controller's
/// simulation built once so that a bad setting fails here rather than in every run.
fn configure(args: &SweepArgs) -> Result<SweepConfig, String> {
    let (seeds, base_seed) = check_counts(args)?;
    let settings = SweepSettings {
        controllers: args.controllers.clone(),
        noise_levels: args.noise.clone(),
        rate_noise_ratio: args.rate_noise_ratio,
        reference_noise_ratio: args.reference_noise_ratio,
        seeds,
        base_seed,
    };
    settings.check().map_err(|e| in_options(&e))?;
    let mut scenario = Scenario::resolve(&args.scenario).map_err(|e| e.to_string())?;
    if args.shard.is_none() {
        // The whole sweep replaces its folder; shards only add their files to theirs.
        crate::experiment::refuse_scenario_inputs_inside(&args.out, &args.scenario, &scenario)?;
    }
    if let Some(duration) = args.duration {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(format!(
                "--duration must be positive and finite (s), got {}",
                lane_math::Compact(duration)
            ));
        }
        scenario.duration = duration;
    }
    SweepConfig::new(scenario, settings).map_err(|e| e.to_string())
}

/// Runs the runs of `shard` with a progress bar, writing its shard file to `out` as they finish
/// (the library's [`study::write_shard`]); returns the number of runs and of those that stopped.
fn write_shard(
    config: &SweepConfig,
    shard: Shard,
    out: &mut dyn std::io::Write,
) -> Result<(usize, usize), String> {
    let total = config.runs().unwrap_or(0);
    let label = if shard == Shard::WHOLE {
        "sweep".to_string()
    } else {
        format!("shard {shard}")
    };
    let bar = crate::progress::bar(shard.run_count(total) as u64, &label);
    let counts = study::write_shard(config, shard, out, || bar.inc(1));
    bar.finish_and_clear();
    counts.map_err(|e| e.to_string())
}

/// Runs the whole sweep into `out` and returns the table. The report is made from `runs.json`
/// as read back, exactly as `merge` makes it from shard files, so both give identical numbers.
fn sweep_whole(config: &SweepConfig, out: &Path) -> Result<String, String> {
    let path = out.join("runs.json");
    let mut file = create(&path)?;
    write_shard(config, Shard::WHOLE, &mut file)?;
    std::io::Write::flush(&mut file)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let mut reader = ShardReader::open(&path).map_err(|e| e.to_string())?;
    let mut cells = CellBuilder::new(&reader.header().config);
    while let Some(run) = reader.next_run().map_err(|e| e.to_string())? {
        cells.add(&run);
    }
    write_report(config, &cells.finish(), out)
}

/// Merges the shard files named by `inputs` into `out` (the staging folder of `target`) and
/// returns the table; the runs are read and written one at a time. Shard files inside `target`
/// are refused: replacing `target` would delete them.
fn merge_files(inputs: &[PathBuf], out: &Path, target: &Path) -> Result<String, String> {
    let paths = study::shard_paths(inputs).map_err(|e| e.to_string())?;
    if let Ok(target_abs) = std::fs::canonicalize(target) {
        for path in &paths {
            if std::fs::canonicalize(path).is_ok_and(|p| p.starts_with(&target_abs)) {
                return Err(format!(
                    "--out {} holds the shard file {} that is being merged, and the merge \
                     replaces that folder whole: merge into another folder",
                    target.display(),
                    path.display()
                ));
            }
        }
    }
    let shards = paths
        .iter()
        .map(|path| ShardReader::open(path))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let Some(first) = shards.first() else {
        return Err("nothing to merge: no shard files given".into());
    };
    let whole = ShardHeader::new(&first.header().config, Shard::WHOLE);
    let path = out.join("runs.json");
    let mut file = create(&path)?;
    let written = |e: std::io::Error| format!("cannot write {}: {e}", path.display());
    study::write_json_line(&mut file, &whole).map_err(|e| e.to_string())?;
    let mut cells = CellBuilder::new(&whole.config);
    study::merge_readers(shards, |run| {
        cells.add(&run);
        study::write_json_line(&mut file, &run)
    })
    .map_err(|e| e.to_string())?;
    std::io::Write::flush(&mut file).map_err(written)?;
    write_report(&whole.config, &cells.finish(), out)
}

/// A buffered new file at `path`, its folder created.
fn create(path: &Path) -> Result<std::io::BufWriter<std::fs::File>, String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    std::fs::File::create(path)
        .map(std::io::BufWriter::new)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Writes `summary.json`, `table.txt` and `tip_error_rms.svg` of a whole sweep from its cells;
/// returns the table.
fn write_report(config: &SweepConfig, cells: &[Cell], out: &Path) -> Result<String, String> {
    let summary = sim_study::summary_json::sweep(config, cells);
    let summary = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())? + "\n";
    write(&out.join("summary.json"), &summary)?;
    let mut table = report::table(config, cells);
    if !report::plot(&out.join("tip_error_rms.svg"), config, cells)? {
        table.push_str("no run completed: no plot drawn\n");
    }
    write(&out.join("table.txt"), &table)?;
    Ok(table)
}

/// The line naming the files of a whole sweep's report in `out`, as `staged` holds them (no plot
/// when no run completed).
fn wrote(out: &Path, staged: &Path) -> String {
    let plot = if staged.join("tip_error_rms.svg").exists() {
        ", tip_error_rms.svg"
    } else {
        ""
    };
    format!(
        "wrote {} (runs.json, summary.json, table.txt{plot})\n",
        console::shown(out)
    )
}

/// Writes `text` to `path`, creating its folder.
fn write(path: &Path, text: &str) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests;
