//! The outcome of each run, the shard file that stores a slice of a sweep's runs, and merging
//! shard files back into the whole sweep.
//!
//! A shard file (format 3) is JSON lines: a [`ShardHeader`] (format, configuration with the
//! digests of its inputs, shard), then one [`RunResult`] per line in index order. It is written
//! and read one run at a time ([`write_json_line`], [`ShardReader`]), so neither a sweep nor a
//! merge holds its runs in memory.

use super::error::{MergeProblem, MetricError, ShardProblem, StudyError};
use super::inputs;
use super::outcome::{RunMetrics, RunOutcome, Stopped};
use super::plan::{RunId, SweepConfig};
use super::shard::{FORMAT, MAX_SHARD_LINE_BYTES, MAX_SHARD_METRIC, MAX_SHARDS, Shard};
use crate::ControllerKind;
use lane_math::Compact;
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Most shard files a merge keeps open; beyond, each is opened for each run read from it.
const MAX_OPEN_SHARD_FILES: usize = 64;

/// Missing shards named in a message; the rest are counted.
const LISTED_MISSING_SHARDS: usize = 5;

/// A slice of a sweep held in memory: its configuration, which shard, and the runs of that
/// shard in index order. The whole sweep is shard 1/1. On disk it is a shard file of JSON lines
/// ([`ShardFile::to_json`]).
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
    pub outcome: StoredOutcome,
}

/// A run's [`RunOutcome`] as a shard file keeps it: the summary metrics of a run that completed,
/// or the message of its [`RunError`](super::RunError) and the time it reached. The typed error does not survive
/// the file (a merge reads it back as the text the sweep wrote), so this is the record of an
/// outcome, not an error type.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum StoredOutcome {
    /// It ran to the end.
    Completed(RunMetrics),
    /// It stopped (divergence, runaway error) or could not be built.
    Failed {
        /// Why, and when: the [`RunError`](super::RunError)'s message.
        error: String,
        /// Simulated time reached (s).
        simulated_s: f64,
    },
}

impl StoredOutcome {
    /// What a sweep keeps of `outcome`: the metrics of a run that completed with finite ones,
    /// otherwise the error's message and the simulated time reached.
    pub fn of(outcome: RunOutcome) -> Self {
        let stopped = match outcome {
            Ok(run) => match RunMetrics::from_summary(&run.summary) {
                Ok(metrics) => return StoredOutcome::Completed(metrics),
                Err(error) => Stopped {
                    error,
                    partial: Some(Box::new(run)),
                },
            },
            Err(stopped) => stopped,
        };
        StoredOutcome::Failed {
            error: lane_math::one_line(&stopped.error.to_string()),
            simulated_s: stopped.simulated_s(),
        }
    }
}

impl RunMetrics {
    /// Checks metrics read from a shard file as any input is checked: each finite, non-negative
    /// and at most [`MAX_SHARD_METRIC`]; the largest tip error at least its RMS (both are taken
    /// over the same samples); each modal RMS within the runaway bound `max_modal_error` that
    /// every sample of a completed run kept to. The error names the field and the value.
    pub fn check(&self, max_modal_error: f64) -> Result<(), MetricError> {
        for (name, value) in self.named() {
            if !(0.0..=MAX_SHARD_METRIC).contains(&value) {
                return Err(MetricError::OutOfRange { name, value });
            }
            if name == "modal_error_rms_rad" && value > max_modal_error {
                return Err(MetricError::AboveRunaway {
                    name,
                    value,
                    bound: max_modal_error,
                });
            }
        }
        if self.tip_error_max_m < self.tip_error_rms_m * (1.0 - 1e-12) {
            return Err(MetricError::MaxBelowRms {
                max: self.tip_error_max_m,
                rms: self.tip_error_rms_m,
            });
        }
        Ok(())
    }
}

impl RunResult {
    /// A run's entry.
    pub fn new(id: &RunId, outcome: StoredOutcome) -> Self {
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
            && self.noise_level.to_bits() == id.noise_level.to_bits()
            && self.controller == id.controller
            && self.seed_index == id.seed_index
            && self.seed == id.seed
    }
}

