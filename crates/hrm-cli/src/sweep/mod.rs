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

use clap::{Args, Subcommand};
use sim_core::study::{self, Outcome, Shard, ShardFile, SweepConfig};
use sim_core::{ControllerKind, Scenario};
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
    #[arg(long, value_delimiter = ',', default_values_t = ControllerKind::ALL)]
    controllers: Vec<ControllerKind>,
    /// Noise levels L, comma-separated: the sensor noise std on (a1, a2) in rad.
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true,
          default_values_t = [0.0, 0.005, 0.01, 0.02, 0.05, 0.1])]
    noise: Vec<f64>,
    /// Sensor noise std on (a1_dot, a2_dot) per unit of L (rad/s per rad).
    #[arg(long, default_value_t = 10.0)]
    rate_noise_ratio: f64,
    /// Noise std on the reference (a1_ref, a2_ref) per unit of L.
    #[arg(long, default_value_t = 0.0)]
    reference_noise_ratio: f64,
    /// Noise realisations (seeds) per noise level and controller.
    #[arg(long, default_value_t = 10)]
    seeds: usize,
    /// The seed the runs' seeds derive from (SplitMix64).
    #[arg(long, default_value_t = 1)]
    base_seed: u64,
    /// Override the scenario's duration (s).
    #[arg(long)]
    duration: Option<f64>,
    /// Run only shard K of N (the runs i with i % N == K - 1) and write DIR/shard-K-of-N.json.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
    /// Output folder.
    #[arg(long, default_value = "hrm-output/sweep")]
    out: PathBuf,
}

/// Runs `hrm sweep` or `hrm sweep merge`.
pub fn run(cli: SweepCli) -> Result<(), String> {
    match cli.command {
        Some(SweepCommand::Merge { out, shards }) => {
            let table = merge_files(&shards, &out)?;
            print!("{table}");
            println!(
                "wrote {} (runs.json, summary.json, table.txt, tip_error_rms.svg)",
                out.display()
            );
            Ok(())
        }
        None => {
            let args = cli.sweep;
            let config = configure(&args)?;
            match args.shard {
                Some(shard) => {
                    let file = run_shard(&config, shard);
                    let path = args
                        .out
                        .join(format!("shard-{}-of-{}.json", shard.index, shard.count));
                    write(&path, &to_json(&file)?)?;
                    let failed = file
                        .runs
                        .iter()
                        .filter(|r| matches!(r.outcome, Outcome::Failed { .. }))
                        .count();
                    println!(
                        "wrote {} ({} runs, {failed} stopped)",
                        path.display(),
                        file.runs.len()
                    );
                    Ok(())
                }
                None => {
                    let table = sweep_whole(&config, &args.out)?;
                    print!("{table}");
                    println!(
                        "wrote {} (runs.json, summary.json, table.txt, tip_error_rms.svg)",
                        args.out.display()
                    );
                    Ok(())
                }
            }
        }
    }
}

/// The sweep's configuration: the scenario resolved, the duration applied, everything
/// checked, and every controller's simulation built once so that a bad setting fails here
/// rather than in every run.
fn configure(args: &SweepArgs) -> Result<SweepConfig, String> {
    let mut scenario = Scenario::resolve(&args.scenario).map_err(|e| e.to_string())?;
    if let Some(duration) = args.duration {
        scenario.duration = duration;
    }
    scenario.noise = Default::default();
    scenario.seed = 0;
    let config = SweepConfig {
        hrm_version: study::VERSION.to_string(),
        scenario,
        controllers: args.controllers.clone(),
        noise_levels: args.noise.clone(),
        rate_noise_ratio: args.rate_noise_ratio,
        reference_noise_ratio: args.reference_noise_ratio,
        seeds: args.seeds,
        base_seed: args.base_seed,
    };
    config.validate()?;
    config.check_builds()?;
    Ok(config)
}

/// Runs the runs of `shard` with a progress bar (the library's [`study::run_shard`]).
fn run_shard(config: &SweepConfig, shard: Shard) -> ShardFile {
    let total = config.runs().unwrap_or(0);
    let label = if shard == Shard::WHOLE {
        "sweep".to_string()
    } else {
        format!("shard {shard}")
    };
    let bar = crate::progress::bar(shard.indices(total).count() as u64, &label);
    let file = study::run_shard(config, shard, || bar.inc(1));
    bar.finish_and_clear();
    file
}

/// Runs the whole sweep into `out` and returns the table. The report is made from `runs.json`
/// as read back, exactly as `merge` makes it from shard files, so both give identical numbers.
fn sweep_whole(config: &SweepConfig, out: &Path) -> Result<String, String> {
    let path = out.join("runs.json");
    let text = to_json(&run_shard(config, Shard::WHOLE))?;
    write(&path, &text)?;
    let parsed = ShardFile::parse(&text, &path)?;
    write_report(&parsed, out)
}

/// Merges the shard files named by `inputs` into `out` and returns the table.
fn merge_files(inputs: &[PathBuf], out: &Path) -> Result<String, String> {
    let shards = study::shard_paths(inputs)?
        .into_iter()
        .map(|path| ShardFile::read(&path).map(|file| (path, file)))
        .collect::<Result<Vec<_>, _>>()?;
    let whole = study::merge(shards)?;
    write(&out.join("runs.json"), &to_json(&whole)?)?;
    write_report(&whole, out)
}

/// Writes `summary.json`, `table.txt` and `tip_error_rms.svg` of a whole sweep; returns the
/// table.
fn write_report(whole: &ShardFile, out: &Path) -> Result<String, String> {
    let cells = study::cells(&whole.config, &whole.runs);
    let summary = report::summary_json(&whole.config, &cells);
    let summary = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())? + "\n";
    write(&out.join("summary.json"), &summary)?;
    let mut table = report::table(&whole.config, &cells);
    if !report::plot(&out.join("tip_error_rms.svg"), &whole.config, &cells)? {
        table.push_str("no run completed: no plot drawn\n");
    }
    write(&out.join("table.txt"), &table)?;
    Ok(table)
}

fn to_json(file: &ShardFile) -> Result<String, String> {
    file.to_json()
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
