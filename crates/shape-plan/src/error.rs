//! The error type of this crate.

use lane_math::{Classify, Compact, ErrorClass, ShapeError, ShapeProblem};

/// Why a plan was refused or not found; every variant names the condition.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// No start led to a shape that reaches the target with the clearance: the best shape
    /// reached is reported (the one with the smallest tip error, ties broken by clearance); when
    /// that shape keeps the clearance, the message says the target was not reached.
    #[error(
        "{}: the best shape reached (the nearest to the target) has clearance {} m (needed {} m) \
         with its tip {} m from the target, after {starts} starts",
        if *.best_clearance >= *.needed {
            "no shape found that reaches the target (the modal family may not reach it from this \
             base angle)"
        } else {
            "no collision-free shape found"
        },
        Compact(*.best_clearance),
        Compact(*.needed),
        Compact(*.tip_error)
    )]
    NoCollisionFreeShape {
        /// The smallest clearance (to obstacles and to itself) of the best shape reached, m.
        best_clearance: f64,
        /// The clearance a shape must keep (the task's margin plus the check slack), m.
        needed: f64,
        /// The distance of that shape's tip from the target, m.
        tip_error: f64,
        /// How many starts were tried.
        starts: usize,
    },
    /// Collision-free shapes reach the target but no checked path leads to any of them.
    #[error(
        "no collision-free motion found: {shapes} collision-free shapes reach the target, but \
         every path tried from the initial shape comes within {} m of a collision (needed {} m)",
        Compact(*.best_clearance),
        Compact(*.needed)
    )]
    NoCollisionFreeMotion {
        /// How many goal shapes were found.
        shapes: usize,
        /// The largest, over the paths tried, of the smallest clearance checked on the path, m.
        best_clearance: f64,
        /// The clearance every check point must keep, m.
        needed: f64,
    },
    /// The initial shape is already closer to an obstacle or to itself than the margin.
    #[error(
        "the initial shape has clearance {} m, less than the {} m the motion must keep",
        Compact(*.clearance),
        Compact(*.needed)
    )]
    InitialTooClose {
        /// The initial shape's smallest clearance, m.
        clearance: f64,
        /// The clearance every check point must keep, m.
        needed: f64,
    },
    /// A follow-the-leader deployment would lay the arm over itself: its centreline turns back
    /// within a few links' length, so that two links sharing no joint overlap.
    #[error(
        "deploy centerline folds the arm onto itself: at tip progress {} m two links that share \
         no joint overlap by {} m (a path the body can follow turns back no sharper than its \
         links and their thickness allow)",
        Compact(*.progress),
        Compact(-*.clearance)
    )]
    DeployFoldsOnItself {
        /// The tip's progress along the centreline at the first overlapping shape, m.
        progress: f64,
        /// That shape's smallest clearance between links that share no joint, m (negative).
        clearance: f64,
    },
    /// The target is farther from the base than the arm is long.
    #[error(
        "target is {} m from the base, beyond the arm's length {} m",
        Compact(*.distance),
        Compact(*.length)
    )]
    OutOfReach {
        /// Distance of the target from the base, m.
        distance: f64,
        /// The arm's length, m.
        length: f64,
    },
    /// The target is nearer an obstacle than a link's capsule around it may be: no shape whose
    /// tip is there keeps the clearance.
    #[error(
        "target is within obstacles[{obstacle}]'s margin: a link ending there (radius {} m) \
         keeps {} m from it, less than the {} m every link must keep",
        Compact(*.radius),
        Compact(*.clearance),
        Compact(*.needed)
    )]
    TargetTooClose {
        /// The obstacle's index (0-based, in the model's order).
        obstacle: usize,
        /// The links' radius, m.
        radius: f64,
        /// The clearance of a link ending at the target from that obstacle, m.
        clearance: f64,
        /// The clearance every shape must keep, m.
        needed: f64,
    },
    /// A deployment deeper than the arm reaches along the channel with its base at the entry.
    #[error(
        "deploy.centerline's length {} m is more than the arm reaches along it with its base at \
         the entry, {} m (the base would pass the entry: the arm is too short for it)",
        Compact(*.depth),
        Compact(*.reach)
    )]
    ArmTooShort {
        /// The depth asked for (m of tip progress).
        depth: f64,
        /// The most tip progress with the base at the entry (m).
        reach: f64,
    },
    /// A number outside its domain.
    #[error("{name} must be {bound}, got {}", Compact(*.value))]
    OutOfRange {
        /// Which input.
        name: &'static str,
        /// What it must be, as words.
        bound: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A count beyond its limit.
    #[error("{name} must be at most {max}, got {got}")]
    TooMany {
        /// Which count.
        name: &'static str,
        /// The count asked for.
        got: usize,
        /// The limit.
        max: usize,
    },
    /// The shape solves a plan may run ([`MAX_PLAN_WORK`](crate::MAX_PLAN_WORK)) would take too
    /// long: `(2 + samples) x max_iterations x pairs x (coordinates + 1)`.
    #[error(
        "samples and max iterations allow {:.2e} operations of shape solves ((2 + samples) x \
         max iterations x {pairs} clearance pairs x (coordinates + 1)), more than the {:e} a \
         plan may take (about ten minutes): fewer samples or iterations, links or obstacles",
        work,
        max
    )]
    TooMuchWork {
        /// The estimate.
        work: f64,
        /// The clearance pairs of one shape.
        pairs: usize,
        /// The limit.
        max: f64,
    },
    /// A slice had the wrong number of entries.
    #[error("{name} has {found} entries, expected {expected}")]
    Dimension {
        /// Which input.
        name: &'static str,
        /// The length expected.
        expected: usize,
        /// The length found.
        found: usize,
    },
    /// The clearance computation refused its input.
    #[error(transparent)]
    Clearance(#[from] clearance::ClearanceError),
    /// The kinematics refused its input.
    #[error(transparent)]
    Kinematics(#[from] backbone_kin::KinError),
}

impl Classify for PlanError {
    /// A target without a collision-free shape or motion, or a channel the body cannot follow
    /// without overlapping itself, is unreachable; wrapped errors keep
    /// their class; every other error is invalid input.
    fn class(&self) -> ErrorClass {
        match self {
            Self::NoCollisionFreeShape { .. }
            | Self::NoCollisionFreeMotion { .. }
            | Self::DeployFoldsOnItself { .. }
            | Self::TargetTooClose { .. }
            | Self::OutOfReach { .. } => ErrorClass::Unreachable,
            Self::Clearance(error) => error.class(),
            Self::Kinematics(error) => error.class(),
            _ => ErrorClass::InvalidInput,
        }
    }
}

/// A refused shape or non-finite number as [`PlanError::Dimension`] or a
/// [`PlanError::OutOfRange`] that must be `"finite"`, with the same message. This crate checks
/// single numbers for finiteness (a vector entry by entry), so the message carries no index.
impl From<ShapeError<'static>> for PlanError {
    fn from(error: ShapeError<'static>) -> Self {
        let name = error.name;
        match error.problem {
            ShapeProblem::Length { expected, found } => Self::Dimension {
                name,
                expected,
                found,
            },
            ShapeProblem::NonFinite { value, .. } => Self::OutOfRange {
                name,
                bound: "finite",
                value,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_error_keeps_its_message() {
        for error in [
            lane_math::check_len("initial shape", 3, 2).unwrap_err(),
            lane_math::check_finite("deploy radius", f64::NAN).unwrap_err(),
        ] {
            let plan = PlanError::from(error);
            assert_eq!(plan.to_string(), error.to_string());
            assert!(plan.is_invalid_input());
        }
    }
}