impl ShardFile {
    /// Parses a shard file's text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &Path) -> Result<Self, StudyError> {
        Self::collect(ShardReader::new(text.as_bytes(), origin)?)
    }

    /// Reads a shard file.
    pub fn read(path: &Path) -> Result<Self, StudyError> {
        Self::collect(ShardReader::open(path)?)
    }

    /// Every run of `reader`.
    fn collect<R: ShardSource>(mut reader: ShardReader<R>) -> Result<Self, StudyError> {
        let mut runs = Vec::new();
        while let Some(run) = reader.next_run()? {
            runs.push(run);
        }
        let ShardHeader {
            format,
            config,
            shard,
        } = reader.header;
        Ok(ShardFile {
            format,
            config,
            shard,
            runs,
        })
    }

    /// The file's text: the header line, then one line per run (what `hrm sweep` writes).
    pub fn to_json(&self) -> Result<String, StudyError> {
        let mut out = Vec::new();
        let header = ShardHeader {
            format: self.format.clone(),
            config: self.config.clone(),
            shard: self.shard,
        };
        write_json_line(&mut out, &header)?;
        for run in &self.runs {
            write_json_line(&mut out, run)?;
        }
        String::from_utf8(out).map_err(|e| StudyError::Write {
            cause: e.to_string(),
        })
    }
}

/// The first line of a shard file: what the runs on the following lines are of.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardHeader {
    /// [`FORMAT`].
    pub format: String,
    /// The sweep, with the digests of its inputs.
    pub config: SweepConfig,
    /// Which slice.
    pub shard: Shard,
}

impl ShardHeader {
    /// The header of `shard` of the sweep `config`.
    pub fn new(config: &SweepConfig, shard: Shard) -> Self {
        ShardHeader {
            format: FORMAT.into(),
            config: config.clone(),
            shard,
        }
    }

    /// The number of runs the shard holds.
    pub fn run_count(&self) -> usize {
        self.shard.run_count(self.config.runs().unwrap_or(0))
    }

    /// Checks the configuration and that the shard is one of a split the sweep can have.
    fn check(&self, origin: &Path) -> Result<(), StudyError> {
        self.config.validate().map_err(|e| {
            StudyError::shard_file(
                origin,
                ShardProblem::InvalidConfig {
                    source: Box::new(e),
                },
            )
        })?;
        let Shard { index, count } = self.shard;
        if !(1..=MAX_SHARDS).contains(&count) || !(1..=count).contains(&index) {
            return Err(StudyError::shard_file(
                origin,
                ShardProblem::OutsideSplit { index, count },
            ));
        }
        Ok(())
    }
}

/// Writes `value` as one line of compact JSON.
pub fn write_json_line<W: Write + ?Sized>(
    out: &mut W,
    value: &impl Serialize,
) -> Result<(), StudyError> {
    let written = |cause: String| StudyError::Write { cause };
    serde_json::to_writer(&mut *out, value)
        .map_err(|e| written(e.to_string()))
        .and_then(|()| out.write_all(b"\n").map_err(|e| written(e.to_string())))
}

/// What a shard file is read from: a buffered reader that may be closed between runs
/// ([`release`](Self::release)) and reopened where it stopped.
pub trait ShardSource: BufRead {
    /// Closes the underlying file until the next read, if there is one.
    fn release(&mut self) {}
}

impl ShardSource for &[u8] {}

/// A shard file on disk, read from where its reading stopped; reopened after a
/// [`release`](ShardSource::release).
#[derive(Debug)]
pub struct ShardInput {
    path: PathBuf,
    offset: u64,
    file: Option<BufReader<File>>,
}

impl ShardInput {
    /// The open file, reopened at the offset reached if it was released.
    fn file(&mut self) -> std::io::Result<&mut BufReader<File>> {
        let file = match self.file.take() {
            Some(file) => file,
            None => {
                let mut file = crate::open_regular_file(&self.path)?;
                file.seek(SeekFrom::Start(self.offset))?;
                BufReader::new(file)
            }
        };
        Ok(self.file.insert(file))
    }
}

impl Read for ShardInput {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.file()?.read(buf)?;
        self.offset += n as u64;
        Ok(n)
    }
}

impl BufRead for ShardInput {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.file()?.fill_buf()
    }

    fn consume(&mut self, amount: usize) {
        if let Some(file) = &mut self.file {
            file.consume(amount);
            self.offset += amount as u64;
        }
    }
}

impl ShardSource for ShardInput {
    fn release(&mut self) {
        self.file = None;
    }
}

/// Reads a shard file one run at a time: the header is read and checked when the reader is
/// made, then [`next_run`](Self::next_run) gives the shard's runs in order, each checked to
/// be the next run of the shard, and refuses a file cut short or holding more lines.
#[derive(Debug)]
pub struct ShardReader<R> {
    input: R,
    origin: PathBuf,
    header: ShardHeader,
    runs_read: usize,
    /// Blank lines (only ASCII whitespace: an editor's final newline, a CRLF copy's lone `\r`)
    /// skipped so far, counted into the line numbers of messages.
    blank_lines: usize,
    line: Vec<u8>,
}

