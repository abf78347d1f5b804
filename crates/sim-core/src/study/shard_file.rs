//! The outcome of each run, the shard file that stores a slice of a sweep's runs, and merging
//! shard files back into the whole sweep.

use super::plan::{MAX_SHARDS, RunId, Shard, SweepConfig};
use crate::{ControllerKind, Summary};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `format` tag of a shard file.
pub const FORMAT: &str = "hrm-sweep-shard/2";

/// Largest shard file read (1 GiB, about two million runs as written).
pub const MAX_SHARD_FILE_BYTES: u64 = 1 << 30;

/// A slice of a sweep: its configuration, which shard, and the runs of that shard in index
/// order. The whole sweep is shard 1/1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile {
    /// [`FORMAT`].
    pub format: String,
    /// The sweep.
    pub config: SweepConfig,
    /// Which slice.
    pub shard: Shard,
    /// One entry per run of the slice, ascending index.
    pub runs: Vec<RunResult>,
}

/// One run: where it sits in the sweep and how it ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunResult {
    /// Index in the sweep's enumeration.
    pub index: usize,
    /// Noise level (rad).
    pub noise_level: f64,
    /// Controller.
    pub controller: ControllerKind,
    /// Which noise realisation of the cell (0-based).
    pub seed_index: usize,
    /// Seed of the run's noise sources.
    pub seed: u64,
    /// Its metrics, or why it stopped.
    pub outcome: Outcome,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Outcome {
    /// It ran to the end.
    Completed(RunMetrics),
    /// It stopped (divergence, runaway error) or could not be built.
    Failed {
        /// Why, and when.
        error: String,
        /// Simulated time reached (s).
        simulated_s: f64,
    },
}

/// The summary metrics a sweep keeps of a run (see [`Summary`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunMetrics {
    /// Tip error RMS (m).
    pub tip_error_rms_m: f64,
    /// Largest tip error (m).
    pub tip_error_max_m: f64,
    /// Modal error RMS per coordinate (rad).
    pub modal_error_rms_rad: Vec<f64>,
    /// Largest joint torque (N m).
    pub peak_joint_torque_nm: f64,
    /// Control effort (N^2 m^2 s).
    pub control_effort_n2m2s: f64,
}

impl RunMetrics {
    /// The kept metrics of `summary`, or an error if one is not finite.
    pub fn from_summary(s: &Summary) -> Result<Self, String> {
        let m = RunMetrics {
            tip_error_rms_m: s.tip_error_rms_m,
            tip_error_max_m: s.tip_error_max_m,
            modal_error_rms_rad: s.modal_error_rms_rad.clone(),
            peak_joint_torque_nm: s.peak_joint_torque_nm,
            control_effort_n2m2s: s.control_effort_n2m2s,
        };
        let values = [
            m.tip_error_rms_m,
            m.tip_error_max_m,
            m.peak_joint_torque_nm,
            m.control_effort_n2m2s,
        ];
        if values
            .iter()
            .chain(&m.modal_error_rms_rad)
            .all(|v| v.is_finite())
        {
            Ok(m)
        } else {
            Err(format!("the run's summary metrics are not finite: {m:?}"))
        }
    }
}

impl RunResult {
    /// A run's entry.
    pub fn new(id: &RunId, outcome: Outcome) -> Self {
        RunResult {
            index: id.index,
            noise_level: id.noise_level,
            controller: id.controller,
            seed_index: id.seed_index,
            seed: id.seed,
            outcome,
        }
    }

    /// Whether the entry's position fields agree with run `id`.
    fn matches(&self, id: &RunId) -> bool {
        self.index == id.index
            && self.noise_level == id.noise_level
            && self.controller == id.controller
            && self.seed_index == id.seed_index
            && self.seed == id.seed
    }
}

impl ShardFile {
    /// Parses a shard file's text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &Path) -> Result<Self, String> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| format!("{} is not JSON: {e}", origin.display()))?;
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            other => {
                return Err(format!(
                    "{} is not an hrm sweep shard file (format {other:?}, expected \"{FORMAT}\")",
                    origin.display()
                ));
            }
        }
        let file: ShardFile = serde_json::from_value(value)
            .map_err(|e| format!("{} is a malformed shard file: {e}", origin.display()))?;
        file.config.validate().map_err(|e| {
            format!(
                "{} holds an invalid sweep configuration: {e}",
                origin.display()
            )
        })?;
        let m = file.config.scenario.n_coords();
        for run in &file.runs {
            if let Outcome::Completed(metrics) = &run.outcome
                && metrics.modal_error_rms_rad.len() != m
            {
                return Err(format!(
                    "{}: run {} has {} modal errors, but its scenario has {m} modal coordinates",
                    origin.display(),
                    run.index,
                    metrics.modal_error_rms_rad.len()
                ));
            }
        }
        Ok(file)
    }

    /// The file's text: pretty JSON with a final newline (what `hrm sweep` writes).
    pub fn to_json(&self) -> Result<String, String> {
        serde_json::to_string_pretty(self)
            .map(|s| s + "\n")
            .map_err(|e| e.to_string())
    }

    /// Reads a shard file (at most `MAX_SHARD_FILE_BYTES`, 1 GiB).
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = crate::read_text_file(path, MAX_SHARD_FILE_BYTES)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        Self::parse(&text, path)
    }
}

