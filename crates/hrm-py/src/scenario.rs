//! `hrm.Scenario`, `hrm.Settings` and `hrm.Run`: the closed-loop experiments of `sim-core`
//! (section 5 of the paper) from Python, closed by a built-in controller or a Python callable.
//!
//! A scenario's settings are its TOML keys (`sim_study::Scenario`), read and written as
//! attributes: `scenario.duration`, `scenario.arm.links`, `scenario.reference.sine.amplitude`.
//! A write is converted to a TOML value and the whole scenario is deserialised again, so a
//! wrong type or an unknown key is refused at once with the library's message; domains
//! (positive periods, array lengths, reachable paths) are checked when the scenario is run,
//! by `Scenario::build`, with the messages `hrm simulate` prints.

use crate::array::States;
use crate::errors::{Error, NumericalError};
use crate::pool::{self, Cancel};
use lane_math::{Classify, ErrorClass};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::{PyAttributeError, PyFileNotFoundError, PyOSError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use sim_core::controller::{ControlContext, Controller, ControllerError, ModalState};
use sim_core::reference::Reference;
use sim_core::{LoopHooks, SimError};
use sim_study::study::{RunOutcome, Stopped};
use sim_study::{ControllerKind, DeployFailure, ScenarioError};
use std::cell::Cell;
use std::sync::{Arc, Mutex, MutexGuard};

/// A closed-loop experiment: arm, modal family, reference, controller, integrator, noise and
/// limits, as in a scenario file (docs/python.md, "Scenarios").
///
/// Build one with Scenario.builtin(name) or Scenario.from_toml(path_or_text). Every key of the
/// TOML file is an attribute: scenario.duration, scenario.seed, scenario.arm.links,
/// scenario.reference.sine.amplitude; a table is a Settings view that writes through. A write
/// with a wrong type or an unknown key raises InvalidInput at once; values outside their domain
/// are refused by run(), with the messages `hrm simulate` prints. None removes an optional key.
#[pyclass(module = "hrm", frozen)]
pub struct Scenario {
    inner: Mutex<sim_study::Scenario>,
}

impl Scenario {
    /// A Python scenario holding `scenario`.
    pub(crate) fn wrap(scenario: sim_study::Scenario) -> Self {
        Self {
            inner: Mutex::new(scenario),
        }
    }

    fn lock(&self) -> MutexGuard<'_, sim_study::Scenario> {
        self.inner
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// A copy of the library's scenario.
    pub(crate) fn get(&self) -> sim_study::Scenario {
        self.lock().clone()
    }
}

/// A `ScenarioError` as a Python exception: an unreadable file is an `OSError`
/// (`FileNotFoundError` when it does not exist), anything else [`InvalidInput`].
fn scenario_error(error: ScenarioError) -> PyErr {
    match &error {
        ScenarioError::Io { path, .. } if !path.exists() => {
            PyFileNotFoundError::new_err(error.to_string())
        }
        ScenarioError::Io { .. } => PyOSError::new_err(error.to_string()),
        _ => Error::input(error.to_string()).into(),
    }
}

/// The scenario as a TOML table (every key it would write to a file).
fn table(scenario: &sim_study::Scenario) -> PyResult<toml::Table> {
    match toml::Value::try_from(scenario) {
        Ok(toml::Value::Table(table)) => Ok(table),
        Ok(_) => unreachable!("a scenario serialises to a table"),
        Err(e) => Err(Error::input(format!("the scenario cannot be written as TOML: {e}")).into()),
    }
}

/// The value at `path` (keys from the top) of `table`.
fn lookup<'a>(table: &'a toml::Table, path: &[String]) -> Option<&'a toml::Value> {
    let (first, rest) = path.split_first()?;
    rest.iter()
        .try_fold(table.get(first)?, |value, key| value.as_table()?.get(key))
}

/// The table at `path` of `table`, for writing.
fn lookup_mut<'a>(table: &'a mut toml::Table, path: &[String]) -> Option<&'a mut toml::Table> {
    path.iter()
        .try_fold(table, |table, key| table.get_mut(key)?.as_table_mut())
}

/// `table` with `value` at `path` + `key` (or the key removed for `None`), deserialised as a
/// scenario: the library's message, after the dotted key, when it does not fit.
fn with_setting(
    mut table: toml::Table,
    path: &[String],
    key: &str,
    value: Option<toml::Value>,
) -> Result<sim_study::Scenario, Error> {
    let dotted = dotted(path, key);
    let parent = lookup_mut(&mut table, path)
        .ok_or_else(|| Error::input(format!("{dotted}: the scenario has no such table")))?;
    match value {
        Some(value) => parent.insert(key.to_string(), value),
        None => parent.remove(key),
    };
    toml::Value::Table(table)
        .try_into::<sim_study::Scenario>()
        .map_err(|e| Error::input(format!("{dotted}: {}", e.message().trim_end())))
}

/// Refuses a view of the table at `path` that the scenario no longer has (replaced by a value,
/// or removed with its parent), as writing through it is refused.
fn check_table(current: &toml::Table, path: &[String]) -> Result<(), Error> {
    match lookup(current, path) {
        _ if path.is_empty() => Ok(()),
        Some(toml::Value::Table(_)) => Ok(()),
        _ => Err(Error::input(format!(
            "{}: the scenario has no such table",
            path.join(".")
        ))),
    }
}

/// `path.key` as a scenario file spells it.
fn dotted(path: &[String], key: &str) -> String {
    path.iter()
        .map(String::as_str)
        .chain([key])
        .collect::<Vec<_>>()
        .join(".")
}

