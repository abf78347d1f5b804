//! `hrm.fuzzy`: Takagi-Sugeno systems (eqs 19-24), from `fuzzy-sugeno`.

use crate::args::count;
use crate::array::{States, evaluate_chunks};
use crate::errors::Error;
use fuzzy_sugeno::{
    AnalysisOptions, AnalysisReport, Evaluator, FuzzyError, FuzzySystem, MAX_SAMPLES_PER_INPUT,
};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyPermissionError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::Path;
use std::sync::Mutex;

/// A zero- or first-order Takagi-Sugeno fuzzy system (eqs 19-21), with MATLAB .fis interop.
///
/// Build one with System.from_fis(path_or_text) or hrm.fuzzy.paper_controller(). Inputs outside
/// a variable's range are evaluated as given, as MATLAB's evalfis does (the `hrm fis eval`
/// default), without a warning.
#[pyclass(module = "hrm.fuzzy", frozen)]
pub struct System {
    system: FuzzySystem,
    evaluator: Mutex<Evaluator>,
}

impl System {
    fn wrap(system: FuzzySystem) -> Self {
        Self {
            evaluator: Mutex::new(Evaluator::new(system.clone())),
            system,
        }
    }
}

/// Reads a `.fis` file as `hrm fis` does (a regular file of at most
/// [`sim_study::MAX_INPUT_FILE_BYTES`]), the path in front of every error.
fn read_fis(path: &Path) -> PyResult<(FuzzySystem, Vec<fuzzy_sugeno::FisNote>)> {
    let shown = path.display();
    let text = sim_study::read_text_file(path, sim_study::MAX_INPUT_FILE_BYTES).map_err(|e| {
        let message = format!("{shown}: {e}");
        match e.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            _ => PyOSError::new_err(message),
        }
    })?;
    let (system, notes) =
        FuzzySystem::from_fis_with_notes(&text).map_err(|e| Error::from(e).context(shown))?;
    Ok((system, notes))
}

/// Issues a `UserWarning` per note of a `.fis` file (`hrm fis` prints them as warnings): what
/// the file said that is accepted but neither kept nor used (an `AndMethod` no rule needs,
/// parameters beyond a function's, unknown keys).
fn warn_notes(py: Python<'_>, notes: &[fuzzy_sugeno::FisNote]) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for note in notes {
        let text =
            std::ffi::CString::new(format!(".fis {note}").replace('\0', " ")).unwrap_or_default();
        PyErr::warn(py, &category, &text, 2)?;
    }
    Ok(())
}

#[pymethods]
impl System {
    /// Loads a MATLAB .fis system: `path_or_text` is a path (str or os.PathLike) or the text of a
    /// .fis file (a str with a line break, or starting with "["). Raises InvalidInput for a
    /// malformed or unsupported file (the message names the line), FileNotFoundError or OSError
    /// when the file cannot be read (a path that is not a regular file, or of more than 16 MiB,
    /// is refused). What the file says that is accepted but neither kept nor used (an
    /// `AndMethod` no rule needs, parameters beyond a function's, unknown keys) is reported as a
    /// `UserWarning` per line, as `hrm fis` prints it.
    #[staticmethod]
    fn from_fis(path_or_text: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (system, notes) = match path_or_text.extract::<String>() {
            Ok(text) if text.contains('\n') || text.trim_start().starts_with('[') => {
                FuzzySystem::from_fis_with_notes(&text).map_err(Error::from)?
            }
            Ok(text) if text.is_empty() => {
                return Err(
                    Error::input("path_or_text is empty: give a path or a .fis text").into(),
                );
            }
            _ => read_fis(&crate::args::path(path_or_text, "path_or_text")?)?,
        };
        warn_notes(path_or_text.py(), &notes)?;
        Ok(Self::wrap(system))
    }

    /// The system as the text of a MATLAB .fis file (System.from_fis reads it back).
    fn to_fis(&self) -> String {
        self.system.to_fis()
    }

