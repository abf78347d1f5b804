//! The error types of this crate.

use lane_math::{Classify, Compact, ErrorClass, ShapeError};

use crate::ode::OdeError;
use backbone_kin::KinError;
use modal_reduce::ReduceError;
use std::fmt;
use std::sync::Arc;

/// The error a controller may fail with: any error type, boxed. The built-in controllers fail
/// with a boxed [`SimError`], which the run reports as it is; any other error is reported as
/// [`SimError::Controller`] carrying it as its source.
pub type ControllerError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Why a simulation could not be built or had to stop.
///
/// Every variant names the condition that failed; the ones raised during a run say when. [`Classify::class`]
/// sorts the variants into the classes a caller acts on: [`ErrorClass::Unreachable`] (a reference the curve cannot reach),
/// [`ErrorClass::Numerical`] (a computation or a run on valid input failed numerically) and
/// [`ErrorClass::InvalidInput`] (a setting, file or model outside its domain). A wrapped
/// library error keeps its own class.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// A setting was out of its domain.
    #[error("{name} {requirement}")]
    InvalidSetting {
        /// Which setting (as it is spelled in a scenario file).
        name: String,
        /// What was wrong with it, e.g. "must be positive and finite, got -1".
        requirement: String,
    },
    /// A point of a Cartesian reference path cannot be reached by the backbone curve.
    #[error(
        "the reference path point ({x:.6}, {y:.6}) at t = {} s is unreachable: {source}",
        Compact(*.t)
    )]
    Unreachable {
        /// Time on the path (s).
        t: f64,
        /// The point's `x` (m).
        x: f64,
        /// The point's `y` (m).
        y: f64,
        /// Which reachability condition failed.
        source: KinError,
    },
    /// A Cartesian reference path passes through a singular point of the inverse kinematics:
    /// the branch point `a1 = 0` of eq 6 or the straight curve `A = 0` (`r = l`), where the rate
    /// of the modal reference is undefined.
    #[error(
        "the reference path passes through a singular point of the inverse kinematics near \
         t = {t} s at ({x:.6}, {y:.6}): {what}, where the modal reference rate is undefined; move \
         the path or change alpha0"
    )]
    SingularPoint {
        /// Which singularity: the branch point or the straight curve.
        what: &'static str,
        /// Time on the path (s).
        t: f64,
        /// The point's `x` (m).
        x: f64,
        /// The point's `y` (m).
        y: f64,
    },
    /// A point of a spatial arm's tip path cannot be reached by its chain.
    #[error(
        "the reference path point ({:.6}, {:.6}, {:.6}) at t = {t} s is unreachable: {source}",
        point[0], point[1], point[2]
    )]
    UnreachableInSpace {
        /// Time on the path (s).
        t: f64,
        /// The point (m).
        point: [f64; 3],
        /// Which reachability condition failed.
        source: KinError,
    },
    /// A spatial arm's tip path passes through a singular point of the chain's inverse
    /// kinematics (the tip cannot move in some direction), where the modal rate is undefined.
    #[error(
        "the reference path passes through a singular point of the inverse kinematics near \
         t = {t} s at ({:.6}, {:.6}, {:.6}): {what}, where the modal reference rate is undefined; \
         move the path or the base",
        point[0], point[1], point[2]
    )]
    SingularPointInSpace {
        /// Which singularity.
        what: &'static str,
        /// Time on the path (s).
        t: f64,
        /// The point (m).
        point: [f64; 3],
    },
    /// The kinematics refused a computation.
    #[error("kinematics: {0}")]
    Kinematics(#[from] KinError),
    /// The reduced dynamics refused a computation (outside of the integrator).
    #[error("reduced dynamics at t = {} s: {source}", Compact(*.t))]
    Dynamics {
        /// When (s).
        t: f64,
        /// The refusal.
        source: ReduceError,
    },
    /// The arm or the modal map could not be built.
    #[error("model: {0}")]
    Model(ReduceError),
    /// The fuzzy system could not be built, loaded or evaluated.
    #[error("fuzzy controller: {0}")]
    Fuzzy(#[from] fuzzy_sugeno::FuzzyError),
    /// The integrator stopped: the dynamics failed or the state blew up between two samples.
    /// The message shows the modal force held over the period (the controller's `tau*`, with a
    /// disturbance's `J^T tau_d`): a divergence from finite inputs is most often a force, or the
    /// gains behind it, beyond the arm's scale.
    #[error(
        "integration diverged under the held modal force tau* = {} N m: {source}",
        lane_math::compact_numbers(&format!("{tau_star:?}"))
    )]
    Integration {
        /// The modal force held over the period, one entry per coordinate.
        tau_star: Vec<f64>,
        /// Why the integrator stopped.
        source: OdeError<ReduceError>,
    },
    /// The spatial chain's dynamics refused a computation at a controller sample (the joint-space
    /// loop of a URDF arm, [`run_chain_loop`](crate::run_chain_loop)).
    #[error("chain dynamics at t = {} s: {source}", Compact(*.t))]
    ChainDynamics {
        /// When (s).
        t: f64,
        /// The refusal.
        source: manip_dyn::DynError,
    },
    /// The joint-space loop's integrator stopped: the chain's dynamics failed or the state blew
    /// up between two controller samples; the message shows the joint torques held over the
    /// period.
    #[error(
        "integration diverged under the held joint torques tau = {}: {source}",
        lane_math::compact_numbers(&format!("{tau:?}"))
    )]
    ChainIntegration {
        /// The joint torques (N m, N for a prismatic joint) held over the period.
        tau: Vec<f64>,
        /// Why the integrator stopped.
        source: OdeError<manip_dyn::DynError>,
    },
    /// The controller produced a NaN or infinite torque.
    #[error(
        "the controller produced a non-finite modal torque {tau_star:?} at t = {} s",
        Compact(*.t)
    )]
    NonFiniteControl {
        /// When (s).
        t: f64,
        /// The torque it produced, one entry per coordinate.
        tau_star: Vec<f64>,
    },
    /// A disturbance hook ([`LoopHooks`](crate::LoopHooks)) produced a NaN or infinite joint
    /// torque.
    #[error(
        "the disturbance hook produced a non-finite joint torque {tau:?} at t = {} s",
        Compact(*.t)
    )]
    NonFiniteDisturbance {
        /// When (s).
        t: f64,
        /// The joint torques it produced, one entry per joint.
        tau: Vec<f64>,
    },
    /// A reference whose sample came out NaN or infinite: parameters beyond what double
    /// precision resolves (checked before the controller sees it).
    #[error(
        "the reference's {name}[{index}] came out {} at t = {} s: its parameters are beyond \
         double precision",
        Compact(*.value),
        Compact(*.t)
    )]
    NonFiniteReference {
        /// When (s).
        t: f64,
        /// `"a"`, `"a_dot"` or `"a_ddot"`.
        name: &'static str,
        /// The coordinate (0-based).
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A disturbance hook's finite joint torques whose modal force `J^T tau_d`, or its sum with
    /// the controller's `tau*`, overflows.
    #[error(
        "the disturbance hook's joint torques at t = {} s give a modal force J^T tau_d (added to \
         tau*) beyond double precision: {}",
        Compact(*.t),
        lane_math::compact_numbers(&format!("{force:?}"))
    )]
    DisturbanceOverflow {
        /// When (s).
        t: f64,
        /// `tau* + J^T tau_d`, one entry per modal coordinate.
        force: Vec<f64>,
    },
    /// Finite modal torques whose control effort (the integral of `|tau*|^2`) passes double
    /// precision: an arm or gains so large that the squares of the torques overflow.
    #[error(
        "the control effort (the integral of |tau*|^2) overflowed at t = {} s under tau* = {} N m: \
         the arm's masses and lengths, or the controller's gains, are beyond double precision",
        Compact(*.t),
        lane_math::compact_numbers(&format!("{tau_star:?}"))
    )]
    EffortOverflow {
        /// When (s).
        t: f64,
        /// The controller's `tau*` at that sample.
        tau_star: Vec<f64>,
    },
    /// A controller failed with an error of its own (one that is not a [`SimError`]).
    #[error("the controller failed at t = {} s: {source}", Compact(*.t))]
    Controller {
        /// When (s).
        t: f64,
        /// The controller's error.
        source: ControllerFailure,
    },
    /// A modal coordinate, measured or referenced, beyond
    /// [`MAX_MODAL_MAGNITUDE`](crate::MAX_MODAL_MAGNITUDE): double precision no longer resolves
    /// its motion (at `1e20` rad every step rounds away), so the run would report nonsense.
    #[error(
        "a{coordinate} (or its reference) is {} rad at t = {} s, beyond the {} rad a run \
         resolves: the run diverged (the noise or the gains too large), or its initial state \
         or reference is out of scale",
        Compact(*.value),
        Compact(*.t),
        Compact(*.bound)
    )]
    OutOfScale {
        /// When (s).
        t: f64,
        /// Which coordinate (1-based).
        coordinate: usize,
        /// The larger magnitude of the coordinate and its reference (rad).
        value: f64,
        /// The bound (rad).
        bound: f64,
    },
    /// A modal tracking error grew beyond the configured bound.
    #[error(
        "runaway tracking error at t = {} s: |a{coordinate} - a{coordinate}_ref| = {} rad exceeds \
         the bound {} rad",
        Compact(*.t),
        Compact(*.error),
        Compact(*.bound)
    )]
    RunawayError {
        /// When (s).
        t: f64,
        /// Which coordinate (1-based: `a1, a2, ...`; the last is `alpha0` when it is free).
        coordinate: usize,
        /// The error's magnitude (rad).
        error: f64,
        /// The bound in force (rad).
        bound: f64,
    },
    /// A joint's tracking error in a joint-space loop ([`run_chain_loop`](crate::run_chain_loop))
    /// grew beyond the configured bound.
    #[error(
        "runaway tracking error at t = {} s: |q{joint} - q{joint}_ref| = {} exceeds the bound {} \
         (limits.max_modal_error, in the joint's unit: rad, or m for a prismatic joint)",
        Compact(*.t),
        Compact(*.error),
        Compact(*.bound)
    )]
    JointRunaway {
        /// When (s).
        t: f64,
        /// Which joint (1-based).
        joint: usize,
        /// The error's magnitude.
        error: f64,
        /// The bound in force.
        bound: f64,
    },
    /// The enforced joint limits (`limits.joint_torque_nm`, `limits.joint_angle_rad`) could not
    /// be met at a controller sample: no modal torque keeps them at that state.
    #[error("joint limits at t = {t} s: {reason}")]
    JointLimits {
        /// When (s).
        t: f64,
        /// Why.
        reason: &'static str,
    },
    /// The system refused the memory of a run's workspaces or record.
    #[error(transparent)]
    OutOfMemory(#[from] lane_math::OutOfMemory),
}

