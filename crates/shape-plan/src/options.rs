//! What a plan must achieve and how much work it may spend.

use crate::error::PlanError;
use lane_math::check_finite;

/// The most iterations of one shape solve [`PlanOptions`] accepts.
pub const MAX_ITERATIONS: usize = 100_000;
/// The most random samples (starts and via points) [`PlanOptions`] accepts.
pub const MAX_SAMPLES: usize = 100_000;
/// The largest clearance, check slack and tip tolerance [`PlanOptions`] accepts (m).
pub const MAX_LENGTH_M: f64 = 1e6;
/// The most check points of one path segment [`PlanOptions`] accepts.
pub const MAX_CHECKS: usize = 10_000_000;

/// The margin, the tolerances and the work bounds of a plan.
///
/// Work is bounded by these numbers alone: at most `2 + samples` shape solves (the free-space
/// inverse kinematics' starts, the initial shape, then `samples` random starts) of at most
/// `max_iterations` iterations each, and at most `samples` via points over the whole plan, every
/// path segment checked at no more than `max_checks` points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// The clearance `c` (m) every link keeps from every obstacle and from the other links, on
    /// the goal shape and all along the motion; non-negative.
    pub clearance: f64,
    /// The slack `epsilon` (m) of the motion checks: check points keep `c + epsilon`, spaced so
    /// that no point in between can lose more than `epsilon` (`docs/theory.md`, "Shape
    /// planning"); positive. Default `1e-3`.
    pub check_slack: f64,
    /// The largest distance of the goal shape's tip from the target (m); positive.
    /// Default `1e-6`.
    pub tip_tolerance: f64,
    /// The most iterations of one shape solve, at least 1. Default 200.
    pub max_iterations: usize,
    /// The random starts of the shape solve after the deterministic ones, and the via points
    /// tried when a straight motion is blocked (one budget for the whole plan). Default 64.
    pub samples: usize,
    /// Random starts and via points are drawn uniformly from `[-A, A]` in every modal coordinate
    /// (around the midpoint of the motion for via points), `A` this amplitude in radians;
    /// positive. Default 2.
    pub sample_amplitude: f64,
    /// The most check points of one path segment. Default `200_000`.
    pub max_checks: usize,
    /// The seed of the random samples: the same seed gives the same plan.
    pub seed: u64,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            clearance: 0.0,
            check_slack: 1e-3,
            tip_tolerance: 1e-6,
            max_iterations: 200,
            samples: 64,
            sample_amplitude: 2.0,
            max_checks: 200_000,
            seed: 0,
        }
    }
}

impl PlanOptions {
    /// Checks every number: finite, in range, counts within their limits.
    pub fn validate(&self) -> Result<(), PlanError> {
        check_finite("clearance", self.clearance)?;
        if self.clearance < 0.0 {
            return Err(PlanError::OutOfRange {
                name: "clearance",
                bound: "non-negative",
                value: self.clearance,
            });
        }
        for (name, value) in [
            ("check slack", self.check_slack),
            ("tip tolerance", self.tip_tolerance),
            ("sample amplitude", self.sample_amplitude),
        ] {
            check_finite(name, value)?;
            if value <= 0.0 {
                return Err(PlanError::OutOfRange {
                    name,
                    bound: "positive",
                    value,
                });
            }
        }
        // Lengths beyond any workspace (a slack of 1e300 m read as a clearance never met).
        for (name, value) in [
            ("clearance", self.clearance),
            ("check slack", self.check_slack),
            ("tip tolerance", self.tip_tolerance),
        ] {
            if value > MAX_LENGTH_M {
                return Err(PlanError::OutOfRange {
                    name,
                    bound: "at most 1e6 m",
                    value,
                });
            }
        }
        for (name, got, max) in [
            ("max iterations", self.max_iterations, MAX_ITERATIONS),
            ("samples", self.samples, MAX_SAMPLES),
            ("max checks", self.max_checks, MAX_CHECKS),
        ] {
            if got > max {
                return Err(PlanError::TooMany { name, got, max });
            }
        }
        for (name, count) in [
            ("max checks", self.max_checks),
            ("max iterations", self.max_iterations),
        ] {
            if count == 0 {
                return Err(PlanError::OutOfRange {
                    name,
                    bound: "at least 1",
                    value: 0.0,
                });
            }
        }
        Ok(())
    }

    /// The clearance every check point of a motion keeps, `c + epsilon`.
    pub fn needed(&self) -> f64 {
        self.clearance + self.check_slack
    }
}
