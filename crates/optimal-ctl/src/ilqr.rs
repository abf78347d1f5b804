//! Control-limited iterative LQR (DDP without second-order dynamics terms, Tassa, Mansard and
//! Todorov 2014) over a finite horizon, for any [`DiscreteDynamics`].

use super::OptimalError;
use super::box_qp::{BoxQp, BoxQpSettings};
use super::discrete::DiscreteDynamics;
use super::step_constraints::{ConstrainedWork, StepConstraints};
use lane_math::dense::{
    multiply, multiply_sized, multiply_transposed, multiply_transposed_sized, symmetrise,
};
use pulp::{Arch, Simd, WithSimd};

/// The most steps a horizon may have.
pub const MAX_HORIZON: usize = 100_000;
/// The most numbers an [`Ilqr`] workspace may hold (256 MiB of `f64`): a guard on
/// `horizon * (2 n_x^2 + 3 n_x n_u)`, the size of the Jacobians (the nominal trajectory's and
/// the line search's) and gains.
pub const MAX_WORKSPACE: usize = 1 << 25;

/// The diagonal quadratic tracking cost of [`Ilqr`]:
///
/// ```text
/// J = sum_{k<N} 1/2 [ (x_k - r_k)^T Q (x_k - r_k) + (u_k - w_k)^T R (u_k - w_k) ]
///     + 1/2 (x_N - r_N)^T Q_f (x_N - r_N)
/// ```
///
/// with `Q = diag(state)`, `R = diag(control)`, `Q_f = diag(terminal)`, the state references
/// `r_k` and the control references `w_k` (a feedforward, e.g. the inverse dynamics along the
/// reference, so that `R` weighs the effort of *correcting*).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackingCost {
    /// `Q`'s diagonal (`n_x` entries, non-negative).
    pub state: Vec<f64>,
    /// `R`'s diagonal (`n_u` entries, positive).
    pub control: Vec<f64>,
    /// `Q_f`'s diagonal (`n_x` entries, non-negative).
    pub terminal: Vec<f64>,
}

/// Stopping rules and regularisation schedule of [`Ilqr::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IlqrSettings {
    /// The most iterations (backward pass and line search), at most 1e4.
    pub max_iterations: usize,
    /// Converged when an accepted iteration lowers the cost by less than this fraction of it.
    pub tolerance: f64,
    /// Converged when the feed-forward steps are this small: the mean over the horizon of
    /// `max_i |k_i| / (|u_i| + 1)` (Tassa et al.'s gradient test).
    pub gradient_tolerance: f64,
    /// The regularisation `mu` of the first iteration (`Q_uu + mu I`); non-negative.
    pub regularisation: f64,
    /// Below this a decreasing `mu` becomes 0; above [`max_regularisation`](Self::max_regularisation)
    /// the solve stops unconverged.
    pub min_regularisation: f64,
    /// See [`min_regularisation`](Self::min_regularisation).
    pub max_regularisation: f64,
    /// Step lengths tried by the line search: `1, 1/2, ..., 2^-(steps-1)` (1 to 60).
    pub line_search_steps: usize,
    /// The per-step box QP.
    pub box_qp: BoxQpSettings,
}

impl Default for IlqrSettings {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            tolerance: 1e-9,
            gradient_tolerance: 1e-7,
            regularisation: 0.0,
            min_regularisation: 1e-8,
            max_regularisation: 1e10,
            line_search_steps: 10,
            box_qp: BoxQpSettings::default(),
        }
    }
}

impl IlqrSettings {
    /// Checks every setting against its domain (the box QP's included).
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] naming the first setting out of its domain.
    pub fn validate(&self) -> Result<(), OptimalError> {
        if self.max_iterations > 10_000 {
            return Err(OptimalError::InvalidSetting {
                name: "max_iterations",
                requirement: "at most 1e4",
                value: self.max_iterations as f64,
            });
        }
        if !(1..=60).contains(&self.line_search_steps) {
            return Err(OptimalError::InvalidSetting {
                name: "line_search_steps",
                requirement: "between 1 and 60",
                value: self.line_search_steps as f64,
            });
        }
        for (name, value) in [
            ("tolerance", self.tolerance),
            ("gradient_tolerance", self.gradient_tolerance),
            ("regularisation", self.regularisation),
            ("min_regularisation", self.min_regularisation),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(OptimalError::InvalidSetting {
                    name,
                    requirement: "non-negative and finite",
                    value,
                });
            }
        }
        let max = self.max_regularisation;
        if !(max.is_finite() && max > self.min_regularisation && max >= self.regularisation) {
            return Err(OptimalError::InvalidSetting {
                name: "max_regularisation",
                requirement: "finite and above min_regularisation and regularisation",
                value: max,
            });
        }
        self.box_qp.validate()
    }
}

/// Growth factor of the regularisation schedule (Tassa, Erez and Todorov 2012, section V).
const REGULARISATION_FACTOR: f64 = 1.6;
/// A line-search step is accepted when it realises this fraction of the predicted decrease.
const ACCEPTANCE: f64 = 1e-4;

/// What an [`Ilqr::solve`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IlqrReport {
    /// Iterations taken (backward passes that reached a line search).
    pub iterations: usize,
    /// The cost of the warm start's rollout.
    pub initial_cost: f64,
    /// The cost of the solution.
    pub cost: f64,
    /// Whether a convergence test (not the iteration limit or the regularisation limit) ended it.
    pub converged: bool,
    /// The regularisation at the end.
    pub regularisation: f64,
    /// Nodes of the last backward pass whose rows (of a constrained solve) admitted no control
    /// within the box at the nominal state, planned within the box alone there.
    pub relaxed_nodes: usize,
}

/// The workspace of control-limited iLQR for `n_x` states, `n_u` controls and a horizon of `N`
/// steps: the trajectory, references, bounds, Jacobians, gains and the per-step QP, all
/// allocated by [`new`](Self::new); [`solve`](Self::solve) allocates nothing.
///
/// Each iteration (Tassa, Mansard and Todorov 2014, Algorithm 2):
///
/// 1. Linearise `x_{k+1} = F(x_k, u_k)` along the current trajectory (`A_k`, `B_k`). Without
///    constraints, the rollout that made the trajectory has mostly done it on its way
///    ([`DiscreteDynamics::linearise`] gives the next state with the Jacobians, so a node's
///    dynamics are evaluated once): the warm start's rollout and each line search's first
///    trial (`alpha = 1`) linearise, except the last allowed iteration's; an accepted later
///    trial is linearised after it.
/// 2. Backward pass from `V_x = Q_f (x_N - r_N)`, `V_xx = Q_f`:
///    `Q_x = l_x + A^T V_x'`, `Q_u = l_u + B^T V_x'`, `Q_xx = Q + A^T V_xx' A`,
///    `Q_uu = R + B^T V_xx' B`, `Q_ux = B^T V_xx' A`; the feed-forward `k` solves the box QP
///    `min 1/2 d^T (Q_uu + mu I) d + Q_u^T d` over `lower - u_k <= d <= upper - u_k`
///    ([`BoxQp`], warm-started from the previous `k`); the gain is
///    `K_f = -(Q_uu + mu I)_ff^-1 Q_ux,f` on the free controls and `K_c = 0` on the clamped ones,
///    so feedback never pushes a saturated control further; then
///    `V_x = Q_x + K^T Q_uu k + K^T Q_u + Q_ux^T k`,
///    `V_xx = Q_xx + K^T Q_uu K + K^T Q_ux + Q_ux^T K`.
/// 3. Forward pass with a backtracking line search on `alpha`:
///    `u'_k = clamp(u_k + alpha k_k + K_k (x'_k - x_k))`, `x'_{k+1} = F(x'_k, u'_k)`, accepted
///    when the cost falls by at least `1e-4` of the predicted
///    `-(alpha sum k^T Q_u + alpha^2 / 2 sum k^T Q_uu k)`.
///
/// `mu` follows the schedule of Tassa, Erez and Todorov 2012: it grows (by a factor that itself
/// grows from 1.6) when `Q_uu + mu I` is not positive definite or no step is accepted, and
/// shrinks after an accepted step. Controls stay in the box throughout: the warm start is
/// projected onto it and every forward pass clamps. The cost is a [`TrackingCost`].
#[derive(Debug, Clone)]
pub struct Ilqr {
    nx: usize,
    nu: usize,
    horizon: usize,
    cost: TrackingCost,
    /// The current trajectory `x_0..x_N`, `u_0..u_{N-1}` and the line search's candidate.
    x: Vec<f64>,
    u: Vec<f64>,
    x_try: Vec<f64>,
    u_try: Vec<f64>,
    /// References `r_0..r_N` and `w_0..w_{N-1}`.
    x_ref: Vec<f64>,
    u_ref: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Per step: `A_k` (`n_x x n_x`), `B_k` (`n_x x n_u`), `K_k` (`n_u x n_x`), `k_k` (`n_u`),
    /// and the Jacobians along the line search's candidate.
    a: Vec<f64>,
    b: Vec<f64>,
    a_try: Vec<f64>,
    b_try: Vec<f64>,
    gain: Vec<f64>,
    feedforward: Vec<f64>,
    /// The backward pass's terms of one step for sizes without their own (stack) body.
    terms: HeapTerms,
    /// The adjoint of [`gradient`](Self::gradient) and its next value.
    adjoint: Vec<f64>,
    adjoint_next: Vec<f64>,
    qp: BoxQp,
    /// The working memory of constrained solves, once reserved.
    constrained: Option<ConstrainedWork>,
    /// Whether `x`, `u` and `gain` are the last solve's plan (shifted or not): a policy the
    /// warm start may follow when its open-loop rollout diverges.
    policy: bool,
    /// The nodes of the last backward pass planned within the box alone.
    relaxed: usize,
}

