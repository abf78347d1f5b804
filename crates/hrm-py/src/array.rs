//! numpy arrays in and out, and the batch driver shared by every method.
//!
//! Every method takes each input as one state of shape `(n,)` or a batch of shape `(N, n)` and
//! answers with the same leading dimension. Inputs are read as float64 in C order without a copy
//! when they already are; other layouts (Fortran order, strided views) are copied once, and other
//! real dtypes (integers, booleans, float32, lists) are converted; anything else (complex,
//! strings, objects) is refused with [`InvalidInput`](crate::errors::InvalidInput), and so are
//! rates beyond the scale a run resolves, as `hrm eval` refuses them. A batch runs
//! with the GIL released, on all cores (rayon) from [`PARALLEL_MIN_STATES`] states on, each
//! worker with its own workspace; its first failing state (the lowest index) names itself in the
//! error message.

use crate::errors::{Error, Result};
use crate::pool::{self, Cancel};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{
    IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyException, PyMemoryError};
use pyo3::prelude::*;
use pyo3::types::PyFloat;
use rayon::prelude::*;
use std::sync::Mutex;

/// Batches of at least this many states are spread over rayon's threads.
pub(crate) const PARALLEL_MIN_STATES: usize = 512;

/// The most states per chunk of a batch (rayon task; each task builds one workspace).
const CHUNK_STATES: usize = 512;

