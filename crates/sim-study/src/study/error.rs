//! The error of the study functions: a sweep that cannot be configured, an input that cannot be
//! read or changed while the sweep ran, a shard file that is refused, shards that do not merge.
//! Every message is one line naming the setting, file, line or run and the problem.

use super::shard::{FORMAT, MAX_SHARD_LINE_BYTES, MAX_SHARD_METRIC, MAX_SHARDS, Shard};
use crate::ControllerKind;
use lane_math::{Classify, Compact, ErrorClass};
use sim_core::SimError;
use std::path::PathBuf;

/// Why a study function refused its input or could not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    /// A sweep setting out of its domain.
    #[error(transparent)]
    Setting(#[from] SettingError),
    /// A scenario setting JSON cannot hold (infinity or NaN).
    #[error(
        "scenario setting {setting} = {value} cannot be written to a shard file (JSON has no \
         infinity or NaN): give a finite value"
    )]
    NotFinite {
        /// The dotted path of the setting, e.g. `limits.max_modal_error`.
        setting: String,
        /// Its value.
        value: f64,
    },
    /// The scenario cannot be serialised (a path that is not UTF-8).
    #[error("a scenario setting cannot be written to a shard file: {cause}")]
    NotWritable {
        /// The serialiser's explanation.
        cause: String,
    },
    /// The scenario's JSON does not read back (`cause`), or reads back changed (`None`).
    #[error(
        "the scenario {}",
        match cause {
            Some(cause) => format!("does not read back from JSON: {cause}"),
            None => "reads back from JSON changed: a setting does not round-trip".into(),
        }
    )]
    NotRoundTrip {
        /// The parser's explanation, `None` if it read back a different scenario.
        cause: Option<String>,
    },
    /// A file the scenario references cannot be read.
    #[error("{input} cannot be read from {}: {cause}", path.display())]
    InputUnreadable {
        /// The setting naming the file, e.g. `controller.fis`.
        input: &'static str,
        /// The file.
        path: PathBuf,
        /// The system's explanation.
        cause: String,
    },
    /// A configuration's input list is not the scenario's and the files it references.
    #[error(
        "inputs lists [{}], but the scenario and the files it references are [{}]",
        listed.join(", "),
        expected.join(", ")
    )]
    InputsListed {
        /// The inputs listed, described.
        listed: Vec<String>,
        /// The inputs the scenario has, described.
        expected: Vec<String>,
    },
    /// A digest that is not 64 hexadecimal digits.
    #[error(
        "the SHA-256 of {input} must be 64 hexadecimal digits, got '{}'",
        sha256.escape_debug()
    )]
    DigestMalformed {
        /// The input, described.
        input: String,
        /// The digest as written.
        sha256: String,
    },
    /// The scenario's digest is not that of its content.
    #[error("the scenario's SHA-256 does not match its content (was the file edited?)")]
    ScenarioEdited,
    /// A controller's simulation of the sweep cannot be built.
    #[error("scenario {scenario} with {controller}: {source}")]
    Build {
        /// The scenario's name.
        scenario: String,
        /// The controller.
        controller: ControllerKind,
        /// Why (boxed: the other variants are small).
        source: Box<SimError>,
    },
    /// A file the scenario references changed while the sweep ran.
    #[error(
        "{input} changed while the sweep ran, so its runs may mix two contents: run the sweep \
         again"
    )]
    InputChanged {
        /// The input, described.
        input: String,
    },
    /// A file the scenario references changed after the sweep was configured (its runs would not
    /// be those of the digest its shards record).
    #[error(
        "{input} changed since the sweep was configured, whose configuration records its former \
         SHA-256: configure the sweep again to run the new contents"
    )]
    InputChangedSinceConfigured {
        /// The input, described.
        input: String,
    },
    /// The caller's `stop` ended the runs.
    #[error("the sweep was stopped before all its runs were done")]
    Stopped,
    /// A configuration made by another `hrm` version was asked to run: its shards would carry
    /// that version's name for this version's results.
    #[error(
        "hrm_version: the sweep was configured by hrm {configured}, this is hrm {running}: \
         configure it again with this version (hrm sweep, hrm.Sweep) to run it"
    )]
    OtherVersion {
        /// The version the configuration records.
        configured: String,
        /// This library's version.
        running: &'static str,
    },
    /// The runs one invocation would run exceed [`MAX_SHARD_WORK`](super::MAX_SHARD_WORK).
    #[error(
        "runs: the {runs} runs of shard {shard} would take an estimated {work:.2e} operations, \
         more than the {max:e} one shard may take (about a day of computing): split the sweep \
         into more shards (--shard K/N under Slurm, Sweep.run_shard(k, n) under Dask) or give \
         fewer seeds, noise levels or controllers"
    )]
    TooMuchWork {
        /// The shard, `K/N` (`1/1` for the whole sweep).
        shard: Shard,
        /// Its runs.
        runs: usize,
        /// Their estimated work, in the units of [`sim_core::MAX_RUN_WORK`].
        work: f64,
        /// The limit.
        max: f64,
    },
    /// A file or folder cannot be read, listed or written.
    #[error("cannot {action} {}: {cause}", path.display())]
    Io {
        /// `read`, `list` or `write`.
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// The system's explanation.
        cause: String,
    },
    /// A shard file or a run that cannot be written as JSON.
    #[error("cannot write a shard file's line: {cause}")]
    Write {
        /// The serialiser's or the system's explanation.
        cause: String,
    },
    /// A folder given to a merge holds no shard file.
    #[error("no shard-*.json files in {}", dir.display())]
    NoShardFiles {
        /// The folder.
        dir: PathBuf,
    },
    /// A shard file that is refused.
    #[error("{}{problem}", origin.display())]
    ShardFile {
        /// The file.
        origin: PathBuf,
        /// What is wrong with it.
        problem: ShardProblem,
    },
    /// Shards that do not make one sweep.
    #[error("{0}")]
    Merge(MergeProblem),
}

