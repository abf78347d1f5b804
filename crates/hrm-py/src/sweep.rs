//! `hrm.Sweep`: the Monte Carlo sweeps of `hrm sweep` (`sim_study::study`) from Python, whole or
//! shard by shard, so that Slurm, Dask, Ray or `concurrent.futures` can schedule the shards
//! (docs/sweep.md). Runs release the GIL and use all cores (rayon).

use crate::errors::Error;
use crate::pool::{self, Cancel};
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim_study::ControllerKind;
use sim_study::study::{self, Shard, ShardFile, SweepConfig, SweepSettings};
use std::path::{Path, PathBuf};

/// A sweep: one scenario run with several controllers at several sensor-noise levels, `seeds`
/// noise realisations each (the `hrm sweep` study, docs/sweep.md).
///
/// Sweep(scenario, noise_levels, seeds, controllers=None, base_seed=1, rate_noise_ratio=10.0,
/// reference_noise_ratio=0.0): `scenario` is a Scenario (its duration applies; its noise and
/// seed are replaced per run) or a built-in name or TOML path; `controllers` defaults to every
/// controller, and names each at most once; noise levels (rad) must be distinct and ascending.
/// Every controller's simulation is built once here, so a bad setting raises InvalidInput at
/// once, naming the keyword ("seeds must be at least 1").
///
/// sweep.run() runs everything and returns the summary; sweep.run_shard(k, n) runs shard k of n
/// and returns the shard file's text, and Sweep.merge(shards) combines shard files into the
/// same summary, bit for bit.
#[pyclass(module = "hrm", frozen)]
pub struct Sweep {
    config: SweepConfig,
}

/// A library error or message as [`InvalidInput`](crate::errors::InvalidInput).
fn input(error: impl std::fmt::Display) -> PyErr {
    Error::input(error.to_string()).into()
}

/// `text` (a sweep's configuration as JSON) as Python objects, through the `json` module (which
/// keeps the order of its keys).
fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// The `summary.json` of a whole sweep (`hrm sweep`'s), as a dict built directly.
fn summary<'py>(py: Python<'py>, whole: &ShardFile) -> PyResult<Bound<'py, PyDict>> {
    let cells = study::cells(&whole.config, &whole.runs);
    let value = sim_study::summary_json::sweep(&whole.config, &cells);
    Ok(crate::value::to_py(py, &value)?.cast_into::<PyDict>()?)
}

/// A shard `index` of `count` (each 1 when not given), checked as `hrm sweep --shard K/N`
/// checks it.
fn shard(index: Option<&Bound<'_, PyAny>>, count: Option<&Bound<'_, PyAny>>) -> PyResult<Shard> {
    let number = |value: Option<&Bound<'_, PyAny>>, name: &str| {
        value.map_or(Ok(1), |v| crate::args::count(v, name, 1))
    };
    let (index, count) = (number(index, "index")?, number(count, "count")?);
    Shard::new(index, count).map_err(input)
}

impl Sweep {
    /// A sweep read back from its configuration's JSON, checked as [`SweepConfig::new`] checks
    /// a new one.
    fn checked(config: SweepConfig) -> PyResult<Self> {
        config.validate().map_err(input)?;
        config.check_builds().map_err(input)?;
        Ok(Self { config })
    }
}

