//! A shape that reaches the target with the clearance: sequential quadratic programming over
//! the modal coordinates with a trust region (`docs/theory.md`, "Shape planning").
//!
//! Each iteration linearises the tip `p(a)` (`T = d p / d a`) and every pair's clearance `d_k(a)`
//! (its modal gradient, [`Arm::gradients`]) and solves the strictly convex QP
//!
//! `min_delta 1/2 |e + T delta|^2 + mu/2 |delta|^2`
//! subject to `d_k + grad d_k . delta >= g_k` for every pair and `|delta|_inf <= Delta`,
//!
//! `e = p(a) - target`, `g_k = c + 3 epsilon / 2` (the margin, the check slack and half of it
//! again for the linearisation). A pair whose row the trust region already implies
//! (`d_k - g_k >= |grad d_k|_1 Delta`, with a factor 2 to spare) is left out of the QP, which
//! has the same solution with fewer rows; when that QP is empty (an iterate in collision whose
//! linearisation cannot clear in one step) the goals become `min(g_k, d_k)`, which `delta = 0`
//! meets. A step is accepted when the exact penalty `phi(a) = 1/2 |e|^2 + rho sum_k
//! max(0, g_k - d_k)`, `rho` the arm's length, falls by at least a tenth of what the
//! linearisation predicts; the trust radius `Delta` doubles after a good step at its bound and
//! quarters after a rejected one.

use crate::arm::Arm;
use crate::data::PlanData;
use crate::error::PlanError;
use crate::options::{MAX_LENGTH_M, PlanOptions};
use clearance::{ClearanceModel, distances};
use optimal_ctl::{LinearQpFailure, ProjectionFailure};

/// The first trust radius (rad, on every coordinate).
const INITIAL_RADIUS: f64 = 0.25;
/// The largest trust radius (rad).
const MAX_RADIUS: f64 = 2.0;
/// Below this trust radius the iteration has stalled.
const MIN_RADIUS: f64 = 1e-12;

/// What a shape solve reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeOutcome {
    /// Whether the shape reaches the target within the tip tolerance with clearance at least
    /// `c + epsilon`.
    pub reached: bool,
    /// The distance of the final shape's tip from the target, m.
    pub tip_error: f64,
    /// The final shape's smallest clearance (to obstacles and to itself), m.
    pub clearance: f64,
    /// Iterations spent.
    pub iterations: usize,
}