impl ShardReader<ShardInput> {
    /// Opens the shard file `path` and reads its header; the file is closed until the first
    /// run is read.
    pub fn open(path: &Path) -> Result<Self, StudyError> {
        let file = crate::open_regular_file(path).map_err(|e| StudyError::io("read", path, e))?;
        let mut reader = Self::new(
            ShardInput {
                path: path.to_path_buf(),
                offset: 0,
                file: Some(BufReader::new(file)),
            },
            path,
        )?;
        reader.input.release();
        Ok(reader)
    }
}

impl<R: ShardSource> ShardReader<R> {
    /// Reads and checks the header from `input`; `origin` names the file in errors.
    pub fn new(mut input: R, origin: &Path) -> Result<Self, StudyError> {
        let refuse = |problem| StudyError::shard_file(origin, problem);
        let mut line = Vec::new();
        if read_line(&mut input, &mut line, origin, 1)? == 0 {
            return Err(refuse(ShardProblem::Empty));
        }
        // A byte-order mark an editor put before the header.
        if line.starts_with(b"\xef\xbb\xbf") {
            line.drain(..3);
        }
        let value: serde_json::Value = match serde_json::from_slice(&line) {
            Ok(value) => value,
            Err(e) => {
                // An older shard file is one pretty-printed object: `{`, then its format.
                let ahead = input.fill_buf().unwrap_or_default();
                let start = [&line[..], &ahead[..ahead.len().min(4096)]].concat();
                // A current header that is not JSON (a NaN written in by hand) is malformed.
                return Err(refuse(match declared_format(&start) {
                    Some(format) if format == FORMAT => ShardProblem::MalformedHeader {
                        cause: format!("its first line is not JSON ({e})"),
                    },
                    Some(format) => ShardProblem::Format {
                        format: Some(format),
                    },
                    None => ShardProblem::NotJson {
                        cause: e.to_string(),
                    },
                }));
            }
        };
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            other => {
                return Err(refuse(ShardProblem::Format {
                    format: other.map(str::to_string),
                }));
            }
        }
        // From the line itself, not the parsed value: a key given twice is refused, as in a
        // run's line (the value keeps the last).
        let header: ShardHeader = serde_json::from_slice(&line).map_err(|e| {
            refuse(ShardProblem::MalformedHeader {
                cause: e.to_string(),
            })
        })?;
        header.check(origin)?;
        Ok(ShardReader {
            input,
            origin: origin.to_path_buf(),
            header,
            runs_read: 0,
            blank_lines: 0,
            line,
        })
    }

    /// The header: the sweep and the shard.
    pub fn header(&self) -> &ShardHeader {
        &self.header
    }

    /// The shard's next run, `None` after its last. Refuses a malformed line, a run that is not
    /// the shard's next, a completed run with a modal error count other than the scenario's,
    /// a file cut short and lines after the last run; blank lines are skipped.
    pub fn next_run(&mut self) -> Result<Option<RunResult>, StudyError> {
        let mut line = self.runs_read + self.blank_lines + 2;
        let mut read = read_line(&mut self.input, &mut self.line, &self.origin, line)?;
        while read > 0 && self.line.iter().all(u8::is_ascii_whitespace) {
            self.blank_lines += 1;
            line += 1;
            read = read_line(&mut self.input, &mut self.line, &self.origin, line)?;
        }
        let refuse = |problem| StudyError::shard_file(&self.origin, problem);
        let shard = self.header.shard;
        let expected = self.header.run_count();
        if read == 0 {
            if self.runs_read < expected {
                return Err(refuse(ShardProblem::CutShort {
                    held: self.runs_read,
                    expected,
                    shard,
                }));
            }
            return Ok(None);
        }
        if self.runs_read == expected {
            return Err(refuse(ShardProblem::ExtraLines {
                line,
                expected,
                shard,
            }));
        }
        let run = run_from_json(&self.line).map_err(|cause| refuse(cause.at(line)))?;
        let i = shard.index - 1 + self.runs_read * shard.count;
        let wanted = self.header.config.run_at(i);
        if !run.matches(&wanted) {
            return Err(refuse(ShardProblem::RunOutOfPlace {
                line,
                run: run.index,
                expected: i,
                shard,
                held: position(run.controller, run.noise_level, run.seed_index, run.seed),
                wanted: position(
                    wanted.controller,
                    wanted.noise_level,
                    wanted.seed_index,
                    wanted.seed,
                ),
            }));
        }
        let m = self.header.config.scenario.n_coords();
        if let StoredOutcome::Completed(metrics) = &run.outcome {
            if metrics.modal_error_rms_rad.len() != m {
                return Err(refuse(ShardProblem::ModalCount {
                    run: run.index,
                    got: metrics.modal_error_rms_rad.len(),
                    expected: m,
                }));
            }
            metrics
                .check(self.header.config.scenario.limits.max_modal_error)
                .map_err(|source| {
                    refuse(ShardProblem::Metric {
                        line,
                        run: run.index,
                        source,
                    })
                })?;
        }
        // A failed run's message is what a sweep writes: one line, its length bounded, so
        // that neither the terminal nor `table.txt` shows a shard's control characters and no
        // merge carries a message of megabytes into every output.
        if let StoredOutcome::Failed { error, .. } = &run.outcome
            && (!lane_math::is_one_line(error) || error.trim().is_empty())
        {
            return Err(refuse(ShardProblem::FailureMessage {
                line,
                run: run.index,
            }));
        }
        let duration = self.header.config.scenario.duration;
        // A run stops at or before its end (the clock's rounding aside).
        if let StoredOutcome::Failed { simulated_s, .. } = &run.outcome
            && !(simulated_s.is_finite()
                && simulated_s.is_sign_positive()
                && *simulated_s <= duration * (1.0 + 1e-9))
        {
            return Err(refuse(ShardProblem::SimulatedTime {
                duration,
                line,
                run: run.index,
                value: *simulated_s,
            }));
        }
        self.runs_read += 1;
        Ok(Some(run))
    }
}

