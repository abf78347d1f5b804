//! The closed loop on a full spatial chain in joint space (a URDF arm): computed torque on the
//! chain's own dynamics, tracking a joint-space [`Reference`], the plant integrated by RK4 with
//! the articulated-body algorithm.
//!
//! At each controller sample `t_k` (every `period` s) the controller reads the state `(q, v)` and
//! the reference `(q_r, v_r, a_r)` and commands, by one RNEA (`manip_dyn::spatial::rnea`),
//!
//! ```text
//! tau = M(q) (a_r + K_d (v_r - v) + K_p (q_r - q)) + C(q, v) v + G(q),
//! ```
//!
//! held until the next sample while RK4 integrates `q_dd = M^-1 (tau - C v - G)` by the ABA in
//! steps of at most `dt`. With the exact model the joint error obeys
//! `e_dd + K_d e_d + K_p e = 0` between samples: it converges for positive gains.
//!
//! [`run_chain_loop_mpc`] runs the same loop with joint-space model-predictive control
//! ([`ChainMpcController`]) in place of computed torque. This loop is separate from the modal
//! loop ([`Simulation`](crate::Simulation)): its state is the joint vector, not modal
//! coordinates.

use crate::controller::ChainMpcController;
use crate::error::{SimError, StoppedRun, check_positive};
use crate::ode::{MAX_RK4_STEPS, OdeSystem, Rk4};
use crate::reference::{Reference, ReferenceSample};
use crate::simulation::{
    MAX_CONTROLLER_SAMPLES, MAX_RECORDED_VALUES, MAX_RUN_WORK, run_work_refusal,
};
use lane_math::Compact;
use lane_math::check_all_finite;
use manip_dyn::DynError;
use manip_dyn::spatial::{SpatialData, SpatialModel, aba, rnea};

/// The settings of a [`run_chain_loop`].
#[derive(Debug, Clone, PartialEq)]
pub struct ChainLoopSettings {
    /// Simulated time (s), positive.
    pub duration: f64,
    /// Controller period (s): the torque is held between samples.
    pub period: f64,
    /// Longest RK4 step (s), at most `period`.
    pub dt: f64,
    /// Recording period (s): every controller sample whose index is a multiple of
    /// `round(record_period / period)` (at least 1) is recorded, and the last.
    pub record_period: f64,
    /// Stiffness per joint (1/s^2), positive (computed torque's; not used by
    /// [`run_chain_loop_mpc`]).
    pub kp: Vec<f64>,
    /// Damping per joint (1/s), positive (computed torque's; not used by
    /// [`run_chain_loop_mpc`]).
    pub kd: Vec<f64>,
    /// Runaway bound on `|q_i - q_r,i|` (rad or m): the run stops past it.
    pub max_joint_error: f64,
    /// The actuators' largest effort per joint (N m or N; positive, infinity for none), or
    /// empty for none: the commanded effort is clamped to `[-limit, limit]` at every controller
    /// sample, as a saturating actuator delivers it.
    pub effort_limits: Vec<f64>,
    /// Each joint's position range `[lower, upper]` (rad or m; infinite ends for none), or
    /// empty for none: a reference sample or initial position outside it stops the run (the
    /// plant has no hard stops; the controller is not asked to drive a joint past its range).
    pub position_limits: Vec<[f64; 2]>,
    /// Viscous damping per joint (N m s/rad or N s/m; non-negative), or empty for none: the
    /// plant's joint `i` receives `tau_i - damping_i v_i` (URDF's `<dynamics damping>`, as
    /// MuJoCo's `damping`).
    pub damping: Vec<f64>,
}

/// The recorded time series of a chain run, `n` values per sample in each joint series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChainRecord {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Joint values, sample after sample.
    pub q: Vec<f64>,
    /// Reference joint values.
    pub q_ref: Vec<f64>,
    /// Commanded joint efforts (N m or N).
    pub tau: Vec<f64>,
}

