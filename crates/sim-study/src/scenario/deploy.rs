//! `[deploy]`: follow-the-leader deployment into a channel (`docs/theory.md`, "Follow-the-leader
//! deployment"). The arm gets a prismatic insertion axis before its first joint, along the
//! centreline's first segment; the kinematic plan ([`shape_plan::follow_the_leader`]) becomes
//! the reference of computed torque on the whole chain (insertion and revolute joints) in the
//! joint-space loop of [`sim_core::run_chain_loop`], and the run's deployment metrics are
//! measured on the shapes the arm took.

use super::arm::ArmKind;
use super::controllers::ControllerKind;
use super::schema::{
    DeploySpec, IntegratorSpec, MAX_DEPLOY_CENTERLINE_POINTS, ReferenceSpec, Scenario, TorqueLimit,
};
use backbone_kin::{BaseAngle, ModalMap, joint_positions};
use manip_dyn::spatial::{SpatialData, rnea};
use manip_dyn::spatial::{SpatialJoint, SpatialLink, SpatialModel, Transform};
use optimal_ctl::MpcSettings;
use shape_plan::{
    Channel, DeployMetrics, DeploySample, DeployTracker, Deployment, MAX_DEPLOY_METRIC_WORK,
    PlanError, deploy_metric_work, follow_the_leader,
};
use sim_core::controller::ChainMpcController;
use sim_core::reference::{Reference, ReferenceSample, SplineMotion};
use sim_core::{
    ChainFailure, ChainLoopSettings, ChainRun, SimError, StoppedRun, run_chain_loop,
    run_chain_loop_mpc,
};

/// Steps of tip progress at which the deployment is planned (and its reference sampled).
pub const DEPLOY_PLAN_STEPS: usize = 400;
/// The most recorded samples a deployment run measures its metrics on (each sample's body is
/// compared with the tip's whole trace up to it).
pub const MAX_DEPLOY_RECORDED_SAMPLES: usize = 2_000;

/// The model step of the deployment's MPC (s): it re-plans every step.
pub const DEPLOY_MPC_STEP_S: f64 = 0.002;
/// The steps of the deployment's MPC horizon (0.05 s).
pub const DEPLOY_MPC_HORIZON: usize = 25;
/// The deployment MPC's box on each joint effort is this multiple of the largest effort the
/// reference's inverse dynamics asks of that joint ...
pub const DEPLOY_MPC_BOX_FACTOR: f64 = 2.0;
/// ... and at least this (N m, or N on the insertion axis).
pub const DEPLOY_MPC_BOX_FLOOR: f64 = 0.1;

/// A finished deployment run.
#[derive(Debug, Clone, PartialEq)]
pub struct DeployRun {
    /// The joint-space run: joint 1 is the insertion `q` (m), joints 2 to `n + 1` the revolute
    /// joints (`theta_1` from the `x` axis, rad).
    pub run: ChainRun,
    /// The base and every link's end point at each recorded sample, `n + 1` points a sample
    /// (what `links.csv` holds).
    pub points: Vec<[f64; 2]>,
    /// Each recorded sample's own deployment metrics.
    pub samples: Vec<DeploySample>,
    /// The deployment metrics of the run, over every recorded sample.
    pub metrics: DeployMetrics,
    /// The deployment metrics of the kinematic plan it tracked.
    pub plan: DeployMetrics,
    /// The channel.
    pub channel: Channel,
}

/// A deployment that stopped: why, and the deployment up to its last recorded sample (its
/// metrics over the samples before the stop), or `None` when it stopped before its first
/// recorded sample (a setting out of its domain, or a failure at `t = 0`).
pub type DeployFailure = StoppedRun<DeployRun>;

impl DeployRun {
    /// The points of recorded sample `k`.
    pub fn points_at(&self, k: usize) -> &[[f64; 2]] {
        let n = self.points.len() / self.run.record.t.len().max(1);
        &self.points[k * n..(k + 1) * n]
    }
}