/// Reads setting `key` of the table at `path`: a table is a [`Settings`] view, a value its
/// Python equivalent, an optional key that is not set `None`; a key the scenario does not have
/// is an `AttributeError`.
fn read_setting(
    py: Python<'_>,
    scenario: &Py<Scenario>,
    path: &[String],
    key: &str,
) -> PyResult<Py<PyAny>> {
    let current = table(&scenario.get().lock())?;
    check_table(&current, path)?;
    let mut full = path.to_vec();
    full.push(key.to_string());
    match lookup(&current, &full) {
        Some(toml::Value::Table(_)) => Ok(Py::new(
            py,
            Settings {
                scenario: scenario.clone_ref(py),
                path: full,
            },
        )?
        .into_any()),
        Some(value) => toml_to_py(py, value),
        None => {
            // A key the scenario may hold but does not: probing it with a value of a type no
            // setting has (an empty array of tables) fails with "unknown field" only if no such
            // setting exists.
            let probe = toml::Value::Array(vec![toml::Value::Table(toml::Table::new())]);
            match with_setting(current, path, key, Some(probe)) {
                Err(e) if e.message.contains("unknown field") => Err(PyAttributeError::new_err(
                    format!("the scenario has no setting {}", dotted(path, key)),
                )),
                _ => Ok(py.None()),
            }
        }
    }
}

/// Writes setting `key` of the table at `path` (`None` removes it).
fn write_setting(
    scenario: &Scenario,
    path: &[String],
    key: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let name = dotted(path, key);
    let value = if value.is_none() {
        None
    } else {
        Some(py_to_toml(value, &name)?)
    };
    let mut inner = scenario.lock();
    let updated = with_setting(table(&inner)?, path, key, value)?;
    *inner = updated;
    Ok(())
}

/// A TOML value as a Python object: tables as dicts, arrays as lists.
fn toml_to_py(py: Python<'_>, value: &toml::Value) -> PyResult<Py<PyAny>> {
    Ok(match value {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any().unbind(),
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any().unbind(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any().unbind(),
        toml::Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(toml_to_py(py, item)?)?;
            }
            list.into_any().unbind()
        }
        toml::Value::Table(table) => {
            let dict = PyDict::new(py);
            for (key, item) in table {
                dict.set_item(key, toml_to_py(py, item)?)?;
            }
            dict.into_any().unbind()
        }
    })
}

/// The deepest nesting of lists and dicts a setting may have (a scenario's deepest, a polyline
/// in a table of the reference, is 3): deeper values are refused before the recursion goes on.
const MAX_SETTING_DEPTH: usize = 16;

/// The most items a list (or array) of a setting may have, checked before it is converted.
const MAX_SETTING_ITEMS: usize = 1 << 20;

/// A Python value as a TOML value for setting `name`: bools, integers (the `seed` beyond 64
/// bits signed as a decimal string, as TOML writes large seeds; any other setting refused
/// there), floats, strings, paths, dicts, and lists,
/// tuples and numpy arrays of those, nested at most [`MAX_SETTING_DEPTH`] deep with at most
/// [`MAX_SETTING_ITEMS`] items per list.
fn py_to_toml(value: &Bound<'_, PyAny>, name: &str) -> PyResult<toml::Value> {
    to_toml_at(value, name, 0)
}