/// The error of a controller from outside this crate, shared so that a [`SimError`] stays
/// cloneable; two failures are equal when their messages are.
#[derive(Debug, Clone)]
pub struct ControllerFailure(pub Arc<dyn std::error::Error + Send + Sync + 'static>);

impl fmt::Display for ControllerFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for ControllerFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&*self.0)
    }
}

impl PartialEq for ControllerFailure {
    fn eq(&self, other: &Self) -> bool {
        self.0.to_string() == other.0.to_string()
    }
}

impl Classify for SimError {
    /// [`Unreachable`](ErrorClass::Unreachable) for a reference point the backbone curve cannot
    /// reach ([`Unreachable`](SimError::Unreachable)); [`Numerical`](ErrorClass::Numerical) for a
    /// run on valid input that failed: an integration that diverged, a non-finite control, a
    /// runaway tracking error, or a controller's own failure; a wrapped library error keeps its
    /// own class; [`OutOfMemory`](ErrorClass::OutOfMemory) for memory the
    /// system refused; otherwise a setting, file or model was outside its domain.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Unreachable { .. } | Self::UnreachableInSpace { .. } => ErrorClass::Unreachable,
            Self::Kinematics(e) => e.class(),
            Self::Dynamics { source, .. } | Self::Model(source) => source.class(),
            Self::Fuzzy(e) => e.class(),
            Self::ChainDynamics { source, .. } => source.class(),
            Self::OutOfMemory(e) => e.class(),
            Self::Integration { .. }
            | Self::ChainIntegration { .. }
            | Self::NonFiniteControl { .. }
            | Self::NonFiniteDisturbance { .. }
            | Self::DisturbanceOverflow { .. }
            | Self::EffortOverflow { .. }
            | Self::Controller { .. }
            | Self::RunawayError { .. }
            | Self::JointRunaway { .. }
            | Self::JointLimits { .. } => ErrorClass::Numerical,
            _ => ErrorClass::InvalidInput,
        }
    }
}