impl Ilqr {
    /// A workspace for `n_x` states, `n_u` controls, `horizon` steps and `cost`. The bounds start
    /// unbounded, the references and the warm start at zero.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] for a dimension or horizon of zero, a horizon above
    /// [`MAX_HORIZON`], a workspace above [`MAX_WORKSPACE`] numbers, or weights that are
    /// negative or not finite (control weights must be positive);
    /// [`OptimalError::Dimension`] for weights of the wrong length.
    pub fn new(
        nx: usize,
        nu: usize,
        horizon: usize,
        cost: &TrackingCost,
    ) -> Result<Self, OptimalError> {
        for (name, value) in [("n_x", nx), ("n_u", nu), ("horizon", horizon)] {
            if value == 0 {
                return Err(OptimalError::InvalidSetting {
                    name,
                    requirement: "at least 1",
                    value: 0.0,
                });
            }
        }
        if horizon > MAX_HORIZON {
            return Err(OptimalError::InvalidSetting {
                name: "horizon",
                requirement: "at most 100000 steps",
                value: horizon as f64,
            });
        }
        if !workspace_fits(nx, nu, horizon) {
            // The workspace's size, in floating point so that it cannot wrap.
            let (x, u) = (nx as f64, nu as f64);
            return Err(OptimalError::InvalidSetting {
                name: "horizon * (2 n_x^2 + 3 n_x n_u) (the workspace's numbers)",
                requirement: "at most 2^25",
                value: horizon as f64 * (2.0 * x * x + 3.0 * x * u),
            });
        }
        for (name, weights, len, positive) in [
            ("state weight", &cost.state, nx, false),
            ("control weight", &cost.control, nu, true),
            ("terminal weight", &cost.terminal, nx, false),
        ] {
            if weights.len() != len {
                return Err(OptimalError::Dimension {
                    name,
                    expected: len,
                    found: weights.len(),
                });
            }
            for &w in weights {
                let ok = w.is_finite() && if positive { w > 0.0 } else { w >= 0.0 };
                if !ok {
                    return Err(OptimalError::InvalidSetting {
                        name,
                        requirement: if positive {
                            "positive and finite"
                        } else {
                            "non-negative and finite"
                        },
                        value: w,
                    });
                }
            }
        }
        let n = horizon;
        Ok(Self {
            nx,
            nu,
            horizon,
            cost: cost.clone(),
            x: vec![0.0; (n + 1) * nx],
            u: vec![0.0; n * nu],
            x_try: vec![0.0; (n + 1) * nx],
            u_try: vec![0.0; n * nu],
            x_ref: vec![0.0; (n + 1) * nx],
            u_ref: vec![0.0; n * nu],
            lower: vec![f64::NEG_INFINITY; nu],
            upper: vec![f64::INFINITY; nu],
            a: vec![0.0; n * nx * nx],
            b: vec![0.0; n * nx * nu],
            a_try: vec![0.0; n * nx * nx],
            b_try: vec![0.0; n * nx * nu],
            gain: vec![0.0; n * nu * nx],
            feedforward: vec![0.0; n * nu],
            terms: HeapTerms::new(nx, nu),
            adjoint: vec![0.0; nx],
            adjoint_next: vec![0.0; nx],
            qp: BoxQp::new(nu),
            constrained: None,
            policy: false,
            relaxed: 0,
        })
    }