/// Reads one line (its newline kept) of at most [`MAX_SHARD_LINE_BYTES`] into `line`; returns
/// its length, 0 at the end of the file.
fn read_line(
    input: &mut impl BufRead,
    line: &mut Vec<u8>,
    origin: &Path,
    number: usize,
) -> Result<usize, StudyError> {
    line.clear();
    let n = input
        .take(MAX_SHARD_LINE_BYTES as u64 + 1)
        .read_until(b'\n', line)
        .map_err(|e| StudyError::io("read", origin, e))?;
    if n > MAX_SHARD_LINE_BYTES {
        return Err(StudyError::shard_file(
            origin,
            ShardProblem::LineTooLong { line: number },
        ));
    }
    Ok(n)
}

/// The value of the first `"format": "..."` in `text` (an older, pretty-printed shard file).
fn declared_format(text: &[u8]) -> Option<String> {
    let text = String::from_utf8_lossy(text);
    let after = text.split_once("\"format\"")?.1.trim_start();
    let value = after.strip_prefix(':')?.trim_start().strip_prefix('"')?;
    Some(value.split_once('"')?.0.to_string())
}

/// The shard files named by `inputs`: files as given, and every `shard-*.json` in a directory.
pub fn shard_paths(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, StudyError> {
    let mut paths = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).map_err(|e| StudyError::io("list", input, e))?;
            let mut found: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                        n.starts_with("shard-") && n.ends_with(".json") && p.is_file()
                    })
                })
                .collect();
            if found.is_empty() {
                return Err(StudyError::NoShardFiles { dir: input.clone() });
            }
            found.sort();
            paths.extend(found);
        } else {
            paths.push(input.clone());
        }
    }
    Ok(paths)
}

/// Combines shards held in memory into the whole sweep (shard 1/1, runs in index order), as
/// [`merge_readers`] does with files; `PathBuf`s name the shards in errors.
pub fn merge(shards: Vec<(PathBuf, ShardFile)>) -> Result<ShardFile, StudyError> {
    let texts = shards
        .into_iter()
        .map(|(path, file)| file.to_json().map(|text| (path, text)))
        .collect::<Result<Vec<_>, _>>()?;
    let readers = texts
        .iter()
        .map(|(path, text)| ShardReader::new(text.as_bytes(), path))
        .collect::<Result<Vec<_>, _>>()?;
    let mut runs = Vec::new();
    let header = merge_readers(readers, |run| {
        runs.push(run);
        Ok(())
    })?;
    Ok(ShardFile {
        format: header.format,
        config: header.config,
        shard: header.shard,
        runs,
    })
}