impl SimError {
    /// The error of building a workspace of the plant: [`SimError::OutOfMemory`] when the system
    /// refused its memory, otherwise [`SimError::Model`].
    pub(crate) fn workspace(error: ReduceError) -> Self {
        match error {
            ReduceError::OutOfMemory(e) => Self::OutOfMemory(e),
            e => Self::Model(e),
        }
    }

    /// The run's error for a controller failure at `t`: a [`SimError`] (the built-in
    /// controllers') as it is, any other error as [`SimError::Controller`].
    pub fn from_controller(t: f64, error: ControllerError) -> Self {
        match error.downcast::<SimError>() {
            Ok(error) => *error,
            Err(source) => SimError::Controller {
                t,
                source: ControllerFailure(Arc::from(source)),
            },
        }
    }

    /// An [`InvalidSetting`](Self::InvalidSetting) error.
    pub fn setting(name: impl Into<String>, requirement: impl Into<String>) -> Self {
        Self::InvalidSetting {
            name: name.into(),
            requirement: requirement.into(),
        }
    }

    /// The setting error of entry `index` of the list `values` named by the setting: the name
    /// gains `[index]` (0-based) where the entries differ, and is left whole where they are one
    /// number (a scenario's single value for every joint). Other errors are returned as they are.
    pub(crate) fn with_entry(self, values: &[f64], index: usize) -> Self {
        match self {
            Self::InvalidSetting { name, requirement }
                if values
                    .iter()
                    .any(|v| v.to_bits() != values[index].to_bits()) =>
            {
                Self::InvalidSetting {
                    name: format!("{name}[{index}]"),
                    requirement,
                }
            }
            other => other,
        }
    }