    /// Sizes the working memory of [`solve_constrained`](Self::solve_constrained) for at most
    /// `max_rows` constraint rows a step (allocates; once, before the solves).
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] when `horizon * max_rows * n_u` would exceed
    /// [`MAX_WORKSPACE`].
    pub fn reserve_constraints(&mut self, max_rows: usize) -> Result<(), OptimalError> {
        if self
            .horizon
            .saturating_mul(max_rows)
            .saturating_mul(self.nu + 1)
            > MAX_WORKSPACE
        {
            return Err(OptimalError::InvalidSetting {
                name: "constraint rows",
                requirement: "small enough for horizon * rows * (n_u + 1) <= 2^25",
                value: max_rows as f64,
            });
        }
        if self.constrained.as_ref().map(ConstrainedWork::max_rows) != Some(max_rows) {
            self.constrained = Some(ConstrainedWork::new(
                self.nx,
                self.nu,
                self.horizon,
                max_rows,
            ));
        }
        Ok(())
    }

    /// The number of states `n_x`.
    pub fn state_dim(&self) -> usize {
        self.nx
    }

    /// The number of controls `n_u`.
    pub fn control_dim(&self) -> usize {
        self.nu
    }

    /// The number of steps `N`.
    pub fn horizon(&self) -> usize {
        self.horizon
    }

    /// Sets the box `lower <= u_k <= upper` on every control (`n_u` entries each; infinite
    /// entries for unbounded controls).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong lengths, [`OptimalError::InvalidSetting`] for a NaN
    /// or `lower > upper`.
    pub fn set_bounds(&mut self, lower: &[f64], upper: &[f64]) -> Result<(), OptimalError> {
        for (name, values) in [("lower bound", lower), ("upper bound", upper)] {
            if values.len() != self.nu {
                return Err(OptimalError::Dimension {
                    name,
                    expected: self.nu,
                    found: values.len(),
                });
            }
        }
        for (&l, &u) in lower.iter().zip(upper) {
            if l.is_nan() || u.is_nan() || l > u || l == f64::INFINITY || u == f64::NEG_INFINITY {
                return Err(OptimalError::InvalidSetting {
                    name: "control bounds",
                    requirement: "ordered (lower <= upper), not NaN, with a finite interior",
                    value: l - u,
                });
            }
        }
        self.lower.copy_from_slice(lower);
        self.upper.copy_from_slice(upper);
        Ok(())
    }

    /// The state references `r_0..r_N`, `(N + 1) x n_x` row-major, to fill before a solve.
    pub fn state_references_mut(&mut self) -> &mut [f64] {
        &mut self.x_ref
    }

    /// The control references `w_0..w_{N-1}`, `N x n_u` row-major, to fill before a solve.
    pub fn control_references_mut(&mut self) -> &mut [f64] {
        &mut self.u_ref
    }

    /// The controls `u_0..u_{N-1}` (`N x n_u` row-major): the warm start before a solve, the
    /// solution after it. Controls set here are rolled out open loop (the last plan's feedback
    /// no longer applies to them).
    pub fn controls_mut(&mut self) -> &mut [f64] {
        self.policy = false;
        &mut self.u
    }

    /// The controls of the last solve (`N x n_u` row-major).
    pub fn controls(&self) -> &[f64] {
        &self.u
    }

    /// The states `x_0..x_N` of the last solve (`(N + 1) x n_x` row-major).
    pub fn states(&self) -> &[f64] {
        &self.x
    }

    /// The feedback gains `K_0..K_{N-1}` of the last solve's last backward pass
    /// (`N x n_u x n_x`), zero rows for clamped controls.
    pub fn gains(&self) -> &[f64] {
        &self.gain
    }

    /// The control bounds `(lower, upper)`.
    pub fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.lower, &self.upper)
    }

    /// Sets the warm start to the control references `w_k`.
    pub fn warm_start_from_control_references(&mut self) {
        self.policy = false;
        self.u.copy_from_slice(&self.u_ref);
    }

    /// Shifts the plan `steps` steps earlier (the controls, the QP warm starts, and the states
    /// and gains the warm start may follow), repeating the last node at the end: the warm start
    /// of a receding horizon that moved on by `steps`.
    pub fn shift(&mut self, steps: usize) {
        let (n, nu, nx) = (self.horizon, self.nu, self.nx);
        let s = steps.min(n - 1);
        if s == 0 {
            return;
        }
        shift_nodes(&mut self.u, nu, s);
        shift_nodes(&mut self.feedforward, nu, s);
        shift_nodes(&mut self.gain, nu * nx, s);
        shift_nodes(&mut self.x, nx, s);
    }

    /// `clamp(u_k + K_k dx)` into `out` (`n_u` entries): the locally optimal feedback of the last
    /// solve at step `k` for a state `dx` away from the planned `x_k`.
    ///
    /// # Panics
    /// If `k >= N` or the slices are shorter than `n_x` and `n_u`.
    pub fn feedback(&self, k: usize, dx: &[f64], out: &mut [f64]) {
        let (nx, nu) = (self.nx, self.nu);
        for (i, out) in out.iter_mut().enumerate().take(nu) {
            let row = &self.gain[(k * nu + i) * nx..(k * nu + i + 1) * nx];
            let correction: f64 = row.iter().zip(dx).map(|(g, d)| g * d).sum();
            *out = (self.u[k * nu + i] + correction).clamp(self.lower[i], self.upper[i]);
        }
    }

    /// Minimises the [`TrackingCost`] from `x0` (`n_x` entries) over the horizon, starting from
    /// the controls in [`controls_mut`](Self::controls_mut) (projected onto the box). The
    /// solution is then in [`controls`](Self::controls), [`states`](Self::states) and
    /// [`gains`](Self::gains). After a solve (and a [`shift`](Self::shift)), the warm start
    /// follows the last plan's feedback `u_k + K_k (x_k - x_plan,k)` from `x0`; controls set by
    /// [`controls_mut`](Self::controls_mut), or the last plan's when following it diverges (the
    /// dynamics refuse a state or the cost is not finite), are rolled out open loop.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] if `dynamics` or `x0` does not match the workspace,
    /// [`OptimalError::InvalidSetting`] for bad settings, a non-finite `x0` or reference, or a
    /// warm start whose rollout the dynamics refuse ([`OptimalError::Dynamics`]).
    pub fn solve<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        x0: &[f64],
        settings: &IlqrSettings,
    ) -> Result<IlqrReport, OptimalError> {
        self.solve_with(dynamics, None, x0, settings)
    }

    /// [`solve`](Self::solve) with the general linear constraints `G u_k <= g` of
    /// `constraints` on every step besides the box. The backward pass solves each step's QP
    /// `min 1/2 d^T (Q_uu + mu I) d + Q_u^T d` subject to the step's rows (at the nominal state)
    /// and the box by [`LinearQp`](crate::LinearQp), with the feedback gain that keeps the
    /// active rows active as the state moves (their state Jacobian by forward differences of
    /// the rows); the forward pass moves every control
    /// to the closest one within the rows at its own state ([`PolytopeProjection`](crate::PolytopeProjection)).
    /// A step without rows is the box QP's, exactly. A step whose rows admit no control within
    /// the box (a warm start, or a state the momentum carries past them) is planned within the
    /// box alone and counted ([`IlqrReport::relaxed_nodes`]); the forward pass keeps a control
    /// whose rows admit none. The warm start's rollout moves its controls within the rows too;
    /// when every such rollout diverges, or the solve from it makes no step, the solve starts
    /// again from the warm start rolled out without the rows, and from the control references
    /// should that diverge as well (rows can ask for any torque the box allows, and a rollout
    /// thrown far from the reference asks for ever more). Needs
    /// [`reserve_constraints`](Self::reserve_constraints) for `constraints.max_rows()` first.
    ///
    /// # Errors
    /// As [`solve`](Self::solve); [`OptimalError::InvalidSetting`] without the reserved rows;
    /// the constraints' own errors.
    pub fn solve_constrained<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        constraints: &mut dyn StepConstraints,
        x0: &[f64],
        settings: &IlqrSettings,
    ) -> Result<IlqrReport, OptimalError> {
        let reserved = self
            .constrained
            .as_ref()
            .map_or(0, ConstrainedWork::max_rows);
        if reserved < constraints.max_rows() {
            return Err(OptimalError::InvalidSetting {
                name: "reserved constraint rows",
                requirement: "at least the constraints' max_rows (Ilqr::reserve_constraints)",
                value: reserved as f64,
            });
        }
        self.solve_with(dynamics, Some(constraints), x0, settings)
    }

    /// Projects the warm start (the control references when `references`) onto the box.
    fn clamp_to_box_from(&mut self, references: bool) {
        if references {
            self.u.copy_from_slice(&self.u_ref);
        }
        for chunk in self.u.chunks_exact_mut(self.nu) {
            for ((u, l), h) in chunk.iter_mut().zip(&self.lower).zip(&self.upper) {
                *u = if u.is_finite() { *u } else { 0.0 }.clamp(*l, *h);
            }
        }
    }

    fn solve_with<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        mut constraints: Option<&mut (dyn StepConstraints + '_)>,
        x0: &[f64],
        settings: &IlqrSettings,
    ) -> Result<IlqrReport, OptimalError> {
        self.check(dynamics, x0, settings)?;
        self.clamp_to_box_from(false);
        // The previous plan's policy, which the warm start follows when there is one (its open
        // loop amplifies the measured state's offset on an unstable arm); the shifted controls
        // open loop otherwise, or when following diverges.
        let follow = self.policy;
        self.policy = false;
        if follow {
            self.x_try.copy_from_slice(&self.x);
            self.u_try.copy_from_slice(&self.u);
        }
        // Within rows, the warm start's rollout moves every control within its step's rows at
        // the state reached (as every forward pass does), so that the first nominal trajectory
        // is feasible; without rows it linearises on its way, unless the dynamics linearise a
        // whole trajectory faster (then every kept trajectory is linearised at once, and a
        // rejected rollout wastes no Jacobians).
        let on_the_fly = constraints.is_none() && !dynamics.linearises_trajectories();
        let work = match (&constraints, self.constrained.as_mut()) {
            (Some(_), Some(work)) => work,
            _ => {
                let report =
                    self.iterate(dynamics, None, (follow, false, on_the_fly), x0, settings)?;
                self.policy = true;
                return Ok(report);
            }
        };
        // A rollout within rows may ask for any torque the box allows, and a trajectory thrown
        // far from the reference asks for ever more: when every warm start within them diverges,
        // or the solve from it makes no step, the solve starts again from the same warm start
        // rolled out without them (the backward and forward passes keep the rows as before).
        work.warm_states.copy_from_slice(&self.x_try);
        work.warm_controls.copy_from_slice(&self.u);
        let within = self.iterate(
            dynamics,
            constraints.as_deref_mut(),
            (follow, true, on_the_fly),
            x0,
            settings,
        );
        let stalled = match &within {
            Ok(report) => report.iterations == 0 && !report.converged,
            Err(error) => diverged(error),
        };
        let report = match &self.constrained {
            Some(work) if stalled => {
                self.x_try.copy_from_slice(&work.warm_states);
                self.u.copy_from_slice(&work.warm_controls);
                self.u_try.copy_from_slice(&work.warm_controls);
                let without = self.iterate(
                    dynamics,
                    constraints.as_deref_mut(),
                    (follow, false, on_the_fly),
                    x0,
                    settings,
                );
                match without {
                    Err(error) if diverged(&error) => {
                        self.clamp_to_box_from(true);
                        let start = (false, false, on_the_fly);
                        self.iterate(dynamics, constraints, start, x0, settings)?
                    }
                    other => other?,
                }
            }
            _ => within?,
        };
        self.policy = true;
        Ok(report)
    }

    /// The iterations of [`solve_with`](Self::solve_with) from the warm start in `u` (following
    /// the plan in `x_try`, `gain` when `follow`; its controls moved within `constraints` when
    /// `project`; its Jacobians computed on the way when `on_the_fly`).
    fn iterate<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        mut constraints: Option<&mut (dyn StepConstraints + '_)>,
        (follow, project, on_the_fly): (bool, bool, bool),
        x0: &[f64],
        settings: &IlqrSettings,
    ) -> Result<IlqrReport, OptimalError> {
        let steps = settings.line_search_steps;
        self.x[..self.nx].copy_from_slice(x0);
        // `jacobians_current`: the Jacobians computed on the way stand for the trajectory.
        let (initial_cost, mut jacobians_current) = match self.warm_rollout(
            dynamics,
            constraints.as_deref_mut().filter(|_| project),
            follow,
            on_the_fly,
        ) {
            Err(error) if follow && diverged(&error) => {
                self.u.copy_from_slice(&self.u_try);
                self.warm_rollout(
                    dynamics,
                    constraints.as_deref_mut().filter(|_| project),
                    false,
                    on_the_fly,
                )?
            }
            other => other?,
        };
        let mut cost = initial_cost;
        let mut mu = settings.regularisation;
        let mut delta = 1.0;
        let mut converged = false;
        let mut iterations = 0;
        let mut linearised = false;
        while iterations < settings.max_iterations {
            if !linearised {
                if !jacobians_current {
                    self.linearise(dynamics)?;
                }
                jacobians_current = false;
                if let (Some(c), Some(work)) = (constraints.as_deref_mut(), &mut self.constrained) {
                    let (nx, nu) = (self.nx, self.nu);
                    for k in 0..self.horizon {
                        let x = &self.x[k * nx..(k + 1) * nx];
                        let u = &self.u[k * nu..(k + 1) * nu];
                        let b = &self.b[k * nx * nu..(k + 1) * nx * nu];
                        work.evaluate(c, k, (x, u, b))?;
                    }
                }
                linearised = true;
            }
            let constrained = constraints.is_some();
            let expected = match self.backward(mu, &settings.box_qp, constrained) {
                Ok(expected) => expected,
                Err(OptimalError::NotPositiveDefinite(_)) => {
                    if !increase(&mut mu, &mut delta, settings) {
                        break;
                    }
                    continue;
                }
                Err(other) => return Err(other),
            };
            iterations += 1;
            if (mu <= settings.min_regularisation
                && self.feedforward_size() < settings.gradient_tolerance)
                || -(expected[0] + expected[1]) <= settings.tolerance * cost.abs()
            {
                converged = true;
                break;
            }
            // No linearisation follows the last iteration's line search.
            let linearising = on_the_fly && iterations < settings.max_iterations;
            let mut accepted = None;
            let mut alpha = 1.0;
            for _ in 0..steps {
                let (candidate, candidate_linearised) = self.forward(
                    dynamics,
                    constraints.as_deref_mut(),
                    alpha,
                    linearising && alpha == 1.0,
                )?;
                let predicted = -(alpha * expected[0] + alpha * alpha * expected[1]);
                if candidate < cost && (cost - candidate) >= ACCEPTANCE * predicted {
                    accepted = Some((candidate, candidate_linearised));
                    break;
                }
                alpha *= 0.5;
            }
            match accepted {
                Some((candidate, candidate_linearised)) => {
                    std::mem::swap(&mut self.x, &mut self.x_try);
                    std::mem::swap(&mut self.u, &mut self.u_try);
                    if candidate_linearised {
                        std::mem::swap(&mut self.a, &mut self.a_try);
                        std::mem::swap(&mut self.b, &mut self.b_try);
                    }
                    jacobians_current = candidate_linearised;
                    linearised = false;
                    let improvement = cost - candidate;
                    cost = candidate;
                    decrease(&mut mu, &mut delta, settings);
                    if improvement <= settings.tolerance * cost.abs() {
                        converged = true;
                        break;
                    }
                }
                None => {
                    if !increase(&mut mu, &mut delta, settings) {
                        break;
                    }
                }
            }
        }
        Ok(IlqrReport {
            iterations,
            initial_cost,
            cost,
            converged,
            regularisation: mu,
            relaxed_nodes: self.relaxed,
        })
    }

    /// The cost of the current trajectory and its gradient with respect to the controls,
    /// `dJ / du_k` into `out` (`N x n_u`), by the adjoint recursion
    /// `lambda_N = Q_f (x_N - r_N)`, `dJ/du_k = l_u + B_k^T lambda_{k+1}`,
    /// `lambda_k = l_x + A_k^T lambda_{k+1}` (first-order optimality: at a solution the gradient
    /// vanishes on the free controls and points into the box on the clamped ones). Re-linearises
    /// along the trajectory.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for a wrong `out` or dynamics; the dynamics' errors.
    pub fn gradient<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        out: &mut [f64],
    ) -> Result<f64, OptimalError> {
        self.check_dynamics(dynamics)?;
        if out.len() != self.horizon * self.nu {
            return Err(OptimalError::Dimension {
                name: "gradient",
                expected: self.horizon * self.nu,
                found: out.len(),
            });
        }
        self.linearise(dynamics)?;
        let (nx, nu, n) = (self.nx, self.nu, self.horizon);
        for i in 0..nx {
            self.adjoint[i] = self.cost.terminal[i] * (self.x[n * nx + i] - self.x_ref[n * nx + i]);
        }
        for k in (0..n).rev() {
            let a = &self.a[k * nx * nx..(k + 1) * nx * nx];
            let b = &self.b[k * nx * nu..(k + 1) * nx * nu];
            multiply_transposed(b, &self.adjoint, &mut out[k * nu..(k + 1) * nu], nu, nx, 1);
            for j in 0..nu {
                out[k * nu + j] +=
                    self.cost.control[j] * (self.u[k * nu + j] - self.u_ref[k * nu + j]);
            }
            multiply_transposed(a, &self.adjoint, &mut self.adjoint_next, nx, nx, 1);
            for i in 0..nx {
                self.adjoint[i] = self.adjoint_next[i]
                    + self.cost.state[i] * (self.x[k * nx + i] - self.x_ref[k * nx + i]);
            }
        }
        Ok(self.trajectory_cost(&self.x, &self.u))
    }

    /// Checks the arguments of a solve.
    fn check<D: DiscreteDynamics + ?Sized>(
        &self,
        dynamics: &D,
        x0: &[f64],
        settings: &IlqrSettings,
    ) -> Result<(), OptimalError> {
        self.check_dynamics(dynamics)?;
        if x0.len() != self.nx {
            return Err(OptimalError::Dimension {
                name: "x0",
                expected: self.nx,
                found: x0.len(),
            });
        }
        let finite = |name, values: &[f64]| match lane_math::first_non_finite(values) {
            None => Ok(()),
            Some((_, value)) => Err(OptimalError::InvalidSetting {
                name,
                requirement: "finite",
                value,
            }),
        };
        finite("x0", x0)?;
        finite("state reference", &self.x_ref)?;
        finite("control reference", &self.u_ref)?;
        settings.validate()
    }

    fn check_dynamics<D: DiscreteDynamics + ?Sized>(
        &self,
        dynamics: &D,
    ) -> Result<(), OptimalError> {
        for (name, got, expected) in [
            ("dynamics states", dynamics.state_dim(), self.nx),
            ("dynamics controls", dynamics.control_dim(), self.nu),
        ] {
            if got != expected {
                return Err(OptimalError::Dimension {
                    name,
                    expected,
                    found: got,
                });
            }
        }
        Ok(())
    }

    /// The warm start's rollout from `x_0`: `x_{k+1} = F(x_k, u_k)` with the current controls
    /// or, when `follow`, with the previous plan's feedback `u_k + K_k (x_k - x̄_k)` about its
    /// states `x̄_k` (kept in `x_try`), clamped to the box. With `constraints`, every control is
    /// then moved to the closest within its step's rows at the state reached, the rows
    /// linearised there (a control whose rows admit none is kept); without, the Jacobians `A_k`,
    /// `B_k` come with each step while `linearising`. The cost, and whether the Jacobians
    /// computed on the way are those of the final trajectory.
    fn warm_rollout<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        constraints: Option<&mut (dyn StepConstraints + '_)>,
        follow: bool,
        mut linearising: bool,
    ) -> Result<(f64, bool), OptimalError> {
        let (nx, nu) = (self.nx, self.nu);
        let mut rows = match (constraints, &mut self.constrained) {
            (Some(c), Some(work)) => Some((c, work)),
            _ => None,
        };
        let mut unmoved = rows.is_some();
        for k in 0..self.horizon {
            let (past, future) = self.x.split_at_mut((k + 1) * nx);
            let (x, next) = (&past[k * nx..(k + 1) * nx], &mut future[..nx]);
            let u = &mut self.u[k * nu..(k + 1) * nu];
            if follow {
                let planned = &self.x_try[k * nx..(k + 1) * nx];
                for (j, u) in u.iter_mut().enumerate() {
                    let row = &self.gain[(k * nu + j) * nx..(k * nu + j + 1) * nx];
                    let correction: f64 = (0..nx).map(|i| row[i] * (x[i] - planned[i])).sum();
                    *u = (*u + correction).clamp(self.lower[j], self.upper[j]);
                }
            }
            let b = &mut self.b[k * nx * nu..(k + 1) * nx * nu];
            let a = &mut self.a[k * nx * nx..(k + 1) * nx * nx];
            match &mut rows {
                None => advance(dynamics, (x, u), next, (a, b), &mut linearising)?,
                Some((c, work)) => {
                    dynamics.linearise(x, u, next, a, b)?;
                    let within = (&self.lower[..], &self.upper[..]);
                    if work.project(&mut **c, k, (x, b), within, u)? == Some(true) {
                        unmoved = false;
                        dynamics.step(x, u, next)?;
                    }
                }
            }
        }
        let current = if rows.is_some() { unmoved } else { linearising };
        let cost = self.trajectory_cost(&self.x, &self.u);
        if cost.is_finite() {
            Ok((cost, current))
        } else {
            Err(OptimalError::InvalidSetting {
                name: "warm start",
                requirement: "a rollout of finite cost",
                value: cost,
            })
        }
    }

    /// The Jacobians along the current trajectory.
    fn linearise<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
    ) -> Result<(), OptimalError> {
        let (nx, nu) = (self.nx, self.nu);
        dynamics.linearise_trajectory(
            &self.x[..self.horizon * nx],
            &self.u[..self.horizon * nu],
            &mut self.x_try[..nx],
            &mut self.a,
            &mut self.b,
        )
    }

    /// The backward pass with regularisation `mu`: gains, feed-forward steps and the expected
    /// decrease terms `[sum k^T Q_u, 1/2 sum k^T Q_uu k]`. The sizes of the reduced model's
    /// `m = 2` and `m = 3` (`n_x = 2m`, `n_u = m`) have their own bodies, in which the small
    /// matrix products are unrolled for them; the same operations in the same order as for any
    /// other size.
    fn backward(
        &mut self,
        mu: f64,
        qp: &BoxQpSettings,
        constrained: bool,
    ) -> Result<[f64; 2], OptimalError> {
        match (self.nx, self.nu) {
            (4, 2) | (6, 3) => Arch::new().dispatch(BackwardOnStack {
                ilqr: self,
                mu,
                qp,
                constrained,
            }),
            _ => {
                // Taken out of the workspace for the pass (no allocation) and put back.
                let mut terms = std::mem::take(&mut self.terms);
                let expected = self.backward_sized::<0, 0>(
                    terms.slices(self.nx, self.nu),
                    mu,
                    qp,
                    constrained,
                );
                self.terms = terms;
                expected
            }
        }
    }

    /// [`backward`](Self::backward) for the sizes with stack terms (`(4, 2)` and `(6, 3)`).
    #[inline(always)]
    fn backward_on_stack(
        &mut self,
        mu: f64,
        qp: &BoxQpSettings,
        constrained: bool,
    ) -> Result<[f64; 2], OptimalError> {
        if self.nx == 4 {
            let mut terms = StackTerms::<4, 2>::default();
            self.backward_sized::<4, 2>(terms.slices(), mu, qp, constrained)
        } else {
            let mut terms = StackTerms::<6, 3>::default();
            self.backward_sized::<6, 3>(terms.slices(), mu, qp, constrained)
        }
    }

    /// [`backward`](Self::backward) for `n_x = NX`, `n_u = NU` known at compile time (the
    /// terms on the stack), or any sizes when both are 0.
    #[inline(always)]
    fn backward_sized<const NX: usize, const NU: usize>(
        &mut self,
        mut t: Terms<'_>,
        mu: f64,
        qp: &BoxQpSettings,
        constrained: bool,
    ) -> Result<[f64; 2], OptimalError> {
        let (nx, nu) = if NX == 0 {
            (self.nx, self.nu)
        } else {
            (NX, NU)
        };
        let n = self.horizon;
        let cost = &self.cost;
        let mut expected = [0.0; 2];
        self.relaxed = 0;
        for i in 0..nx {
            t.v_x[i] = cost.terminal[i] * (self.x[n * nx + i] - self.x_ref[n * nx + i]);
        }
        t.v_xx.fill(0.0);
        for i in 0..nx {
            t.v_xx[i * nx + i] = cost.terminal[i];
        }
        for k in (0..n).rev() {
            let a = &self.a[k * nx * nx..(k + 1) * nx * nx];
            let b = &self.b[k * nx * nu..(k + 1) * nx * nu];
            let u = &self.u[k * nu..(k + 1) * nu];
            // Q_x, Q_u.
            product_transposed::<NX, NX, 1>(a, t.v_x, t.q_x, (nx, nx, 1));
            product_transposed::<NU, NX, 1>(b, t.v_x, t.q_u, (nu, nx, 1));
            for i in 0..nx {
                t.q_x[i] += cost.state[i] * (self.x[k * nx + i] - self.x_ref[k * nx + i]);
            }
            for (j, q) in t.q_u.iter_mut().enumerate() {
                *q += cost.control[j] * (u[j] - self.u_ref[k * nu + j]);
            }
            // Q_uu first, Q_xx and Q_ux after it: the copy of Q_uu below then reads values
            // stored long before (a wide load of values just stored one by one waits for them
            // to reach the cache).
            product::<NX, NX, NU>(t.v_xx, b, t.vb, (nx, nx, nu));
            product_transposed::<NU, NX, NU>(b, t.vb, t.q_uu, (nu, nx, nu));
            for j in 0..nu {
                t.q_uu[j * nu + j] += cost.control[j];
            }
            product::<NX, NX, NX>(t.v_xx, a, t.va, (nx, nx, nx));
            product_transposed::<NX, NX, NX>(a, t.va, t.q_xx, (nx, nx, nx));
            product_transposed::<NU, NX, NX>(b, t.va, t.q_ux, (nu, nx, nx));
            for i in 0..nx {
                t.q_xx[i * nx + i] += cost.state[i];
            }
            // The feed-forward step: the box QP on (Q_uu + mu I, Q_u).
            t.hessian.copy_from_slice(t.q_uu);
            for (j, &uj) in u.iter().enumerate() {
                t.hessian[j * nu + j] += mu;
                t.step_lower[j] = self.lower[j] - uj;
                t.step_upper[j] = self.upper[j] - uj;
            }
            let ff = &mut self.feedforward[k * nu..(k + 1) * nu];
            let gain = &mut self.gain[k * nu * nx..(k + 1) * nu * nx];
            // Penalties beyond double precision (a margin no motion keeps) overflow the
            // gradient: named here rather than as a QP's malformed input.
            if !t.q_u.iter().all(|g| g.is_finite()) {
                return Err(OptimalError::NonFinite("the backward pass's gradient Q_u"));
            }
            // The step's rows and the box: the general QP and the gain that keeps the active
            // rows active; the box alone without rows, or where they admit no control.
            let within_rows = match &mut self.constrained {
                Some(work) if constrained && work.counts[k] > 0 => {
                    let feasible = work.feedforward(
                        k,
                        (t.hessian, t.q_u, t.q_ux),
                        u,
                        (&self.lower, &self.upper),
                        ff,
                        gain,
                    )?;
                    self.relaxed += usize::from(!feasible);
                    feasible
                }
                _ => false,
            };
            if !within_rows {
                self.qp
                    .solve(t.hessian, t.q_u, t.step_lower, t.step_upper, ff, qp)?;
                // The gain on the free controls, zero on the clamped ones (negated before the
                // solve, which is exact: the solve's roundings are symmetric in sign).
                for (g, q) in gain.iter_mut().zip(t.q_ux.iter()) {
                    *g = -*q;
                }
                self.qp.solve_free(gain, nx);
            }
            // The value function.
            product::<NU, NU, NX>(t.q_uu, gain, t.quu_gain, (nu, nu, nx));
            product::<NU, NU, 1>(t.q_uu, ff, t.quu_ff, (nu, nu, 1));
            for (j, f) in ff.iter().enumerate() {
                expected[0] += f * t.q_u[j];
                expected[1] += 0.5 * f * t.quu_ff[j];
            }
            value_function::<NX, NU>(&mut t, gain, ff, (nx, nu));
            symmetrise(t.v_xx, nx);
        }
        Ok(expected)
    }

    /// The forward pass at step length `alpha` into `x_try`, `u_try`, every control moved within
    /// the step's rows at its state when there are `constraints` (kept where they admit none),
    /// the Jacobians into `a_try`, `b_try` when `linearising`; its cost (infinite if the dynamics
    /// refuse a state on the way), and whether the Jacobians were computed at every node.
    fn forward<D: DiscreteDynamics + ?Sized>(
        &mut self,
        dynamics: &mut D,
        mut constraints: Option<&mut (dyn StepConstraints + '_)>,
        alpha: f64,
        mut linearising: bool,
    ) -> Result<(f64, bool), OptimalError> {
        let (nx, nu) = (self.nx, self.nu);
        self.x_try[..nx].copy_from_slice(&self.x[..nx]);
        for k in 0..self.horizon {
            let policy = (
                &self.gain[k * nu * nx..(k + 1) * nu * nx],
                &self.u[k * nu..(k + 1) * nu],
                &self.feedforward[k * nu..(k + 1) * nu],
            );
            let states = (
                &self.x_try[k * nx..(k + 1) * nx],
                &self.x[k * nx..(k + 1) * nx],
            );
            let (bounds, out) = (
                (&self.lower[..], &self.upper[..]),
                &mut self.u_try[k * nu..(k + 1) * nu],
            );
            match (nx, nu) {
                (4, 2) => policy_control::<4, 2>(policy, states, bounds, alpha, out),
                (6, 3) => policy_control::<6, 3>(policy, states, bounds, alpha, out),
                _ => policy_control::<0, 0>(policy, states, bounds, alpha, out),
            }
            if let (Some(c), Some(work)) = (constraints.as_deref_mut(), &mut self.constrained) {
                // A control whose rows admit none is kept, as in the warm start; a state the
                // rows' model refuses ends the candidate as the dynamics' refusal does.
                match work.project(
                    c,
                    k,
                    (
                        &self.x_try[k * nx..(k + 1) * nx],
                        &self.b[k * nx * nu..(k + 1) * nx * nu],
                    ),
                    (&self.lower, &self.upper),
                    &mut self.u_try[k * nu..(k + 1) * nu],
                ) {
                    Ok(_) => {}
                    Err(OptimalError::Dynamics(_)) => return Ok((f64::INFINITY, false)),
                    Err(other) => return Err(other),
                }
            }
            let (past, future) = self.x_try.split_at_mut((k + 1) * nx);
            if advance(
                dynamics,
                (
                    &past[k * nx..(k + 1) * nx],
                    &self.u_try[k * nu..(k + 1) * nu],
                ),
                &mut future[..nx],
                (
                    &mut self.a_try[k * nx * nx..(k + 1) * nx * nx],
                    &mut self.b_try[k * nx * nu..(k + 1) * nx * nu],
                ),
                &mut linearising,
            )
            .is_err()
            {
                return Ok((f64::INFINITY, false));
            }
        }
        let cost = self.trajectory_cost(&self.x_try, &self.u_try);
        Ok((
            if cost.is_nan() { f64::INFINITY } else { cost },
            linearising,
        ))
    }

    /// The tracking cost of a trajectory.
    fn trajectory_cost(&self, x: &[f64], u: &[f64]) -> f64 {
        match (self.nx, self.nu) {
            (4, 2) => self.trajectory_cost_sized::<4, 2>(x, u),
            (6, 3) => self.trajectory_cost_sized::<6, 3>(x, u),
            _ => self.trajectory_cost_sized::<0, 0>(x, u),
        }
    }

    /// [`trajectory_cost`](Self::trajectory_cost) for `n_x = NX`, `n_u = NU` known at compile
    /// time, or any sizes when both are 0: the same sum in the same order.
    #[inline(always)]
    fn trajectory_cost_sized<const NX: usize, const NU: usize>(&self, x: &[f64], u: &[f64]) -> f64 {
        let (nx, nu) = if NX == 0 {
            (self.nx, self.nu)
        } else {
            (NX, NU)
        };
        let n = self.horizon;
        let c = &self.cost;
        let (state, terminal, control) = (&c.state[..nx], &c.terminal[..nx], &c.control[..nu]);
        let mut total = 0.0;
        for k in 0..=n {
            let weights = if k == n { terminal } else { state };
            let (x, x_ref) = (&x[k * nx..(k + 1) * nx], &self.x_ref[k * nx..(k + 1) * nx]);
            for i in 0..nx {
                let e = x[i] - x_ref[i];
                total += 0.5 * weights[i] * e * e;
            }
            if k < n {
                let (u, u_ref) = (&u[k * nu..(k + 1) * nu], &self.u_ref[k * nu..(k + 1) * nu]);
                for j in 0..nu {
                    let e = u[j] - u_ref[j];
                    total += 0.5 * control[j] * e * e;
                }
            }
        }
        total
    }

    /// Tassa et al.'s gradient measure: the mean over the horizon of
    /// `max_i |k_i| / (|u_i| + 1)`.
    fn feedforward_size(&self) -> f64 {
        let nu = self.nu;
        let total: f64 = self
            .feedforward
            .chunks_exact(nu)
            .zip(self.u.chunks_exact(nu))
            .map(|(k, u)| {
                k.iter()
                    .zip(u)
                    .map(|(k, u)| k.abs() / (u.abs() + 1.0))
                    .fold(0.0, f64::max)
            })
            .sum();
        total / self.horizon as f64
    }
}

