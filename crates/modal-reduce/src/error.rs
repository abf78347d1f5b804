//! The error type of this crate, and the checks of computed results that produce it.

use lane_math::{Classify, EntryIndex, ErrorClass, ShapeError, ShapeProblem};

use backbone_kin::KinError;
use manip_dyn::DynError;

/// Why a reduced-dynamics computation was refused.
///
/// Every variant names the condition that failed, so a caller (or the `hrm` command line) can
/// print it as one readable line. [`Classify::class`] sorts the variants into the classes a caller
/// acts on: [`ErrorClass::Numerical`] (a
/// computation on valid input failed in double precision), [`ErrorClass::Unreachable`] (a
/// kinematic target the curve cannot reach, from [`KinError`]) and
/// [`ErrorClass::InvalidInput`] (the input is malformed or outside the model's domain). A
/// wrapped [`DynError`] or [`KinError`] keeps its own class.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReduceError {
    /// The full-chain dynamics refused the computation.
    #[error("chain dynamics: {0}")]
    Dyn(#[from] DynError),
    /// The modal map refused the computation.
    #[error("modal map: {0}")]
    Kin(#[from] KinError),
    /// The modal map and the chain disagree on the number of joints.
    #[error("the modal map has {joints} joints but the chain has {links} links")]
    LinkCountMismatch {
        /// Rows of the modal Jacobian `J`.
        joints: usize,
        /// Links of the chain.
        links: usize,
    },
    /// The modal map was built for links of other relative lengths than the chain's, so its `J`
    /// would put the links at the wrong arc lengths of the curve (eq 7).
    #[error(
        "the modal map's link {link} spans {map_fraction:e} of the curve but the chain's link          {link} spans {chain_fraction:e}: build the map from the chain's link lengths          (ReducedModel::from_chain or ModalMap::new)"
    )]
    GeometryMismatch {
        /// 0-based index of the first link that differs.
        link: usize,
        /// `L_i / l` of the map's links.
        map_fraction: f64,
        /// `L_i / l` of the chain's links.
        chain_fraction: f64,
    },
    /// The modal Jacobian has dependent columns, so `M* = J^T M J` would be singular.
    #[error(
        "the modal Jacobian J ({links} x {coords}) is column-rank-deficient (smallest eigenvalue \
         of its column-normalised Gram matrix is {min_eigenvalue:e}), so M* = J^T M J would be \
         singular: use fewer modal coordinates or more links"
    )]
    RankDeficient {
        /// Links (rows of `J`).
        links: usize,
        /// Modal coordinates (columns of `J`).
        coords: usize,
        /// Smallest eigenvalue of `D^-1/2 J^T J D^-1/2`, `D = diag(J^T J)` (1 for orthogonal
        /// columns, 0 for dependent ones).
        min_eigenvalue: f64,
    },
    /// A slice had the wrong number of entries, or a workspace belongs to another model.
    #[error("{name} has {found} entries, expected {expected}")]
    Dimension {
        /// Which input, output or workspace.
        name: &'static str,
        /// The size the computation needs.
        expected: usize,
        /// The size it got.
        found: usize,
    },
    /// An input that must be finite was NaN or infinite.
    #[error("{name}{} must be finite, got {value}", EntryIndex(*index))]
    NonFinite {
        /// Which input.
        name: &'static str,
        /// 0-based index of the first offending entry of a slice; `None` for a scalar input.
        index: Option<usize>,
        /// The offending value.
        value: f64,
    },
    /// The Cholesky factorisation of `M*` met a non-positive pivot. `M*` is positive definite for
    /// every valid chain and full-rank map, so this signals numbers too extreme for double
    /// precision.
    #[error("the reduced mass matrix M* is not numerically positive definite")]
    NotPositiveDefinite,
    /// A computed quantity overflowed although every input was finite.
    #[error(
        "the computed {name} is not finite (inputs beyond double precision: too large, or a \
         mass or length too small to divide by)"
    )]
    NonFiniteResult {
        /// Which quantity.
        name: &'static str,
    },
    /// The eq-18 iteration cannot converge at this state.
    #[error(
        "the eq-18 Jacobi iteration diverges here: the spectral radius of M0*^-1 M1* is \
         {spectral_radius:.4} >= 1 (M* is not diagonally dominant enough); solve M* a_ddot = rhs \
         directly with forward_dynamics"
    )]
    JacobiDiverged {
        /// Spectral radius of the iteration matrix `M0*^-1 M1*` (eq 16-18).
        spectral_radius: f64,
    },
    /// The eq-18 iteration converges in theory but did not reach the tolerance in time.
    #[error(
        "the eq-18 Jacobi iteration did not reach the tolerance in {iterations} iterations \
         (spectral radius {spectral_radius:.4}, last relative update {relative_update:e})"
    )]
    JacobiNotConverged {
        /// Iterations performed.
        iterations: usize,
        /// Spectral radius of `M0*^-1 M1*` (below 1, but close to it).
        spectral_radius: f64,
        /// `|x_{k+1} - x_k|_inf / |x_{k+1}|_inf` at the last iteration.
        relative_update: f64,
    },
    /// A setting of the eq-18 iteration was out of its domain.
    #[error("Jacobi setting {name} must be {requirement}, got {value}")]
    InvalidSetting {
        /// Which setting.
        name: &'static str,
        /// What it must be.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A workspace built for a planar arm given with a spatial one, or the reverse.
    #[error("a workspace built for a {built} arm was given a {given} arm")]
    WrongFamily {
        /// The family the workspace was built for (`"planar"` or `"spatial"`).
        built: &'static str,
        /// The family of the arm given.
        given: &'static str,
    },
    /// The system refused the memory of a reduced model's or a workspace's arrays.
    #[error(transparent)]
    OutOfMemory(#[from] lane_math::OutOfMemory),
}

impl Classify for ReduceError {
    /// [`Numerical`](ErrorClass::Numerical) when a computation on valid input failed in double
    /// precision: `M*` not numerically positive definite, a result that overflowed, the eq-18
    /// iteration diverging or not converging; a wrapped [`DynError`] or [`KinError`] keeps its
    /// own class; [`OutOfMemory`](ErrorClass::OutOfMemory) for memory the system refused;
    /// otherwise the input was malformed or outside the model's domain.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Dyn(e) => e.class(),
            Self::Kin(e) => e.class(),
            Self::OutOfMemory(e) => e.class(),
            Self::NotPositiveDefinite
            | Self::NonFiniteResult { .. }
            | Self::JacobiDiverged { .. }
            | Self::JacobiNotConverged { .. } => ErrorClass::Numerical,
            _ => ErrorClass::InvalidInput,
        }
    }
}

