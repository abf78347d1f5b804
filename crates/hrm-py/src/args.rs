//! Keyword arguments read with their names in every message: a wrong type is a `TypeError`
//! naming the argument and the type given, a value out of range an
//! [`InvalidInput`](crate::errors::InvalidInput) naming it.

use crate::array::passes_through;
use crate::errors::Error;
use numpy::{PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyFloat, PyInt, PyString};

/// The `TypeError` for argument `name` given a `value` of the wrong type.
pub(crate) fn wrong_type(name: &str, expected: &str, value: &Bound<'_, PyAny>) -> PyErr {
    let given = value
        .get_type()
        .name()
        .map_or_else(|_| "object".to_string(), |n| n.to_string());
    let article = if given.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    PyTypeError::new_err(format!("{name} must be {expected}, got {article} {given}"))
}

/// A real number for argument `name` (a Python or numpy int or float).
pub(crate) fn real(value: &Bound<'_, PyAny>, name: &str) -> PyResult<f64> {
    // A bool is an int to Python, but `link_length=True` is a slip, not a length of 1 (numpy's
    // `np.True_` too).
    if value.is_instance_of::<PyString>() || value.is_instance_of::<PyBytes>() || is_bool(value) {
        return Err(wrong_type(name, "a real number", value));
    }
    value.extract::<f64>().map_err(|e| {
        if passes_through(value.py(), &e) {
            e
        } else {
            wrong_type(name, "a real number", value)
        }
    })
}

/// An optional real number for argument `name` ([`real`]), `default` when not given.
pub(crate) fn real_or(value: Option<&Bound<'_, PyAny>>, name: &str, default: f64) -> PyResult<f64> {
    value.map_or(Ok(default), |v| real(v, name))
}

/// A count argument (`links`, `harmonics`, `samples`) as a `usize`: a negative number or one
/// beyond 64 bits is an [`InvalidInput`](crate::errors::InvalidInput) naming `name`, not an `OverflowError`. `minimum` is
/// the smallest count the message asks for; the libraries check the actual bounds. A `bool` is
/// refused.
pub(crate) fn count(value: &Bound<'_, PyAny>, name: &str, minimum: u32) -> PyResult<usize> {
    // `bool` is an `int` to Python: `links=True` is a mistake, not one link (numpy's too).
    if is_bool(value) {
        return Err(Error::input(format!(
            "{name} must be a whole number, got a bool ({})",
            value.repr()?
        ))
        .into());
    }
    if let Ok(count) = value.extract::<usize>() {
        return Ok(count);
    }
    match value.extract::<i128>() {
        Ok(n) if n < 0 => {
            Err(Error::input(format!("{name} must be at least {minimum}, got {n}")).into())
        }
        _ => Err(Error::input(format!(
            "{name} must be a whole number of at most 64 bits, got {}",
            value.repr()?
        ))
        .into()),
    }
}

/// A string for argument `name` (a Python `str`).
pub(crate) fn text(value: &Bound<'_, PyAny>, name: &str) -> PyResult<String> {
    match value.cast::<PyString>() {
        Ok(s) => Ok(s.to_cow()?.into_owned()),
        Err(_) => Err(wrong_type(name, "a str", value)),
    }
}

/// A 1-D sequence of real numbers for argument `name` (a list, tuple or numpy array; not a
/// string) of at most `max_len` entries: a wrong type is a `TypeError`, another number of
/// dimensions or more entries an `InvalidInput`.
pub(crate) fn reals(value: &Bound<'_, PyAny>, name: &str, max_len: usize) -> PyResult<Vec<f64>> {
    if value.is_instance_of::<PyString>() || value.is_instance_of::<PyBytes>() {
        return Err(wrong_type(name, "a sequence of real numbers", value));
    }
    crate::array::vector(value, name, max_len)
}

/// A seed for argument `name`: a whole number from 0 to 2^64 - 1.
pub(crate) fn seed(value: &Bound<'_, PyAny>, name: &str) -> PyResult<u64> {
    if let Ok(seed) = value.extract::<u64>() {
        return Ok(seed);
    }
    match value.extract::<i128>() {
        Ok(n) => Err(Error::input(format!(
            "{name} must be a whole number from 0 to 2^64 - 1, got {n}"
        ))
        .into()),
        Err(e) if passes_through(value.py(), &e) => Err(e),
        Err(_) => Err(wrong_type(name, "a whole number", value)),
    }
}