/// [`Ilqr::backward`] for the sizes with stack terms, run by [`pulp::Arch::dispatch`] so that
/// its unrolled products are compiled for the processor's instruction set (the same operations
/// in the same order: no fused multiply-adds, the same bits).
struct BackwardOnStack<'a> {
    ilqr: &'a mut Ilqr,
    mu: f64,
    qp: &'a BoxQpSettings,
    constrained: bool,
}

impl WithSimd for BackwardOnStack<'_> {
    type Output = Result<[f64; 2], OptimalError>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> Self::Output {
        let Self {
            ilqr,
            mu,
            qp,
            constrained,
        } = self;
        ilqr.backward_on_stack(mu, qp, constrained)
    }
}

/// The value function's derivatives after a step's gains, into `t.v_x` and `t.v_xx`:
/// `V_x = Q_x + K^T (Q_uu k + Q_u) + Q_ux^T k` and `V_xx = Q_xx + K^T (Q_uu K + Q_ux) + Q_ux^T K`,
/// each entry summed over the controls in their order. For `n_x = NX`, `n_u = NU` known at
/// compile time the sums run in local arrays (kept in vector registers), or in `t` when both
/// are 0.
#[inline(always)]
fn value_function<const NX: usize, const NU: usize>(
    t: &mut Terms<'_>,
    gain: &[f64],
    ff: &[f64],
    (nx, nu): (usize, usize),
) {
    let (q, gain, ff) = ((&*t.q_x, &*t.q_xx), &gain[..nu * nx], &ff[..nu]);
    let steps = (&*t.quu_ff, &*t.q_u, &*t.quu_gain, &*t.q_ux);
    if NX == 0 {
        value_rows(q, steps, (gain, ff), (t.v_x, t.v_xx));
    } else {
        let (mut v_x, mut v_xx) = ([0.0; NX], [[0.0; NX]; NX]);
        value_rows(q, steps, (gain, ff), (&mut v_x, v_xx.as_flattened_mut()));
        t.v_x.copy_from_slice(&v_x);
        t.v_xx.copy_from_slice(v_xx.as_flattened());
    }
}

