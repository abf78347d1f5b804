//! Explicit Runge-Kutta integrators for small ODE systems `y' = f(t, y)`.
//!
//! Two methods, both with their stage vectors allocated once at construction so that a step
//! allocates nothing:
//!
//! - [`Rk4`]: the classical fixed-step fourth-order method (the paper names neither an integrator
//!   nor a step size; the shipped scenarios choose this one at `1e-4` s);
//! - [`DormandPrince`]: the adaptive Dormand-Prince 5(4) pair with the first-same-as-last property,
//!   an embedded fourth-order error estimate and the standard step-size controller.
//!
//! Both integrate over an interval `[t0, t1]` and land exactly on `t1`, which is what a sampled
//! controller with a zero-order hold needs: the right-hand side is smooth between two samples.

mod dopri5;
mod rk4;

pub use dopri5::{DormandPrince, MIN_RTOL, Tolerances};
pub use rk4::{MAX_RK4_STEPS, Rk4};

use lane_math::{Classify, Compact, ErrorClass};

/// The right-hand side `f(t, y)` of a first-order system `y' = f(t, y)`.
pub trait OdeSystem {
    /// Why an evaluation of the right-hand side failed.
    type Error;

    /// Writes `f(t, y)` into `dy` (`y` and `dy` have the integrator's dimension).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error>;
}

/// Counts of the work an integration did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (always zero for fixed-step methods).
    pub rejected: usize,
    /// Evaluations of the right-hand side.
    pub evaluations: usize,
}

/// Why an integration stopped; `E` is the right-hand side's error type.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OdeError<E> {
    /// The right-hand side reported an error.
    #[error("the right-hand side failed at t = {}: {source}", Compact(*.t))]
    Rhs {
        /// Time of the failing evaluation.
        t: f64,
        /// The right-hand side's error.
        source: E,
    },
    /// The state or its derivative became NaN or infinite.
    #[error("the state became non-finite at t = {}", Compact(*.t))]
    NonFinite {
        /// Start of the step that produced it.
        t: f64,
    },
    /// The adaptive step size fell below the minimum allowed step.
    #[error(
        "the step size fell to {h:e} at t = {}, below the minimum {h_min:e} (a stiff or singular \
         problem, or an atol too small for the state's rounding)",
        Compact(*.t)
    )]
    StepTooSmall {
        /// Where it happened.
        t: f64,
        /// The step size that was refused.
        h: f64,
        /// The minimum step size in force.
        h_min: f64,
    },
    /// The integration needed more steps than allowed.
    #[error(
        "more than {max_steps} steps were needed to integrate over the interval (stopped at t = {t})"
    )]
    MaxSteps {
        /// Where it stopped.
        t: f64,
        /// The limit in force.
        max_steps: usize,
    },
    /// The state vector does not have the integrator's dimension.
    #[error("the state has {found} entries, the integrator was built for {expected}")]
    Dimension {
        /// The integrator's dimension.
        expected: usize,
        /// The state's length.
        found: usize,
    },
    /// The interval or step size was not usable.
    #[error("invalid integration setting: {0}")]
    InvalidSetting(&'static str),
    /// A setting of [`Tolerances`] was not usable.
    #[error("invalid integration setting: {name} {requirement}")]
    InvalidTolerance {
        /// The setting's field (`rtol`, `atol`, ...).
        name: &'static str,
        /// What it must be, and the value given.
        requirement: String,
    },
}

impl<E: Classify> Classify for OdeError<E> {
    /// The right-hand side's error keeps its class; a state that blew up, a step that fell too
    /// small and a step budget spent are [`Numerical`](ErrorClass::Numerical); a state of the
    /// wrong dimension or an unusable interval, step or tolerance is
    /// [`InvalidInput`](ErrorClass::InvalidInput).
    fn class(&self) -> ErrorClass {
        match self {
            Self::Rhs { source, .. } => source.class(),
            Self::NonFinite { .. } | Self::StepTooSmall { .. } | Self::MaxSteps { .. } => {
                ErrorClass::Numerical
            }
            Self::Dimension { .. } | Self::InvalidSetting(_) | Self::InvalidTolerance { .. } => {
                ErrorClass::InvalidInput
            }
        }
    }
}

/// Checks `y` against the dimension and the interval `[t0, t1]`.
fn check_call<E>(dim: usize, y: &[f64], t0: f64, t1: f64) -> Result<(), OdeError<E>> {
    if y.len() != dim {
        return Err(OdeError::Dimension {
            expected: dim,
            found: y.len(),
        });
    }
    if !(t0.is_finite() && t1.is_finite()) {
        return Err(OdeError::InvalidSetting("the interval ends must be finite"));
    }
    if t1 < t0 {
        return Err(OdeError::InvalidSetting(
            "the interval must not end before it starts",
        ));
    }
    if y.iter().any(|v| !v.is_finite()) {
        return Err(OdeError::NonFinite { t: t0 });
    }
    Ok(())
}

/// Evaluates the right-hand side, tagging its error with the time.
fn eval<S: OdeSystem>(
    system: &mut S,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
    stats: &mut Stats,
) -> Result<(), OdeError<S::Error>> {
    stats.evaluations += 1;
    system
        .rhs(t, y, dy)
        .map_err(|source| OdeError::Rhs { t, source })
}

/// `out = y + h * sum_j coeffs[j] * stages[j]`, skipping zero coefficients.
fn combine(out: &mut [f64], y: &[f64], h: f64, coeffs: &[f64], stages: &[&[f64]]) {
    out.copy_from_slice(y);
    for (&c, k) in coeffs.iter().zip(stages) {
        if c != 0.0 {
            let hc = h * c;
            for (o, &kj) in out.iter_mut().zip(k.iter()) {
                *o += hc * kj;
            }
        }
    }
}