/// The refusal of a scenario key a deployment does not use.
fn unused(name: &str, why: &str) -> SimError {
    SimError::setting(name, format!("is not used with [deploy]: {why}"))
}

/// The scenario field a deployment error of `shape-plan` is about.
fn plan_field(error: PlanError) -> SimError {
    let name = match &error {
        PlanError::OutOfRange { name, .. } | PlanError::TooMany { name, .. } => {
            if name.contains("radius") && !name.contains("link") {
                "deploy.radius"
            } else if name.contains("link radius") {
                "arm.radius"
            } else if name.contains("harmonics") {
                "modal.harmonics"
            } else {
                "deploy.centerline"
            }
        }
        _ => "deploy.centerline",
    };
    SimError::setting(name, format!("cannot be deployed into: {error}"))
}

impl Scenario {
    /// The channel of the scenario's `[deploy]` (`None` without one). Errors name
    /// `deploy.centerline` (fewer than two points, more than [`MAX_DEPLOY_CENTERLINE_POINTS`],
    /// a spatial `[x, y, z]` point, a non-finite coordinate, two equal consecutive points) or
    /// `deploy.radius` (not positive and finite, or above 1e6 m: [`shape_plan::MAX_CENTERLINE_EXTENT`]).
    pub fn channel(&self) -> Result<Option<Channel>, SimError> {
        let Some(DeploySpec { centerline, radius }) = &self.deploy else {
            return Ok(None);
        };
        if !(radius.is_finite() && *radius > 0.0) {
            return Err(SimError::setting(
                "deploy.radius",
                format!("must be positive and finite (m), got {radius}"),
            ));
        }
        if centerline.len() > MAX_DEPLOY_CENTERLINE_POINTS {
            return Err(SimError::setting(
                "deploy.centerline",
                format!(
                    "has {} points, at most {MAX_DEPLOY_CENTERLINE_POINTS} allowed",
                    centerline.len()
                ),
            ));
        }
        let mut points = Vec::with_capacity(centerline.len());
        for (k, point) in centerline.iter().enumerate() {
            match point.as_slice() {
                [x, y] => points.push([*x, *y]),
                [_, _, _] => {
                    return Err(SimError::setting(
                        "deploy.centerline",
                        format!(
                            "point {} is [x, y, z]: spatial channels are not supported, give \
                             planar points [x, y] (the arm moves in the plane z = 0)",
                            k + 1
                        ),
                    ));
                }
                other => {
                    return Err(SimError::setting(
                        "deploy.centerline",
                        format!(
                            "point {} has {} numbers, expected a point [x, y]",
                            k + 1,
                            other.len()
                        ),
                    ));
                }
            }
        }
        Channel::new(&points, *radius).map(Some).map_err(plan_field)
    }

    /// The follow-the-leader plan of the scenario's `[deploy]` (`None` without one): the tip
    /// from the entry to the centreline's end in [`DEPLOY_PLAN_STEPS`] steps, the revolute
    /// joints fitted with `modal.harmonics` harmonics of the whole chain's modal map (exact when
    /// `2K` is the number of links). Errors as [`channel`](Self::channel), and naming the key
    /// that makes the deployment impossible (an arm shorter than the channel:
    /// `deploy.centerline`; `2K` above the links: `modal.harmonics`).
    pub fn deployment(&self) -> Result<Option<(Channel, Deployment)>, SimError> {
        let Some(channel) = self.channel()? else {
            return Ok(None);
        };
        let chain = self.arm.to_chain()?;
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let k = self.modal.harmonics;
        if k == 0 || 2 * k > lengths.len() {
            return Err(SimError::setting(
                "modal.harmonics",
                format!(
                    "must be between 1 and half the arm's {} links for a deployment (the fit of \
                     the joint angles), got {k}",
                    lengths.len()
                ),
            ));
        }
        let plan = follow_the_leader(
            &channel,
            &lengths,
            self.arm.radius.unwrap_or(0.0),
            k,
            channel.length(),
            DEPLOY_PLAN_STEPS,
        )
        .map_err(plan_field)?;
        Ok(Some((channel, plan)))
    }