/// [`value_function`] into `(v_x, v_xx)` from `(Q_x, Q_xx)`, `(Q_uu k, Q_u, Q_uu K, Q_ux)` and
/// the gains `(K, k)`, row by row.
#[inline(always)]
fn value_rows(
    (q_x, q_xx): (&[f64], &[f64]),
    (quu_ff, q_u, quu_gain, q_ux): (&[f64], &[f64], &[f64], &[f64]),
    (gain, ff): (&[f64], &[f64]),
    (v_x, v_xx): (&mut [f64], &mut [f64]),
) {
    let nx = v_x.len();
    v_x.copy_from_slice(q_x);
    v_xx.copy_from_slice(q_xx);
    let controls = gain.chunks_exact(nx).zip(q_ux.chunks_exact(nx));
    let steps = quu_gain
        .chunks_exact(nx)
        .zip(ff.iter().zip(quu_ff.iter().zip(q_u)));
    for ((gain_row, q_ux_row), (step_row, (&f, (&quu_f, &q_u)))) in controls.zip(steps) {
        let w = quu_f + q_u;
        for ((v, &g), &q) in v_x.iter_mut().zip(gain_row).zip(q_ux_row) {
            *v += g * w + q * f;
        }
        for ((v_row, &g), &q) in v_xx.chunks_exact_mut(nx).zip(gain_row).zip(q_ux_row) {
            let columns = v_row
                .iter_mut()
                .zip(step_row.iter().zip(q_ux_row).zip(gain_row));
            for (v, ((&qg, &qu), &gl)) in columns {
                *v += g * (qg + qu) + q * gl;
            }
        }
    }
}

