//! `[task]`: what the arm must achieve, planned before the controller runs (`shape-plan`), and
//! the reference of kind `"planned"` that follows the plan.

use super::schema::{AngleLimit, ReferenceSpec, Scenario, TaskSpec};
use clearance::{ClearanceData, ClearanceModel};
use lane_math::Compact;
use modal_reduce::PlantModel;
use shape_plan::{Arm, ArmScratch, Plan, PlanError, PlanOptions, PlanarArm, Planner, SpatialArm};
use sim_core::SimError;
use sim_core::reference::Waypoints;

impl Scenario {
    /// The plan of the scenario's `[task]` (`None` without one): for `kind = "reach"` a goal
    /// shape whose chain tip is on `target` (`[x, y]` for a planar arm, `[x, y, z]` for a
    /// spatial one) with every link at least `clearance` from every obstacle and from the other
    /// links, and a motion to it from the initial shape (`initial.a`, default the straight arm
    /// `a = 0`) that keeps the margin (`shape_plan::Planner::plan` on the planar or the
    /// spatial modal arm, warm-started from its free-space inverse kinematics, `docs/theory.md`
    /// "Shape planning"), seeded by the scenario's seed. Errors name the task's field, or say
    /// "no collision-free shape found" with the best clearance reached.
    pub fn plan(&self) -> Result<Option<Plan>, SimError> {
        let model = self.plant()?;
        self.plan_for(&model)
    }

    /// [`plan`](Self::plan) for the scenario's modal arm, already built.
    pub(super) fn plan_for(&self, model: &PlantModel) -> Result<Option<Plan>, SimError> {
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
        let workspace = self.workspace();
        if target.len() != workspace.dims() {
            return Err(SimError::setting(
                "task.target",
                format!(
                    "must be {}, got {}",
                    workspace.point_words(),
                    super::obstacles::numbers(target.len())
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
        options.validate().map_err(task_field)?;
        let m = model.plant().n_coords();
        let initial = match &self.initial {
            Some(initial) => initial.a.clone(),
            None => vec![0.0; m],
        };
        if initial.len() != m {
            return Err(SimError::setting(
                "initial.a",
                format!("must have {m} entries, got {}", initial.len()),
            ));
        }
        // The plan interpolates from the initial shape: beyond a thousand radians a modal
        // coordinate turns the joints by hundreds of turns, and its squares leave double
        // precision long before 1e300.
        if let Some(a) = initial
            .iter()
            .find(|a| a.is_nan() || a.abs() > MAX_TASK_INITIAL_RAD)
        {
            return Err(SimError::setting(
                "initial.a",
                format!(
                    "must be finite and within {MAX_TASK_INITIAL_RAD} rad with a [task] (the plan \
                     moves from it), got {}",
                    Compact(*a)
                ),
            ));
        }
        let plan = match model {
            PlantModel::Planar(planar) => {
                let lengths: Vec<f64> = planar.chain().link_lengths().collect();
                let alpha0 = self.planar_alpha0()?.base_angle();
                let arm = PlanarArm::new(&lengths, self.modal.harmonics, alpha0);
                self.plan_arm(arm.map_err(task_field)?, options, &initial, target)
            }
            PlantModel::Spatial(spatial) => {
                let map = spatial.map();
                let arm = SpatialArm::new(map.link_lengths(), map.harmonics(), *spatial.base());
                self.plan_arm(arm.map_err(task_field)?, options, &initial, target)
            }
        };
        plan.map(Some)
    }

    /// The plan of `arm` among the scenario's obstacles from `initial` to `target`.
    fn plan_arm<A: Arm>(
        &self,
        arm: A,
        options: PlanOptions,
        initial: &[f64],
        target: &[f64],
    ) -> Result<Plan, SimError> {
        let n = arm.n_links();
        let clearance_model = match self.clearance_model(n, self.workspace())? {
            Some(model) => model,
            None => ClearanceModel::new(n, 0.0, Vec::new())
                .map_err(|e| SimError::setting("arm", format!("cannot be measured: {e}")))?,
        };
        let mut planner = Planner::new(arm, clearance_model, options).map_err(task_field)?;
        let plan = planner.plan(initial, target).map_err(|e| match e {
            // The start the scenario gives, or the straight arm of its default start: the
            // clearance asked for is what it cannot keep there.
            PlanError::InitialTooClose { .. } if self.initial.is_none() => SimError::setting(
                "task.clearance",
                format!("cannot be met from the arm's start (a = 0, no [initial]): {e}"),
            ),
            e => task_field(e),
        })?;
        self.check_plan_angles(&planner, &plan)?;
        Ok(plan)
    }

    /// Refuses a plan whose waypoints turn a joint beyond `limits.joint_angle_rad`: the planner
    /// keeps clearance, not joint angles, and the run would stop at the first limit its
    /// projection cannot keep.
    fn check_plan_angles<A: Arm>(&self, planner: &Planner<A>, plan: &Plan) -> Result<(), SimError> {
        let Some(limits) = &self.limits.joint_angle_rad else {
            return Ok(());
        };
        let (arm, clearance) = (planner.arm(), planner.clearance());
        let mut scratch = ArmScratch::new(arm);
        let mut data = ClearanceData::new(clearance, arm.n_coords())
            .map_err(|e| SimError::setting("arm", format!("cannot be measured: {e}")))?;
        for (k, a) in plan.path.iter().enumerate() {
            arm.place(clearance, &mut data, &mut scratch, a)
                .map_err(task_field)?;
            for (j, theta) in scratch.theta.iter().enumerate() {
                let limit = match limits {
                    AngleLimit::All(limit) => *limit,
                    AngleLimit::PerJoint(limits) => limits.get(j).copied().unwrap_or(f64::INFINITY),
                };
                if theta.abs() > limit {
                    return Err(SimError::setting(
                        "limits.joint_angle_rad",
                        format!(
                            "cannot be kept by the [task]'s plan (the planner keeps clearance, not \
                             joint angles): its waypoint {k} turns joint {} to {} rad, beyond {} rad",
                            j + 1,
                            Compact(*theta),
                            Compact(limit)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The reference of kind `"planned"`: the plan's waypoints in `travel_time`
    /// ([`Waypoints`]). Refused without a `[task]`, and a `[task]` is refused with any other
    /// reference.
    pub(super) fn planned_reference(
        &self,
        model: &PlantModel,
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

/// The largest modal coordinate of `initial.a` a `[task]` plans from (rad).
const MAX_TASK_INITIAL_RAD: f64 = 1e3;

/// A planner's error as a setting error naming the task's field it comes from.
fn task_field(e: PlanError) -> SimError {
    let name = match &e {
        PlanError::OutOfRange { name, .. } | PlanError::TooMany { name, .. } => match *name {
            "clearance" => "task.clearance",
            "check slack" => "task.check_slack",
            "samples" => "task.samples",
            "max iterations" => "task.max_iterations",
            "target coordinate" => "task.target",
            _ => "task",
        },
        PlanError::TooMuchWork { .. } => "task.samples",
        PlanError::OutOfReach { .. } | PlanError::TargetTooClose { .. } => "task.target",
        PlanError::InitialTooClose { .. } => "initial.a",
        _ => "task",
    };
    SimError::setting(name, format!("cannot be met: {e}"))
}
