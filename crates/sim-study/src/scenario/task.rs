//! `[task]`: what the arm must achieve, planned before the controller runs (`shape-plan`), and
//! the reference of kind `"planned"` that follows the plan.

use super::obstacles::Workspace;
use super::schema::{ReferenceSpec, Scenario, TaskSpec};
use clearance::ClearanceModel;
use modal_reduce::ReducedModel;
use shape_plan::{Plan, PlanOptions, PlanarArm, Planner};
use sim_core::SimError;
use sim_core::reference::Waypoints;

impl Scenario {
    /// The plan of the scenario's `[task]` (`None` without one): for `kind = "reach"` a goal
    /// shape whose chain tip is on `target` with every link at least `clearance` from every
    /// obstacle and from the other links, and a motion to it from the initial shape (`initial.a`,
    /// default the straight arm `a = 0`) that keeps the margin (`shape_plan::Planner::plan`,
    /// `docs/theory.md` "Shape planning"), seeded by the scenario's seed. Errors name the task's
    /// field, or say "no collision-free shape found" with the best clearance reached.
    pub fn plan(&self) -> Result<Option<Plan>, SimError> {
        let model = self.model()?;
        self.plan_for(&model)
    }

    /// [`plan`](Self::plan) for the scenario's reduced model, already built.
    pub(super) fn plan_for(&self, model: &ReducedModel) -> Result<Option<Plan>, SimError> {
        let Some(TaskSpec::Reach {
            target,
            clearance,
            check_slack,
            samples,
            max_iterations,
        }) = &self.task
        else {
            return Ok(None);
        };
        if target.len() != 2 {
            return Err(SimError::setting(
                "task.target",
                format!(
                    "must be a point [x, y] of the arm's plane, got {} numbers",
                    target.len()
                ),
            ));
        }
        let defaults = PlanOptions::default();
        let options = PlanOptions {
            clearance: *clearance,
            check_slack: check_slack.unwrap_or(defaults.check_slack),
            samples: samples.unwrap_or(defaults.samples),
            max_iterations: max_iterations.unwrap_or(defaults.max_iterations),
            seed: self.seed,
            ..defaults
        };
        let field = |e: shape_plan::PlanError| {
            let name = match &e {
                shape_plan::PlanError::OutOfRange { name, .. }
                | shape_plan::PlanError::TooMany { name, .. } => match *name {
                    "clearance" => "task.clearance",
                    "check slack" => "task.check_slack",
                    "samples" => "task.samples",
                    "max iterations" => "task.max_iterations",
                    "target coordinate" => "task.target",
                    _ => "task",
                },
                shape_plan::PlanError::OutOfReach { .. } => "task.target",
                shape_plan::PlanError::InitialTooClose { .. } => "initial.a",
                _ => "task",
            };
            SimError::setting(name, format!("cannot be met: {e}"))
        };
        options.validate().map_err(field)?;
        let lengths: Vec<f64> = model.chain().link_lengths().collect();
        let arm = PlanarArm::new(
            &lengths,
            self.modal.harmonics,
            self.planar_alpha0()?.base_angle(),
        )
        .map_err(field)?;
        let clearance_model = match self.clearance_model(lengths.len(), Workspace::Planar)? {
            Some(model) => model,
            None => ClearanceModel::new(lengths.len(), 0.0, Vec::new())
                .map_err(|e| SimError::setting("arm", format!("cannot be measured: {e}")))?,
        };
        let initial = match &self.initial {
            Some(initial) => initial.a.clone(),
            None => vec![0.0; model.n_coords()],
        };
        if initial.len() != model.n_coords() {
            return Err(SimError::setting(
                "initial.a",
                format!(
                    "must have {} entries, got {}",
                    model.n_coords(),
                    initial.len()
                ),
            ));
        }
        let mut planner = Planner::new(arm, clearance_model, options).map_err(field)?;
        planner.plan(&initial, target).map(Some).map_err(field)
    }

    /// The reference of kind `"planned"`: the plan's waypoints in `travel_time`
    /// ([`Waypoints`]). Refused without a `[task]`, and a `[task]` is refused with any other
    /// reference.
    pub(super) fn planned_reference(
        &self,
        model: &ReducedModel,
    ) -> Result<Option<Waypoints>, SimError> {
        match (&self.reference, &self.task) {
            (ReferenceSpec::Planned { travel_time }, Some(_)) => {
                let plan = self
                    .plan_for(model)?
                    .ok_or_else(|| SimError::setting("task", "gave no plan"))?;
                Waypoints::new(&plan.path, *travel_time).map(Some)
            }
            (ReferenceSpec::Planned { .. }, None) => Err(SimError::setting(
                "reference",
                "of kind \"planned\" follows the plan of a [task] or a [deploy]: give one \
                 ([task] kind = \"reach\", target, clearance)",
            )),
            (_, Some(_)) => Err(SimError::setting(
                "task",
                "is planned for the reference of kind \"planned\": set [reference] kind = \
                 \"planned\" and travel_time",
            )),
            (_, None) => Ok(None),
        }
    }
}
