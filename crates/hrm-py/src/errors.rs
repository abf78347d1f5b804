//! The three exceptions of the package (and `MemoryError`) and the mapping of every library error onto them.
//!
//! The classification is the library's one ([`ErrorClass`], which every library error reports
//! through [`Classify`]), the one `hrm eval` reports as its error `kind`
//! (`docs/eval-protocol.md`), and the messages are the libraries' own `Display` text, so Python
//! sees what the CLI prints:
//! malformed or out-of-domain input is [`InvalidInput`] (a `ValueError`), a target the backbone
//! curve cannot reach is [`Unreachable`], and a computation that failed in double precision
//! (a mass matrix that is not numerically positive definite, a non-finite result) is
//! [`NumericalError`], and memory the system refused (a model's arrays, a workspace, a result or
//! a run's record sized by valid input) is Python's own `MemoryError`.

use lane_math::{Classify, ErrorClass};
use pyo3::exceptions::{PyArithmeticError, PyMemoryError, PyValueError};
use pyo3::{PyErr, create_exception};

create_exception!(
    hrm,
    InvalidInput,
    PyValueError,
    "An input outside the model's domain: a wrong shape or dtype, a non-finite number, a \
     non-positive length, mass or inertia, an unknown name. The message names the input and the \
     problem."
);
create_exception!(
    hrm,
    Unreachable,
    PyValueError,
    "An inverse-kinematics target that the backbone curve cannot reach (farther than the arm's \
     length, at the base, or outside the branch's range)."
);
create_exception!(
    hrm,
    NumericalError,
    PyArithmeticError,
    "A computation that failed in double precision: a mass matrix that is not numerically \
     positive definite, an iteration that did not converge, or a result that came out non-finite."
);

/// A refused computation: which exception, and its one-line message. Unlike a `PyErr` it can be
/// built and carried without the GIL, inside a batch running on other threads.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Error {
    /// Which exception: one per [`ErrorClass`].
    pub kind: ErrorClass,
    /// The message, as the CLI prints it.
    pub message: String,
}

/// The result type of the computations behind every method.
pub(crate) type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An [`InvalidInput`] with this message.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorClass::InvalidInput,
            message: message.into(),
        }
    }

    /// A [`NumericalError`] with this message.
    pub fn numerical(message: impl Into<String>) -> Self {
        Self {
            kind: ErrorClass::Numerical,
            message: message.into(),
        }
    }

    /// The same error with `context: ` in front of its message (e.g. the failing state of a
    /// batch).
    pub fn context(self, context: impl std::fmt::Display) -> Self {
        Self {
            kind: self.kind,
            message: format!("{context}: {}", self.message),
        }
    }
}

/// The exception of the error's class, its message one line as the CLI prints it
/// ([`lane_math::one_line`]: control characters escaped, any number written out in full by a
/// library, `1e-300` as 302 characters, in exponent form, cut to 2,000 characters).
impl From<Error> for PyErr {
    fn from(error: Error) -> PyErr {
        let message = lane_math::one_line(&error.message);
        match error.kind {
            ErrorClass::Unreachable => Unreachable::new_err(message),
            ErrorClass::Numerical => NumericalError::new_err(message),
            ErrorClass::OutOfMemory => PyMemoryError::new_err(message),
            _ => InvalidInput::new_err(message),
        }
    }
}

/// A library error as the exception of its [`ErrorClass`], with the library's own message.
impl<E: Classify + std::fmt::Display> From<E> for Error {
    fn from(error: E) -> Self {
        Self {
            kind: error.class(),
            message: error.to_string(),
        }
    }
}

/// Refuses a computed vector with a non-finite entry, as `hrm eval` does: "{name} came out
/// non-finite ({value})". A check of a result, not of an input: the libraries checked the inputs
/// ([`lane_math::check_values`], an [`InvalidInput`]), so a non-finite result is an overflow, a
/// [`NumericalError`], and only the search for the entry ([`lane_math::first_non_finite`]) is
/// shared.
pub(crate) fn check_finite(name: &str, values: &[f64]) -> Result<()> {
    match lane_math::first_non_finite(values) {
        Some((_, v)) => Err(Error::numerical(format!(
            "{name} came out non-finite ({v})"
        ))),
        None => Ok(()),
    }
}