#[pymethods]
impl Sweep {
    #[new]
    #[pyo3(signature = (
        scenario, noise_levels, seeds, controllers=None, base_seed=None, rate_noise_ratio=None,
        reference_noise_ratio=None
    ), text_signature = "(scenario, noise_levels, seeds, controllers=None, base_seed=1, \
        rate_noise_ratio=10.0, reference_noise_ratio=0.0)")]
    #[allow(clippy::too_many_arguments)]
    fn new(
        scenario: &Bound<'_, PyAny>,
        noise_levels: &Bound<'_, PyAny>,
        seeds: &Bound<'_, PyAny>,
        controllers: Option<&Bound<'_, PyAny>>,
        base_seed: Option<&Bound<'_, PyAny>>,
        rate_noise_ratio: Option<&Bound<'_, PyAny>>,
        reference_noise_ratio: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let rate_noise_ratio = crate::args::real_or(rate_noise_ratio, "rate_noise_ratio", 10.0)?;
        let reference_noise_ratio =
            crate::args::real_or(reference_noise_ratio, "reference_noise_ratio", 0.0)?;
        let scenario = match scenario.cast::<Scenario>() {
            Ok(s) => s.get().get(),
            Err(_) => {
                let name = crate::args::path(scenario, "scenario")?;
                sim_study::Scenario::resolve(&name.to_string_lossy()).map_err(input)?
            }
        };
        let controllers = match controllers {
            None => ControllerKind::ALL.to_vec(),
            Some(names) => controller_kinds(names)?,
        };
        let settings = SweepSettings {
            controllers,
            noise_levels: crate::args::reals(
                noise_levels,
                "noise_levels",
                study::MAX_NOISE_LEVELS,
            )?,
            rate_noise_ratio,
            reference_noise_ratio,
            seeds: crate::args::count(seeds, "seeds", 1)?,
            base_seed: base_seed.map_or(Ok(1), |s| crate::args::seed(s, "base_seed"))?,
        };
        let config = SweepConfig::new(scenario, settings).map_err(input)?;
        Ok(Self { config })
    }

    /// The number of runs: noise levels x controllers x seeds.
    #[getter]
    fn n_runs(&self) -> usize {
        self.config.runs().unwrap_or(0)
    }

    /// The indices of the runs shard `index` of `count` takes (1 <= index <= count): the runs i
    /// with i % count == index - 1, as `hrm sweep --shard index/count`.
    fn shard_runs(
        &self,
        index: &Bound<'_, PyAny>,
        count: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<usize>> {
        Ok(shard(Some(index), Some(count))?
            .indices(self.n_runs())
            .collect())
    }

    /// Runs shard `index` of `count` (the whole sweep by default) on all cores, with the GIL
    /// released, and returns the shard file's JSON text: what `hrm sweep --shard index/count`
    /// writes to shard-index-of-count.json. Runs that diverge are recorded as failed, not raised.
    /// Ctrl-C raises KeyboardInterrupt within 0.05 s; the runs under way finish in the background
    /// first (no new lock-step group starts).
    #[pyo3(signature = (index=None, count=None), text_signature = "($self, index=1, count=1)")]
    fn run_shard(
        &self,
        py: Python<'_>,
        index: Option<&Bound<'_, PyAny>>,
        count: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<String> {
        let shard = shard(index, count)?;
        // The files the scenario references as the configuration records them, before the runs
        // (a sweep configured, or unpickled, where the `.fis` has other contents) and after.
        if let Some(changed) = study::changed_input(&self.config).map_err(input)? {
            return Err(input(study::StudyError::InputChangedSinceConfigured {
                input: changed,
            }));
        }
        let cancel = Cancel::new();
        let file = pool::run(py, &cancel, || {
            study::run_shard_until(&self.config, shard, || {}, || cancel.is_set())
        })?
        .map_err(input)?;
        if let Some(changed) = study::changed_input(&self.config).map_err(input)? {
            return Err(input(study::StudyError::InputChanged { input: changed }));
        }
        file.to_json().map_err(input)
    }

    /// Runs the whole sweep and returns its summary: the dict `hrm sweep` writes to
    /// summary.json ({"config": ..., "cells": [...]}, one cell per noise level and controller).
    fn run<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let text = self.run_shard(py, None, None)?;
        // As `hrm sweep` does: the report from the runs as read back, like a merge's.
        let whole = ShardFile::parse(&text, Path::new("runs.json")).map_err(input)?;
        summary(py, &whole)
    }

    /// Combines shard files into the summary of the whole sweep (the summary.json of `hrm sweep
    /// merge`, equal to an unsharded run's). Each item of `shards` is a shard file's text (as
    /// run_shard returns it), a path to one, or a directory whose shard-*.json files are all
    /// taken. Shards of different sweeps or splits, a shard given twice or missing, and runs out
    /// of place raise InvalidInput naming the files concerned.
    #[staticmethod]
    fn merge<'py>(py: Python<'py>, shards: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        if shards.is_instance_of::<pyo3::types::PyString>() {
            return Err(pyo3::exceptions::PyTypeError::new_err(
                "shards must be a list of shard files' texts, paths or directories, got a str: \
                 give [text] for one shard",
            ));
        }
        let mut files = Vec::new();
        let mut paths = Vec::new();
        for (k, item) in shards.try_iter()?.enumerate() {
            let item = item?;
            match item.extract::<String>() {
                // A shard's text starts with its header's `{` (after a byte-order mark an
                // editor may have put there), a path does not.
                Ok(text)
                    if text
                        .trim_start_matches('\u{feff}')
                        .trim_start()
                        .starts_with('{') =>
                {
                    let origin = PathBuf::from(format!("shards[{k}]"));
                    files.push((
                        origin.clone(),
                        ShardFile::parse(&text, &origin).map_err(input)?,
                    ));
                }
                _ => paths.push(shard_path(&item, k)?),
            }
        }
        for path in study::shard_paths(&paths).map_err(input)? {
            let file = ShardFile::read(&path).map_err(input)?;
            files.push((path, file));
        }
        let whole = py.detach(|| study::merge(files)).map_err(input)?;
        summary(py, &whole)
    }

    /// The sweep's configuration as JSON (the "config" of its shard files and summary);
    /// Sweep.from_json reads it back.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.config).map_err(input)
    }

    /// A sweep from its configuration's JSON (Sweep.to_json, or the "config" of a shard file),
    /// checked as the constructor checks it.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let config: SweepConfig = serde_json::from_str(text)
            .map_err(|e| input(format!("malformed sweep configuration: {e}")))?;
        Self::checked(config)
    }

    /// The configuration as a dict: `hrm_version`, `scenario`, `settings` (the keywords),
    /// `inputs` (the SHA-256 of the scenario and its files).
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.to_json()?)
    }

    /// The scenario swept (a copy).
    #[getter]
    fn scenario(&self, py: Python<'_>) -> PyResult<Py<Scenario>> {
        Py::new(py, Scenario::wrap(self.config.scenario.clone()))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((
            slf.get_type().getattr("from_json")?,
            (slf.get().to_json()?,),
        ))
    }

    fn __repr__(&self) -> String {
        let c = &self.config;
        format!(
            "Sweep(scenario={:?}, controllers={:?}, noise_levels={:?}, seeds={}, base_seed={}, \
             runs={})",
            c.scenario.name,
            c.settings
                .controllers
                .iter()
                .map(|k| k.name())
                .collect::<Vec<_>>(),
            c.settings.noise_levels,
            c.settings.seeds,
            c.settings.base_seed,
            self.n_runs()
        )
    }
}