    /// The deployment's arm as a spatial chain in the plane `z = 0`: a prismatic insertion
    /// joint along the centreline's first segment `d` (massless carriage; at `q = 0` the tip is
    /// at the entry `E` and the base joint at `E - l d`), then the planar arm's revolute joints
    /// about `z` ([`SpatialModel::from_planar`], gravity along `-y`).
    pub fn deploy_model(&self, channel: &Channel) -> Result<SpatialModel, SimError> {
        let chain = self.arm.to_chain()?;
        let planar = SpatialModel::from_planar(&chain);
        let (e, d, l) = (channel.entry(), channel.axis(), chain.total_length());
        let mut joints = vec![SpatialJoint::prismatic(
            [d[0], d[1], 0.0],
            Transform::translation([e[0] - l * d[0], e[1] - l * d[1], 0.0]),
        )];
        joints.extend_from_slice(planar.joints());
        let carriage = SpatialLink {
            mass: 0.0,
            com: [0.0; 3],
            inertia: [[0.0; 3]; 3],
        };
        let mut links = vec![carriage];
        links.extend_from_slice(planar.links());
        SpatialModel::new(joints, links, planar.gravity())
            .map_err(|e| SimError::setting("arm", format!("cannot carry an insertion axis: {e}")))
    }

    /// Runs the scenario's deployment: the plan ([`deployment`](Self::deployment)) sampled at
    /// its steps as joint values `(q, J a + theta_0)`, interpolated by [`SplineMotion`] over
    /// `reference.travel_time` (then held), tracked from rest at its start by computed torque
    /// (`controller.kp`, `controller.kd`: one entry per joint, the insertion first; defaults 2500
    /// and 100), or with `controller.kind = "mpc"` by joint-space MPC ([`ChainMpcController`],
    /// `deploy_mpc_settings`), every `controller.period` (default the RK4 step) on the whole chain
    /// ([`deploy_model`](Self::deploy_model), [`run_chain_loop`]), and measures the deployment
    /// metrics on the arm's shape at every recorded sample (the deployed length being the
    /// insertion `q`).
    ///
    /// # Errors
    /// As [`deployment`](Self::deployment); [`SimError::InvalidSetting`] naming the key for
    /// what a deployment does not use (`alpha0`: the insertion axis sets it; `initial`,
    /// `obstacles`, `task`, noise, `limits` other than `max_modal_error`, a controller other
    /// than computed torque or MPC, dopri5, a reference other than `"planned"`) and for more than
    /// [`MAX_DEPLOY_RECORDED_SAMPLES`] recorded samples; the run's errors ([`run_chain_loop`]).
    pub fn run_deploy(&self) -> Result<DeployRun, DeployFailure> {
        self.run_deploy_wrapping(|reference| reference)
    }