/// A refused shape or non-finite input as [`ReduceError::Dimension`] or
/// [`ReduceError::NonFinite`], with the same message.
impl From<ShapeError<'static>> for ReduceError {
    fn from(error: ShapeError<'static>) -> Self {
        let name = error.name;
        match error.problem {
            ShapeProblem::Length { expected, found } => Self::Dimension {
                name,
                expected,
                found,
            },
            ShapeProblem::NonFinite { index, value } => Self::NonFinite { name, index, value },
        }
    }
}

/// Checks that a computed vector is finite. Unlike an input's, a result's non-finite value is a
/// [`ReduceError::NonFiniteResult`] (numerical: finite inputs overflowed), not the caller's
/// fault, so it is not reported as the [`ShapeError`] of an input.
pub(crate) fn check_finite_result(name: &'static str, values: &[f64]) -> Result<(), ReduceError> {
    lane_math::check_all_finite(name, values).map_err(|_| ReduceError::NonFiniteResult { name })
}

/// Checks that the computed terms `M*`, `C*` and `G*` (eq 14) are finite, naming the first
/// that is not.
pub(crate) fn check_terms_finite(
    mass: &[f64],
    coriolis: &[f64],
    gravity: &[f64],
) -> Result<(), ReduceError> {
    check_finite_result("reduced mass matrix M*", mass)?;
    check_finite_result("reduced Coriolis vector C*", coriolis)?;
    check_finite_result("reduced gravity vector G*", gravity)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_error_keeps_its_message() {
        for error in [
            lane_math::check_len("a_ddot", 3, 2).unwrap_err(),
            lane_math::check_values("tau_star", &[0.0, f64::NAN], 2).unwrap_err(),
        ] {
            let reduce = ReduceError::from(error);
            assert_eq!(reduce.to_string(), error.to_string());
            assert!(reduce.is_invalid_input());
        }
    }
}