/// Combines shards into the whole sweep: refuses shards of different sweeps (naming the first
/// setting that differs, or the referenced file whose content differs), of different splits, a
/// shard given twice and missing shards, then passes every run to `sink` in index order, read
/// from the files as it comes (a file cut short or with a run out of place is refused by its
/// reader). Returns the header of the whole sweep (shard 1/1).
pub fn merge_readers<R: ShardSource>(
    mut shards: Vec<ShardReader<R>>,
    mut sink: impl FnMut(RunResult) -> Result<(), StudyError>,
) -> Result<ShardHeader, StudyError> {
    let Some(first) = shards.first() else {
        return Err(StudyError::Merge(MergeProblem::Nothing));
    };
    let (first_path, config) = (first.origin.clone(), first.header.config.clone());
    let (first_shard, count) = (first.header.shard, first.header.shard.count);
    let refuse = |problem| Err(StudyError::Merge(problem));
    for other in &shards {
        let (first, other_path) = (first_path.clone(), other.origin.clone());
        match config.first_difference(&other.header.config).as_deref() {
            None => {}
            Some("inputs") => {
                let (here, there) = (&config.inputs, &other.header.config.inputs);
                return refuse(match inputs::first_changed(here, there) {
                    Some((input, there)) => MergeProblem::DifferentContents {
                        first,
                        other: other_path,
                        input: input.describe(),
                        here: input.sha256.clone(),
                        there: there.to_string(),
                    },
                    // Lists of different lengths: the settings naming files differ.
                    None => MergeProblem::DifferentSweeps {
                        first,
                        other: other_path,
                        field: "inputs".to_string(),
                    },
                });
            }
            Some(field) => {
                return refuse(MergeProblem::DifferentSweeps {
                    first,
                    other: other_path,
                    field: field.to_string(),
                });
            }
        }
        if other.header.shard.count != count {
            return refuse(MergeProblem::DifferentSplits {
                first,
                first_shard,
                other: other_path,
                shard: other.header.shard,
            });
        }
    }
    // The scenario as `hrm sweep` checks it: a header edited by hand (with its digest) is
    // read, but a sweep that could not have run is not merged.
    config.check_builds().map_err(|source| {
        StudyError::shard_file(
            &first_path,
            ShardProblem::InvalidConfig {
                source: Box::new(source),
            },
        )
    })?;
    shards.sort_by_key(|s| s.header.shard.index);
    if let Some(pair) = shards
        .windows(2)
        .find(|w| w[0].header.shard == w[1].header.shard)
    {
        return refuse(MergeProblem::Twice {
            shard: pair[0].header.shard,
            first: pair[0].origin.clone(),
            second: pair[1].origin.clone(),
        });
    }
    if shards.len() < count {
        let mut given = shards.iter().map(|s| s.header.shard.index).peekable();
        let absent: Vec<Shard> = (1..=count)
            .filter(|&k| given.next_if_eq(&k).is_none())
            .take(LISTED_MISSING_SHARDS)
            .map(|index| Shard { index, count })
            .collect();
        let more = count - shards.len() - absent.len();
        return refuse(MergeProblem::Missing { absent, more });
    }
    let keep_open = count <= MAX_OPEN_SHARD_FILES;
    for i in 0..config.runs().unwrap_or(0) {
        let reader = &mut shards[i % count];
        let run = reader.next_run()?.ok_or_else(|| {
            StudyError::Merge(MergeProblem::EndsEarly {
                path: reader.origin.clone(),
                run: i,
            })
        })?;
        if !keep_open {
            reader.input.release();
        }
        sink(run)?;
    }
    for reader in &mut shards {
        reader.next_run()?;
        reader.input.release();
    }
    Ok(ShardHeader::new(&config, Shard::WHOLE))
}

/// A run's position fields as a message names them: "controller pd, noise level 0.01, seed index
/// 2, seed 1234".
fn position(controller: ControllerKind, noise_level: f64, seed_index: usize, seed: u64) -> String {
    format!(
        "controller {}, noise level {}, seed index {seed_index}, seed {seed}",
        controller.name(),
        Compact(noise_level)
    )
}

/// A run line read as JSON; the error names the field at fault (`outcome: ...`) where the
/// parser's message does not.
fn run_from_json(line: &[u8]) -> Result<RunResult, NotARun> {
    let mut parser = serde_json::Deserializer::from_slice(line);
    let run = serde_path_to_error::deserialize(&mut parser).map_err(|e| {
        let path = e.path().to_string();
        let cause = e.into_inner().to_string();
        NotARun(if path == "." {
            cause
        } else {
            format!("{path}: {cause}")
        })
    })?;
    parser.end().map_err(|e| NotARun(e.to_string()))?;
    Ok(run)
}

/// Why a line is not a run, before its line number is known.
struct NotARun(String);

impl NotARun {
    /// The [`ShardProblem::NotARun`] of line `line`.
    fn at(self, line: usize) -> ShardProblem {
        ShardProblem::NotARun {
            line,
            cause: self.0,
        }
    }
}