/// The metrics of a chain run.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainSummary {
    /// Controller samples taken (including the one at the final time).
    pub controller_samples: usize,
    /// Accepted RK4 steps.
    pub steps: usize,
    /// Root mean square of `q_i - q_r,i` per joint over the recorded samples.
    pub joint_error_rms: Vec<f64>,
    /// Largest `|q_i - q_r,i|` per joint over the recorded samples.
    pub joint_error_max: Vec<f64>,
    /// `|q - q_r|` (Euclidean, over the joints) at the final time.
    pub final_error: f64,
    /// Largest `|tau_i|` per joint over the controller samples (the delivered efforts, within
    /// the effort limits).
    pub peak_joint_efforts: Vec<f64>,
    /// The share of controller samples at which an effort limit clamped the command (0 without
    /// limits).
    pub effort_limited_share: f64,
}

/// A finished chain run.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainRun {
    /// The metrics.
    pub summary: ChainSummary,
    /// The time series.
    pub record: ChainRecord,
}

/// A chain run that stopped: why, and the run up to its last recorded sample (its metrics over
/// the samples before the stop, `final_error` at the last recorded one), or `None` when it
/// stopped before its first recorded sample (a setting out of its domain, or a failure at
/// `t = 0`).
pub type ChainFailure = StoppedRun<ChainRun>;

/// The plant between two controller samples: `(q, v)' = (v, ABA(q, v, tau - damping v))`
/// (`applied` holds the damped efforts; without damping `tau` goes in as it is).
struct Plant<'a> {
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
    tau: &'a [f64],
    damping: &'a [f64],
    applied: &'a mut [f64],
}

impl OdeSystem for Plant<'_> {
    type Error = DynError;

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), DynError> {
        let n = self.model.n_links();
        let (q, v) = y.split_at(n);
        let (q_dot, v_dot) = dy.split_at_mut(n);
        q_dot.copy_from_slice(v);
        if self.damping.is_empty() {
            return aba(self.model, self.data, q, v, self.tau, v_dot);
        }
        let joints = self
            .applied
            .iter_mut()
            .zip(self.tau.iter().zip(self.damping));
        for ((applied, (&tau, &damping)), &v) in joints.zip(v) {
            *applied = tau - damping * v;
        }
        aba(self.model, self.data, q, v, self.applied, v_dot)
    }
}

/// Checks the settings against a chain of `n` joints; returns the number of controller periods.
fn check(
    settings: &ChainLoopSettings,
    n: usize,
    gains: bool,
    controller_work: f64,
) -> Result<usize, SimError> {
    check_positive("duration", settings.duration)?;
    check_positive("controller.period", settings.period)?;
    check_positive("integrator.dt", settings.dt)?;
    check_positive("record_period", settings.record_period)?;
    check_positive("limits.max_modal_error", settings.max_joint_error)?;
    if settings.dt > settings.period {
        return Err(SimError::setting(
            "integrator.dt",
            format!(
                "must be at most the controller period {} s, got {}",
                Compact(settings.period),
                Compact(settings.dt)
            ),
        ));
    }
    let checked: &[(&str, &Vec<f64>)] = if gains {
        &[
            ("controller.kp", &settings.kp),
            ("controller.kd", &settings.kd),
        ]
    } else {
        &[]
    };
    for &(name, gains) in checked {
        if gains.len() != n {
            return Err(SimError::setting(
                name,
                format!("has {} entries, expected one per joint ({n})", gains.len()),
            ));
        }
        for &g in gains.iter() {
            check_positive(name, g)?;
        }
    }
    check_joint_limits(settings, n)?;
    let periods = (settings.duration / settings.period).ceil();
    let steps = periods * (settings.period / settings.dt).ceil();
    let recorded = (periods / (settings.record_period / settings.period).round().max(1.0) + 2.0)
        * (3 * n) as f64;
    if periods >= MAX_CONTROLLER_SAMPLES
        || steps > MAX_RK4_STEPS
        || recorded > MAX_RECORDED_VALUES as f64
    {
        return Err(SimError::setting(
            "duration",
            format!(
                "= {} s takes {} controller samples and {} RK4 steps recording {} values, \
                 past the loop's limits ({MAX_CONTROLLER_SAMPLES}, \
                 {MAX_RK4_STEPS}, {MAX_RECORDED_VALUES})",
                Compact(settings.duration),
                Compact(periods),
                Compact(steps),
                Compact(recorded)
            ),
        ));
    }
    check_chain_work(settings, n, (periods, steps), controller_work)?;
    Ok(periods as usize)
}