/// [`py_to_toml`] at nesting `depth`.
fn to_toml_at(value: &Bound<'_, PyAny>, name: &str, depth: usize) -> PyResult<toml::Value> {
    if depth > MAX_SETTING_DEPTH {
        return Err(Error::input(format!(
            "{name} is nested more than {MAX_SETTING_DEPTH} levels deep"
        ))
        .into());
    }
    let too_many = |items: usize| {
        Error::input(format!(
            "{name} has {items} items, more than the {MAX_SETTING_ITEMS} a setting may have"
        ))
    };
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if value.cast::<PyString>().is_ok() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if value.cast::<PyInt>().is_ok() {
        if let Ok(i) = value.extract::<i64>() {
            return Ok(toml::Value::Integer(i));
        }
        // The seed alone is a `u64`, which TOML writes beyond `i64` as a decimal string.
        return match value.extract::<u64>() {
            Ok(u) if name == "seed" => Ok(toml::Value::String(u.to_string())),
            Ok(u) => Err(Error::input(format!(
                "{name} must be at most {} (the largest integer a scenario setting holds), got {u}",
                i64::MAX
            ))
            .into()),
            Err(_) => {
                Err(Error::input(format!("{name}: an integer that does not fit 64 bits")).into())
            }
        };
    }
    if let Ok(f) = value.cast::<PyFloat>() {
        return Ok(toml::Value::Float(f.value()));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (key, item) in dict.iter() {
            let key: String = key
                .extract()
                .map_err(|_| Error::input(format!("{name}: table keys must be strings")))?;
            let item = to_toml_at(&item, &format!("{name}.{key}"), depth + 1)?;
            table.insert(key, item);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.cast::<PyList>().is_ok() || value.cast::<PyTuple>().is_ok() {
        let items = value.len()?;
        if items > MAX_SETTING_ITEMS {
            return Err(too_many(items).into());
        }
        let items = value
            .try_iter()?
            .map(|item| to_toml_at(&item?, name, depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if value.hasattr("__fspath__")? {
        let os = value.py().import("os")?;
        return to_toml_at(&os.call_method1("fspath", (value,))?, name, depth);
    }
    // numpy arrays and scalars (float32, int64, ...) become Python lists and numbers.
    if value.hasattr("tolist")? {
        if let Ok(size) = value.getattr("size").and_then(|s| s.extract::<usize>())
            && size > MAX_SETTING_ITEMS
        {
            return Err(too_many(size).into());
        }
        let plain = value.call_method0("tolist")?;
        if plain.cast::<PyList>().is_ok()
            || plain.cast::<PyFloat>().is_ok()
            || plain.cast::<PyInt>().is_ok()
        {
            return to_toml_at(&plain, name, depth);
        }
    }
    Err(Error::input(format!(
        "{name} cannot be set to a {}",
        value.get_type().name()?
    ))
    .into())
}

/// A table of a scenario (`scenario.arm`, `scenario.reference.sine`): its keys are attributes
/// that read and write the scenario itself.
///
/// A table the scenario does not hold yet (e.g. `initial`) is set whole, as a dict:
/// `scenario.initial = {"a": [0.1, 0.0]}`.
#[pyclass(module = "hrm", frozen)]
pub struct Settings {
    scenario: Py<Scenario>,
    path: Vec<String>,
}

#[pymethods]
impl Settings {
    fn __getattr__(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyAny>> {
        if name.starts_with("__") {
            return Err(PyAttributeError::new_err(name.to_string()));
        }
        read_setting(py, &self.scenario, &self.path, name)
    }

    fn __setattr__(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        write_setting(self.scenario.get(), &self.path, name, value)
    }

    fn __delattr__(&self, py: Python<'_>, name: &str) -> PyResult<()> {
        write_setting(
            self.scenario.get(),
            &self.path,
            name,
            &py.None().into_bound(py),
        )
    }

    /// `pickle` and `copy.deepcopy` support: the view rebuilt as `functools.reduce(getattr,
    /// path, scenario)`, on a copy of its scenario; a stale view (its table removed) raises as
    /// its reads do, rather than pickling to `None`.
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (Bound<'py, PyAny>, Vec<String>, Py<Scenario>),
    )> {
        check_table(&table(&self.scenario.get().lock())?, &self.path)?;
        Ok((
            py.import("functools")?.getattr("reduce")?,
            (
                py.import("builtins")?.getattr("getattr")?,
                self.path.clone(),
                self.scenario.clone_ref(py),
            ),
        ))
    }

    /// The table as a dict (a copy: writing to it does not change the scenario).
    fn to_dict(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let current = table(&self.scenario.get().lock())?;
        check_table(&current, &self.path)?;
        let value = lookup(&current, &self.path)
            .cloned()
            .unwrap_or(toml::Value::Table(toml::Table::new()));
        toml_to_py(py, &value)
    }

    /// The table's keys that are set.
    fn __dir__(&self) -> PyResult<Vec<String>> {
        let current = table(&self.scenario.get().lock())?;
        Ok(match lookup(&current, &self.path) {
            Some(toml::Value::Table(t)) => t.keys().cloned().collect(),
            _ => Vec::new(),
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let dict = self.to_dict(py)?;
        Ok(format!(
            "Settings({}: {})",
            self.path.join("."),
            dict.bind(py).repr()?
        ))
    }
}

/// A controller for `Scenario.run`: a built-in one by name, or a Python callable.
enum Choice {
    BuiltIn(ControllerKind),
    Python(Py<PyAny>),
}

impl Choice {
    fn read(controller: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Self>> {
        let Some(controller) = controller.filter(|c| !c.is_none()) else {
            return Ok(None);
        };
        if let Ok(name) = controller.extract::<String>() {
            let kind: ControllerKind = name.parse().map_err(Error::from)?;
            return Ok(Some(Choice::BuiltIn(kind)));
        }
        if controller.is_callable() {
            return Ok(Some(Choice::Python(controller.clone().unbind())));
        }
        Err(Error::input(format!(
            "controller must be a built-in controller's name ({}) or a callable f(t, a, a_dot, \
             ref) -> tau_star, got a {}",
            ControllerKind::ALL.map(ControllerKind::name).join(", "),
            controller.get_type().name()?
        ))
        .into())
    }
}

/// The reference a Python controller receives at a sample (reference noise included in `a`).
#[pyclass(module = "hrm", frozen)]
pub struct ReferenceSample {
    a: Py<PyArray1<f64>>,
    a_dot: Py<PyArray1<f64>>,
    a_ddot: Py<PyArray1<f64>>,
}

#[pymethods]
impl ReferenceSample {
    /// A reference sample of `a`, `a_dot` and `a_ddot` (each m numbers; copied), e.g. to test a
    /// controller outside a run.
    #[new]
    fn new(
        py: Python<'_>,
        a: &Bound<'_, PyAny>,
        a_dot: &Bound<'_, PyAny>,
        a_ddot: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let (a, a_dot, a_ddot) = (
            crate::args::reals(a, "a", backbone_kin::MAX_LINKS)?,
            crate::args::reals(a_dot, "a_dot", backbone_kin::MAX_LINKS)?,
            crate::args::reals(a_ddot, "a_ddot", backbone_kin::MAX_LINKS)?,
        );
        if a_dot.len() != a.len() || a_ddot.len() != a.len() {
            return Err(Error::input(format!(
                "a, a_dot and a_ddot must have the same length, got {}, {} and {}",
                a.len(),
                a_dot.len(),
                a_ddot.len()
            ))
            .into());
        }
        for (name, values) in [("a", &a), ("a_dot", &a_dot), ("a_ddot", &a_ddot)] {
            lane_math::check_all_finite(name, values).map_err(|e| Error::input(e.to_string()))?;
        }
        sim_core::check_coordinates("a", &a, a.len())
            .and_then(|()| sim_core::check_rates("a_dot", &a_dot, a_dot.len()))
            .map_err(|e| Error::input(e.to_string()))?;
        Ok(Self {
            a: PyArray1::from_vec(py, a).unbind(),
            a_dot: PyArray1::from_vec(py, a_dot).unbind(),
            a_ddot: PyArray1::from_vec(py, a_ddot).unbind(),
        })
    }

    /// `pickle` and `copy.deepcopy` support: the sample rebuilt from its three arrays.
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyAny>,
        (Py<PyArray1<f64>>, Py<PyArray1<f64>>, Py<PyArray1<f64>>),
    ) {
        let py = slf.py();
        let sample = slf.get();
        (
            slf.get_type().into_any(),
            (
                sample.a.clone_ref(py),
                sample.a_dot.clone_ref(py),
                sample.a_ddot.clone_ref(py),
            ),
        )
    }

    /// Desired modal coordinates (rad), shape (m,).
    #[getter]
    fn a(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.a.clone_ref(py)
    }

    /// Desired rates (rad/s), shape (m,).
    #[getter]
    fn a_dot(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.a_dot.clone_ref(py)
    }

    /// Desired accelerations (rad/s^2), shape (m,).
    #[getter]
    fn a_ddot(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.a_ddot.clone_ref(py)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "ReferenceSample(a={}, a_dot={}, a_ddot={})",
            self.a.bind(py).repr()?,
            self.a_dot.bind(py).repr()?,
            self.a_ddot.bind(py).repr()?
        ))
    }
}

/// A Python callable `f(t, a, a_dot, ref) -> tau_star` as a `sim-core` controller. An exception
/// it raises, or a return value that is not `m` finite numbers, is kept in `raised` and ends
/// the run (the run reports a controller failure); `Scenario.run` then raises it as it is, with
/// its traceback.
struct PythonController {
    function: Py<PyAny>,
    m: usize,
    raised: Arc<Mutex<Option<PyErr>>>,
}

/// The error the run reports when the Python controller raised (the exception itself is kept).
#[derive(Debug)]
struct Raised;

impl std::fmt::Display for Raised {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the Python controller raised an exception")
    }
}

impl std::error::Error for Raised {}

impl PythonController {
    fn call(&self, py: Python<'_>, ctx: &ControlContext<'_>, tau_star: &mut [f64]) -> PyResult<()> {
        let reference = ReferenceSample {
            a: PyArray1::from_slice(py, &ctx.reference.a).unbind(),
            a_dot: PyArray1::from_slice(py, &ctx.reference.a_dot).unbind(),
            a_ddot: PyArray1::from_slice(py, &ctx.reference.a_ddot).unbind(),
        };
        let out = self.function.bind(py).call1((
            ctx.t,
            PyArray1::from_slice(py, &ctx.measured.a),
            PyArray1::from_slice(py, &ctx.measured.a_dot),
            reference,
        ))?;
        let t = ctx.t;
        let context = |message: String| {
            Error::input(format!(
                "the controller's return value at t = {t} s: {message}"
            ))
        };
        let values = States::read_one(&out, "tau_star", self.m).map_err(|e| {
            if crate::array::passes_through(py, &e) {
                return e;
            }
            let message = e.value(py).str().map(|s| s.to_string()).unwrap_or_default();
            PyErr::from(context(message))
        })?;
        let values = values.values();
        if values.iter().any(|v| !v.is_finite()) {
            return Err(NumericalError::new_err(format!(
                "the controller returned a non-finite tau_star {values:?} at t = {} s",
                lane_math::Compact(t)
            )));
        }
        tau_star.copy_from_slice(values);
        Ok(())
    }
}

/// A built-in controller that fails at its next sample once the user pressed Ctrl-C, so that an
/// interrupted run stops (the interrupt is raised in place of the run's result).
struct Interruptible {
    inner: Box<dyn Controller>,
    cancel: Cancel,
}

/// The error of an [`Interruptible`] controller that was interrupted.
#[derive(Debug)]
struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted by the user")
    }
}

impl std::error::Error for Interrupted {}

impl Controller for Interruptible {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        if self.cancel.is_set() {
            return Err(Box::new(Interrupted));
        }
        self.inner.control(ctx, tau_star)
    }

    fn n_coords(&self) -> Option<usize> {
        self.inner.n_coords()
    }
}

/// A deployment's reference that fails at its next sample once the user pressed Ctrl-C, so that
/// an interrupted deployment stops (the interrupt is raised in place of the run's result).
struct InterruptibleReference {
    inner: Box<dyn Reference>,
    cancel: Cancel,
}

impl Reference for InterruptibleReference {
    fn n_coords(&self) -> usize {
        self.inner.n_coords()
    }

    fn sample(
        &mut self,
        t: f64,
        out: &mut sim_core::reference::ReferenceSample,
    ) -> Result<(), SimError> {
        if self.cancel.is_set() {
            return Err(SimError::from_controller(t, Box::new(Interrupted)));
        }
        self.inner.sample(t, out)
    }
}

impl Controller for PythonController {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        Python::attach(|py| self.call(py, ctx, tau_star)).map_err(|error| {
            *self
                .raised
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(error);
            Box::new(Raised) as ControllerError
        })
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.m)
    }
}