/// What is wrong with a shard file; written right after the file's name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ShardProblem {
    /// No first line.
    #[error(" is empty, not an hrm sweep shard file")]
    Empty,
    /// The first line is not JSON.
    #[error(" is not an hrm sweep shard file: its first line is not JSON ({cause})")]
    NotJson {
        /// The parser's explanation.
        cause: String,
    },
    /// The file declares another format, or none.
    #[error(
        " is not an hrm sweep shard file ({}, expected \"{FORMAT}\"){}",
        match format {
            Some(f) => format!("format \"{}\"", f.escape_debug()),
            None => "no format".into(),
        },
        match format {
            Some(f) if f.starts_with("hrm-sweep-shard/") => {
                ": shard files of older versions cannot be merged, run the shard again"
            }
            _ => "",
        }
    )]
    Format {
        /// The format declared.
        format: Option<String>,
    },
    /// The header line is not a [`ShardHeader`](super::ShardHeader).
    #[error(" has a malformed header: {cause}")]
    MalformedHeader {
        /// The parser's explanation.
        cause: String,
    },
    /// The header's sweep configuration is refused.
    #[error(" holds an invalid sweep configuration: {source}")]
    InvalidConfig {
        /// Why.
        source: Box<StudyError>,
    },
    /// A shard outside every split.
    #[error(
        " is shard {index} of a split into {count} shards; a split has 1 to {MAX_SHARDS} \
         shards, numbered from 1"
    )]
    OutsideSplit {
        /// `K`.
        index: usize,
        /// `N`.
        count: usize,
    },
    /// The file ends before the shard's last run.
    #[error(" is cut short: it holds {held} of the {expected} runs of shard {shard}")]
    CutShort {
        /// The runs read.
        held: usize,
        /// The runs the shard has.
        expected: usize,
        /// The shard.
        shard: Shard,
    },
    /// Lines after the shard's last run.
    #[error(": line {line}: more lines than the {expected} runs of shard {shard}")]
    ExtraLines {
        /// The first extra line.
        line: usize,
        /// The runs the shard has.
        expected: usize,
        /// The shard.
        shard: Shard,
    },
    /// A line that is not a run.
    #[error(": line {line} is not a run: {cause}")]
    NotARun {
        /// The line.
        line: usize,
        /// The parser's explanation.
        cause: String,
    },
    /// A run out of place.
    #[error(
        ": line {line} holds run {run} ({held}), which is not run {expected} of this sweep \
         ({wanted}), the next of its shard {shard}"
    )]
    RunOutOfPlace {
        /// The line.
        line: usize,
        /// The run it holds.
        run: usize,
        /// The run it should hold.
        expected: usize,
        /// The shard.
        shard: Shard,
        /// The held run's controller, noise level and seed.
        held: String,
        /// The expected run's.
        wanted: String,
    },
    /// A completed run with another number of modal errors than the scenario's coordinates.
    #[error(
        ": run {run} has {got} modal errors, but its scenario has {expected} modal coordinates"
    )]
    ModalCount {
        /// The run.
        run: usize,
        /// Its modal errors.
        got: usize,
        /// The scenario's modal coordinates.
        expected: usize,
    },
    /// A completed run's metric no run gives.
    #[error(": line {line}: run {run}: {source}")]
    Metric {
        /// The line.
        line: usize,
        /// The run.
        run: usize,
        /// Which metric and why.
        source: MetricError,
    },
    /// A failed run's simulated time that is negative, not finite or past the scenario's
    /// duration.
    #[error(
        ": line {line}: run {run}: simulated_s = {} must be finite, non-negative and at most \
         the scenario's duration, {} s",
        Compact(*value),
        Compact(*duration)
    )]
    SimulatedTime {
        /// The scenario's duration (s).
        duration: f64,
        /// The line.
        line: usize,
        /// The run.
        run: usize,
        /// The time written.
        value: f64,
    },
    /// A failed run's message that is not one line of at most about 2,000 characters, as a sweep
    /// writes it ([`lane_math::one_line`]).
    #[error(
        ": line {line}: run {run}: outcome.failed.error is not a message a sweep writes: it must \
         be one line without control characters, not blank, of at most about 2000 characters"
    )]
    FailureMessage {
        /// The line.
        line: usize,
        /// The run.
        run: usize,
    },
    /// A line longer than [`MAX_SHARD_LINE_BYTES`].
    #[error(
        ": line {line} is longer than the {MAX_SHARD_LINE_BYTES} bytes a shard file's line may \
         have"
    )]
    LineTooLong {
        /// The line.
        line: usize,
    },
}