    /// `pickle` and `copy.deepcopy` support: the system rebuilt from its .fis text.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        Ok((slf.get_type().getattr("from_fis")?, (slf.get().to_fis(),)))
    }

    /// The system's name.
    #[getter]
    fn name(&self) -> &str {
        self.system.name()
    }

    /// The input variables' names, in order.
    #[getter]
    fn inputs(&self) -> Vec<String> {
        self.system
            .inputs()
            .iter()
            .map(|v| v.name.clone())
            .collect()
    }

    /// The output variables' names, in order.
    #[getter]
    fn outputs(&self) -> Vec<String> {
        self.system
            .outputs()
            .iter()
            .map(|v| v.name.clone())
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "System(name={:?}, inputs={}, outputs={}, rules={})",
            self.system.name(),
            self.system.inputs().len(),
            self.system.outputs().len(),
            self.system.rules().len()
        )
    }

    /// The outputs at input vector(s) `x`: shape (n_inputs,) gives (n_outputs,), (N, n_inputs)
    /// gives (N, n_outputs) (singleton fuzzification, rule firing, eq 21's defuzzifier). A batch
    /// runs through the evaluator's SIMD batch (several points per instruction), each row's
    /// outputs equal to those of evaluating it alone.
    fn eval<'py>(&self, py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let (n_in, n_out) = (self.system.inputs().len(), self.system.outputs().len());
        let x = States::read(x, "x", n_in)?;
        let fresh = || Ok(Evaluator::new(self.system.clone()));
        // The evaluator's batch (SIMD across points); it refuses non-finite outputs itself.
        let out = evaluate_chunks(
            py,
            [&x],
            n_out,
            self.system.rules().len() * n_in.max(1) * 4,
            &self.evaluator,
            fresh,
            |evaluator, [x], out| {
                evaluator.eval_batch(x, out).map_err(|error| match error {
                    FuzzyError::Batch { row, source } => (row, Error::from(*source)),
                    // The driver passes whole rows: a shape error cannot happen.
                    other => (0, Error::from(other)),
                })
            },
        )?;
        Ok(out.into_py(py, &[n_out]))
    }

    /// Wang's completeness, consistency and continuity checks of the rule base (`hrm fis
    /// check`), as a dict: "passed", "report" (the text `hrm fis check` prints) and one dict per
    /// property with its own "passed" and details (0-based rule, input, set and output indices).
    ///
    /// `coverage`: the degree to which some rule's antecedent must hold at every point;
    /// `samples`: evenly spaced samples per input (set landmarks are added); `max_jump`: the
    /// largest allowed jump between neighbouring rules, as a fraction of the output's range.
    #[pyo3(
        signature = (coverage=None, samples=None, max_jump=None),
        text_signature = "($self, coverage=0.5, samples=21, max_jump=1.0)"
    )]
    fn check<'py>(
        &self,
        py: Python<'py>,
        coverage: Option<&Bound<'py, PyAny>>,
        samples: Option<&Bound<'py, PyAny>>,
        max_jump: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (coverage, max_jump) = (
            crate::args::real_or(coverage, "coverage", 0.5)?,
            crate::args::real_or(max_jump, "max_jump", 1.0)?,
        );
        let samples = samples.map_or(Ok(21), |s| count(s, "samples", 2))?;
        if !(2..=MAX_SAMPLES_PER_INPUT).contains(&samples) {
            return Err(Error::input(format!(
                "samples must be at least 2 and at most {MAX_SAMPLES_PER_INPUT}, got {samples}"
            ))
            .into());
        }
        let options = AnalysisOptions {
            coverage,
            samples_per_input: samples,
            max_relative_jump: max_jump,
            ..AnalysisOptions::default()
        };
        let report = py
            .detach(|| self.system.analyze(&options))
            .map_err(|e| match e {
                // The library's option by the name this method gives it.
                FuzzyError::AnalysisOption {
                    name: "max_relative_jump",
                    requirement,
                    value,
                } => Error::input(format!(
                    "max_jump must {requirement}, got {}",
                    lane_math::Compact(value)
                )),
                other => Error::from(other),
            })?;
        report_dict(py, &report)
    }
}

/// The analysis report as nested dicts.
fn report_dict<'py>(py: Python<'py>, report: &AnalysisReport) -> PyResult<Bound<'py, PyDict>> {
    let completeness = PyDict::new(py);
    completeness.set_item("passed", report.completeness.passed())?;
    completeness.set_item("threshold", report.completeness.threshold)?;
    completeness.set_item("grid", report.completeness.grid.clone())?;
    let coverage = PyList::empty(py);
    for output in &report.completeness.outputs {
        let entry = PyDict::new(py);
        entry.set_item("weakest_strength", output.weakest_strength)?;
        entry.set_item("weakest_point", output.weakest_point.clone())?;
        entry.set_item("strongest_rules", output.strongest_rules.clone())?;
        coverage.append(entry)?;
    }
    completeness.set_item("outputs", coverage)?;

    let consistency = PyDict::new(py);
    consistency.set_item("passed", report.consistency.passed())?;
    let conflicts = PyList::empty(py);
    for conflict in &report.consistency.conflicts {
        let entry = PyDict::new(py);
        entry.set_item("rules", conflict.rules.to_vec())?;
        entry.set_item("output", conflict.output)?;
        conflicts.append(entry)?;
    }
    consistency.set_item("conflicts", conflicts)?;

    let continuity = PyDict::new(py);
    continuity.set_item("passed", report.continuity.passed())?;
    continuity.set_item("max_relative_jump", report.continuity.max_relative_jump)?;
    let jumps = PyList::empty(py);
    for jump in &report.continuity.outputs {
        match jump {
            None => jumps.append(py.None())?,
            Some(jump) => {
                let entry = PyDict::new(py);
                entry.set_item("rules", jump.rules.to_vec())?;
                entry.set_item("input", jump.input)?;
                entry.set_item("sets", jump.sets.to_vec())?;
                entry.set_item("jump", jump.jump)?;
                entry.set_item("relative", jump.relative)?;
                jumps.append(entry)?;
            }
        }
    }
    continuity.set_item("outputs", jumps)?;

    let dict = PyDict::new(py);
    dict.set_item("passed", report.passed())?;
    dict.set_item("completeness", completeness)?;
    dict.set_item("consistency", consistency)?;
    dict.set_item("continuity", continuity)?;
    dict.set_item("report", report.to_string())?;
    Ok(dict)
}

/// The paper's fuzzy controller (eqs 22-24, Table 1 as corrected in docs/theory.md): inputs
/// (da1, da2, a1_dot, a2_dot) (measured minus desired), outputs (tau1*, tau2*), 16 rules.
#[pyfunction]
pub(crate) fn paper_controller() -> System {
    System::wrap(fuzzy_sugeno::paper_controller())
}