/// Checks the per-joint limits and damping: each list empty or one entry per joint, efforts
/// positive (infinity allowed), ranges ordered and not NaN, damping non-negative and finite.
fn check_joint_limits(settings: &ChainLoopSettings, n: usize) -> Result<(), SimError> {
    for (name, len) in [
        ("effort limits", settings.effort_limits.len()),
        ("position limits", settings.position_limits.len()),
        ("damping", settings.damping.len()),
    ] {
        if len != 0 && len != n {
            return Err(SimError::setting(
                name,
                format!("has {len} entries, expected one per joint ({n}) or none"),
            ));
        }
    }
    let joint =
        |i: usize, what: String| SimError::setting("arm.urdf", format!("joint {}: {what}", i + 1));
    for (i, &limit) in settings.effort_limits.iter().enumerate() {
        if limit.is_nan() || limit <= 0.0 {
            return Err(joint(
                i,
                format!("effort limit must be positive, got {limit}"),
            ));
        }
    }
    for (i, &[lower, upper]) in settings.position_limits.iter().enumerate() {
        if lower.is_nan() || upper.is_nan() || lower > upper {
            return Err(joint(
                i,
                format!("position limits must be ordered, got [{lower}, {upper}]"),
            ));
        }
    }
    for (i, &damping) in settings.damping.iter().enumerate() {
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(joint(
                i,
                format!("damping must be non-negative and finite, got {damping}"),
            ));
        }
    }
    Ok(())
}

/// Refuses joint values outside their position limits: the first joint of `values` (at time
/// `t`, as `what`) beyond its range.
fn check_within_range(
    limits: &[[f64; 2]],
    values: &[f64],
    t: f64,
    what: &str,
) -> Result<(), SimError> {
    let outside = limits
        .iter()
        .zip(values)
        .position(|(&[lower, upper], &x)| !(lower <= x && x <= upper));
    match outside {
        None => Ok(()),
        Some(i) => {
            let [lower, upper] = limits[i];
            Err(SimError::setting(
                what,
                format!(
                    "sets joint {} to {} at t = {} s, outside its position limits [{}, {}] \
                     (the URDF's <limit>)",
                    i + 1,
                    Compact(values[i]),
                    Compact(t),
                    Compact(lower),
                    Compact(upper)
                ),
            ))
        }
    }
}

/// The work of one joint in one articulated-body evaluation of the plant, in the units of
/// [`MAX_RUN_WORK`] (multiply-adds of about 0.7 ns): measured 0.5-1 us a joint and RK4 step
/// (four evaluations) for chains of 7 and 4,096 joints, where 4 x 256 units are 0.7 us.
const ABA_JOINT_WORK: f64 = 256.0;

/// The work of one joint in the computed-torque law's RNEA at a controller sample, in
/// [`MAX_RUN_WORK`]'s units.
const RNEA_JOINT_WORK: f64 = 128.0;

/// Refuses a run whose estimated work exceeds [`MAX_RUN_WORK`] (as the modal loop's runs are):
/// four articulated-body evaluations of `n` joints an RK4 step, the computed-torque law's RNEA
/// at every controller sample, and the MPC's solves (`controller_work`, 0 for computed torque).
fn check_chain_work(
    settings: &ChainLoopSettings,
    n: usize,
    (periods, steps): (f64, f64),
    controller_work: f64,
) -> Result<(), SimError> {
    let joints = n as f64;
    let (plant, law) = (
        4.0 * steps * joints * ABA_JOINT_WORK,
        (periods + 1.0) * joints * RNEA_JOINT_WORK,
    );
    let work = plant + law + controller_work;
    if work <= MAX_RUN_WORK {
        return Ok(());
    }
    let controller = if controller_work > 0.0 {
        format!(", {controller_work:.2e} of the MPC's solves")
    } else {
        format!(", {law:.2e} of the control law")
    };
    let parts = format!(
        "{plant:.2e} for {} RK4 steps of the {n}-joint chain{controller}",
        Compact(steps)
    );
    Err(run_work_refusal(
        settings.duration,
        work,
        &parts,
        "a longer integrator.dt or fewer joints",
    ))
}