/// `out = a b` (`a` `r x k`, `b` `k x c`): [`multiply_sized`] for sizes known at compile time,
/// [`multiply`] when `R` is 0.
#[inline(always)]
fn product<const R: usize, const K: usize, const C: usize>(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
    (r, k, c): (usize, usize, usize),
) {
    if R == 0 {
        multiply(a, b, out, r, k, c);
    } else {
        multiply_sized::<R, K, C>(a, b, out);
    }
}

/// `out = a^T b` (`a` `k x r`, `b` `k x c`), as [`product`].
#[inline(always)]
fn product_transposed<const R: usize, const K: usize, const C: usize>(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
    (r, k, c): (usize, usize, usize),
) {
    if R == 0 {
        multiply_transposed(a, b, out, r, k, c);
    } else {
        multiply_transposed_sized::<R, K, C>(a, b, out);
    }
}

/// Whether the workspace of `n_x` states, `n_u` controls and `horizon` steps,
/// `horizon * (2 n_x^2 + 3 n_x n_u)` numbers, is within [`MAX_WORKSPACE`].
pub(crate) fn workspace_fits(nx: usize, nu: usize, horizon: usize) -> bool {
    let per_step = nx
        .saturating_mul(nx)
        .saturating_mul(2)
        .saturating_add(nx.saturating_mul(nu).saturating_mul(3));
    horizon.saturating_mul(per_step) <= MAX_WORKSPACE
}

