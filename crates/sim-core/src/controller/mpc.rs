//! Model-predictive control in the loop: [`Mpc`] re-planned every model step from the measured
//! state over a preview of the reference, with the plan's feedback in between.

use super::mpc_limits::{MpcConstraints, MpcLimits};
use super::{ControlContext, Controller, ControllerError, check_context};
use crate::error::SimError;
use crate::reference::{Reference, ReferencePreview};
use modal_reduce::Plant;
use optimal_ctl::{Mpc, MpcSettings, OptimalError};

/// The solver that `build` makes (its refusal named `controller.mpc`) and the preview of
/// `reference` over its horizon, for a model of `coords` coordinates (`have`: how the model
/// counts them, in the refusal of a reference of another number).
pub(super) fn solver_and_preview<T>(
    settings: &MpcSettings,
    reference: Box<dyn Reference>,
    (coords, have): (usize, &str),
    build: impl FnOnce() -> Result<T, OptimalError>,
) -> Result<(T, ReferencePreview), SimError> {
    if reference.n_coords() != coords {
        return Err(SimError::setting(
            "controller.mpc",
            format!(
                "previews a reference of {} coordinates, {have}",
                reference.n_coords()
            ),
        ));
    }
    let solver = build().map_err(|error| SimError::setting("controller.mpc", error.to_string()))?;
    let preview = ReferencePreview::new(reference, settings.horizon + 1, settings.step)?;
    Ok((solver, preview))
}

/// Receding-horizon MPC ([`Mpc`]): at the first sample, and then at the first sample at least one
/// model step `h` after the last plan, it previews the reference over the horizon
/// (`t, t + h, ..., t + N h`; node 0 is the reference the loop hands it), shifts the previous
/// plan by the steps elapsed as the warm start, and re-plans from the measured state by
/// control-limited iLQR. At every sample it applies the plan's first torque with its locally
/// optimal feedback about the planned state ([`Mpc::control`]), clamped to the `tau*` limits.
///
/// It previews its own copy of the loop's reference (a [`Reference`] is sampled by time alone,
/// so both agree); reference noise reaches it through node 0. A run that restarts at an earlier
/// time (a new run of the same [`Simulation`](crate::Simulation)) starts planning afresh.
/// The loop's actuator limits ([`ControlContext::tau_star_limits`], a scenario's
/// `[limits] tau_star`), when set, replace the settings' limits at every plan, so the solver
/// plans within the torques the loop will let through. With [`MpcLimits`]
/// ([`with_limits`](Self::with_limits)) every plan is also made within the joint-torque
/// polytope, the joint angle limits and the clearance margin ([`MpcConstraints`],
/// [`Mpc::solve_constrained`]); a node whose rows admit no torque (a state the arm was pushed
/// into, or its momentum carries it to) is planned within the box alone and counted
/// ([`relaxed_nodes`](Self::relaxed_nodes)). Nothing allocates per sample.
#[derive(Debug)]
pub struct MpcController {
    mpc: Mpc,
    preview: ReferencePreview,
    /// The time of the last plan.
    plan_time: f64,
    /// The rows every plan keeps besides the box, if any.
    constraints: Option<MpcConstraints>,
    /// Nodes planned within the box alone because their rows admitted no torque.
    relaxed: usize,
}

/// Slack on "at least one step after the last plan" (relative to the step).
const PLAN_SLACK: f64 = 1e-9;