/// Runs computed torque on `model` from rest at `q0` (one value per joint), tracking
/// `reference` (one coordinate per joint).
///
/// # Errors
/// [`SimError::InvalidSetting`] for a setting out of its domain (named as in a scenario file) or
/// a reference or `q0` of the wrong length; [`SimError::ChainDynamics`] if the dynamics fail at
/// a controller sample, [`SimError::ChainIntegration`] if they fail or blow up between two,
/// [`SimError::JointRunaway`] past `max_joint_error`; each in a [`ChainFailure`] with the run up
/// to the stop when it stopped after its first controller sample.
pub fn run_chain_loop(
    model: &SpatialModel,
    reference: &mut dyn Reference,
    q0: &[f64],
    settings: &ChainLoopSettings,
) -> Result<ChainRun, ChainFailure> {
    run(model, reference, q0, settings, None)
}

/// Runs [`run_chain_loop`]'s loop with `mpc` in place of computed torque: at each controller
/// sample the effort is `mpc`'s ([`ChainMpcController::command`]); `settings.kp` and
/// `settings.kd` are not used.
///
/// # Errors
/// As [`run_chain_loop`]; [`SimError::Controller`] when the MPC fails at a sample.
pub fn run_chain_loop_mpc(
    model: &SpatialModel,
    reference: &mut dyn Reference,
    q0: &[f64],
    settings: &ChainLoopSettings,
    mpc: &mut ChainMpcController,
) -> Result<ChainRun, ChainFailure> {
    run(model, reference, q0, settings, Some(mpc))
}