/// Moves the nodes of `buffer` (`width` numbers each) `s` nodes earlier, repeating the last.
fn shift_nodes(buffer: &mut [f64], width: usize, s: usize) {
    let nodes = buffer.len() / width;
    buffer.copy_within(s * width.., 0);
    let (head, tail) = buffer.split_at_mut((nodes - s) * width);
    let last = &head[(nodes - s - 1) * width..];
    for chunk in tail.chunks_exact_mut(width) {
        chunk.copy_from_slice(last);
    }
}

/// Whether a warm start's rollout failed because its trajectory diverged: the dynamics refused
/// a state on the way, or its cost is not finite.
fn diverged(error: &OptimalError) -> bool {
    matches!(
        error,
        OptimalError::Dynamics(_)
            | OptimalError::InvalidSetting {
                name: "warm start",
                ..
            }
    )
}

/// The backward pass's terms of one step, row-major: `V_x'` (`n_x`), `V_xx'` (`n_x x n_x`),
/// `Q_x`, `Q_u`, `Q_xx`, `Q_uu`, `Q_ux`; `V_xx' A` (`n_x x n_x`), `V_xx' B` (`n_x x n_u`),
/// `Q_uu K` (`n_u x n_x`), `Q_uu k` (`n_u`), the regularised Hessian (`n_u x n_u`) and the step
/// bounds (`n_u` each).
struct Terms<'t> {
    v_x: &'t mut [f64],
    v_xx: &'t mut [f64],
    q_x: &'t mut [f64],
    q_u: &'t mut [f64],
    q_xx: &'t mut [f64],
    q_uu: &'t mut [f64],
    q_ux: &'t mut [f64],
    va: &'t mut [f64],
    vb: &'t mut [f64],
    quu_gain: &'t mut [f64],
    quu_ff: &'t mut [f64],
    hessian: &'t mut [f64],
    step_lower: &'t mut [f64],
    step_upper: &'t mut [f64],
}

/// [`Terms`] on the stack for `n_x = NX`, `n_u = NU`: their sizes known where they are used.
struct StackTerms<const NX: usize, const NU: usize> {
    v_x: [f64; NX],
    v_xx: [[f64; NX]; NX],
    q_x: [f64; NX],
    q_u: [f64; NU],
    q_xx: [[f64; NX]; NX],
    q_uu: [[f64; NU]; NU],
    q_ux: [[f64; NX]; NU],
    va: [[f64; NX]; NX],
    vb: [[f64; NU]; NX],
    quu_gain: [[f64; NX]; NU],
    quu_ff: [f64; NU],
    hessian: [[f64; NU]; NU],
    step_lower: [f64; NU],
    step_upper: [f64; NU],
}

impl<const NX: usize, const NU: usize> Default for StackTerms<NX, NU> {
    fn default() -> Self {
        Self {
            v_x: [0.0; NX],
            v_xx: [[0.0; NX]; NX],
            q_x: [0.0; NX],
            q_u: [0.0; NU],
            q_xx: [[0.0; NX]; NX],
            q_uu: [[0.0; NU]; NU],
            q_ux: [[0.0; NX]; NU],
            va: [[0.0; NX]; NX],
            vb: [[0.0; NU]; NX],
            quu_gain: [[0.0; NX]; NU],
            quu_ff: [0.0; NU],
            hessian: [[0.0; NU]; NU],
            step_lower: [0.0; NU],
            step_upper: [0.0; NU],
        }
    }
}