/// A Python callable `f(t, a, a_dot) -> tau_d` as the loop's disturbance hook: the external
/// joint torques (N m, one per joint) acting from the controller sample at `t` to the next, or
/// `None` for none. An exception it raises, or a return value that is not `n` finite numbers,
/// is kept in `raised` and ends the run (its torque is made non-finite, which stops the loop);
/// `Scenario.run` then raises it as it is.
struct PythonDisturbance {
    function: Py<PyAny>,
    n: usize,
    raised: Option<PyErr>,
}

impl PythonDisturbance {
    fn call(&self, py: Python<'_>, t: f64, state: &ModalState, tau: &mut [f64]) -> PyResult<bool> {
        let out = self.function.bind(py).call1((
            t,
            PyArray1::from_slice(py, &state.a),
            PyArray1::from_slice(py, &state.a_dot),
        ))?;
        if out.is_none() {
            return Ok(false);
        }
        let context = |message: String| {
            Error::input(format!(
                "the disturbance's return value at t = {t} s: {message}"
            ))
        };
        let values = States::read_one(&out, "tau", self.n).map_err(|e| {
            let message = e.value(py).str().map(|s| s.to_string()).unwrap_or_default();
            PyErr::from(context(message))
        })?;
        let values = values.values();
        if values.iter().any(|v| !v.is_finite()) {
            return Err(NumericalError::new_err(format!(
                "the disturbance returned a non-finite joint torque {values:?} at t = {} s",
                lane_math::Compact(t)
            )));
        }
        tau.copy_from_slice(values);
        Ok(true)
    }
}

