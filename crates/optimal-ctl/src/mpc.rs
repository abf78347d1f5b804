//! Receding-horizon model-predictive control of the reduced model: control-limited iLQR over a
//! horizon of the semi-implicit Euler discretisation, re-planned from the measured state and
//! warm-started from the previous plan shifted by the time elapsed.

use modal_reduce::{Plant, PlantData, PlantDerivatives, ReducedDerivativesBatch};

use super::OptimalError;
use super::discrete::{ReducedEuler, check_step};
use super::ilqr::{Ilqr, IlqrReport, IlqrSettings, TrackingCost};
use super::step_constraints::StepConstraints;

/// The settings of [`Mpc`]: horizon, model step, the weights of the tracking cost and the
/// `tau*` limits.
#[derive(Debug, Clone, PartialEq)]
pub struct MpcSettings {
    /// Steps of the horizon `N` (1 to 10000).
    pub horizon: usize,
    /// The model's step `h` (s): the horizon covers `N h` seconds.
    pub step: f64,
    /// Weight on the coordinate errors `a - a_ref` (1/rad^2 per second of horizon), `m` entries.
    pub position_weight: Vec<f64>,
    /// Weight on the rate errors `a_dot - a_ref_dot`, `m` entries.
    pub rate_weight: Vec<f64>,
    /// Weight on `tau* - tau*_ref` (1/(N m)^2 per second), `m` entries, positive; `tau*_ref` is
    /// the inverse dynamics along the reference.
    pub effort_weight: Vec<f64>,
    /// The terminal weight is this many seconds of the running state weight.
    pub terminal_seconds: f64,
    /// `|tau*_i| <= limit_i` (N m), `m` positive entries, or `None` for no limits.
    pub tau_star_limits: Option<Vec<f64>>,
    /// The iLQR solver's settings (a warm-started solve needs few iterations).
    pub solver: IlqrSettings,
}

impl MpcSettings {
    /// Settings for `m` coordinates: 60 steps of 5 ms (a 0.3 s horizon), position weight
    /// `1e4`, rate weight `1`, effort weight `1e-3`, a terminal weight of 0.1 s, no limits, at
    /// most 5 iterations per solve starting from the regularisation `1e-2`.
    pub fn uniform(m: usize) -> Self {
        Self {
            horizon: 60,
            step: 0.005,
            position_weight: vec![1e4; m],
            rate_weight: vec![1.0; m],
            effort_weight: vec![1e-3; m],
            terminal_seconds: 0.1,
            tau_star_limits: None,
            solver: IlqrSettings {
                max_iterations: 5,
                tolerance: 1e-6,
                gradient_tolerance: 1e-6,
                // Steps on the small effort weight are long and the quadratic model poor over
                // them: starting regularised finds lower costs in fewer line-search trials.
                regularisation: 1e-2,
                ..IlqrSettings::default()
            },
        }
    }

    /// The most modal coordinates `m` whose plan over `horizon` steps (`2m` states, `m`
    /// controls) the solver's workspace holds ([`MAX_WORKSPACE`](crate::MAX_WORKSPACE)
    /// numbers): 199 for the default 60 steps.
    pub fn max_coords(&self) -> usize {
        let horizon = self.horizon.max(1);
        // `horizon * 14 m^2` numbers: from the square root's estimate, down to the first fit.
        let mut m = (crate::MAX_WORKSPACE as f64 / (14.0 * horizon as f64)).sqrt() as usize + 1;
        while m > 0 && !crate::ilqr::workspace_fits(2 * m, m, horizon) {
            m -= 1;
        }
        m
    }
}

/// The most steps of an MPC horizon.
pub const MAX_MPC_HORIZON: usize = 10_000;