/// A metric of a completed run, read from a shard file, that no run gives.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MetricError {
    /// Outside `[0, MAX_SHARD_METRIC]`.
    #[error(
        "{name} = {} is not a metric a run gives: it must lie in [0, {MAX_SHARD_METRIC:e}]",
        Compact(*value)
    )]
    OutOfRange {
        /// The metric.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A modal RMS above the runaway bound a completed run kept to.
    #[error(
        "{name} = {} exceeds the scenario's runaway bound limits.max_modal_error = {}, which a \
         completed run keeps to",
        Compact(*value),
        Compact(*bound)
    )]
    AboveRunaway {
        /// The metric.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The scenario's bound.
        bound: f64,
    },
    /// A largest tip error below its RMS.
    #[error(
        "tip_error_max_m = {} is below tip_error_rms_m = {}: a maximum is at least the RMS of \
         the same samples",
        Compact(*max),
        Compact(*rms)
    )]
    MaxBelowRms {
        /// The largest tip error (m).
        max: f64,
        /// The RMS tip error (m).
        rms: f64,
    },
}

/// Why shards do not make one sweep.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MergeProblem {
    /// No shard given.
    #[error("nothing to merge: no shard files given")]
    Nothing,
    /// Two shards of sweeps whose configurations differ.
    #[error(
        "{} and {} come from different sweeps (their configurations differ in {field})",
        first.display(),
        other.display()
    )]
    DifferentSweeps {
        /// The first shard file.
        first: PathBuf,
        /// The other.
        other: PathBuf,
        /// The first setting that differs (a scenario's key by its path, `scenario.duration`).
        field: String,
    },
    /// Two shards run with different contents of an input.
    #[error(
        "{} and {} were run with different contents of {input}: SHA-256 {}... against {}...; \
         merge only the shards of one sweep",
        first.display(),
        other.display(),
        &here[..here.len().min(12)],
        &there[..there.len().min(12)]
    )]
    DifferentContents {
        /// The first shard file.
        first: PathBuf,
        /// The other.
        other: PathBuf,
        /// The input, described.
        input: String,
        /// Its digest in the first.
        here: String,
        /// Its digest in the other.
        there: String,
    },
    /// Two shards of different splits.
    #[error(
        "{} is shard {shard} but {} is shard {first_shard}: every shard must come from the same \
         split",
        other.display(),
        first.display()
    )]
    DifferentSplits {
        /// The first shard file.
        first: PathBuf,
        /// Its shard.
        first_shard: Shard,
        /// The other.
        other: PathBuf,
        /// Its shard.
        shard: Shard,
    },
    /// One shard given twice.
    #[error("shard {shard} is given twice: {} and {}", first.display(), second.display())]
    Twice {
        /// The shard.
        shard: Shard,
        /// One file.
        first: PathBuf,
        /// The other.
        second: PathBuf,
    },
    /// Shards missing.
    #[error(
        "cannot merge: {} {}{} {} missing",
        if absent.len() + more > 1 { "shards" } else { "shard" },
        absent.iter().map(Shard::to_string).collect::<Vec<_>>().join(", "),
        if *more > 0 { format!(" and {more} more") } else { String::new() },
        if absent.len() + more > 1 { "are" } else { "is" }
    )]
    Missing {
        /// The first missing shards.
        absent: Vec<Shard>,
        /// How many more are missing.
        more: usize,
    },
    /// A shard file that ends before one of its runs.
    #[error("{} ends before run {run}", path.display())]
    EndsEarly {
        /// The file.
        path: PathBuf,
        /// The run.
        run: usize,
    },
}