    /// Runs the deployment as [`run_deploy`](Self::run_deploy) does, with the reference the
    /// loop tracks passed through `wrap`, which the loop samples at every controller sample (e.g.
    /// a wrapper that stops the run when a Python user presses Ctrl-C). The MPC's own horizon
    /// samples the plan unwrapped.
    ///
    /// # Errors
    /// As [`run_deploy`](Self::run_deploy), and the wrapped reference's.
    pub fn run_deploy_wrapping(
        &self,
        wrap: impl FnOnce(Box<dyn Reference>) -> Box<dyn Reference>,
    ) -> Result<DeployRun, DeployFailure> {
        if self.deploy.is_none() {
            return Err(SimError::setting(
                "deploy",
                "is required to run a deployment ([deploy] centerline, radius)",
            )
            .into());
        }
        let travel_time = self.check_deploy_keys()?;
        let IntegratorSpec::Rk4 { dt } = self.integrator else {
            return Err(unused(
                "integrator.method = \"dopri5\"",
                "the joint-space loop integrates by RK4",
            )
            .into());
        };
        let period = self.controller_period()?;
        // A deployment faster than one controller period is one jump: its accelerations
        // overflow (1e-300 s gave a NaN joint acceleration at t = 0).
        if travel_time < period {
            return Err(SimError::setting(
                "reference.travel_time",
                format!(
                    "= {} s is shorter than one controller period ({} s): the deployment would \
                     be a single jump",
                    lane_math::Compact(travel_time),
                    lane_math::Compact(period)
                ),
            )
            .into());
        }
        let record_period = self.record_period.unwrap_or(period);
        if !(record_period > 0.0 && self.duration > 0.0)
            || self.duration / record_period > MAX_DEPLOY_RECORDED_SAMPLES as f64
        {
            return Err(SimError::setting(
                "record_period",
                format!(
                    "must give at most {MAX_DEPLOY_RECORDED_SAMPLES} recorded samples for the \
                     deployment's metrics, got a duration of {} s recorded every {} s",
                    self.duration, record_period
                ),
            )
            .into());
        }
        // The metrics of the plan's shapes and of every recorded one, bounded before any is
        // computed.
        let links = self.arm.link_count(None)?;
        if self.controller.kind == ControllerKind::Mpc {
            // The insertion and every revolute joint, refused before the plan is made.
            let mut settings = MpcSettings::uniform(1);
            settings.horizon = DEPLOY_MPC_HORIZON;
            let max = settings.max_coords();
            if links + 1 > max {
                return Err(SimError::setting(
                    "arm.links",
                    format!(
                        "is {links}: with the insertion, {} joints, more than the {max} whose \
                         plan over the deployment MPC's {DEPLOY_MPC_HORIZON}-step horizon the \
                         solver holds",
                        links + 1
                    ),
                )
                .into());
            }
        }
        let shapes = DEPLOY_PLAN_STEPS + 2 + (self.duration / record_period) as usize;
        let work = deploy_metric_work(links, shapes);
        if work > MAX_DEPLOY_METRIC_WORK {
            return Err(SimError::setting(
                "arm.links",
                format!(
                    "is {links}: measured at {shapes} shapes (the plan's and one every \
                     record_period), they take {work:.1e} units of work, more than the \
                     {MAX_DEPLOY_METRIC_WORK:e} a deployment may: fewer links or a longer \
                     record_period"
                ),
            )
            .into());
        }
        let (channel, plan) = self
            .deployment()?
            .ok_or_else(|| SimError::setting("deploy", "gave no plan"))?;
        let model = self.deploy_model(&channel)?;
        let chain = self.arm.to_chain()?;
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let n = lengths.len();
        let axis = channel.axis();
        let map = ModalMap::new(
            &lengths,
            self.modal.harmonics,
            BaseAngle::Fixed(axis[1].atan2(axis[0])),
        )
        .map_err(|e| SimError::setting("modal.harmonics", e.to_string()))?;
        let mut knots = Vec::with_capacity(plan.frames.len());
        for frame in &plan.frames {
            let mut joints = vec![0.0; n + 1];
            joints[0] = frame.insertion;
            map.joint_angles(&frame.modal, &mut joints[1..])
                .map_err(|e| SimError::setting("modal.harmonics", e.to_string()))?;
            knots.push(joints);
        }
        let mut reference = SplineMotion::new(&knots, travel_time)?;
        let mut start = ReferenceSample::zeros(n + 1);
        reference.sample(0.0, &mut start)?;
        let mpc = self.controller.kind == ControllerKind::Mpc;
        let (kp, kd) = if mpc {
            (Vec::new(), Vec::new())
        } else {
            self.controller.computed_torque_gains(n + 1)?
        };
        let settings = ChainLoopSettings {
            duration: self.duration,
            period,
            dt,
            record_period,
            kp,
            kd,
            max_joint_error: self.limits.max_modal_error,
            effort_limits: Vec::new(),
            position_limits: Vec::new(),
            damping: Vec::new(),
        };
        let mut tracked = wrap(Box::new(reference.clone()));
        let outcome = if mpc {
            let mut mpc_settings = deploy_mpc_settings(&model, &reference, travel_time)?;
            if let Some(limits) = &self.limits.joint_torque_nm {
                set_joint_torque_box(&mut mpc_settings, limits, n)?;
            }
            let mut controller =
                ChainMpcController::new(&model, &mpc_settings, Box::new(reference))?;
            run_chain_loop_mpc(
                &model,
                tracked.as_mut(),
                &start.a,
                &settings,
                &mut controller,
            )
        } else {
            run_chain_loop(&model, tracked.as_mut(), &start.a, &settings)
        };
        // A run that stopped is measured up to the stop.
        let (run, stop) = ChainFailure::split(outcome)?;
        let radius = self.arm.radius.unwrap_or(0.0);
        let mut tracker = DeployTracker::new(&channel, &lengths, radius).map_err(plan_field)?;
        tracker.reserve(run.record.t.len()).map_err(plan_field)?;
        let length = chain.total_length();
        let (e, d) = (channel.entry(), axis);
        let mut points = vec![[0.0; 2]; run.record.t.len() * (n + 1)];
        let mut samples = Vec::with_capacity(run.record.t.len());
        for (k, shape) in points.chunks_exact_mut(n + 1).enumerate() {
            let joints = &run.record.q[k * (n + 1)..(k + 1) * (n + 1)];
            let q = joints[0];
            joint_positions(&lengths, &joints[1..], shape)
                .map_err(|e| SimError::setting("arm", e.to_string()))?;
            let base = [e[0] + (q - length) * d[0], e[1] + (q - length) * d[1]];
            for p in shape.iter_mut() {
                p[0] += base[0];
                p[1] += base[1];
            }
            samples.push(tracker.add(shape, q));
        }
        let deployed = DeployRun {
            metrics: tracker.metrics(),
            plan: plan.metrics,
            samples,
            run,
            points,
            channel,
        };
        match stop {
            None => Ok(deployed),
            Some(error) => Err(DeployFailure {
                error,
                partial: Some(Box::new(deployed)),
            }),
        }
    }