/// Model-predictive control of a reduced model: a workspace built once for a model and settings,
/// then [`set_reference`](Self::set_reference) for the `N + 1` nodes of the horizon,
/// [`shift`](Self::shift) to warm-start from the previous plan, [`solve`](Self::solve) from the
/// measured state, and [`control`](Self::control) for the torque at any time before the next
/// plan. Nothing allocates after [`new`](Self::new).
///
/// The problem solved at each plan, with `x = (a, a_dot)`, `u = tau*`, `h` the step:
///
/// ```text
/// minimise   sum_{k<N} h/2 [ |x_k - r_k|^2_Q + |u_k - w_k|^2_R ] + 1/2 |x_N - r_N|^2_{Q_f}
/// subject to x_0 = measured state,  x_{k+1} = Euler_h(x_k, u_k),  -limit <= u_k <= limit,
/// ```
///
/// `r_k` the reference at `t + k h`, `w_k = M*(r) a_ref_dd + C*(r) + G*(r)` its inverse dynamics
/// (so that the effort weight penalises the correction, not the torque that holds the arm
/// against gravity), `Q = diag(position, rate)`, `R = diag(effort)`, `Q_f = terminal_seconds Q`.
/// The running weights are multiplied by `h`, so that they mean the same for any step.
#[derive(Debug, Clone)]
pub struct Mpc {
    m: usize,
    step: f64,
    solver: IlqrSettings,
    ilqr: Ilqr,
    data: PlantData,
    derivatives: PlantDerivatives,
    /// A planar model's trajectories linearised SIMD across nodes.
    batch: Option<ReducedDerivativesBatch>,
    /// `2m`: the state and its deviation from the plan.
    state: Vec<f64>,
    deviation: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    planned: bool,
}

