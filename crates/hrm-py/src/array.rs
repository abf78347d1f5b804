//! numpy arrays in and out, and the batch driver shared by every method.
//!
//! Every method takes each input as one state of shape `(n,)` or a batch of shape `(N, n)` and
//! answers with the same leading dimension. Inputs are read as float64 in C order without a copy
//! when they already are; other layouts (Fortran order, strided views) are copied once, and other
//! real dtypes (integers, booleans, float32, lists) are converted; anything else (complex,
//! strings, objects) is refused with [`InvalidInput`](crate::errors::InvalidInput). A batch runs
//! with the GIL released, on all cores (rayon) from [`PARALLEL_MIN_STATES`] states on, each
//! worker with its own workspace; its first failing state (the lowest index) names itself in the
//! error message.

use crate::errors::{Error, Result};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyFloat;
use rayon::prelude::*;
use std::sync::Mutex;

/// Batches of at least this many states are spread over rayon's threads.
pub(crate) const PARALLEL_MIN_STATES: usize = 512;

/// States per rayon task (each task builds one workspace).
const CHUNK_STATES: usize = 512;

/// The most values one result may hold (2 GiB of float64); a larger batch is refused before
/// anything is allocated.
pub(crate) const MAX_OUTPUT_VALUES: usize = 1 << 28;

/// One input argument: a float64 array of one state `(width,)` or a batch `(N, width)`.
pub(crate) struct States<'py> {
    name: &'static str,
    array: PyReadonlyArrayDyn<'py, f64>,
    /// The values in C order when the array is not C-contiguous.
    copy: Option<Vec<f64>>,
    /// `None` for one state, `Some(N)` for a batch.
    batch: Option<usize>,
}

impl<'py> States<'py> {
    /// Reads `object` as states of `width` values each; `name` is the argument's name in messages.
    pub(crate) fn read(
        object: &Bound<'py, PyAny>,
        name: &'static str,
        width: usize,
    ) -> PyResult<Self> {
        let array = float64_array(object, name)?;
        let array = array
            .try_readonly()
            .map_err(|e| Error::input(format!("{name}: {e}")))?;
        let batch = match *array.shape() {
            [w] if w == width => None,
            [w] => {
                return Err(
                    Error::input(format!("{name} has {w} entries, expected {width}")).into(),
                );
            }
            [n, w] if w == width => Some(n),
            [n, w] => {
                return Err(Error::input(format!(
                    "{name} has shape ({n}, {w}), expected (N, {width})"
                ))
                .into());
            }
            ref shape => {
                return Err(Error::input(format!(
                    "{name} must be one state of shape ({width},) or a batch of shape (N, \
                     {width}), got an array of shape {shape:?}"
                ))
                .into());
            }
        };
        let copy = (!array.is_c_contiguous()).then(|| array.as_array().iter().copied().collect());
        Ok(Self {
            name,
            array,
            copy,
            batch,
        })
    }

    /// The values, state after state.
    pub(crate) fn values(&self) -> &[f64] {
        match &self.copy {
            Some(copy) => copy,
            None => self
                .array
                .as_slice()
                .expect("a C-contiguous array is a slice"),
        }
    }

    /// Whether the argument is a batch `(N, width)` rather than one state.
    pub(crate) fn is_batch(&self) -> bool {
        self.batch.is_some()
    }

    /// A description of the shape for messages: `(n,)` or `(N, n)`.
    fn shape_text(&self) -> String {
        match *self.array.shape() {
            [w] => format!("({w},)"),
            [n, w] => format!("({n}, {w})"),
            _ => unreachable!("checked in States::read"),
        }
    }
}

/// `object` as a float64 numpy array: itself when it is one, otherwise converted by
/// `numpy.asarray` if it holds booleans, integers or floats.
fn float64_array<'py>(
    object: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(array) = object.cast::<PyArrayDyn<f64>>() {
        return Ok(array.clone());
    }
    let py = object.py();
    let numpy = py.import("numpy")?;
    let array = numpy
        .call_method1("asarray", (object,))
        .map_err(|e| Error::input(format!("{name} is not an array of numbers: {e}")))?;
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "b" | "i" | "u" | "f") {
        return Err(Error::input(format!(
            "{name} must hold real numbers (float64, or a dtype convertible to it), got dtype {}",
            dtype.str()?
        ))
        .into());
    }
    let converted = array.call_method1("astype", ("float64",))?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// Checks that the inputs agree on being one state or batches of the same length, and returns
