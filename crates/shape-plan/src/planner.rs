//! The plan: a goal shape and a checked motion to it from the initial shape, with the
//! fallbacks of `docs/theory.md`, "Shape planning".

use crate::arm::Arm;
use crate::data::PlanData;
use crate::error::PlanError;
use crate::motion::check_segment;
use crate::options::PlanOptions;
use crate::shape::solve_shape;
use clearance::{ClearanceModel, distances};
use lane_math::{check_finite, check_len};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A collision-free shape that reaches the target and a motion to it.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The goal shape's modal coordinates.
    pub goal: Vec<f64>,
    /// The motion: waypoints in modal coordinates, the initial shape first and the goal last,
    /// joined by straight segments. Every shape on it keeps the clearance `c`.
    pub path: Vec<Vec<f64>>,
    /// The goal's tip distance from the target, m.
    pub tip_error: f64,
    /// The goal shape's smallest clearance, m.
    pub goal_clearance: f64,
    /// The smallest clearance at the path's check points (at least `c + epsilon`), m.
    pub path_clearance: f64,
    /// Check points visited over the whole plan (including paths rejected).
    pub checks: usize,
    /// Shape solves started.
    pub starts: usize,
    /// Shape-solve iterations over the whole plan.
    pub iterations: usize,
}

/// The most work of a plan's shape solves, `(2 + samples) x max_iterations x pairs x
/// (coordinates + 1)`, about ten minutes (1,024 obstacles, 300 samples and the default 200
/// iterations: 1.9e9, 15 s); the motion checks are bounded by `max_checks` a segment.
pub const MAX_PLAN_WORK: f64 = 1e11;

/// Plans shapes and motions of one arm among one set of obstacles; built once, reused for
/// many targets.
#[derive(Debug, Clone)]
pub struct Planner<A: Arm> {
    arm: A,
    clearance: ClearanceModel,
    options: PlanOptions,
    data: PlanData,
}

impl<A: Arm> Planner<A> {
    /// A planner for `arm` among the obstacles (and with the link radius) of `clearance`.
    pub fn new(arm: A, clearance: ClearanceModel, options: PlanOptions) -> Result<Self, PlanError> {
        options.validate()?;
        // Each iteration of a shape solve measures every pair and its gradient.
        let pairs = clearance.pairs().len();
        let work = (2.0 + options.samples as f64)
            * options.max_iterations as f64
            * pairs as f64
            * (arm.n_coords() as f64 + 1.0);
        if work > MAX_PLAN_WORK {
            return Err(PlanError::TooMuchWork {
                work,
                pairs,
                max: MAX_PLAN_WORK,
            });
        }
        let data = PlanData::new(&arm, &clearance)?;
        Ok(Self {
            arm,
            clearance,
            options,
            data,
        })
    }

    /// The arm.
    pub fn arm(&self) -> &A {
        &self.arm
    }

    /// The links' radius and the obstacles.
    pub fn clearance(&self) -> &ClearanceModel {
        &self.clearance
    }

    /// The margin, tolerances and work bounds.
    pub fn options(&self) -> &PlanOptions {
        &self.options
    }

    /// The smallest clearance (to obstacles and to itself) of the shape `a`.
    pub fn shape_clearance(&mut self, a: &[f64]) -> Result<f64, PlanError> {
        check_len("modal coordinates", a.len(), self.arm.n_coords())?;
        let data = &mut self.data;
        self.arm
            .place(&self.clearance, &mut data.trial, &mut data.scratch, a)?;
        let (obstacles, itself) = distances(&self.clearance, &mut data.trial);
        Ok(obstacles.min(itself))
    }