/// The loop, with computed torque (`mpc` = `None`) or `mpc`.
fn run(
    model: &SpatialModel,
    reference: &mut dyn Reference,
    q0: &[f64],
    settings: &ChainLoopSettings,
    mut mpc: Option<&mut ChainMpcController>,
) -> Result<ChainRun, ChainFailure> {
    let n = model.n_links();
    let controller_work = mpc
        .as_deref()
        .map_or(0.0, |mpc| mpc.work(settings.duration));
    let periods = check(settings, n, mpc.is_none(), controller_work)?;
    if reference.n_coords() != n {
        return Err(SimError::setting(
            "reference",
            format!(
                "sets {} coordinates, expected one per joint of the URDF arm ({n})",
                reference.n_coords()
            ),
        )
        .into());
    }
    if q0.len() != n {
        return Err(SimError::setting(
            "initial.a",
            format!("has {} entries, expected one per joint ({n})", q0.len()),
        )
        .into());
    }
    check_all_finite("initial.a", q0).map_err(SimError::from)?;
    check_within_range(&settings.position_limits, q0, 0.0, "initial.a")?;
    let mut data = SpatialData::new(model);
    let mut rk4 = Rk4::new(2 * n);
    let mut state = vec![0.0; 2 * n];
    state[..n].copy_from_slice(q0);
    let mut sample = ReferenceSample::zeros(n);
    let (mut command, mut tau) = (vec![0.0; n], vec![0.0; n]);
    let mut applied = vec![0.0; n];
    let mut limited_samples = 0usize;
    let mut record = ChainRecord::default();
    let mut squares = vec![0.0; n];
    let mut summary = ChainSummary {
        controller_samples: 0,
        steps: 0,
        joint_error_rms: vec![0.0; n],
        joint_error_max: vec![0.0; n],
        final_error: 0.0,
        peak_joint_efforts: vec![0.0; n],
        effort_limited_share: 0.0,
    };
    let every = ((settings.record_period / settings.period).round() as usize).max(1);
    // The recorded samples (every `every`-th and the last), reserved once: the loop allocates
    // nothing per step (bounded by `check`).
    let samples = periods / every + 2;
    record.t.reserve_exact(samples);
    for values in [&mut record.q, &mut record.q_ref, &mut record.tau] {
        values.reserve_exact(samples * n);
    }
    // The samples, into `record` and `summary` (those up to a stop are kept).
    let mut samples_of = || -> Result<(), SimError> {
        for k in 0..=periods {
            let t = (k as f64 * settings.period).min(settings.duration);
            reference.sample(t, &mut sample)?;
            check_within_range(&settings.position_limits, &sample.a, t, "reference")?;
            let (q, v) = state.split_at(n);
            for (i, (r, x)) in sample.a.iter().zip(q).enumerate() {
                let error = r - x;
                if error.abs() > settings.max_joint_error || !error.is_finite() {
                    return Err(SimError::JointRunaway {
                        t,
                        joint: i + 1,
                        error: error.abs(),
                        bound: settings.max_joint_error,
                    });
                }
            }
            match mpc.as_deref_mut() {
                None => {
                    for i in 0..n {
                        command[i] = sample.a_ddot[i]
                            + settings.kd[i] * (sample.a_dot[i] - v[i])
                            + settings.kp[i] * (sample.a[i] - q[i]);
                    }
                    rnea(model, &mut data, q, v, &command, &mut tau)
                        .map_err(|source| SimError::ChainDynamics { t, source })?;
                }
                Some(mpc) => mpc
                    .command(model, t, q, v, &sample, &mut tau)
                    .map_err(|error| SimError::from_controller(t, error))?,
            }
            summary.controller_samples += 1;
            let mut limited = false;
            for (effort, &limit) in tau.iter_mut().zip(&settings.effort_limits) {
                if effort.abs() > limit {
                    *effort = effort.clamp(-limit, limit);
                    limited = true;
                }
            }
            limited_samples += usize::from(limited);
            for (peak, effort) in summary.peak_joint_efforts.iter_mut().zip(&tau) {
                *peak = peak.max(effort.abs());
            }
            if k % every == 0 || k == periods {
                record.t.push(t);
                record.q.extend_from_slice(q);
                record.q_ref.extend_from_slice(&sample.a);
                record.tau.extend_from_slice(&tau);
                for i in 0..n {
                    let error = (q[i] - sample.a[i]).abs();
                    squares[i] += error * error;
                    summary.joint_error_max[i] = summary.joint_error_max[i].max(error);
                }
            }
            if k == periods {
                summary.final_error = q
                    .iter()
                    .zip(&sample.a)
                    .map(|(x, r)| (x - r).powi(2))
                    .sum::<f64>()
                    .sqrt();
                break;
            }
            let t1 = ((k + 1) as f64 * settings.period).min(settings.duration);
            let mut plant = Plant {
                model,
                data: &mut data,
                tau: &tau,
                damping: &settings.damping,
                applied: &mut applied,
            };
            let stats = rk4
                .integrate(&mut plant, t, t1, &mut state, settings.dt)
                .map_err(|source| SimError::ChainIntegration {
                    tau: tau.clone(),
                    source,
                })?;
            summary.steps += stats.accepted;
        }
        Ok(())
    };
    let outcome = samples_of();
    if summary.controller_samples > 0 {
        summary.effort_limited_share = limited_samples as f64 / summary.controller_samples as f64;
    }
    let samples = record.t.len();
    for (rms, square) in summary.joint_error_rms.iter_mut().zip(&squares) {
        *rms = (square / samples as f64).sqrt();
    }
    match outcome {
        Ok(()) => Ok(ChainRun { summary, record }),
        Err(error) => {
            let partial = (samples > 0).then(|| {
                let last = (samples - 1) * n..samples * n;
                summary.final_error = record.q[last.clone()]
                    .iter()
                    .zip(&record.q_ref[last])
                    .map(|(x, r)| (x - r).powi(2))
                    .sum::<f64>()
                    .sqrt();
                Box::new(ChainRun { summary, record })
            });
            Err(ChainFailure { error, partial })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::{Sinusoid, Step};
    use manip_dyn::spatial::{SpatialJoint, SpatialLink, Transform};

    /// Seven joints alternating yaw, pitch and roll, 0.15 m apart, under ROS gravity.
    fn arm() -> SpatialModel {
        let axes = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
        let joints = (0..7)
            .map(|i| {
                let offset = if i == 0 { 0.0 } else { 0.15 };
                SpatialJoint::revolute(axes[i % 3], Transform::translation([offset, 0.0, 0.0]))
            })
            .collect();
        let links = (0..7)
            .map(|i| {
                SpatialLink::cuboid(1.0 - 0.1 * i as f64, [0.15, 0.04, 0.04], [0.075, 0.0, 0.0])
            })
            .collect();
        SpatialModel::new(joints, links, [0.0, 0.0, -9.81]).unwrap()
    }

    fn settings(n: usize) -> ChainLoopSettings {
        ChainLoopSettings {
            duration: 1.0,
            period: 1e-4,
            dt: 1e-4,
            record_period: 1e-4,
            kp: vec![400.0; n],
            kd: vec![40.0; n],
            max_joint_error: 3.0,
            effort_limits: Vec::new(),
            position_limits: Vec::new(),
            damping: Vec::new(),
        }
    }

    #[test]
    fn a_step_converges_at_the_closed_loop_rate() {
        let model = arm();
        let target = [0.3, -0.2, 0.1, 0.4, -0.3, 0.2, 0.1];
        let mut step = Step::new(&[0.0; 7], &target, 0.0).unwrap();
        let run = run_chain_loop(&model, &mut step, &[0.0; 7], &settings(7)).unwrap();
        // e'' + 40 e' + 400 e = 0 from e(0) = target: e(t) = e0 (1 + 20 t) exp(-20 t), 2e-8 of
        // it at t = 1 s; the zero-order hold of the torque over 0.1 ms adds O(1e-3) relative.
        let e0 = target.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(
            run.summary.final_error < 1e-6 * e0,
            "{}",
            run.summary.final_error
        );
        let at = |t: f64| {
            let k = (t / 1e-4).round() as usize;
            (0..7)
                .map(|i| (run.record.q[7 * k + i] - target[i]).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        let exact = |t: f64| e0 * (1.0 + 20.0 * t) * (-20.0 * t).exp();
        for t in [0.05, 0.1, 0.2] {
            assert!(
                (at(t) - exact(t)).abs() < 1e-2 * exact(t),
                "t = {t}: {} vs {}",
                at(t),
                exact(t)
            );
        }
        assert_eq!(run.summary.controller_samples, 10001);
        assert_eq!(run.summary.steps, 10000);
        assert_eq!(run.record.t.len(), 10001);
    }

    #[test]
    fn a_sine_is_tracked() {
        let model = arm();
        let mut sine = Sinusoid::new(&[0.0; 7], &[0.2; 7], &[1.0; 7], &[0.0; 7]).unwrap();
        let run = run_chain_loop(&model, &mut sine, &[0.0; 7], &settings(7)).unwrap();
        // Starting at rest on the reference as it moves at v0 = 0.4 pi rad/s: the error
        // e = -v0 t exp(-20 t) peaks at v0 / (20 e) at t = 50 ms, then only the zero-order hold's
        // O(period) lag remains.
        let peak = 0.4 * std::f64::consts::PI / (20.0 * std::f64::consts::E);
        for e in &run.summary.joint_error_max {
            assert!((e - peak).abs() < 0.02 * peak, "{:?}", run.summary);
        }
        assert!(
            run.summary.final_error < 3e-3,
            "{}",
            run.summary.final_error
        );
    }

    #[test]
    fn a_run_that_stops_keeps_its_samples_up_to_the_stop() {
        let model = arm();
        let target = [0.3, -0.2, 0.1, 0.4, -0.3, 0.2, 0.1];
        let mut s = settings(7);
        s.max_joint_error = 0.35;
        s.record_period = 1e-2;
        // The step at t = 0.25 s puts joint 4 beyond the bound at once.
        let mut step = Step::new(&[0.0; 7], &target, 0.25).unwrap();
        let failure = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        assert!(
            matches!(failure.error, SimError::JointRunaway { joint: 4, t, .. } if (t - 0.25).abs() < 1e-12),
            "{:?}",
            failure.error
        );
        assert_eq!(failure.to_string(), failure.error.to_string());
        let run = failure.partial.expect("samples before the stop");
        // Every 100th controller sample of the 2500 before the step.
        assert_eq!(run.record.t.len(), 25);
        assert!((run.record.t[24] - 0.24).abs() < 1e-12);
        assert_eq!(run.record.q.len(), 25 * 7);
        assert_eq!(run.summary.controller_samples, 2500);
        // At rest on a zero reference before the step: the errors over the samples are zero.
        assert!(run.summary.joint_error_max.iter().all(|e| *e < 1e-12));
        assert!(run.summary.final_error < 1e-12);
    }

    #[test]
    fn a_runaway_joint_is_named_in_joint_terms() {
        let model = arm();
        let target = [0.3, -0.2, 0.1, 0.4, -0.3, 0.2, 0.1];
        let mut step = Step::new(&[0.0; 7], &target, 0.0).unwrap();
        let mut s = settings(7);
        s.max_joint_error = 0.35;
        let failure = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        // Joint 4's step of 0.4 rad is beyond the bound at once: nothing was recorded.
        assert_eq!(failure.partial, None);
        let e = failure.error;
        assert!(
            matches!(
                e,
                SimError::JointRunaway {
                    t: 0.0,
                    joint: 4,
                    bound: 0.35,
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(
            e.to_string()
                .starts_with("runaway tracking error at t = 0 s: |q4 - q4_ref| = 0.4 exceeds"),
            "{e}"
        );
    }

    #[test]
    fn bad_settings_are_named() {
        let model = arm();
        let mut step = Step::constant(&[0.0; 7]).unwrap();
        let mut s = settings(7);
        s.kp.pop();
        let e = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        assert!(
            e.to_string().starts_with("controller.kp has 6 entries"),
            "{e}"
        );
        let mut s = settings(7);
        s.dt = 1e-2;
        let e = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        assert!(
            e.to_string().starts_with("integrator.dt must be at most"),
            "{e}"
        );
        let mut short = Step::constant(&[0.0; 3]).unwrap();
        let e = run_chain_loop(&model, &mut short, &[0.0; 7], &settings(7)).unwrap_err();
        assert!(e.to_string().contains("one per joint"), "{e}");
        let mut s = settings(7);
        s.duration = 1e12;
        let e = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        assert!(e.to_string().contains("past the loop's limits"), "{e}");
    }

    #[test]
    fn efforts_saturate_at_their_limits() {
        let model = arm();
        let target = [0.3, -0.2, 0.1, 0.4, -0.3, 0.2, 0.1];
        let mut step = Step::new(&[0.0; 7], &target, 0.0).unwrap();
        let free = run_chain_loop(&model, &mut step, &[0.0; 7], &settings(7)).unwrap();
        assert_eq!(free.summary.effort_limited_share, 0.0);
        // 90% of the second joint's free peak (the others free): the step's first samples
        // saturate, the hold does not.
        let mut s = settings(7);
        s.effort_limits = vec![f64::INFINITY; 7];
        s.effort_limits[1] = 0.9 * free.summary.peak_joint_efforts[1];
        let mut step = Step::new(&[0.0; 7], &target, 0.0).unwrap();
        let limited = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap();
        let share = limited.summary.effort_limited_share;
        assert!(share > 0.0 && share < 0.5, "{share}");
        for ((peak, limit), tau) in limited
            .summary
            .peak_joint_efforts
            .iter()
            .zip(&s.effort_limits)
            .zip(limited.record.tau.chunks_exact(7).flat_map(|t| t.iter()))
        {
            assert!(
                *peak <= *limit && tau.abs() <= *limit,
                "{peak} {limit} {tau}"
            );
        }
        // Within its limits the arm moves otherwise but still gets there.
        assert!(limited.summary.final_error < 1e-3, "{:?}", limited.summary);
        assert_ne!(limited.record.q, free.record.q);
    }

    #[test]
    fn damping_opposes_each_joint_rate() {
        let model = arm();
        let (q, v) = (
            [0.2, -0.1, 0.3, 0.0, 0.5, -0.4, 0.1],
            [1.0, -2.0, 0.5, 3.0, -1.0, 0.2, 2.0],
        );
        let tau = [1.0, 2.0, -1.0, 0.5, 0.2, -0.3, 0.1];
        let damping = [0.5, 1.0, 2.0, 0.0, 0.3, 0.1, 4.0];
        let mut data = SpatialData::new(&model);
        let mut applied = [0.0; 7];
        let mut plant = Plant {
            model: &model,
            data: &mut data,
            tau: &tau,
            damping: &damping,
            applied: &mut applied,
        };
        let y: Vec<f64> = q.iter().chain(&v).copied().collect();
        let mut dy = [0.0; 14];
        plant.rhs(0.0, &y, &mut dy).unwrap();
        // The same as the undamped plant under tau - damping v.
        let damped: Vec<f64> = (0..7).map(|i| tau[i] - damping[i] * v[i]).collect();
        let mut expected = [0.0; 7];
        aba(
            &model,
            &mut SpatialData::new(&model),
            &q,
            &v,
            &damped,
            &mut expected,
        )
        .unwrap();
        assert_eq!(&dy[..7], &v);
        assert_eq!(&dy[7..], &expected);
        // Under gravity compensation alone the undamped arm holds still; the damping is
        // not in the controller's model, so the damped arm's run differs.
        let mut s = settings(7);
        (s.kp, s.kd) = (vec![1e-6; 7], vec![1e-6; 7]);
        s.duration = 0.5;
        s.damping = vec![1e-3; 7];
        let mut hold = Step::constant(&[0.3; 7]).unwrap();
        let run = run_chain_loop(&model, &mut hold, &[0.0; 7], &s).unwrap();
        s.damping.clear();
        let mut hold = Step::constant(&[0.3; 7]).unwrap();
        let free = run_chain_loop(&model, &mut hold, &[0.0; 7], &s).unwrap();
        assert_ne!(run.record.q, free.record.q);
    }

    #[test]
    fn references_outside_the_position_limits_stop_the_run() {
        let model = arm();
        let mut s = settings(7);
        s.position_limits = vec![[-1.0, 1.0]; 7];
        s.position_limits[3] = [-0.2, 0.2];
        let mut step = Step::new(&[0.0; 7], &[0.1, 0.1, 0.1, 0.3, 0.1, 0.1, 0.1], 0.1).unwrap();
        let e = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        assert_eq!(
            e.to_string(),
            "reference sets joint 4 to 0.3 at t = 0.1 s, outside its position limits [-0.2, \
             0.2] (the URDF's <limit>)"
        );
        // The run up to the stop is kept.
        assert!(e.partial.is_some_and(|run| run.record.t.len() == 1000));
        let mut inside = Step::constant(&[0.0; 7]).unwrap();
        let e = run_chain_loop(
            &model,
            &mut inside,
            &[0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0],
            &s,
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("initial.a sets joint 4 to 0.5 at t = 0 s"),
            "{e}"
        );
        // Limits out of their domain are named.
        s.position_limits[2] = [1.0, -1.0];
        let e = run_chain_loop(&model, &mut inside, &[0.0; 7], &s).unwrap_err();
        assert!(
            e.to_string()
                .contains("joint 3: position limits must be ordered"),
            "{e}"
        );
        let mut s = settings(7);
        s.effort_limits = vec![0.0; 7];
        let e = run_chain_loop(&model, &mut inside, &[0.0; 7], &s).unwrap_err();
        assert!(
            e.to_string()
                .contains("joint 1: effort limit must be positive"),
            "{e}"
        );
    }

    #[test]
    fn runs_of_hours_are_refused_up_front() {
        let model = arm();
        let mut step = Step::constant(&[0.0; 7]).unwrap();
        // 5e8 RK4 steps of seven joints: within each count's own bound, about an hour in all.
        let mut s = settings(7);
        (s.duration, s.record_period) = (5e4, 100.0);
        let e = run_chain_loop(&model, &mut step, &[0.0; 7], &s).unwrap_err();
        let message = e.to_string();
        assert!(
            message.starts_with("duration = 50000 s would take an estimated"),
            "{e}"
        );
        assert!(message.contains("the 7-joint chain"), "{e}");
        assert!(!message.contains('\n'), "{e}");
        // A fiftieth of it (about a minute) runs as before: checked here up to the work bound,
        // not run.
        s.duration = 1e3;
        let periods = (s.duration / s.period).ceil();
        assert!(check(&s, 7, true, 0.0).is_ok_and(|k| k as f64 == periods));
    }
}