/// the batch length (`None` for one state).
fn common_batch(inputs: &[&States<'_>]) -> Result<Option<usize>> {
    let first = inputs[0];
    for other in &inputs[1..] {
        if other.batch != first.batch {
            return Err(Error::input(format!(
                "{} has shape {} but {} has shape {}: give every input as one state or all as \
                 batches of the same length",
                first.name,
                first.shape_text(),
                other.name,
                other.shape_text()
            )));
        }
    }
    Ok(first.batch)
}

/// A computed result: the batch length and `per_state` values for each state.
pub(crate) struct Output {
    batch: Option<usize>,
    values: Vec<f64>,
}

impl Output {
    /// The result as a numpy array of shape `(N, *shape)` for a batch and `shape` for one state;
    /// one state of a scalar result (`shape == []`) is a Python float.
    pub(crate) fn into_py<'py>(self, py: Python<'py>, shape: &[usize]) -> Bound<'py, PyAny> {
        if self.batch.is_none() && shape.is_empty() {
            return PyFloat::new(py, self.values[0]).into_any();
        }
        let full: Vec<usize> = self
            .batch
            .into_iter()
            .chain(shape.iter().copied())
            .collect();
        ArrayD::from_shape_vec(IxDyn(&full), self.values)
            .expect("the driver allocates N * per_state values")
            .into_pyarray(py)
            .into_any()
    }
}

/// Runs `compute(workspace, [row of each input], out)` for every state of `inputs`, writing
/// `per_state` values per state. One state runs at once on `shared`, the object's own workspace;
/// a batch runs with the GIL released, sequentially on `shared` or, from
/// [`PARALLEL_MIN_STATES`] states on, in parallel with a `fresh()` workspace per task.
pub(crate) fn evaluate<const K: usize, W: Send>(
    py: Python<'_>,
    inputs: [&States<'_>; K],
    per_state: usize,
    shared: &Mutex<W>,
    fresh: impl Fn() -> W + Sync,
    compute: impl Fn(&mut W, [&[f64]; K], &mut [f64]) -> Result<()> + Sync,
) -> PyResult<Output> {
    let batch = common_batch(&inputs)?;
    let widths: [usize; K] = std::array::from_fn(|k| match inputs[k].array.shape() {
        [.., w] => *w,
        [] => unreachable!("checked in States::read"),
    });
    let values: [&[f64]; K] = std::array::from_fn(|k| inputs[k].values());
    let rows = |state: usize| -> [&[f64]; K] {
        std::array::from_fn(|k| &values[k][state * widths[k]..(state + 1) * widths[k]])
    };
    let lock = || {
        shared
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    };
    let Some(n_states) = batch else {
        let mut out = vec![0.0; per_state];
        compute(&mut lock(), rows(0), &mut out)?;
        return Ok(Output { batch, values: out });
    };
    let total = n_states
        .checked_mul(per_state)
        .filter(|&t| t <= MAX_OUTPUT_VALUES)
        .ok_or_else(|| {
            Error::input(format!(
                "a batch of {n_states} states would give {n_states} x {per_state} result values, \
                 more than the limit of {MAX_OUTPUT_VALUES}: split the batch"
            ))
        })?;
    let mut out = vec![0.0; total];
    let run_chunk = |workspace: &mut W, first: usize, chunk: &mut [f64]| {
        for (i, state_out) in chunk.chunks_exact_mut(per_state).enumerate() {
            let state = first + i;
            compute(workspace, rows(state), state_out).map_err(|e| (state, e))?;
        }
        Ok(())
    };
    let result: std::result::Result<(), (usize, Error)> = py.detach(|| {
        if n_states < PARALLEL_MIN_STATES {
            return run_chunk(&mut lock(), 0, &mut out);
        }
        let failures: Vec<(usize, Error)> = out
            .par_chunks_mut(CHUNK_STATES * per_state)
            .enumerate()
            .map_init(&fresh, |workspace, (c, chunk)| {
                run_chunk(workspace, c * CHUNK_STATES, chunk)
            })
            .filter_map(std::result::Result::err)
            .collect();
        match failures.into_iter().min_by_key(|(state, _)| *state) {
            Some(failure) => Err(failure),
            None => Ok(()),
        }
    });
    result.map_err(|(state, error)| error.context(format!("state {state}")))?;
    Ok(Output { batch, values: out })
}