impl Mpc {
    /// The controller for `model` with `settings`.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] or [`OptimalError::Dimension`] for settings out of their
    /// domain or of the wrong length (horizon above [`MAX_MPC_HORIZON`], a weight or limit that
    /// is negative, zero where it must be positive, or not finite);
    /// [`OptimalError::Dynamics`] with `ReduceError::OutOfMemory` when the system refuses the
    /// memory of a planar model's batch derivatives.
    pub fn new<'p>(
        model: impl Into<Plant<'p>>,
        settings: &MpcSettings,
    ) -> Result<Self, OptimalError> {
        let model = model.into();
        let m = model.n_coords();
        let cost = tracking_cost(settings, m)?;
        let h = settings.step;
        let ilqr = Ilqr::new(2 * m, m, settings.horizon, &cost)?;
        let mut mpc = Self {
            m,
            step: h,
            solver: settings.solver,
            ilqr,
            data: PlantData::new(model),
            derivatives: PlantDerivatives::new(model),
            batch: match model {
                Plant::Planar(planar) => Some(ReducedDerivativesBatch::try_new(planar)?),
                Plant::Spatial(_) => None,
            },
            state: vec![0.0; 2 * m],
            deviation: vec![0.0; 2 * m],
            lower: vec![0.0; m],
            upper: vec![0.0; m],
            planned: false,
        };
        mpc.set_limits(settings.tau_star_limits.as_deref())?;
        Ok(mpc)
    }

    /// The number of modal coordinates `m`.
    pub fn n_coords(&self) -> usize {
        self.m
    }

    /// The model step `h` (s).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The horizon `N` (steps).
    pub fn horizon(&self) -> usize {
        self.ilqr.horizon()
    }

    /// An upper estimate of one solve's work for an arm of `n_joints` joints with `rows`
    /// constraint rows a node ([`solve_constrained`](Self::solve_constrained); 0 for
    /// [`solve`](Self::solve)), in multiply-adds of the reduced dynamics (`n m^2` an
    /// evaluation): every iteration of [`IlqrSettings::max_iterations`](crate::IlqrSettings)
    /// taking every line-search trial (a rollout each) and linearising the horizon (about `16 m`
    /// evaluations a node), plus `64 m^2` a row and node for the constrained QPs. Measured
    /// against it (6 December): the 10-link planar solve 92 us of an estimated 0.5e6, the
    /// 200-link spatial one (400 joints, `m = 8`) 0.27 s of an estimated 1.06e9.
    pub fn solve_work(&self, n_joints: usize, rows: usize) -> f64 {
        let m = self.m as f64;
        let per_node = n_joints as f64 * m * m * (self.solver.line_search_steps as f64 + 16.0 * m)
            + 64.0 * rows as f64 * m * m;
        self.solver.max_iterations as f64 * self.horizon() as f64 * per_node
    }

    /// The iLQR workspace: the last plan's controls, states and gains.
    pub fn ilqr(&self) -> &Ilqr {
        &self.ilqr
    }

    /// Sets `|tau*_i| <= limits_i` (`m` positive entries, N m), or no limits.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for a wrong length, [`OptimalError::InvalidSetting`] for a
    /// limit that is not positive (infinity is allowed: no limit on that coordinate).
    pub fn set_limits(&mut self, limits: Option<&[f64]>) -> Result<(), OptimalError> {
        set_box(&mut self.ilqr, limits, &mut self.lower, &mut self.upper)
    }

    /// Sets the reference of node `k` (`0..=N`, time `t + k h` of the plan): `a`, `a_dot` and,
    /// for `k < N`, the feed-forward torque from `a_ddot` by the inverse dynamics (eq 15).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for `k > N` or wrong lengths, [`OptimalError::Dynamics`] if
    /// the model refuses the reference state.
    pub fn set_reference<'p>(
        &mut self,
        model: impl Into<Plant<'p>>,
        k: usize,
        a: &[f64],
        a_dot: &[f64],
        a_ddot: &[f64],
    ) -> Result<(), OptimalError> {
        let (m, n) = (self.m, self.horizon());
        check_reference(k, n, m, [("a", a), ("a_dot", a_dot), ("a_ddot", a_ddot)])?;
        let x_ref = &mut self.ilqr.state_references_mut()[k * 2 * m..(k + 1) * 2 * m];
        x_ref[..m].copy_from_slice(a);
        x_ref[m..].copy_from_slice(a_dot);
        if k < n {
            model.into().terms(&mut self.data, a, a_dot)?;
            let (mass, c, g) = (
                self.data.mass_matrix(),
                self.data.coriolis(),
                self.data.gravity(),
            );
            let w = &mut self.ilqr.control_references_mut()[k * m..(k + 1) * m];
            for i in 0..m {
                let mut tau = c[i] + g[i];
                for (j, acc) in a_ddot.iter().enumerate() {
                    tau += mass[(i, j)] * acc;
                }
                w[i] = tau;
            }
        }
        Ok(())
    }

    /// Moves the previous plan `steps` steps earlier as the next warm start (the first plan
    /// starts from the feed-forward torques instead).
    pub fn shift(&mut self, steps: usize) {
        self.ilqr.shift(steps);
    }

    /// Plans from the state `(a, a_dot)` over the references set: control-limited iLQR from the
    /// warm start (the shifted previous plan, or the reference torques for the first plan).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong lengths or a model of another size; the solver's and
    /// the dynamics' errors.
    pub fn solve<'p>(
        &mut self,
        model: impl Into<Plant<'p>>,
        a: &[f64],
        a_dot: &[f64],
    ) -> Result<IlqrReport, OptimalError> {
        self.plan(model.into(), a, a_dot, None)
    }

    /// Plans as [`solve`](Self::solve) does within the general linear constraints of
    /// `constraints` at every node besides the `tau*` box ([`Ilqr::solve_constrained`]): the
    /// joint-torque polytope ([`JointTorqueRows`](crate::JointTorqueRows)), or joint limits and
    /// clearances linearised through the step's `B`. The first call sizes the solver's
    /// constraint memory (allocates); later calls with as many rows do not. A node whose rows
    /// admit no torque within the box is planned within the box alone
    /// ([`IlqrReport::relaxed_nodes`]).
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_constrained<'p>(
        &mut self,
        model: impl Into<Plant<'p>>,
        a: &[f64],
        a_dot: &[f64],
        constraints: &mut dyn StepConstraints,
    ) -> Result<IlqrReport, OptimalError> {
        self.plan(model.into(), a, a_dot, Some(constraints))
    }

    fn plan(
        &mut self,
        model: Plant<'_>,
        a: &[f64],
        a_dot: &[f64],
        constraints: Option<&mut (dyn StepConstraints + '_)>,
    ) -> Result<IlqrReport, OptimalError> {
        let m = self.m;
        if model.n_coords() != m {
            return Err(OptimalError::Dimension {
                name: "model coordinates",
                expected: m,
                found: model.n_coords(),
            });
        }
        for (name, values) in [("a", a), ("a_dot", a_dot)] {
            if values.len() != m {
                return Err(OptimalError::Dimension {
                    name,
                    expected: m,
                    found: values.len(),
                });
            }
        }
        if !self.planned {
            self.ilqr.warm_start_from_control_references();
        }
        self.state[..m].copy_from_slice(a);
        self.state[m..].copy_from_slice(a_dot);
        let mut dynamics =
            ReducedEuler::new(model, &mut self.data, &mut self.derivatives, self.step)?;
        if let Some(batch) = &mut self.batch {
            dynamics = dynamics.with_batch(batch);
        }
        let report = match constraints {
            None => self.ilqr.solve(&mut dynamics, &self.state, &self.solver)?,
            Some(rows) => {
                self.ilqr.reserve_constraints(rows.max_rows())?;
                self.ilqr
                    .solve_constrained(&mut dynamics, rows, &self.state, &self.solver)?
            }
        };
        self.planned = true;
        Ok(report)
    }

    /// Sizes the solver's memory for [`solve_constrained`](Self::solve_constrained) with at
    /// most `max_rows` rows a node (allocates; `solve_constrained` does it on its first call).
    ///
    /// # Errors
    /// As [`Ilqr::reserve_constraints`].
    pub fn reserve_constraints(&mut self, max_rows: usize) -> Result<(), OptimalError> {
        self.ilqr.reserve_constraints(max_rows)
    }

    /// Forgets the previous plan: the next [`solve`](Self::solve) warm-starts from the
    /// reference torques.
    pub fn reset(&mut self) {
        self.planned = false;
    }

    /// Whether a plan has been made since the last [`reset`](Self::reset).
    pub fn planned(&self) -> bool {
        self.planned
    }

    /// The torque `elapsed` seconds after the last plan, for the state `(a, a_dot)`:
    /// `clamp(u_0 + K_0 (x - x_plan(elapsed)))`, the plan's first control with its locally
    /// optimal feedback about the planned state, interpolated linearly between nodes 0 and 1
    /// (`elapsed` is clamped to `[0, h]`). Into `tau_star` (`m` entries).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong lengths, [`OptimalError::InvalidSetting`] before
    /// the first plan.
    pub fn control(
        &mut self,
        elapsed: f64,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &mut [f64],
    ) -> Result<(), OptimalError> {
        plan_feedback(
            &self.ilqr,
            self.planned,
            self.step,
            elapsed,
            [("a", a), ("a_dot", a_dot)],
            &mut self.deviation,
            ("tau_star", tau_star),
        )
    }
}