    /// This error with its setting `from` named `to`, for a front end that spells the setting
    /// otherwise (`modal.harmonics` is a request's `harmonics`); any other error as it is.
    ///
    /// ```
    /// use sim_core::SimError;
    /// let error = SimError::setting("modal.harmonics", "must be at least 1");
    /// assert_eq!(
    ///     error.renamed("modal.harmonics", "harmonics").to_string(),
    ///     "harmonics must be at least 1"
    /// );
    /// let other = SimError::setting("arm.links", "must be at least 1");
    /// assert_eq!(other.renamed("modal.harmonics", "harmonics").to_string(), "arm.links must be at least 1");
    /// ```
    pub fn renamed(self, from: &str, to: &str) -> Self {
        match self {
            Self::InvalidSetting { name, requirement } if name == from => Self::InvalidSetting {
                name: to.to_string(),
                requirement,
            },
            other => other,
        }
    }
}

/// Checks that `value` is positive and finite.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!("must be positive and finite, got {}", Compact(value)),
        ))
    }
}

/// Checks that the setting `name`'s `value` is non-negative and finite.
///
/// # Errors
/// [`SimError::InvalidSetting`]: "controller.pd_kp must be non-negative and finite, got -1".
pub fn check_non_negative(name: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!("must be non-negative and finite, got {}", Compact(value)),
        ))
    }
}

/// A refused shape or non-finite setting as [`InvalidSetting`](SimError::InvalidSetting),
/// named as the scenario file spells it: `"reference.points must be finite, got NaN"` (a
/// setting's message names the setting, not the entry of its array).
impl From<ShapeError<'_>> for SimError {
    fn from(error: ShapeError<'_>) -> Self {
        Self::setting(error.name, error.problem.to_string())
    }
}

/// A joint-space run (`T`: a [`ChainRun`](crate::ChainRun), or a front end's run built on one)
/// that stopped: why, and the run up to its last recorded sample, or `None` when it stopped
/// before its first recorded sample (a setting out of its domain, or a failure at `t = 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct StoppedRun<T> {
    /// Why and when the run stopped.
    pub error: SimError,
    /// The run up to the stop.
    pub partial: Option<Box<T>>,
}

impl<T> StoppedRun<T> {
    /// `outcome` as the run (whole, or up to its stop) and why it stopped, if it did; the error
    /// alone of a run that stopped before its first recorded sample.
    ///
    /// # Errors
    /// The error of a run without a recorded sample.
    pub fn split(outcome: Result<T, Self>) -> Result<(T, Option<SimError>), SimError> {
        match outcome {
            Ok(run) => Ok((run, None)),
            Err(Self {
                error,
                partial: Some(run),
            }) => Ok((*run, Some(error))),
            Err(Self {
                error,
                partial: None,
            }) => Err(error),
        }
    }
}

impl<T> fmt::Display for StoppedRun<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.error.fmt(f)
    }
}

impl<T: fmt::Debug> std::error::Error for StoppedRun<T> {}

impl<T> From<SimError> for StoppedRun<T> {
    fn from(error: SimError) -> Self {
        Self {
            error,
            partial: None,
        }
    }
}

impl<T> From<StoppedRun<T>> for SimError {
    fn from(failure: StoppedRun<T>) -> Self {
        failure.error
    }
}