    /// Plans a shape whose tip is within the tip tolerance of `target` (`dimension()` entries)
    /// with every link at least `c` from every obstacle and from the other links, and a motion
    /// from `initial` that keeps `c` throughout.
    ///
    /// The goal is solved by [`solve_shape`] from, in turn, the free-space inverse kinematics'
    /// shapes, the initial shape and `samples` random shapes, until one reaches the target and
    /// a motion to it is found: first the straight segment in modal space, then, from one
    /// budget of `samples` via points for the whole plan, two segments through a random via
    /// point. The random numbers come from `seed`, so a plan is reproducible.
    ///
    /// Errors: [`PlanError::InitialTooClose`] when `initial` keeps less than `c + epsilon`;
    /// [`PlanError::OutOfReach`] for a target beyond the arm's length;
    /// [`PlanError::TargetTooClose`] for a target whose link would come nearer an obstacle than
    /// the clearance;
    /// [`PlanError::NoCollisionFreeShape`] (with the best shape reached) when no start reaches
    /// the target with the clearance; [`PlanError::NoCollisionFreeMotion`] when goals were found
    /// but no checked path leads to one; input errors for sizes and non-finite numbers.
    pub fn plan(&mut self, initial: &[f64], target: &[f64]) -> Result<Plan, PlanError> {
        let arm = &self.arm;
        let m = arm.n_coords();
        check_len("initial shape", initial.len(), m)?;
        check_len("target", target.len(), arm.dimension())?;
        for &x in initial {
            check_finite("initial shape coordinate", x)?;
        }
        for &x in target {
            check_finite("target coordinate", x)?;
        }
        let mut goal_point = [0.0; 3];
        goal_point[..target.len()].copy_from_slice(target);
        let base = arm.base();
        // `hypot` keeps a target far beyond the arm (1e300 m) finite in the message.
        let offset: [f64; 3] = std::array::from_fn(|d| goal_point[d] - base[d]);
        let distance = offset[0].hypot(offset[1]).hypot(offset[2]);
        // A target at the arm's length is the straight arm's tip, whatever the rounding of the
        // sum of its links.
        if distance > arm.length() * (1.0 + 4.0 * f64::EPSILON) {
            return Err(PlanError::OutOfReach {
                distance,
                length: arm.length(),
            });
        }
        let needed = self.options.needed();
        let initial_clearance = self.shape_clearance(initial)?;
        if initial_clearance < needed {
            return Err(PlanError::InitialTooClose {
                clearance: initial_clearance,
                needed,
            });
        }
        // The tip ends a link, whose capsule keeps the margin only if the target does.
        let radius = self.clearance.radius();
        let near = self
            .clearance
            .obstacles()
            .iter()
            .map(|obstacle| obstacle.signed_distance(goal_point) - radius)
            .enumerate()
            .find(|&(_, clearance)| clearance < needed);
        if let Some((obstacle, clearance)) = near {
            return Err(PlanError::TargetTooClose {
                obstacle,
                radius,
                clearance,
                needed,
            });
        }
        let (arm, clearance, options, data) =
            (&self.arm, &self.clearance, &self.options, &mut self.data);
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let amplitude = options.sample_amplitude;
        let mut starts: Vec<Vec<f64>> = arm.free_space_starts(goal_point, initial);
        starts.push(initial.to_vec());
        let mut plan = Plan {
            goal: Vec::new(),
            path: Vec::new(),
            tip_error: f64::INFINITY,
            goal_clearance: f64::NEG_INFINITY,
            path_clearance: f64::INFINITY,
            checks: 0,
            starts: 0,
            iterations: 0,
        };
        // The best shape reached: smallest tip error, then largest clearance.
        let mut best = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut goals, mut via_left, mut best_path) = (0, options.samples, f64::NEG_INFINITY);
        let via_per_goal = (options.samples / 4).max(1);
        let mut a = vec![0.0; m];
        let mut via = vec![0.0; m];
        for start in 0..starts.len() + options.samples {
            if let Some(given) = starts.get(start) {
                a.copy_from_slice(given);
            } else {
                for x in &mut a {
                    *x = rng.random_range(-amplitude..=amplitude);
                }
            }
            plan.starts += 1;
            let outcome = solve_shape(arm, clearance, options, data, goal_point, &mut a)?;
            plan.iterations += outcome.iterations;
            if (outcome.tip_error, -outcome.clearance) < (best.0, -best.1) {
                best = (outcome.tip_error, outcome.clearance);
            }
            if !outcome.reached {
                continue;
            }
            goals += 1;
            let straight = check_segment(arm, clearance, options, data, initial, &a)?;
            plan.checks += straight.checks;
            best_path = best_path.max(straight.clearance);
            let mut path = None;
            if straight.clear {
                path = Some(vec![initial.to_vec(), a.clone()]);
                plan.path_clearance = straight.clearance;
            } else {
                for _ in 0..via_per_goal.min(via_left) {
                    via_left -= 1;
                    for ((v, x), y) in via.iter_mut().zip(initial).zip(&a) {
                        *v = 0.5 * (x + y) + rng.random_range(-amplitude..=amplitude);
                    }
                    let first = check_segment(arm, clearance, options, data, initial, &via)?;
                    plan.checks += first.checks;
                    if !first.clear {
                        continue;
                    }
                    let second = check_segment(arm, clearance, options, data, &via, &a)?;
                    plan.checks += second.checks;
                    best_path = best_path.max(first.clearance.min(second.clearance));
                    if second.clear {
                        path = Some(vec![initial.to_vec(), via.clone(), a.clone()]);
                        plan.path_clearance = first.clearance.min(second.clearance);
                        break;
                    }
                }
            }
            if let Some(path) = path {
                plan.goal = a;
                plan.path = path;
                plan.tip_error = outcome.tip_error;
                plan.goal_clearance = outcome.clearance;
                return Ok(plan);
            }
        }
        if goals > 0 {
            Err(PlanError::NoCollisionFreeMotion {
                shapes: goals,
                best_clearance: best_path,
                needed,
            })
        } else {
            Err(PlanError::NoCollisionFreeShape {
                best_clearance: best.1,
                needed,
                tip_error: best.0,
                starts: plan.starts,
            })
        }
    }
}