/// Checks a reference at node `k` of a `horizon`-node plan (`k <= horizon`): the position, rate
/// and acceleration `values`, `dim` each.
pub(crate) fn check_reference(
    k: usize,
    horizon: usize,
    dim: usize,
    values: [(&'static str, &[f64]); 3],
) -> Result<(), OptimalError> {
    if k > horizon {
        return Err(OptimalError::Dimension {
            name: "reference node",
            expected: horizon,
            found: k,
        });
    }
    for (name, values) in values {
        if values.len() != dim {
            return Err(OptimalError::Dimension {
                name,
                expected: dim,
                found: values.len(),
            });
        }
    }
    Ok(())
}

/// The [`TrackingCost`] of `settings` for `m` coordinates (the running weights times the step,
/// the terminal weight `terminal_seconds` of the running state weight), after checking every
/// setting against its domain.
pub(crate) fn tracking_cost(
    settings: &MpcSettings,
    m: usize,
) -> Result<TrackingCost, OptimalError> {
    check_step(settings.step)?;
    if settings.horizon == 0 || settings.horizon > MAX_MPC_HORIZON {
        return Err(OptimalError::InvalidSetting {
            name: "horizon",
            requirement: "between 1 and 10000 steps",
            value: settings.horizon as f64,
        });
    }
    let terminal = settings.terminal_seconds;
    if !(terminal.is_finite() && (0.0..=1e6).contains(&terminal)) {
        return Err(OptimalError::InvalidSetting {
            name: "terminal_seconds",
            requirement: "non-negative and at most 1e6 s",
            value: terminal,
        });
    }
    settings.solver.validate()?;
    for (name, weights, positive) in [
        ("position_weight", &settings.position_weight, false),
        ("rate_weight", &settings.rate_weight, false),
        ("effort_weight", &settings.effort_weight, true),
    ] {
        if weights.len() != m {
            return Err(OptimalError::Dimension {
                name,
                expected: m,
                found: weights.len(),
            });
        }
        let ok = |w: f64| w <= 1e12 && if positive { w > 0.0 } else { w >= 0.0 };
        if let Some(&w) = weights.iter().find(|w| !ok(**w)) {
            return Err(OptimalError::InvalidSetting {
                name,
                requirement: if positive {
                    "positive and at most 1e12"
                } else {
                    "non-negative and at most 1e12"
                },
                value: w,
            });
        }
    }
    let h = settings.step;
    // A weight times the step must stay a positive number: 5e-324 * 0.005 is zero.
    if let Some(&w) = settings.effort_weight.iter().find(|w| **w * h <= 0.0) {
        return Err(OptimalError::InvalidSetting {
            name: "effort_weight",
            requirement: "large enough that effort_weight * step is a positive number",
            value: w,
        });
    }
    let state: Vec<f64> = settings
        .position_weight
        .iter()
        .chain(&settings.rate_weight)
        .map(|w| w * h)
        .collect();
    let cost = TrackingCost {
        terminal: state.iter().map(|w| w / h * terminal).collect(),
        state,
        control: settings.effort_weight.iter().map(|w| w * h).collect(),
    };
    Ok(cost)
}

/// Sets `ilqr`'s box to `|u_i| <= limits_i` (positive, infinity allowed), or none; `lower` and
/// `upper` are its workspace (`n_u` entries each).
pub(crate) fn set_box(
    ilqr: &mut Ilqr,
    limits: Option<&[f64]>,
    lower: &mut [f64],
    upper: &mut [f64],
) -> Result<(), OptimalError> {
    match limits {
        None => {
            lower.fill(f64::NEG_INFINITY);
            upper.fill(f64::INFINITY);
        }
        Some(limits) => {
            if limits.len() != lower.len() {
                return Err(OptimalError::Dimension {
                    name: "tau_star_limits",
                    expected: lower.len(),
                    found: limits.len(),
                });
            }
            if let Some(&l) = limits.iter().find(|l| l.is_nan() || **l <= 0.0) {
                return Err(OptimalError::InvalidSetting {
                    name: "tau_star_limits",
                    requirement: "positive",
                    value: l,
                });
            }
            for ((lower, upper), &l) in lower.iter_mut().zip(upper.iter_mut()).zip(limits) {
                *lower = -l;
                *upper = l;
            }
        }
    }
    ilqr.set_bounds(lower, upper)
}

/// The plan's first control with its feedback about the planned state `elapsed` seconds after
/// the plan (interpolated between nodes 0 and 1, `elapsed` clamped to `[0, step]`), for the
/// measured `(a, a_dot)` (each named, `m` = half of `deviation`'s entries), into the named
/// `out`; `deviation` is its workspace (`2m` entries).
///
/// # Errors
/// [`OptimalError::Dimension`] naming a measurement or `out` whose length is not `m`,
/// [`OptimalError::InvalidSetting`] before the first plan.
pub(crate) fn plan_feedback(
    ilqr: &Ilqr,
    planned: bool,
    step: f64,
    elapsed: f64,
    [(a_name, a), (a_dot_name, a_dot)]: [(&'static str, &[f64]); 2],
    deviation: &mut [f64],
    (out_name, out): (&'static str, &mut [f64]),
) -> Result<(), OptimalError> {
    let m = deviation.len() / 2;
    for (name, len) in [
        (a_name, a.len()),
        (a_dot_name, a_dot.len()),
        (out_name, out.len()),
    ] {
        if len != m {
            return Err(OptimalError::Dimension {
                name,
                expected: m,
                found: len,
            });
        }
    }
    if !planned {
        return Err(OptimalError::InvalidSetting {
            name: "plan",
            requirement: "made (solve) before the first control",
            value: 0.0,
        });
    }
    let fraction = if elapsed.is_finite() {
        (elapsed / step).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = ilqr.states();
    for i in 0..2 * m {
        let planned = x[i] + fraction * (x[2 * m + i] - x[i]);
        let measured = if i < m { a[i] } else { a_dot[i - m] };
        deviation[i] = measured - planned;
    }
    ilqr.feedback(0, deviation, out);
    Ok(())
}