impl LoopHooks for PythonDisturbance {
    fn disturbance(&mut self, t: f64, state: &ModalState, tau: &mut [f64]) -> bool {
        match Python::attach(|py| self.call(py, t, state, tau)) {
            Ok(applied) => applied,
            Err(error) => {
                self.raised = Some(error);
                tau.fill(f64::NAN);
                true
            }
        }
    }
}

#[pymethods]
impl Scenario {
    /// A scenario shipped with hrm, by name (Scenario.builtin_names()): "paper-tracking"
    /// (Figures 10-11), "paper-responses-step", "-sine", "-noise" (Figure 9), and
    /// "harmonic-tracking", "free-base-tracking", "spatial-tracking" and "spatial-long" (spatial
    /// arms), and "narrow-gap" and "spatial-clutter" (a [task] planned between obstacles, then
    /// tracked, by a planar and a spatial arm).
    #[staticmethod]
    fn builtin(name: &Bound<'_, PyAny>) -> PyResult<Self> {
        let name = crate::args::text(name, "name")?;
        Ok(Self::wrap(
            sim_study::Scenario::builtin(&name).map_err(scenario_error)?,
        ))
    }

    /// The names of the shipped scenarios.
    #[staticmethod]
    fn builtin_names() -> Vec<&'static str> {
        sim_study::Scenario::builtin_names().collect()
    }

    /// Reads a scenario: `path_or_text` is a path (str or os.PathLike; a relative controller.fis
    /// is taken relative to the file) or the TOML text itself (a str with a line break). Raises
    /// InvalidInput for malformed TOML (the message names the line and column), FileNotFoundError
    /// or OSError when the file cannot be read.
    #[staticmethod]
    fn from_toml(path_or_text: &Bound<'_, PyAny>) -> PyResult<Self> {
        let scenario = match path_or_text.extract::<String>() {
            Ok(text) if text.contains('\n') => sim_study::Scenario::from_toml(&text),
            Ok(text) if text.is_empty() => {
                return Err(Error::input(
                    "path_or_text is empty: give a path or a scenario's TOML",
                )
                .into());
            }
            _ => sim_study::Scenario::load(&crate::args::path(path_or_text, "path_or_text")?),
        };
        Ok(Self::wrap(scenario.map_err(scenario_error)?))
    }

    /// The scenario as TOML text (Scenario.from_toml reads it back; `hrm simulate --scenario`
    /// runs it).
    fn to_toml(&self) -> String {
        self.lock().to_toml()
    }

    /// The whole scenario as a dict of its settings (a copy).
    fn to_dict(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        toml_to_py(py, &toml::Value::Table(table(&self.lock())?))
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        Self::wrap(self.get())
    }

    /// The number of modal coordinates m: 2K with alpha0 fixed, 2K + 1 with it free; 4K for a
    /// spatial arm.
    #[getter]
    fn n_coords(&self) -> usize {
        self.lock().n_coords()
    }

    /// The names of the modal coordinates: a1, ..., a2K, then alpha0 when it is free; for a
    /// spatial arm az1, ..., az2K, ay1, ..., ay2K.
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.lock().coordinate_names()
    }

    fn __getattr__(slf: &Bound<'_, Self>, name: &str) -> PyResult<Py<PyAny>> {
        if name.starts_with("__") {
            return Err(PyAttributeError::new_err(name.to_string()));
        }
        read_setting(slf.py(), &slf.clone().unbind(), &[], name)
    }

    fn __setattr__(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        write_setting(self, &[], name, value)
    }

    fn __delattr__(&self, py: Python<'_>, name: &str) -> PyResult<()> {
        write_setting(self, &[], name, &py.None().into_bound(py))
    }

    /// The settings that are set, and the methods.
    fn __dir__(slf: &Bound<'_, Self>) -> PyResult<Vec<String>> {
        let mut names: Vec<String> = table(&slf.get().lock())?.keys().cloned().collect();
        for name in slf.get_type().dir()? {
            names.push(name.extract()?);
        }
        names.sort();
        names.dedup();
        Ok(names)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((slf.get_type().getattr("from_toml")?, (slf.get().to_toml(),)))
    }

    fn __repr__(&self) -> String {
        let s = self.lock();
        format!(
            "Scenario(name={:?}, controller={}, duration={}, coordinates={:?})",
            s.name,
            s.controller.kind,
            s.duration,
            s.coordinate_names()
        )
    }

    /// Runs the closed loop and returns a Run (time series and summary).
    ///
    /// `controller`: None for the scenario's own (`scenario.controller.kind`), a built-in name
    /// ("fuzzy", "pd", "computed-torque", "fuzzy-gc", "lqr", "mpc"), or a callable f(t, a, a_dot, ref) ->
    /// tau_star called at every controller sample with the time (s), the measured modal state
    /// (numpy arrays of shape (m,), sensor noise included) and the reference (a ReferenceSample
    /// with a, a_dot, a_ddot), returning m modal torques (N m); scenario.controller.period sets
    /// its sampling. An exception raised by the callable stops the run and propagates as it is;
    /// a return value of the wrong shape or dtype raises InvalidInput, a non-finite one
    /// NumericalError.
    ///
    /// A scenario whose settings are out of their domain raises InvalidInput before anything
    /// runs. A run that diverges (runaway tracking error, integrator failure) returns a Run
    /// whose `failure` says when and why, with the data up to the stop.
    ///
    /// `disturbance`: None, or a callable f(t, a, a_dot) -> tau_d called at every controller
    /// sample with the time (s) and the true modal state (numpy arrays of shape (m,)), returning
    /// the external joint torques (N m, shape (n,), one per joint: a push on the arm) that act
    /// until the next sample, or None for none. The loop adds their modal force J^T tau_d to the
    /// controller's tau_star; the recorded tau_star stays the controller's and the recorded
    /// joint torques are the actuators' (the push subtracted). Its exceptions and bad return
    /// values are raised as a controller's are.
    ///
    /// Built-in controllers run with the GIL released, and Ctrl-C stops them within 0.05 s
    /// (KeyboardInterrupt); a Python controller holds the GIL, and Ctrl-C interrupts it as any
    /// Python code. A Python disturbance takes the GIL when it is called.
    #[pyo3(signature = (controller=None, disturbance=None))]
    fn run(
        &self,
        py: Python<'_>,
        controller: Option<&Bound<'_, PyAny>>,
        disturbance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Run> {
        let _nested = NestedRun::enter()?;
        let mut scenario = self.get();
        let choice = Choice::read(controller)?;
        let mut hooks = match disturbance {
            None => None,
            Some(f) if f.is_none() => None,
            Some(f) if f.is_callable() => Some(PythonDisturbance {
                function: f.clone().unbind(),
                n: scenario.plant().map_err(Error::from)?.plant().n_joints(),
                raised: None,
            }),
            Some(f) => {
                return Err(Error::input(format!(
                    "disturbance must be None or a callable f(t, a, a_dot) -> tau, got {}",
                    f.get_type().name()?
                ))
                .into());
            }
        };
        let run = |simulation: &mut sim_core::Simulation, hooks: &mut Option<PythonDisturbance>| {
            match hooks {
                Some(hooks) => simulation.run_with(hooks),
                None => simulation.run(),
            }
        };
        let (result, label) = match choice {
            Some(Choice::Python(function)) => {
                let raised = Arc::new(Mutex::new(None));
                let controller = PythonController {
                    function,
                    m: scenario.n_coords(),
                    raised: Arc::clone(&raised),
                };
                // Planning a [task] may take seconds: without the GIL.
                let mut simulation = py
                    .detach(|| scenario.build_with_controller(Box::new(controller)))
                    .map_err(Error::from)?;
                let result = run(&mut simulation, &mut hooks);
                if let Some(error) = raised
                    .lock()
                    .unwrap_or_else(|poisoned| poisoned.into_inner())
                    .take()
                {
                    return Err(error);
                }
                (result, "python")
            }
            builtin => {
                if let Some(Choice::BuiltIn(kind)) = builtin {
                    scenario.controller.kind = kind;
                }
                let cancel = Cancel::new();
                let flag = cancel.clone();
                // Built (a [task] planned) and run without the GIL.
                let outcome = pool::run(py, &cancel, || {
                    let mut simulation = scenario.build_wrapping(move |inner| {
                        Box::new(Interruptible {
                            inner,
                            cancel: flag.clone(),
                        })
                    })?;
                    Ok::<_, SimError>(run(&mut simulation, &mut hooks))
                })?;
                (
                    outcome.map_err(Error::from)?,
                    scenario.controller.kind.name(),
                )
            }
        };
        if let Some(error) = hooks.and_then(|hooks| hooks.raised) {
            return Err(error);
        }
        let result = result.map_err(Stopped::from);
        Run::new(py, &scenario, label, result)
    }

    /// Runs the scenario's deployment (`[deploy]`: the arm on its insertion axis
    /// follow-the-leader into the channel, in joint space, by computed torque or with
    /// `controller.kind = "mpc"` by joint-space MPC) and returns a dict: `summary` (the
    /// `summary.json` of `hrm simulate`: the joint-space run's fields, `deploy_tip_error_m`,
    /// `deploy_shape_deviation_pct`, `deploy_min_wall_clearance_m`,
    /// `deploy_min_self_clearance_m` (`None` below three links), `deploy_length_m` and the
    /// plan's under `plan`), `t` (shape (K,)), `q`, `q_ref`, `tau` (shape (K, n + 1), the
    /// insertion first) and `points` (shape (K, n + 1, 2): the base and every link's end, as
    /// `links.csv`). Runs with the GIL released. A scenario without `[deploy]` or with keys a
    /// deployment does not use raises InvalidInput naming the key. A run that stops (runaway
    /// tracking error, integrator or controller failure) returns the data up to its last
    /// recorded sample, its summary with the extra keys "error" and "stopped_at_s" as the
    /// summary.json of `hrm simulate` (and `Run.failure` of `Scenario.run`); one that stops
    /// before its first recorded sample raises the error of its class. Ctrl-C stops the loop
    /// within about 0.05 s (KeyboardInterrupt); the plan before it runs to its end.
    fn run_deploy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let _nested = NestedRun::enter()?;
        let scenario = self.get();
        let cancel = Cancel::new();
        let flag = cancel.clone();
        let (run, stop) = DeployFailure::split(pool::run(py, &cancel, || {
            scenario.run_deploy_wrapping(|inner| {
                Box::new(InterruptibleReference {
                    inner,
                    cancel: flag,
                })
            })
        })?)
        .map_err(Error::from)?;
        let out = PyDict::new(py);
        let mut summary = sim_study::summary_json::deploy(&scenario, &run);
        if let Some(error) = &stop {
            summary = sim_study::summary_json::stopped(summary, error, &run.run);
        }
        out.set_item("summary", crate::value::to_py(py, &summary)?)?;
        let record = &run.run.record;
        let joints = run.run.summary.joint_error_rms.len();
        out.set_item("t", PyArray1::from_slice(py, &record.t))?;
        out.set_item("q", matrix(py, record.q.clone(), joints))?;
        out.set_item("q_ref", matrix(py, record.q_ref.clone(), joints))?;
        out.set_item("tau", matrix(py, record.tau.clone(), joints))?;
        let width = run.points.len().checked_div(record.t.len()).unwrap_or(0);
        let flat: Vec<f64> = run.points.iter().flatten().copied().collect();
        let points = numpy::ndarray::Array3::from_shape_vec((record.t.len(), width, 2), flat)
            .map_err(|e| Error::numerical(format!("deployment points: {e}")))?;
        out.set_item("points", points.into_pyarray(py))?;
        Ok(out)
    }
}