/// A path for argument `name`: a `str` or an `os.PathLike`.
pub(crate) fn path(value: &Bound<'_, PyAny>, name: &str) -> PyResult<std::path::PathBuf> {
    value.extract().map_err(|e| {
        if passes_through(value.py(), &e) {
            e
        } else if value.is_instance_of::<PyString>() {
            // A str the file system cannot encode (a lone surrogate): the codec says where.
            Error::input(format!("{name} is not a usable file name: {e}")).into()
        } else {
            wrong_type(name, "a str or an os.PathLike", value)
        }
    })
}

/// A finite 3-vector for argument `name` (a gravity vector, a position, roll-pitch-yaw angles).
pub(crate) fn vec3(value: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    let values = reals(value, name, 3)?;
    let vector: [f64; 3] = values.as_slice().try_into().map_err(|_| {
        Error::input(format!(
            "{name} must have 3 entries (x, y, z), got {}",
            values.len()
        ))
    })?;
    if let Some((i, v)) = vector.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::input(format!("{name}[{i}] must be finite, got {v}")).into());
    }
    Ok(vector)
}

/// Rows of three real numbers for argument `name` (per-link principal inertias): an `(n, 3)`
/// array or a list of triples.
pub(crate) fn rows3(value: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; 3]>> {
    if value.is_instance_of::<PyString>() || value.is_instance_of::<PyBytes>() {
        return Err(wrong_type(name, "rows of three real numbers", value));
    }
    let array = crate::array::float64_array(value, name, 3 * backbone_kin::MAX_LINKS)?;
    let shape = array.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(Error::input(format!(
            "{name} must be rows of three numbers, shape (n, 3), got an array of shape {shape:?}"
        ))
        .into());
    }
    let flat: Vec<f64> = crate::array::vector(
        &array.reshape([shape[0] * 3])?.into_any(),
        name,
        3 * backbone_kin::MAX_LINKS,
    )?;
    Ok(flat
        .chunks_exact(3)
        .map(|row| [row[0], row[1], row[2]])
        .collect())
}

/// A spatial arm's `gravity` (`SpatialArm`, `Chain.from_urdf`): one number `g` along `-z`, as a
/// scenario and `hrm eval` read it, or a vector `(x, y, z)` (default `(0, 0, -9.81)`); a `bool`
/// is a `TypeError`.
pub(crate) fn spatial_gravity(value: Option<&Bound<'_, PyAny>>) -> PyResult<sim_study::Gravity> {
    Ok(match value {
        None => sim_study::Gravity::Vector([0.0, 0.0, -9.81]),
        Some(g) if is_bool(g) => {
            return Err(wrong_type("gravity", "a number g or a vector (x, y, z)", g));
        }
        Some(g) if is_scalar(g) => sim_study::Gravity::Magnitude(real(g, "gravity")?),
        Some(g) => sim_study::Gravity::Vector(vec3(g, "gravity")?),
    })
}

/// Whether `value` is one Python or numpy `bool` (or a 0-d array of one), which `gravity`
/// does not take for a number.
pub(crate) fn is_bool(value: &Bound<'_, PyAny>) -> bool {
    value.is_instance_of::<PyBool>()
        || (is_scalar(value)
            && value
                .getattr("dtype")
                .and_then(|dtype| dtype.getattr("kind"))
                .and_then(|kind| kind.extract::<String>())
                .is_ok_and(|kind| kind == "b"))
}

/// Whether `value` is one number (a Python `int` or `float`, or a numpy scalar or 0-d array),
/// which `gravity` reads as `g` along `-z` as a scenario and `hrm eval` do.
fn is_scalar(value: &Bound<'_, PyAny>) -> bool {
    value.is_instance_of::<PyFloat>()
        || value.is_instance_of::<PyInt>()
        || value
            .getattr("ndim")
            .and_then(|ndim| ndim.extract::<usize>())
            .is_ok_and(|ndim| ndim == 0)
}