    /// Refuses the keys a deployment does not use; returns the reference's travel time.
    fn check_deploy_keys(&self) -> Result<f64, SimError> {
        if self.alpha0.is_some() {
            return Err(unused(
                "alpha0",
                "the insertion axis (the centreline's first segment) sets the base angle",
            ));
        }
        if self.initial.is_some() {
            return Err(unused(
                "initial",
                "the arm starts at rest, fully retracted (its tip at the entry)",
            ));
        }
        if !self.obstacles.is_empty() {
            return Err(unused("obstacles", "the channel's walls are the obstacles"));
        }
        if self.task.is_some() {
            return Err(unused("task", "the deployment is the plan"));
        }
        if self.arm.kind == ArmKind::Spatial {
            return Err(SimError::setting(
                "arm.kind",
                "is \"spatial\": a deployment's arm is planar (it moves in the plane z = 0 of \
                 its channel)",
            ));
        }
        let mpc = self.controller.kind == ControllerKind::Mpc;
        if let Some((name, why)) = self.unused_by_joint_space_loops(mpc) {
            return Err(unused(name, why));
        }
        if !matches!(
            self.controller.kind,
            ControllerKind::ComputedTorque | ControllerKind::Mpc
        ) {
            return Err(SimError::setting(
                "controller.kind",
                format!(
                    "must be \"computed-torque\" or \"mpc\" with [deploy] (the controllers of \
                     the whole chain, insertion axis included, in joint space), got \"{}\"",
                    self.controller.kind
                ),
            ));
        }
        match self.reference {
            ReferenceSpec::Planned { travel_time } => Ok(travel_time),
            _ => Err(SimError::setting(
                "reference",
                "must be of kind \"planned\" with [deploy] (the deployment's plan), with its \
                 travel_time",
            )),
        }
    }
}

