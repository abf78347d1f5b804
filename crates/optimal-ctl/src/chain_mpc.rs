//! Receding-horizon model-predictive control of a full chain in joint space ([`ChainEuler`]):
//! the problem of [`Mpc`](crate::Mpc) with the joint vector for the modal coordinates and the
//! joint efforts for `tau*`.

use manip_dyn::spatial::{SpatialData, SpatialDerivativeData, SpatialModel, rnea};

use super::OptimalError;
use super::chain_euler::ChainEuler;
use super::ilqr::{Ilqr, IlqrReport, IlqrSettings};
use super::mpc::{MpcSettings, check_reference, plan_feedback, set_box, tracking_cost};

/// Model-predictive control of a spatial chain (`n` joints, any kind): at each plan,
///
/// ```text
/// minimise   sum_{k<N} h/2 [ |x_k - r_k|^2_Q + |u_k - w_k|^2_R ] + 1/2 |x_N - r_N|^2_{Q_f}
/// subject to x_0 = measured (q, v),  x_{k+1} = ChainEuler_h(x_k, u_k),  -limit <= u_k <= limit,
/// ```
///
/// `r_k` the joint reference at `t + k h`, `w_k = RNEA(q_r, v_r, q_r_dd)` its inverse dynamics,
/// the weights and the box (`tau_star_limits`: here the joint efforts, N m or N) as in
/// [`MpcSettings`]. Used as [`Mpc`](crate::Mpc): [`set_reference`](Self::set_reference) for
/// the `N + 1` nodes, [`shift`](Self::shift), [`solve`](Self::solve), then
/// [`control`](Self::control) until the next plan. Nothing allocates after [`new`](Self::new).
#[derive(Debug, Clone)]
pub struct ChainMpc {
    n: usize,
    step: f64,
    solver: IlqrSettings,
    ilqr: Ilqr,
    data: SpatialData,
    derivatives: SpatialDerivativeData,
    state: Vec<f64>,
    deviation: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    planned: bool,
}

impl ChainMpc {
    /// The controller of `model` with `settings` (one weight and limit per joint).
    ///
    /// # Errors
    /// As [`Mpc::new`](crate::Mpc::new).
    pub fn new(model: &SpatialModel, settings: &MpcSettings) -> Result<Self, OptimalError> {
        let n = model.n_links();
        let cost = tracking_cost(settings, n)?;
        let ilqr = Ilqr::new(2 * n, n, settings.horizon, &cost)?;
        let mut mpc = Self {
            n,
            step: settings.step,
            solver: settings.solver,
            ilqr,
            data: SpatialData::new(model),
            derivatives: SpatialDerivativeData::new(model),
            state: vec![0.0; 2 * n],
            deviation: vec![0.0; 2 * n],
            lower: vec![0.0; n],
            upper: vec![0.0; n],
            planned: false,
        };
        set_box(
            &mut mpc.ilqr,
            settings.tau_star_limits.as_deref(),
            &mut mpc.lower,
            &mut mpc.upper,
        )?;
        Ok(mpc)
    }

    /// The number of joints `n`.
    pub fn n_joints(&self) -> usize {
        self.n
    }

    /// The model step `h` (s).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The horizon `N` (steps).
    pub fn horizon(&self) -> usize {
        self.ilqr.horizon()
    }

    /// The estimated work of one solve, in multiply-adds (the unit of
    /// [`Mpc::solve_work`](crate::Mpc::solve_work)): at most `max_iterations` iterations of the
    /// horizon's nodes, each node's backward pass on `2n` states (`16 n^3`: `A^T V_xx A` and
    /// the gains) and its rollouts and linearisation (the articulated-body algorithm and its
    /// derivatives, `256 n` a trial of the line search and `2048 n` for the Jacobians).
    pub fn solve_work(&self) -> f64 {
        let n = self.n as f64;
        let trials = self.solver.line_search_steps as f64;
        let per_node = 16.0 * n.powi(3) + 256.0 * n * (trials + 8.0);
        self.solver.max_iterations as f64 * self.horizon() as f64 * per_node
    }

    /// The iLQR workspace: the last plan's controls, states and gains.
    pub fn ilqr(&self) -> &Ilqr {
        &self.ilqr
    }

    /// Sets the reference of node `k` (`0..=N`): `q`, `v` and, for `k < N`, the feed-forward
    /// effort `RNEA(q, v, q_dd)`.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for `k > N` or wrong lengths, [`OptimalError::ChainDynamics`]
    /// if the model refuses the reference state.
    pub fn set_reference(
        &mut self,
        model: &SpatialModel,
        k: usize,
        q: &[f64],
        v: &[f64],
        q_dd: &[f64],
    ) -> Result<(), OptimalError> {
        let (n, horizon) = (self.n, self.horizon());
        check_reference(k, horizon, n, [("q", q), ("v", v), ("q_dd", q_dd)])?;
        let x_ref = &mut self.ilqr.state_references_mut()[k * 2 * n..(k + 1) * 2 * n];
        x_ref[..n].copy_from_slice(q);
        x_ref[n..].copy_from_slice(v);
        if k < horizon {
            let w = &mut self.ilqr.control_references_mut()[k * n..(k + 1) * n];
            rnea(model, &mut self.data, q, v, q_dd, w)?;
        }
        Ok(())
    }

    /// Moves the previous plan `steps` steps earlier as the next warm start.
    pub fn shift(&mut self, steps: usize) {
        self.ilqr.shift(steps);
    }

    /// Forgets the previous plan: the next solve warm-starts from the reference efforts.
    pub fn reset(&mut self) {
        self.planned = false;
    }

    /// Whether a plan has been made since the last [`reset`](Self::reset).
    pub fn planned(&self) -> bool {
        self.planned
    }

    /// Plans from the state `(q, v)` over the references set by control-limited iLQR, from the
    /// shifted previous plan (or the reference efforts for the first plan).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong lengths or another model's size; the solver's and
    /// the dynamics' errors.
    pub fn solve(
        &mut self,
        model: &SpatialModel,
        q: &[f64],
        v: &[f64],
    ) -> Result<IlqrReport, OptimalError> {
        let n = self.n;
        for (name, len) in [
            ("model joints", model.n_links()),
            ("q", q.len()),
            ("v", v.len()),
        ] {
            if len != n {
                return Err(OptimalError::Dimension {
                    name,
                    expected: n,
                    found: len,
                });
            }
        }
        if !self.planned {
            self.ilqr.warm_start_from_control_references();
        }
        self.state[..n].copy_from_slice(q);
        self.state[n..].copy_from_slice(v);
        let mut dynamics =
            ChainEuler::new(model, &mut self.data, &mut self.derivatives, self.step)?;
        let report = self.ilqr.solve(&mut dynamics, &self.state, &self.solver)?;
        self.planned = true;
        Ok(report)
    }

    /// The effort `elapsed` seconds after the last plan for the state `(q, v)`: the plan's first
    /// control with its locally optimal feedback about the planned state, clamped to the box, as
    /// [`Mpc::control`](crate::Mpc::control). Into `tau` (`n` entries).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong lengths, [`OptimalError::InvalidSetting`] before
    /// the first plan.
    pub fn control(
        &mut self,
        elapsed: f64,
        q: &[f64],
        v: &[f64],
        tau: &mut [f64],
    ) -> Result<(), OptimalError> {
        plan_feedback(
            &self.ilqr,
            self.planned,
            self.step,
            elapsed,
            [("q", q), ("v", v)],
            &mut self.deviation,
            ("tau", tau),
        )
    }
}