impl Classify for StudyError {
    /// Always [`InvalidInput`](ErrorClass::InvalidInput): a study refuses its settings, its
    /// scenario, its files; a run that fails numerically is an outcome, not an error of the
    /// study.
    fn class(&self) -> ErrorClass {
        ErrorClass::InvalidInput
    }
}

impl StudyError {
    /// A [`StudyError::ShardFile`] error.
    pub(crate) fn shard_file(origin: &std::path::Path, problem: ShardProblem) -> Self {
        Self::ShardFile {
            origin: origin.to_path_buf(),
            problem,
        }
    }

    /// A [`StudyError::Io`] error.
    pub(crate) fn io(action: &'static str, path: &std::path::Path, cause: impl ToString) -> Self {
        Self::Io {
            action,
            path: path.to_path_buf(),
            cause: cause.to_string(),
        }
    }
}

/// A sweep setting out of its domain: the setting (a field of [`SweepSettings`](super::SweepSettings)) and what is
/// wrong with it, written `"{setting} {problem}"` (e.g. "seeds must be at least 1"); a front end
/// may name it its own way (`hrm sweep` writes its option, "--seeds must be at least 1").
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{setting} {problem}")]
pub struct SettingError {
    /// The setting's name, as in [`SweepSettings`](super::SweepSettings).
    pub setting: &'static str,
    /// What is wrong, a phrase that follows the name.
    pub problem: String,
}

impl SettingError {
    /// The error of `setting`, with `problem` the phrase that follows its name.
    pub(super) fn new(setting: &'static str, problem: impl Into<String>) -> Self {
        Self {
            setting,
            problem: problem.into(),
        }
    }
}