/// The height of a run's viewer in a notebook (pixels).
const VIEW_HEIGHT: u32 = 720;

/// A scene given as JSON text (docs/run-view.md: `{"title", "caption", "runs": [...]}`, each
/// run planar or spatial, with optional obstacles, channels, joint torques and series) as a
/// self-contained HTML page; any run, also one computed elsewhere. Refused with InvalidInput
/// naming the field when the data does not fit the format.
#[pyfunction]
pub fn view_html(scene: &str) -> PyResult<String> {
    let scene: run_view::Scene =
        serde_json::from_str(scene).map_err(|e| Error::input(format!("scene: {e}")))?;
    run_view::page(
        &scene.title,
        &scene.caption,
        std::slice::from_ref(&scene),
        run_view::PAGE_SAMPLES,
    )
    .map_err(|e| Error::input(e.to_string()).into())
}

/// The result of Scenario.run: the time series at the recording period (one row per recorded
/// controller sample) and the summary metrics.
///
/// A run that stopped early (runaway tracking error, integrator failure) has `failure` set to
/// the reason and holds the data up to the stop (a runaway error's sample included; a sample
/// whose controller or integration failed has no torque and is not); its summary has
/// the extra keys "error" and "stopped_at_s", as the summary.json of `hrm simulate` does.
#[pyclass(module = "hrm", frozen)]
pub struct Run {
    /// The time series, read-only numpy arrays.
    arrays: [Py<PyAny>; 8],
    /// The summary (`sim_study::summary_json::run`): each read of `summary` builds a fresh dict
    /// from it.
    summary: serde_json::Value,
    failure: Option<String>,
    controller: String,
    coordinates: Vec<String>,
    /// The run as the viewer draws it (`run-view`), with the scenario's name, or why it cannot
    /// be drawn (a run that stopped before its first sample, an arm of more links than the
    /// viewer draws): the run itself stands either way.
    view: Result<run_view::Scene, String>,
}