impl<const NX: usize, const NU: usize> StackTerms<NX, NU> {
    #[inline(always)]
    fn slices(&mut self) -> Terms<'_> {
        Terms {
            v_x: &mut self.v_x,
            v_xx: self.v_xx.as_flattened_mut(),
            q_x: &mut self.q_x,
            q_u: &mut self.q_u,
            q_xx: self.q_xx.as_flattened_mut(),
            q_uu: self.q_uu.as_flattened_mut(),
            q_ux: self.q_ux.as_flattened_mut(),
            va: self.va.as_flattened_mut(),
            vb: self.vb.as_flattened_mut(),
            quu_gain: self.quu_gain.as_flattened_mut(),
            quu_ff: &mut self.quu_ff,
            hessian: self.hessian.as_flattened_mut(),
            step_lower: &mut self.step_lower,
            step_upper: &mut self.step_upper,
        }
    }
}

/// [`Terms`] in the workspace, for any sizes (allocated once by [`Ilqr::new`]).
#[derive(Debug, Clone, Default)]
struct HeapTerms(Vec<f64>);

impl HeapTerms {
    /// The total size of the terms: `2 nx + 4 nu + 3 nx^2 + 2 nu^2 + 3 nu nx` (the lengths
    /// [`Self::slices`] takes, in [`Terms`]' order).
    fn len(nx: usize, nu: usize) -> usize {
        2 * nx + 4 * nu + 3 * nx * nx + 2 * nu * nu + 3 * nu * nx
    }

    fn new(nx: usize, nu: usize) -> Self {
        Self(vec![0.0; Self::len(nx, nu)])
    }

    fn slices(&mut self, nx: usize, nu: usize) -> Terms<'_> {
        let mut rest = self.0.as_mut_slice();
        let mut take = |size: usize| {
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(size);
            rest = tail;
            part
        };
        Terms {
            v_x: take(nx),
            v_xx: take(nx * nx),
            q_x: take(nx),
            q_u: take(nu),
            q_xx: take(nx * nx),
            q_uu: take(nu * nu),
            q_ux: take(nu * nx),
            va: take(nx * nx),
            vb: take(nx * nu),
            quu_gain: take(nu * nx),
            quu_ff: take(nu),
            hessian: take(nu * nu),
            step_lower: take(nu),
            step_upper: take(nu),
        }
    }
}

/// The forward pass's control at one node, `u + alpha k + K (x_try - x)` summed term by term in
/// that order, clamped to the box: `policy` is `(K, u, k)` of the node (`n_u x n_x`, `n_u`,
/// `n_u`), `states` its `(x_try, x)`. For `n_x = NX`, `n_u = NU` known at compile time, or the
/// slices' sizes when both are 0.
#[inline(always)]
fn policy_control<const NX: usize, const NU: usize>(
    (gain, u, feedforward): (&[f64], &[f64], &[f64]),
    (x_try, x): (&[f64], &[f64]),
    (lower, upper): (&[f64], &[f64]),
    alpha: f64,
    out: &mut [f64],
) {
    let (nx, nu) = if NX == 0 {
        (x.len(), u.len())
    } else {
        (NX, NU)
    };
    let (x_try, x) = (&x_try[..nx], &x[..nx]);
    let rows = gain[..nu * nx].chunks_exact(nx);
    let controls = u[..nu].iter().zip(&feedforward[..nu]);
    let bounds = lower[..nu].iter().zip(&upper[..nu]);
    for (((row, (&u, &f)), (&lower, &upper)), out) in rows.zip(controls).zip(bounds).zip(out) {
        let mut u = u + alpha * f;
        for ((g, &x_try), &x) in row.iter().zip(x_try).zip(x) {
            u += g * (x_try - x);
        }
        *out = u.clamp(lower, upper);
    }
}

/// One node of a rollout: `next = F(x, u)`, and the Jacobians `(A, B)` with it while
/// `linearising`. A node whose linearisation fails is stepped instead and ends `linearising` for
/// the rest of the rollout (the solve's own linearisation then meets the failure); the step's
/// error is returned.
fn advance<D: DiscreteDynamics + ?Sized>(
    dynamics: &mut D,
    (x, u): (&[f64], &[f64]),
    next: &mut [f64],
    (a, b): (&mut [f64], &mut [f64]),
    linearising: &mut bool,
) -> Result<(), OptimalError> {
    if *linearising {
        if dynamics.linearise(x, u, next, a, b).is_ok() {
            return Ok(());
        }
        *linearising = false;
    }
    dynamics.step(x, u, next)
}

/// Grows the regularisation; `false` once it passes its maximum.
fn increase(mu: &mut f64, delta: &mut f64, settings: &IlqrSettings) -> bool {
    *delta = (*delta * REGULARISATION_FACTOR).max(REGULARISATION_FACTOR);
    *mu = (*mu * *delta).max(settings.min_regularisation.max(f64::MIN_POSITIVE));
    *mu <= settings.max_regularisation
}

/// Shrinks the regularisation, to zero below its minimum.
fn decrease(mu: &mut f64, delta: &mut f64, settings: &IlqrSettings) {
    *delta = (*delta / REGULARISATION_FACTOR).min(1.0 / REGULARISATION_FACTOR);
    *mu *= *delta;
    if *mu < settings.min_regularisation {
        *mu = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `count` scrambled numbers in `[-1, 1]`: sines of an irrational progression from `seed`.
    fn numbers(count: usize, seed: u64) -> Vec<f64> {
        (0..count)
            .map(|i| (1e3 * (seed as f64 + 0.618_034 * i as f64)).sin())
            .collect()
    }

    /// A workspace of `n_u` controls and `2 n_u` states with pseudo-random Jacobians, trajectory,
    /// references and previous feed-forward steps, and a box that clamps some of the steps.
    fn scrambled(nu: usize, seed: u64) -> Ilqr {
        let nx = 2 * nu;
        let cost = TrackingCost {
            state: numbers(nx, seed).iter().map(|w| 2.0 + w).collect(),
            control: numbers(nu, seed + 1)
                .iter()
                .map(|w| 0.1 + 0.05 * w)
                .collect(),
            terminal: numbers(nx, seed + 2).iter().map(|w| 5.0 + w).collect(),
        };
        let mut ilqr = Ilqr::new(nx, nu, 12, &cost).unwrap();
        for (i, buffer) in [
            &mut ilqr.x,
            &mut ilqr.u,
            &mut ilqr.x_ref,
            &mut ilqr.u_ref,
            &mut ilqr.a,
            &mut ilqr.b,
            &mut ilqr.feedforward,
        ]
        .into_iter()
        .enumerate()
        {
            let len = buffer.len();
            buffer.copy_from_slice(&numbers(len, seed + 3 + i as u64));
        }
        ilqr.set_bounds(&vec![-1.2; nu], &vec![1.1; nu]).unwrap();
        ilqr
    }

    #[test]
    fn stack_backward_passes_have_the_bits_of_the_general_one() {
        let qp = BoxQpSettings::default();
        for (nu, seed) in [(2, 1), (2, 40), (3, 7), (3, 90)] {
            let mut stacked = scrambled(nu, seed);
            let mut general = stacked.clone();
            let expected = stacked.backward(1e-3, &qp, false).unwrap();
            let mut terms = std::mem::take(&mut general.terms);
            let slices = terms.slices(2 * nu, nu);
            let general_expected = general
                .backward_sized::<0, 0>(slices, 1e-3, &qp, false)
                .unwrap();
            let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&expected), bits(&general_expected), "n_u = {nu}");
            assert_eq!(bits(&stacked.gain), bits(&general.gain), "n_u = {nu}");
            assert_eq!(
                bits(&stacked.feedforward),
                bits(&general.feedforward),
                "n_u = {nu}"
            );
            // Some steps are clamped, some gains free: both kinds of node are compared.
            assert!(stacked.gain.contains(&0.0));
            assert!(stacked.gain.iter().any(|&g| g != 0.0));
        }
    }
}