/// The work (floating-point operations, as the methods estimate it) of one chunk of a batch,
/// when that is fewer than [`CHUNK_STATES`] states: a few milliseconds, the delay of Ctrl-C.
const WORK_PER_CHUNK: usize = 1 << 22;

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
        Self::read_shaped(object, name, width, false)
    }

    /// Reads `object` as one state of `width` values (a callable's return value: a batch is
    /// refused as any other shape).
    pub(crate) fn read_one(
        object: &Bound<'py, PyAny>,
        name: &'static str,
        width: usize,
    ) -> PyResult<Self> {
        Self::read_shaped(object, name, width, true)
    }

    /// [`read`](Self::read), or [`read_one`](Self::read_one) when `one_state`.
    fn read_shaped(
        object: &Bound<'py, PyAny>,
        name: &'static str,
        width: usize,
        one_state: bool,
    ) -> PyResult<Self> {
        let array = float64_array(object, name, MAX_OUTPUT_VALUES)?;
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
            ref shape if one_state => {
                return Err(Error::input(format!(
                    "{name} must have shape ({width},), got an array of shape {shape:?}"
                ))
                .into());
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
        let copy = if array.is_c_contiguous() && array.as_slice().is_ok() {
            None
        } else {
            let view = array.as_array();
            let mut copy = lane_math::try_with_capacity(view.len(), name).map_err(Error::from)?;
            copy.extend(view.iter().copied());
            Some(copy)
        };
        let states = Self {
            name,
            array,
            copy,
            batch,
        };
        // Rates and modal coordinates beyond the scale a run resolves are refused as `hrm eval`
        // refuses them (a free base angle, the last entry of `a`, with the coordinates: a run
        // bounds it too).
        let scale = if sim_core::RATE_NAMES.contains(&name) {
            sim_core::check_rates(name, states.values(), width)
        } else if name == "a" {
            sim_core::check_coordinates(name, states.values(), width)
        } else {
            Ok(())
        };
        scale.map_err(|e| Error::input(e.to_string()))?;
        Ok(states)
    }

    /// Reads each `(object, name)` argument as states of `width` values (see [`States::read`]);
    /// the first argument that fails names itself in the error.
    pub(crate) fn read_all<const K: usize>(
        arguments: [(&Bound<'py, PyAny>, &'static str); K],
        width: usize,
    ) -> PyResult<[Self; K]> {
        let mut states = Vec::with_capacity(K);
        for (object, name) in arguments {
            states.push(Self::read(object, name, width)?);
        }
        Ok(states.try_into().ok().expect("one States per argument"))
    }

    /// The values, state after state.
    pub(crate) fn values(&self) -> &[f64] {
        match &self.copy {
            Some(copy) => copy,
            None => self
                .array
                .as_slice()
                .expect("checked in States::read: the array is a slice"),
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

/// Whether `error` must reach the caller as it is rather than inside an
/// [`InvalidInput`](crate::errors::InvalidInput): a `KeyboardInterrupt` (or any other
/// `BaseException` that is not an `Exception`, such as `SystemExit`) and a `MemoryError`.
pub(crate) fn passes_through(py: Python<'_>, error: &PyErr) -> bool {
    !error.is_instance_of::<PyException>(py) || error.is_instance_of::<PyMemoryError>(py)
}

/// Whether numpy `array` can be read in place: its data and strides are multiples of 8 bytes
/// (a field of a packed structured array is not, and has to be copied first).
fn aligned(array: &Bound<'_, PyArrayDyn<f64>>) -> bool {
    let align = align_of::<f64>();
    (array.data() as usize).is_multiple_of(align)
        && array
            .strides()
            .iter()
            .all(|&stride| stride.unsigned_abs().is_multiple_of(align))
}

/// `object` as an aligned float64 numpy array: itself when it is one, otherwise converted by
/// `numpy.asarray` if it holds booleans, integers or floats (an unaligned view is copied). A
/// numpy masked array with masked entries is refused (its mask cannot be honoured), one
/// without is read as its data. A `KeyboardInterrupt` or `MemoryError` raised while the object
/// is converted propagates as it is. More than `max_len` values are refused before any copy.
pub(crate) fn float64_array<'py>(
    object: &Bound<'py, PyAny>,
    name: &str,
    max_len: usize,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = object.py();
    let exact = object.is_exact_instance_of::<PyUntypedArray>();
    if exact
        && let Ok(array) = object.cast::<PyArrayDyn<f64>>()
        && aligned(array)
    {
        check_size(array.len(), name, max_len)?;
        return Ok(array.clone());
    }
    let numpy = py.import("numpy")?;
    let wrap = |e: PyErr| {
        if passes_through(py, &e) {
            e
        } else {
            Error::input(format!("{name} is not an array of numbers: {e}")).into()
        }
    };
    let mut object = object.clone();
    if !exact && object.hasattr("mask").map_err(wrap)? {
        let masked = numpy.getattr("ma")?;
        if masked
            .call_method1("is_masked", (&object,))
            .map_err(wrap)?
            .is_truthy()?
        {
            return Err(Error::input(format!(
                "{name} is a masked array with masked entries, which hrm cannot skip: fill \
                 them (x.filled(value)) or leave those states out"
            ))
            .into());
        }
        object = masked.call_method1("getdata", (&object,)).map_err(wrap)?;
    }
    let array = numpy.call_method1("asarray", (&object,)).map_err(wrap)?;
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "b" | "i" | "u" | "f") {
        return Err(Error::input(format!(
            "{name} must hold real numbers (float64, or a dtype convertible to it), got dtype {}",
            dtype.str()?
        ))
        .into());
    }
    // A broadcast view of a few bytes may stand for billions of values: bounded before the copy.
    check_size(array.getattr("size")?.extract()?, name, max_len)?;
    // `astype` copies into a fresh, aligned array (also when the dtype already is float64).
    let converted = array.call_method1("astype", ("float64",))?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

/// A zeroed buffer of `len` float64 values, or a `MemoryError` naming `what` when the system
/// refuses the memory (instead of aborting the interpreter).
pub(crate) fn zeros(len: usize, what: &'static str) -> Result<Vec<f64>> {
    Ok(lane_math::try_filled(len, 0.0, what)?)
}

/// Refuses an argument `name` of `size` values beyond `max_len`.
fn check_size(size: usize, name: &str, max_len: usize) -> Result<()> {
    if size > max_len {
        return Err(Error::input(format!(
            "{name} has {size} values, more than the limit of {max_len}"
        )));
    }
    Ok(())
}

/// `object` as a vector of float64 values (a 1-D array, list or tuple of real numbers, read as
/// [`States`] are) of at most `max_len` values; `name` is the argument's name in messages.
pub(crate) fn vector(object: &Bound<'_, PyAny>, name: &str, max_len: usize) -> PyResult<Vec<f64>> {
    let array = float64_array(object, name, max_len)?;
    let array = array
        .try_readonly()
        .map_err(|e| Error::input(format!("{name}: {e}")))?;
    if array.ndim() != 1 {
        return Err(Error::input(format!(
            "{name} must be a 1-D sequence of numbers, got an array of shape {:?}",
            array.shape()
        ))
        .into());
    }
    Ok(array.as_array().iter().copied().collect())
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

/// Work (about the floating-point operations of one state) from which one state is computed
/// with the GIL released, as batches are, so that other Python threads run meanwhile.
pub(crate) const DETACH_MIN_WORK: usize = 1 << 16;

/// Total work of a batch from which it runs on the package's pool with Ctrl-C checked between
/// chunks ([`pool::run`]) even below [`PARALLEL_MIN_STATES`] states.
const INTERRUPTIBLE_MIN_WORK: usize = 1 << 24;

/// Runs `compute(workspace, [row of each input], out)` for every state of `inputs`, writing
/// `per_state` values per state; `work` estimates one state's floating-point operations. One
/// state runs at once on `shared`, the object's own workspace (with the GIL released from
/// [`DETACH_MIN_WORK`] on); a batch runs with the GIL released, sequentially on `shared` or,
/// from [`PARALLEL_MIN_STATES`] states on, in parallel on the package's pool with a `fresh()`
/// workspace per task, Ctrl-C checked between chunks.
pub(crate) fn evaluate<const K: usize, W: Send>(
    py: Python<'_>,
    inputs: [&States<'_>; K],
    per_state: usize,
    work: usize,
    shared: &Mutex<W>,
    fresh: impl Fn() -> Result<W> + Sync,
    compute: impl Fn(&mut W, [&[f64]; K], &mut [f64]) -> Result<()> + Sync,
) -> PyResult<Output> {
    evaluate_chunks(
        py,
        inputs,
        per_state,
        work,
        shared,
        fresh,
        |workspace, chunk, out| {
            let states = out.len() / per_state;
            for (i, state_out) in out.chunks_exact_mut(per_state).enumerate() {
                let rows = std::array::from_fn(|k| {
                    let width = chunk[k].len() / states;
                    &chunk[k][i * width..(i + 1) * width]
                });
                compute(workspace, rows, state_out).map_err(|e| (i, e))?;
            }
            Ok(())
        },
    )
}

/// [`evaluate`] with `compute_chunk(workspace, [rows of each input], out)` called on runs of
/// consecutive states at once (a batch entry point of the library); a failure names its state,
/// counted from the start of the run.
pub(crate) fn evaluate_chunks<const K: usize, W: Send>(
    py: Python<'_>,
    inputs: [&States<'_>; K],
    per_state: usize,
    work: usize,
    shared: &Mutex<W>,
    fresh: impl Fn() -> Result<W> + Sync,
    compute_chunk: impl Fn(&mut W, [&[f64]; K], &mut [f64]) -> std::result::Result<(), (usize, Error)>
    + Sync,
) -> PyResult<Output> {
    let batch = common_batch(&inputs)?;
    let widths: [usize; K] = std::array::from_fn(|k| match inputs[k].array.shape() {
        [.., w] => *w,
        [] => unreachable!("checked in States::read"),
    });
    let values: [&[f64]; K] = std::array::from_fn(|k| inputs[k].values());
    let rows = |first: usize, count: usize| -> [&[f64]; K] {
        std::array::from_fn(|k| &values[k][first * widths[k]..(first + count) * widths[k]])
    };
    let lock = || {
        shared
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    };
    let Some(n_states) = batch else {
        let mut out = zeros(per_state, "the result")?;
        let mut one = || compute_chunk(&mut lock(), rows(0, 1), &mut out).map_err(|(_, e)| e);
        if work >= DETACH_MIN_WORK {
            py.detach(one)?;
        } else {
            one()?;
        }
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
    let mut out = zeros(total, "the result of the batch")?;
    let run_chunk = |workspace: &mut W, first: usize, chunk: &mut [f64]| {
        let count = chunk.len() / per_state;
        compute_chunk(workspace, rows(first, count), chunk).map_err(|(state, e)| (first + state, e))
    };
    // A chunk the user interrupted: never reported, the KeyboardInterrupt is.
    let stopped = || (0, Error::input("interrupted"));
    // Chunks of about WORK_PER_CHUNK (a few milliseconds), at most CHUNK_STATES states: Ctrl-C
    // is checked between them.
    let chunk_states = (WORK_PER_CHUNK / work.max(1)).clamp(1, CHUNK_STATES);
    let chunk_values = chunk_states * per_state.max(1);
    let serial = |cancel: &Cancel, out: &mut [f64]| {
        let mut workspace = lock();
        for (c, chunk) in out.chunks_mut(chunk_values).enumerate() {
            if cancel.is_set() {
                return Err(stopped());
            }
            run_chunk(&mut workspace, c * chunk_states, chunk)?;
        }
        Ok(())
    };
    let result: std::result::Result<(), (usize, Error)> = if n_states < PARALLEL_MIN_STATES {
        if n_states.saturating_mul(work) < INTERRUPTIBLE_MIN_WORK {
            py.detach(|| serial(&Cancel::new(), &mut out))
        } else {
            {
                let cancel = Cancel::new();
                pool::run(py, &cancel, || serial(&cancel, &mut out))?
            }
        }
    } else {
        let cancel = Cancel::new();
        pool::run(py, &cancel, || {
            let failures: Vec<(usize, Error)> = out
                .par_chunks_mut(chunk_values)
                .enumerate()
                .map_init(&fresh, |workspace, (c, chunk)| {
                    if cancel.is_set() {
                        return Err(stopped());
                    }
                    let first = c * chunk_states;
                    match workspace {
                        Ok(workspace) => run_chunk(workspace, first, chunk),
                        Err(refused) => Err((first, refused.clone())),
                    }
                })
                .filter_map(std::result::Result::err)
                .collect();
            match failures.into_iter().min_by_key(|(state, _)| *state) {
                Some(failure) => Err(failure),
                None => Ok(()),
            }
        })?
    };
    result.map_err(|(state, error)| error.context(format!("state {state}")))?;
    Ok(Output { batch, values: out })
}