/// The controller kinds of `controllers`: a sequence of names (not one string), each a known
/// kind, the wrong type a `TypeError` and an unknown name an `InvalidInput`, both naming it.
fn controller_kinds(controllers: &Bound<'_, PyAny>) -> PyResult<Vec<ControllerKind>> {
    use pyo3::types::{PyBytes, PyString};
    let expected = "a sequence of controller names";
    if controllers.is_instance_of::<PyString>() || controllers.is_instance_of::<PyBytes>() {
        return Err(crate::args::wrong_type(
            "controllers",
            expected,
            controllers,
        ));
    }
    let items = controllers
        .try_iter()
        .map_err(|_| crate::args::wrong_type("controllers", expected, controllers))?;
    let mut kinds = Vec::new();
    for (i, item) in items.enumerate() {
        if i >= ControllerKind::ALL.len() {
            return Err(Error::input(format!(
                "controllers lists more than the {} kinds there are (each once)",
                ControllerKind::ALL.len()
            ))
            .into());
        }
        let name = crate::args::text(&item?, &format!("controllers[{i}]"))?;
        let kind = name.parse::<ControllerKind>();
        kinds.push(
            kind.map_err(|e| Error::from(e.renamed("controller", &format!("controllers[{i}]"))))?,
        );
    }
    Ok(kinds)
}

/// Item `k` of `Sweep.merge`'s shards as a path: a `str`, `bytes` (the file system's own
/// encoding) or an `os.PathLike`; anything else is a TypeError naming the item and its type.
fn shard_path(item: &Bound<'_, PyAny>, k: usize) -> PyResult<PathBuf> {
    if let Ok(bytes) = item.cast::<pyo3::types::PyBytes>() {
        use std::os::unix::ffi::OsStrExt;
        let bytes = bytes.as_bytes();
        // A shard file's text read in binary mode is not a path (it would be "read" as one).
        if bytes.trim_ascii_start().starts_with(b"{") {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "shards[{k}] is bytes holding a shard file's text, not a path: give the text as a \
                 str (bytes.decode())"
            )));
        }
        return Ok(PathBuf::from(std::ffi::OsStr::from_bytes(bytes)));
    }
    item.extract::<PathBuf>().map_err(|_| {
        let kind = item
            .get_type()
            .name()
            .map_or_else(|_| "?".to_owned(), |name| name.to_string());
        pyo3::exceptions::PyTypeError::new_err(format!(
            "shards[{k}] must be a shard file's text, or a path (str, bytes or os.PathLike) to \
             a shard file or a directory of them, got a {kind}"
        ))
    })
}