/// The shard files named by `inputs`: files as given, and every `shard-*.json` in a directory.
pub fn shard_paths(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut paths = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input)
                .map_err(|e| format!("cannot list {}: {e}", input.display()))?;
            let mut found: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                        n.starts_with("shard-") && n.ends_with(".json") && p.is_file()
                    })
                })
                .collect();
            if found.is_empty() {
                return Err(format!("no shard-*.json files in {}", input.display()));
            }
            found.sort();
            paths.extend(found);
        } else {
            paths.push(input.clone());
        }
    }
    Ok(paths)
}

/// Combines shards into the whole sweep (shard 1/1, runs in index order). Refuses shards of
/// different sweeps or shard counts, a shard given twice, runs out of place or duplicated, and
/// missing runs, naming the files and shards concerned.
pub fn merge(shards: Vec<(PathBuf, ShardFile)>) -> Result<ShardFile, String> {
    let Some((first_path, first)) = shards.first() else {
        return Err("nothing to merge: no shard files given".into());
    };
    let config = first.config.clone();
    config.validate().map_err(|e| {
        format!(
            "{} holds an invalid sweep configuration: {e}",
            first_path.display()
        )
    })?;
    let count = first.shard.count;
    if !(1..=MAX_SHARDS).contains(&count) {
        return Err(format!(
            "{} is shard {} of a split into {count} shards; a split has 1 to {MAX_SHARDS}",
            first_path.display(),
            first.shard.index
        ));
    }
    let total = config.runs().unwrap_or(0);
    let mut shard_files: Vec<Option<PathBuf>> = vec![None; count];
    let mut slots: Vec<Option<RunResult>> = vec![None; total];
    for (path, file) in &shards {
        if let Some(field) = config.first_difference(&file.config) {
            return Err(format!(
                "{} and {} come from different sweeps (their configurations differ in {field})",
                first_path.display(),
                path.display()
            ));
        }
        let shard = file.shard;
        if shard.count != count || shard.index == 0 || shard.index > count {
            return Err(format!(
                "{} is shard {shard} but {} is shard {} of {count}: every shard must come from \
                 the same split",
                path.display(),
                first_path.display(),
                first.shard
            ));
        }
        if let Some(other) = shard_files[shard.index - 1].replace(path.clone()) {
            return Err(format!(
                "shard {shard} is given twice: {} and {}",
                other.display(),
                path.display()
            ));
        }
    }
    for (path, file) in shards {
        for run in file.runs {
            let i = run.index;
            if i >= total || !file.shard.contains(i) || !run.matches(&config.run_at(i)) {
                return Err(format!(
                    "{} holds run {i}, which is not run {i} of its shard {} of this sweep",
                    path.display(),
                    file.shard
                ));
            }
            if slots[i].replace(run).is_some() {
                return Err(format!("{} holds run {i} twice", path.display()));
            }
        }
    }
    let absent: Vec<String> = (1..=count)
        .filter(|k| shard_files[k - 1].is_none())
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !absent.is_empty() {
        let (noun, verb) = if absent.len() > 1 {
            ("shards", "are")
        } else {
            ("shard", "is")
        };
        return Err(format!(
            "cannot merge: {noun} {} {verb} missing",
            absent.join(", ")
        ));
    }
    let missing: Vec<usize> = (0..total).filter(|&i| slots[i].is_none()).collect();
    if let Some(&i) = missing.first() {
        return Err(format!(
            "cannot merge: {} of {total} runs are missing (first: run {i}, in shard {}/{count}); \
             was a shard file cut short?",
            missing.len(),
            i % count + 1
        ));
    }
    Ok(ShardFile {
        format: FORMAT.into(),
        config,
        shard: Shard::WHOLE,
        runs: slots.into_iter().flatten().collect(),
    })
}