/// `values` (`rows x width`, row-major) as a numpy array of shape `(rows, width)`.
fn matrix(py: Python<'_>, values: Vec<f64>, width: usize) -> Py<PyAny> {
    let rows = values.len().checked_div(width).unwrap_or(0);
    Array2::from_shape_vec((rows, width), values)
        .expect("a record holds whole rows")
        .into_pyarray(py)
        .into_any()
        .unbind()
}

impl Run {
    fn new(
        py: Python<'_>,
        scenario: &sim_study::Scenario,
        controller: &str,
        result: RunOutcome,
    ) -> PyResult<Self> {
        let summary = sim_study::summary_json::run(&result);
        let (run, failure) = match result {
            Ok(run) => (run, None),
            // Memory the system refused (the run's record) is a `MemoryError`, not a failed run.
            Err(Stopped { error, .. }) if error.class() == ErrorClass::OutOfMemory => {
                return Err(Error::from(error).into());
            }
            Err(Stopped {
                error,
                partial: Some(run),
            }) => (*run, Some(error.to_string())),
            Err(Stopped {
                error,
                partial: None,
            }) => return Err(Error::from(error).into()),
        };
        let view = if run.record.is_empty() {
            let failure = failure.as_deref().unwrap_or("no samples");
            Err(format!(
                "the run has no sample to show: it stopped at its start ({failure})"
            ))
        } else {
            run_view::from_record(scenario, controller, &run.record, failure.as_deref())
                .map(|drawn| run_view::Scene {
                    title: format!("{} with {controller}", scenario.name),
                    caption: scenario.description.clone(),
                    runs: vec![drawn],
                })
                .map_err(|e| format!("the viewer cannot draw the run: {e}"))
        };
        let r = run.record;
        let (m, n) = (r.n_coords, r.n_joints);
        // A planar arm's tips in its plane, (x, y); a spatial arm's (x, y, z).
        let spatial = scenario.arm.kind == sim_study::ArmKind::Spatial;
        let tips = |tips: Vec<[f64; 2]>, z: Vec<f64>| {
            if spatial {
                let values = tips.iter().zip(&z).flat_map(|(p, &z)| [p[0], p[1], z]);
                matrix(py, values.collect(), 3)
            } else {
                matrix(py, tips.into_iter().flatten().collect(), 2)
            }
        };
        let arrays = [
            r.t.into_pyarray(py).into_any().unbind(),
            matrix(py, r.a, m),
            matrix(py, r.a_dot, m),
            matrix(py, r.a_ref, m),
            matrix(py, r.tau_star, m),
            matrix(py, r.joint_torques, n),
            tips(r.tip, r.tip_z),
            tips(r.tip_ref, r.tip_ref_z),
        ];
        Self::assemble(
            py,
            arrays,
            summary,
            failure,
            controller.to_string(),
            scenario.coordinate_names(),
            view,
        )
    }

    /// A run of these parts, its arrays made read-only.
    fn assemble(
        py: Python<'_>,
        arrays: [Py<PyAny>; 8],
        summary: serde_json::Value,
        failure: Option<String>,
        controller: String,
        coordinates: Vec<String>,
        view: Result<run_view::Scene, String>,
    ) -> PyResult<Self> {
        for array in &arrays {
            array
                .bind(py)
                .getattr("flags")?
                .setattr("writeable", false)?;
        }
        Ok(Self {
            arrays,
            summary,
            failure,
            controller,
            coordinates,
            view,
        })
    }
}

#[pymethods]
impl Run {
    /// Sample times (s), shape (K,).
    #[getter]
    fn t(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[0].clone_ref(py)
    }

    /// Modal coordinates (rad), shape (K, m).
    #[getter]
    fn a(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[1].clone_ref(py)
    }

    /// Modal rates (rad/s), shape (K, m).
    #[getter]
    fn a_dot(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[2].clone_ref(py)
    }

    /// The reference without reference noise (rad), shape (K, m).
    #[getter]
    fn a_ref(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[3].clone_ref(py)
    }

    /// Modal torques tau* held from each sample to the next (N m), shape (K, m).
    #[getter]
    fn tau_star(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[4].clone_ref(py)
    }

