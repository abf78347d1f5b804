//! The one classification of the workspace's errors.

/// The class of an error: what a caller does about it. Every error type of the `hrm` library
/// crates sorts its variants into these classes ([`Classify`]), a wrapped error of another crate
/// keeping its own class; `hrm eval` reports the class as an error's `kind` and the Python
/// package raises one exception per class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorClass {
    /// An input outside its domain: a malformed file, a wrong shape, a non-finite number, a
    /// setting out of range, an unknown name.
    InvalidInput,
    /// A target the backbone curve cannot reach (too far, at the base, off the branch).
    Unreachable,
    /// A computation on valid input that failed in double precision: a matrix that is not
    /// numerically positive definite, an iteration that did not converge, a result or a run
    /// that came out non-finite or ran away.
    Numerical,
    /// The system refused the memory of a buffer sized by valid input (an allocation within
    /// the documented limits that the machine cannot give).
    OutOfMemory,
}

impl ErrorClass {
    /// The class's name as `hrm eval` reports it: `invalid_input`, `unreachable`, `numerical`,
    /// `out_of_memory`.
    ///
    /// ```
    /// assert_eq!(lane_math::ErrorClass::InvalidInput.name(), "invalid_input");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            Self::InvalidInput => "invalid_input",
            Self::Unreachable => "unreachable",
            Self::Numerical => "numerical",
            Self::OutOfMemory => "out_of_memory",
        }
    }
}

/// An error that knows its [`ErrorClass`]. The predicates are the class, read three ways.
///
/// ```
/// use lane_math::{Classify, ErrorClass};
///
/// struct Diverged;
/// impl Classify for Diverged {
///     fn class(&self) -> ErrorClass {
///         ErrorClass::Numerical
///     }
/// }
/// assert!(Diverged.is_numerical() && !Diverged.is_invalid_input() && !Diverged.is_unreachable());
/// ```
pub trait Classify {
    /// The error's class.
    fn class(&self) -> ErrorClass;

    /// Whether the error is [`ErrorClass::InvalidInput`].
    fn is_invalid_input(&self) -> bool {
        self.class() == ErrorClass::InvalidInput
    }

    /// Whether the error is [`ErrorClass::Unreachable`].
    fn is_unreachable(&self) -> bool {
        self.class() == ErrorClass::Unreachable
    }

    /// Whether the error is [`ErrorClass::Numerical`].
    fn is_numerical(&self) -> bool {
        self.class() == ErrorClass::Numerical
    }
}

impl<E: Classify + ?Sized> Classify for Box<E> {
    fn class(&self) -> ErrorClass {
        (**self).class()
    }
}