impl MpcController {
    /// MPC of `model`'s coordinates with `settings`, previewing `reference` (the loop's
    /// reference, or a copy of it).
    ///
    /// ```
    /// use backbone_kin::ModalMap;
    /// use manip_dyn::ChainModel;
    /// use modal_reduce::ReducedModel;
    /// use sim_core::controller::{ControlContext, Controller, ModalState, MpcController};
    /// use optimal_ctl::MpcSettings;
    /// use sim_core::reference::{ReferenceSample, Step};
    ///
    /// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
    /// let mut settings = MpcSettings::uniform(3);
    /// settings.tau_star_limits = Some(vec![5.0; 3]);
    /// let reference = Step::constant(&[0.5, 0.1, 1.5])?;
    /// let mut mpc = MpcController::new(&model, &settings, Box::new(reference))?;
    /// let measured = ModalState::new(&[0.4, 0.0, 1.5], &[0.0; 3])?;
    /// let mut target = ReferenceSample::zeros(3);
    /// target.a.copy_from_slice(&[0.5, 0.1, 1.5]);
    /// let ctx = ControlContext {
    ///     t: 0.0,
    ///     measured: &measured,
    ///     reference: &target,
    ///     model: (&model).into(),
    ///     tau_star_limits: None,
    /// };
    /// let mut tau = [0.0; 3];
    /// mpc.control(&ctx, &mut tau)?;
    /// assert!(tau.iter().all(|t| t.abs() <= 5.0));
    /// # Ok::<(), Box<dyn std::error::Error + Send + Sync>>(())
    /// ```
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] for settings out of their domain (named `controller.mpc`) or
    /// a reference with another number of coordinates.
    pub fn new<'p>(
        model: impl Into<Plant<'p>>,
        settings: &MpcSettings,
        reference: Box<dyn Reference>,
    ) -> Result<Self, SimError> {
        let model = model.into();
        let m = model.n_coords();
        super::check_coordinate_count("controller.mpc", m)?;
        let (mpc, preview) = solver_and_preview(
            settings,
            reference,
            (m, &format!("the model has {m}")),
            || Mpc::new(model, settings),
        )?;
        Ok(Self {
            mpc,
            preview,
            plan_time: 0.0,
            constraints: None,
            relaxed: 0,
        })
    }

    /// The controller planning within `limits` as well (for `model`, the arm it was built
    /// for); empty limits change nothing. Sizes the rows' memory (allocates, once).
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the limit out of its domain ([`MpcConstraints::new`]).
    pub fn with_limits<'p>(
        mut self,
        model: impl Into<Plant<'p>>,
        limits: &MpcLimits,
    ) -> Result<Self, SimError> {
        self.constraints = MpcConstraints::new(model, limits, self.mpc.step())?;
        if let Some(constraints) = &self.constraints {
            self.mpc
                .reserve_constraints(constraints.max_rows())
                .map_err(|e| SimError::setting("controller.mpc", e.to_string()))?;
        }
        Ok(self)
    }

    /// The MPC workspace: the last plan.
    pub fn mpc(&self) -> &Mpc {
        &self.mpc
    }

    /// The rows the plans keep besides the box, if any.
    pub fn constraints(&self) -> Option<&MpcConstraints> {
        self.constraints.as_ref()
    }

    /// How many nodes, over every plan's last backward pass, were planned within the `tau*`
    /// box alone because the rows of [`with_limits`](Self::with_limits) admitted no torque
    /// there.
    pub fn relaxed_nodes(&self) -> usize {
        self.relaxed
    }

    /// Re-plans at `ctx.t` from the measured state.
    fn plan(&mut self, ctx: &ControlContext<'_>) -> Result<(), ControllerError> {
        let t = ctx.t;
        let h = self.mpc.step();
        if self.mpc.planned() {
            if t < self.plan_time {
                self.mpc.reset();
            } else {
                let steps = ((t - self.plan_time) / h).round().max(1.0);
                self.mpc.shift(steps.min(usize::MAX as f64) as usize);
            }
        }
        let samples = self.preview.advance(t)?;
        for (k, sample) in samples.iter().enumerate() {
            let sample = if k == 0 { ctx.reference } else { sample };
            self.mpc
                .set_reference(ctx.model, k, &sample.a, &sample.a_dot, &sample.a_ddot)?;
        }
        if let Some(limits) = ctx.tau_star_limits {
            self.mpc.set_limits(Some(limits))?;
        }
        let (a, a_dot) = (&ctx.measured.a, &ctx.measured.a_dot);
        match &mut self.constraints {
            None => {
                self.mpc
                    .solve(ctx.model, a, a_dot)
                    .map_err(|e| plan_failure(e, false))?;
            }
            Some(constraints) => {
                let mut rows = constraints.bind(ctx.model);
                let report = self
                    .mpc
                    .solve_constrained(ctx.model, a, a_dot, &mut rows)
                    .map_err(|e| plan_failure(e, true))?;
                self.relaxed += report.relaxed_nodes;
            }
        }
        self.plan_time = t;
        Ok(())
    }
}

/// A solve's failure as the loop reports it: one whose every trajectory left double precision
/// (the dynamics refused a state of the rollout, or the penalties overflowed the backward pass)
/// says that the plan diverged and, with rows, that they may admit no motion from the measured
/// state (a clearance margin beyond the arm's clearance, say); any other failure as it is.
fn plan_failure(error: OptimalError, constrained: bool) -> ControllerError {
    match error {
        OptimalError::Dynamics(_) | OptimalError::NonFinite(_) => format!(
            "the plan from the measured state diverged ({error}){}",
            if constrained {
                ": the limits and the clearance margin it keeps may admit no motion from this \
                 state"
            } else {
                ""
            }
        )
        .into(),
        other => other.into(),
    }
}

impl Controller for MpcController {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        check_context(ctx, self.mpc.n_coords(), tau_star)?;
        let due = self.plan_time + self.mpc.step() * (1.0 - PLAN_SLACK);
        if !self.mpc.planned() || ctx.t >= due || ctx.t < self.plan_time {
            self.plan(ctx)?;
        }
        self.mpc.control(
            ctx.t - self.plan_time,
            &ctx.measured.a,
            &ctx.measured.a_dot,
            tau_star,
        )?;
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.mpc.n_coords())
    }

    /// A solve every model step (and one at the start), each at most
    /// [`Mpc::solve_work`](optimal_ctl::Mpc::solve_work) with the constraints' rows.
    fn work(&self, duration: f64, n_joints: usize) -> f64 {
        let rows = self
            .constraints
            .as_ref()
            .map_or(0, MpcConstraints::max_rows);
        ((duration / self.mpc.step()).ceil() + 1.0) * self.mpc.solve_work(n_joints, rows)
    }
}