    /// Joint torques tau = M J a_ddot + C + G (eq 13) at each sample (N m), shape (K, n).
    #[getter]
    fn joint_torques(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[5].clone_ref(py)
    }

    /// The discrete chain's tip (m), shape (K, 2); (K, 3) for a spatial arm.
    #[getter]
    fn tip(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[6].clone_ref(py)
    }

    /// The reference tip: the backbone curve's end at a_ref, the path point for a path (m),
    /// shape (K, 2); for a spatial arm the chain's tip at a_ref, shape (K, 3).
    #[getter]
    fn tip_ref(&self, py: Python<'_>) -> Py<PyAny> {
        self.arrays[7].clone_ref(py)
    }

    /// The summary metrics: a dict with the keys of `hrm simulate`'s summary.json (a fresh
    /// copy at each read).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        Ok(crate::value::to_py(py, &self.summary)?.cast_into::<PyDict>()?)
    }

    /// `pickle` and `copy.deepcopy` support: the run rebuilt from its arrays, summary, failure,
    /// controller, coordinate names and viewer scene.
    #[allow(
        clippy::type_complexity,
        reason = "pickle's (callable, arguments) pair"
    )]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Vec<Py<PyAny>>,
            String,
            Option<String>,
            String,
            Vec<String>,
            String,
        ),
    )> {
        let py = slf.py();
        let run = slf.get();
        let view = serde_json::to_string(&run.view).map_err(|e| Error::input(e.to_string()))?;
        let summary = run.summary.to_string();
        Ok((
            slf.get_type().getattr("_restore")?,
            (
                run.arrays.iter().map(|a| a.clone_ref(py)).collect(),
                summary,
                run.failure.clone(),
                run.controller.clone(),
                run.coordinates.clone(),
                view,
            ),
        ))
    }

    /// The run `__reduce__` took apart (pickle's constructor; not for direct use).
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        arrays: Vec<Bound<'_, PyAny>>,
        summary: String,
        failure: Option<String>,
        controller: String,
        coordinates: Vec<String>,
        view: &str,
    ) -> PyResult<Self> {
        let arrays: [Py<PyAny>; 8] = arrays
            .into_iter()
            .map(|a| -> PyResult<Py<PyAny>> {
                // A copy: the pickled run's arrays stay its own.
                Ok(a.call_method0("copy")?.unbind())
            })
            .collect::<PyResult<Vec<_>>>()?
            .try_into()
            .map_err(|_| Error::input("a run has 8 arrays"))?;
        let view = serde_json::from_str(view).map_err(|e| Error::input(format!("view: {e}")))?;
        let summary =
            serde_json::from_str(&summary).map_err(|e| Error::input(format!("summary: {e}")))?;
        Self::assemble(py, arrays, summary, failure, controller, coordinates, view)
    }

    /// Why and when the run stopped early, or None for a run that completed.
    #[getter]
    fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }

    /// The controller: a built-in name, or "python" for a callable.
    #[getter]
    fn controller(&self) -> &str {
        &self.controller
    }

    /// The names of the modal coordinates (the columns of a, a_dot, a_ref, tau_star).
    #[getter]
    fn coordinates(&self) -> Vec<String> {
        self.coordinates.clone()
    }

    /// The run as a self-contained HTML page (no network): the arm link by link, coloured by
    /// joint torque, the reference path and the tip's trace, played in sync with the tip error,
    /// modal coordinates, tau* and joint torques (what `hrm view` writes). Save it to a file
    /// and open it in a browser. A run that stopped before its first sample, or that the
    /// viewer cannot draw (an arm of more than 1,000 links), raises InvalidInput saying which.
    fn view_html(&self) -> PyResult<String> {
        let view = self
            .view
            .as_ref()
            .map_err(|reason| Error::input(reason.clone()))?;
        run_view::page(
            &view.title,
            "",
            std::slice::from_ref(view),
            run_view::PAGE_SAMPLES,
        )
        .map_err(|e| Error::input(e.to_string()).into())
    }

    /// The page of `view_html` in an iframe: what Jupyter shows for a Run (None, so that
    /// Jupyter shows `repr`, for a run the viewer cannot draw).
    fn _repr_html_(&self) -> PyResult<Option<String>> {
        if self.view.is_err() {
            return Ok(None);
        }
        Ok(Some(run_view::iframe(&self.view_html()?, VIEW_HEIGHT)))
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let samples = self.arrays[0].bind(py).len().unwrap_or(0);
        match &self.failure {
            None => format!(
                "Run(controller={:?}, samples={samples}, completed)",
                self.controller
            ),
            Some(e) => format!(
                "Run(controller={:?}, samples={samples}, stopped: {e})",
                self.controller
            ),
        }
    }
}

thread_local! {
    /// The runs in progress on this thread: a Python controller or disturbance that runs a
    /// scenario nests them.
    static NESTED_RUNS: Cell<usize> = const { Cell::new(0) };
}

/// The most runs one thread may nest: each level takes Rust stack that Python's recursion limit
/// does not count (a controller that runs its own scenario again crashed the interpreter at
/// about 480 levels).
const MAX_NESTED_RUNS: usize = 16;

/// One level of [`NESTED_RUNS`], left when dropped.
struct NestedRun;

impl NestedRun {
    /// Enters a run, or raises `RecursionError` beyond [`MAX_NESTED_RUNS`].
    fn enter() -> PyResult<Self> {
        NESTED_RUNS.with(|runs| {
            if runs.get() >= MAX_NESTED_RUNS {
                return Err(pyo3::exceptions::PyRecursionError::new_err(format!(
                    "runs nested more than {MAX_NESTED_RUNS} deep: a controller or disturbance \
                     that runs a scenario runs one again"
                )));
            }
            runs.set(runs.get() + 1);
            Ok(NestedRun)
        })
    }
}

impl Drop for NestedRun {
    fn drop(&mut self) {
        NESTED_RUNS.with(|runs| runs.set(runs.get() - 1));
    }
}