/// Solves for a shape whose tip is on `target` with every pair's clearance at least
/// `c + epsilon` (module docs), from the modal coordinates in `a`, which receive the last
/// accepted iterate. Allocation-free.
///
/// Returns the outcome whether or not it reached the target; errors are for bad input (options
/// that [`PlanOptions::validate`] refuses, a non-finite start, a target coordinate not finite or
/// beyond [`MAX_LENGTH_M`], sizes that disagree).
pub fn solve_shape<A: Arm>(
    arm: &A,
    clearance: &ClearanceModel,
    options: &PlanOptions,
    data: &mut PlanData,
    target: [f64; 3],
    a: &mut [f64],
) -> Result<ShapeOutcome, PlanError> {
    options.validate()?;
    let m = arm.n_coords();
    lane_math::check_len("modal coordinates", a.len(), m)?;
    for &x in a.iter() {
        lane_math::check_finite("start coordinate", x)?;
    }
    for x in target {
        lane_math::check_finite("target coordinate", x)?;
        if x.abs() > MAX_LENGTH_M {
            return Err(PlanError::OutOfRange {
                name: "target coordinate",
                bound: "at most 1e6 m in magnitude",
                value: x,
            });
        }
    }
    let goal = options.needed() + 0.5 * options.check_slack;
    let rho = arm.length();

    arm.place(clearance, &mut data.current, &mut data.scratch, a)?;
    distances(clearance, &mut data.current);
    arm.gradients(
        clearance,
        &mut data.current,
        &mut data.scratch,
        &mut data.gradients,
        &mut data.tip_jacobian,
    )?;
    let mut state = Evaluation::of(&data.current, clearance, target, goal, rho, arm.n_links());
    let mut radius = INITIAL_RADIUS;
    let mut iterations = 0;
    loop {
        let reached =
            state.tip_error <= options.tip_tolerance && state.clearance >= options.needed();
        if reached || iterations >= options.max_iterations || radius < MIN_RADIUS {
            return Ok(ShapeOutcome {
                reached,
                tip_error: state.tip_error,
                clearance: state.clearance,
                iterations,
            });
        }
        iterations += 1;
        // The QP: H = T^T T + mu I, q = T^T e.
        let t = &data.tip_jacobian;
        let mut trace = 0.0;
        for i in 0..m {
            for j in 0..m {
                let h = (0..3).map(|d| t[d * m + i] * t[d * m + j]).sum::<f64>();
                data.hessian[i * m + j] = h;
            }
            trace += data.hessian[i * m + i];
            data.linear[i] = (0..3).map(|d| t[d * m + i] * state.error[d]).sum();
        }
        let mu = 1e-9 * (trace / m as f64 + rho * rho);
        for i in 0..m {
            data.hessian[i * m + i] += mu;
        }
        let mut solved = false;
        for relaxed in [false, true] {
            // A pair's row `-grad d_k . delta <= d_k - g_k` that the trust region implies
            // (its bound at least twice the largest `|grad d_k|_1 Delta` the box allows) is left
            // out: the same feasible set with fewer rows.
            let mut rows = 0;
            for (k, &d) in data.current.distances().iter().enumerate() {
                let gradient = &data.gradients[k * m..(k + 1) * m];
                let target_clearance = if relaxed { goal.min(d) } else { goal };
                let bound = d - target_clearance;
                let reach = radius * gradient.iter().map(|g| g.abs()).sum::<f64>();
                if bound > 2.0 * reach {
                    continue;
                }
                let row = &mut data.rows[rows * m..(rows + 1) * m];
                for (r, g) in row.iter_mut().zip(gradient) {
                    *r = -g;
                }
                data.bounds[rows] = bound.min(f64::MAX);
                rows += 1;
            }
            for l in 0..m {
                for sign in [1.0, -1.0] {
                    let row = &mut data.rows[rows * m..(rows + 1) * m];
                    row.fill(0.0);
                    row[l] = sign;
                    data.bounds[rows] = radius;
                    rows += 1;
                }
            }
            match data.qp.solve(
                &data.hessian,
                &data.linear,
                &data.rows[..rows * m],
                &data.bounds[..rows],
                &mut data.step,
            ) {
                Ok(_) => {
                    solved = true;
                    break;
                }
                Err(LinearQpFailure::Projection(
                    ProjectionFailure::Empty | ProjectionFailure::NoConvergence,
                )) if !relaxed => {}
                Err(_) => break,
            }
        }
        if !solved {
            radius *= 0.25;
            continue;
        }
        // The merit the linearisation predicts.
        let mut model_tip = 0.0;
        for d in 0..3 {
            let row = &data.tip_jacobian[d * m..(d + 1) * m];
            let moved =
                state.error[d] + row.iter().zip(&data.step).map(|(x, y)| x * y).sum::<f64>();
            model_tip += 0.5 * moved * moved;
        }
        let mut model_violation = 0.0;
        for (k, &d) in data.current.distances().iter().enumerate() {
            let slope: f64 = data.gradients[k * m..(k + 1) * m]
                .iter()
                .zip(&data.step)
                .map(|(x, y)| x * y)
                .sum();
            model_violation += (goal - d - slope).max(0.0);
        }
        let predicted = state.merit - (model_tip + rho * model_violation);
        if predicted.is_nan() || predicted <= 1e-15 * (1.0 + state.merit) {
            radius *= 0.25;
            continue;
        }
        for ((p, x), s) in data.point.iter_mut().zip(a.iter()).zip(&data.step) {
            *p = x + s;
        }
        arm.place(clearance, &mut data.trial, &mut data.scratch, &data.point)?;
        distances(clearance, &mut data.trial);
        let trial = Evaluation::of(&data.trial, clearance, target, goal, rho, arm.n_links());
        let ratio = (state.merit - trial.merit) / predicted;
        let longest = data.step.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        if ratio >= 0.1 {
            a.copy_from_slice(&data.point);
            std::mem::swap(&mut data.current, &mut data.trial);
            arm.gradients(
                clearance,
                &mut data.current,
                &mut data.scratch,
                &mut data.gradients,
                &mut data.tip_jacobian,
            )?;
            state = trial;
            if ratio > 0.75 && longest >= 0.9 * radius {
                radius = (2.0 * radius).min(MAX_RADIUS);
            }
        } else {
            radius = 0.25 * longest.min(radius);
        }
    }
}

/// The tip error, the smallest clearance and the merit of one placed shape.
#[derive(Debug, Clone, Copy)]
struct Evaluation {
    error: [f64; 3],
    tip_error: f64,
    clearance: f64,
    merit: f64,
}

impl Evaluation {
    fn of(
        data: &clearance::ClearanceData,
        model: &ClearanceModel,
        target: [f64; 3],
        goal: f64,
        rho: f64,
        n_links: usize,
    ) -> Self {
        let tip = data.points()[n_links];
        let error = [tip[0] - target[0], tip[1] - target[1], tip[2] - target[2]];
        let squared = error.iter().map(|x| x * x).sum::<f64>();
        let violation: f64 = data.distances().iter().map(|d| (goal - d).max(0.0)).sum();
        Self {
            error,
            tip_error: squared.sqrt(),
            clearance: data
                .min_obstacle_clearance(model)
                .min(data.min_self_clearance(model)),
            merit: 0.5 * squared + rho * violation,
        }
    }
}