/// Sets the box of the deployment MPC's revolute joints (all but the insertion's, the last `n`
/// of `settings`' limits) to `[limits] joint_torque_nm`: one number for every joint, or one per
/// joint, base first.
///
/// # Errors
/// [`SimError::InvalidSetting`] naming `limits.joint_torque_nm` for another number of limits
/// than the arm's `n` joints, or a limit that is not positive and finite.
fn set_joint_torque_box(
    settings: &mut MpcSettings,
    limits: &TorqueLimit,
    n: usize,
) -> Result<(), SimError> {
    const FIELD: &str = "limits.joint_torque_nm";
    let given = match limits {
        TorqueLimit::All(limit) => std::slice::from_ref(limit),
        TorqueLimit::PerJoint(limits) if limits.len() == n => limits.as_slice(),
        TorqueLimit::PerJoint(limits) => {
            return Err(SimError::setting(
                FIELD,
                format!(
                    "has {} entries, the arm has {n} joints (the insertion's box is the \
                     deployment MPC's own)",
                    limits.len()
                ),
            ));
        }
    };
    if let Some(l) = given.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        return Err(SimError::setting(
            FIELD,
            format!("must be positive and finite (N m), got {l}"),
        ));
    }
    let Some(box_limits) = settings.tau_star_limits.as_mut() else {
        return Err(SimError::setting(FIELD, "has no box to set"));
    };
    let joints = box_limits.len() - n;
    for (j, limit) in box_limits[joints..].iter_mut().enumerate() {
        *limit = given[j.min(given.len() - 1)];
    }
    Ok(())
}

/// The deployment's MPC ([`ChainMpcController`]) on `model`: [`MpcSettings::uniform`]'s weights
/// (effort weight 1 per (N m)^2 s: the joint-space efforts of light links need more weight
/// than modal torques) over [`DEPLOY_MPC_HORIZON`] steps of [`DEPLOY_MPC_STEP_S`], and a box on
/// each joint effort of [`DEPLOY_MPC_BOX_FACTOR`] times the largest `|RNEA(q_r, v_r, q_r_dd)|`
/// along the reference (sampled every model step over `travel_time`, then held), at least
/// [`DEPLOY_MPC_BOX_FLOOR`].
fn deploy_mpc_settings(
    model: &SpatialModel,
    reference: &SplineMotion,
    travel_time: f64,
) -> Result<MpcSettings, SimError> {
    let n = model.n_links();
    let mut settings = MpcSettings::uniform(n);
    settings.step = DEPLOY_MPC_STEP_S;
    settings.horizon = DEPLOY_MPC_HORIZON;
    settings.effort_weight = vec![1.0; n];
    let mut reference = reference.clone();
    let mut sample = ReferenceSample::zeros(n);
    let mut data = SpatialData::new(model);
    let mut effort = vec![0.0; n];
    let mut peak = vec![DEPLOY_MPC_BOX_FLOOR / DEPLOY_MPC_BOX_FACTOR; n];
    let samples = (travel_time / DEPLOY_MPC_STEP_S).ceil().min(1e6) as usize;
    for k in 0..=samples {
        reference.sample(k as f64 * DEPLOY_MPC_STEP_S, &mut sample)?;
        rnea(
            model,
            &mut data,
            &sample.a,
            &sample.a_dot,
            &sample.a_ddot,
            &mut effort,
        )
        .map_err(|source| SimError::ChainDynamics { t: 0.0, source })?;
        for (p, e) in peak.iter_mut().zip(&effort) {
            *p = p.max(e.abs());
        }
    }
    settings.tau_star_limits = Some(peak.iter().map(|p| DEPLOY_MPC_BOX_FACTOR * p).collect());
    Ok(settings)
}
