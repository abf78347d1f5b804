//! The closed loop of the paper's Figures 6 and 8: reference -> controller -> modal torques ->
//! reduced dynamics (eq 15) -> state, with the controller sampled at its own period and its
//! output held in between (zero-order hold).

use crate::controller::{ControlContext, Controller, ModalState};
use crate::error::{SimError, check_non_negative, check_positive};
use crate::noise::GaussianNoise;
use crate::ode::{DormandPrince, MAX_RK4_STEPS, OdeSystem, Rk4, Stats, Tolerances};
use crate::record::{Metrics, Record, Sample, Summary};
use crate::reference::continuation::Family;
use crate::reference::{Reference, ReferenceSample};
use backbone_kin::BaseAngle;
use clearance::{ClearanceData, ClearanceModel};
use lane_math::Compact;
use lane_math::check_all_finite;
use limits::LimitProjection;
use modal_reduce::{Plant, PlantData, PlantModel, ReduceError};
use std::sync::Arc;

mod hooks;
mod limits;
mod lockstep;
mod prepared;

pub use hooks::{LoopHooks, NoHooks};
pub use limits::JOINT_ANGLE_APPROACH_S;
pub use lockstep::Lockstep;
pub use prepared::{ControllerFactory, Prepared, ReferenceFactory, RunNoise};

/// ChaCha streams of the two noise sources, so that each has its own sequence.
const REFERENCE_NOISE_STREAM: u64 = 1;
const SENSOR_NOISE_STREAM: u64 = 2;
/// How close to a whole number a ratio of periods must be (relative).
const PERIOD_SLACK: f64 = 1e-9;

/// How the dynamics are integrated between two controller samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Fixed-step RK4 with step `dt` (s); the controller period must be a whole number of steps.
    Rk4 {
        /// The step (s).
        dt: f64,
    },
    /// Adaptive Dormand-Prince 5(4) with error control, restarted at every sample (its step size
    /// carries over).
    DormandPrince(Tolerances),
}

/// The settings of a closed-loop run.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopSettings {
    /// The integrator between controller samples.
    pub integrator: Integrator,
    /// Controller sampling period (s).
    pub controller_period: f64,
    /// Simulated time (s): a whole number of controller periods.
    pub duration: f64,
    /// Recording period (s): a whole number of controller periods. The summary's tracking errors
    /// (RMS and maxima) are taken over the recorded samples; its torque peaks, limit checks and
    /// clamped fractions, and the runaway check, over every controller sample.
    pub record_period: f64,
    /// Seed of the noise sources.
    pub seed: u64,
    /// Standard deviation of the Gaussian noise added to the reference `a_ref` at each sample
    /// (rad): `m` entries, or none for no noise.
    pub reference_noise_std: Vec<f64>,
    /// Standard deviation of the Gaussian sensor noise on the measured `(a, a_dot)` (rad, rad/s):
    /// `2m` entries (the `m` coordinates, then the `m` rates), or none for no noise.
    pub sensor_noise_std: Vec<f64>,
    /// A run stops with [`SimError::RunawayError`] when `|a_i - a_i_ref|` exceeds this (rad).
    pub max_modal_error: f64,
    /// Optional per-joint torque limits (N m), enforced: at every controller sample the
    /// (saturated) `tau*` is projected onto the modal torques whose joint torques at the
    /// sample's state are within them (`docs/theory.md`, "Enforced joint limits"); the summary
    /// reports how often the projection acted and checks the joint torques at every sample.
    pub joint_torque_limits: Option<Vec<f64>>,
    /// Optional per-joint angle limits (rad, `|theta_j| <= limit_j`, `theta = J a + theta_0`),
    /// enforced in the same projection: every joint's predicted rate at the next sample is kept
    /// at most `(limit_j - theta_j) / T` towards its limit ([`JOINT_ANGLE_APPROACH_S`]). The
    /// initial state must be within them.
    pub joint_angle_limits: Option<Vec<f64>>,
    /// Optional limits on the modal forces `tau*` (N m, `m` entries, finite and positive; not joint torques):
    /// every controller's output is clamped to `[-limit_i, limit_i]` before it is applied
    /// (the clamped torque is what is held, recorded and summed into the effort), and each
    /// sample records which coordinates were clamped. Controllers see them in
    /// [`ControlContext::tau_star_limits`].
    pub tau_star_limits: Option<Vec<f64>>,
    /// Optional links and obstacles: the arm's clearance to the obstacles and to itself is
    /// measured at every controller sample, and its smallest values reported in the summary.
    pub clearance: Option<ClearanceModel>,
}

impl LoopSettings {
    /// The controller samples a run of these settings takes: one at every whole controller
    /// period and the final one (what a [`LoopHooks`] observer sees; 1 for settings whose
    /// duration is not a whole number of periods, which [`check`](Self::check) refuses).
    pub fn controller_samples(&self) -> usize {
        sample_counts(self).0 + 1
    }

    /// Checks the settings for `plant` as [`Simulation::new`] does, before a reference or a
    /// controller exists: their sizes, bounds and the run's work without the controller's own
    /// (so that a front end refuses a run of hours before it plans its reference).
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the setting.
    pub fn check(&self, plant: Plant<'_>) -> Result<(), SimError> {
        validate(self, plant)
    }

    /// Settings without noise or limits, recording every sample, with a runaway bound of pi rad.
    pub fn new(integrator: Integrator, controller_period: f64, duration: f64) -> Self {
        Self {
            integrator,
            controller_period,
            duration,
            record_period: controller_period,
            seed: 0,
            reference_noise_std: Vec::new(),
            sensor_noise_std: Vec::new(),
            max_modal_error: std::f64::consts::PI,
            joint_torque_limits: None,
            joint_angle_limits: None,
            tau_star_limits: None,
            clearance: None,
        }
    }
}

/// A completed run.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// The time series.
    pub record: Record,
    /// The metrics.
    pub summary: Summary,
}

/// A run that had to stop, with everything recorded before it did.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error} (data kept up to t = {} s)", Compact(summary.simulated_s))]
pub struct RunFailure {
    /// Why and when the run stopped.
    pub error: SimError,
    /// The time series up to the last good sample.
    pub record: Record,
    /// The metrics up to the last good sample.
    pub summary: Summary,
}

/// A run in progress: what [`Simulation::run`] accumulates sample by sample.
struct Progress {
    record: Record,
    metrics: Metrics,
    /// Accepted and rejected integrator steps so far.
    steps: usize,
    rejected: usize,
    /// The controller samples of the run after the first, and how many make one recording
    /// period.
    samples: usize,
    record_every: usize,
}

impl Progress {
    /// The run stopped by `error`, with what was recorded so far.
    fn fail(self, error: SimError) -> Box<RunFailure> {
        Box::new(RunFailure {
            error,
            summary: self.metrics.summary(self.steps, self.rejected),
            record: self.record,
        })
    }

    /// The completed run.
    fn finish(self) -> Run {
        Run {
            summary: self.metrics.summary(self.steps, self.rejected),
            record: self.record,
        }
    }
}

/// The reduced dynamics (planar or spatial) with a held modal torque: `y = [a, a_dot]` (`2m`
/// entries).
struct Dynamics {
    model: Arc<PlantModel>,
    data: PlantData,
    tau_star: Vec<f64>,
}

impl OdeSystem for Dynamics {
    type Error = ReduceError;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), ReduceError> {
        let m = self.tau_star.len();
        dy[..m].copy_from_slice(&y[m..]);
        self.model.plant().forward_dynamics(
            &mut self.data,
            &y[..m],
            &y[m..],
            &self.tau_star,
            &mut dy[m..],
        )
    }
}

/// Where the tips come from: for a planar arm the chain's tip and the backbone curve's end at
/// the reference (eqs 3-4); for a spatial arm the chain's tip at the state and at the reference
/// (the spatial curve has no closed form, and the continuation tracks the chain's tip).
/// Either places the chain's `n + 1` points, from which the tip is the last.
struct Tips {
    kind: TipKind,
    /// The chain's points at the state placed last, base to tip (`z = 0` in the plane).
    points: Vec<[f64; 3]>,
}

enum TipKind {
    Planar {
        family: Box<Family>,
        link_lengths: Vec<f64>,
        theta: Vec<f64>,
        planar: Vec<[f64; 2]>,
    },
    Spatial {
        theta: Vec<f64>,
    },
}

impl Tips {
    fn new(model: &PlantModel) -> Result<Self, SimError> {
        let kind = match model {
            PlantModel::Planar(model) => {
                let link_lengths: Vec<f64> = model.chain().link_lengths().collect();
                let curve_length = link_lengths.iter().sum();
                let map = model.map();
                let fixed = match map.base_angle() {
                    BaseAngle::Fixed(alpha0) => Some(alpha0),
                    BaseAngle::Free => None,
                };
                TipKind::Planar {
                    family: Box::new(Family::new(curve_length, map.harmonics(), fixed)?),
                    link_lengths,
                    theta: vec![0.0; model.n_links()],
                    planar: vec![[0.0; 2]; model.n_links() + 1],
                }
            }
            PlantModel::Spatial(model) => TipKind::Spatial {
                theta: vec![0.0; 2 * model.n_links()],
            },
        };
        Ok(Self {
            kind,
            points: vec![[0.0; 3]; model.plant().n_links() + 1],
        })
    }

    /// Places the chain at `a` into [`points`](Self::points): through the same forward
    /// kinematics as its tip, so that the last point is the tip bit for bit.
    fn place(&mut self, model: &PlantModel, a: &[f64]) -> Result<(), SimError> {
        match (&mut self.kind, model) {
            (
                TipKind::Planar {
                    link_lengths,
                    theta,
                    planar,
                    ..
                },
                PlantModel::Planar(model),
            ) => {
                model.map().joint_angles(a, theta)?;
                backbone_kin::joint_positions(link_lengths, theta, planar)?;
                for (point, p) in self.points.iter_mut().zip(planar.iter()) {
                    *point = [p[0], p[1], 0.0];
                }
            }
            (TipKind::Spatial { theta }, PlantModel::Spatial(model)) => {
                let map = model.map();
                map.joint_angles(a, theta)?;
                backbone_kin::spatial_joint_positions(
                    map.link_lengths(),
                    model.base(),
                    theta,
                    &mut self.points,
                )?;
            }
            _ => unreachable!("the tips are built for the simulation's own model"),
        }
        Ok(())
    }

    /// The tip at `a` (the chain placed there, [`place`](Self::place)) and the reference tip
    /// at `a_ref`, `[x, y, z]` (`z = 0` in the plane).
    fn at(
        &mut self,
        model: &PlantModel,
        a: &[f64],
        a_ref: &[f64],
    ) -> Result<([f64; 3], [f64; 3]), SimError> {
        self.place(model, a)?;
        let tip = self.points[self.points.len() - 1];
        let tip_ref = match (&mut self.kind, model) {
            (TipKind::Planar { family, .. }, PlantModel::Planar(_)) => {
                let [x_ref, y_ref] = family.end_point(a_ref)?;
                [x_ref, y_ref, 0.0]
            }
            (TipKind::Spatial { theta }, PlantModel::Spatial(model)) => {
                let map = model.map();
                map.joint_angles(a_ref, theta)?;
                backbone_kin::spatial_tip_position(map.link_lengths(), model.base(), theta)?
            }
            _ => unreachable!("the tips are built for the simulation's own model"),
        };
        Ok((tip, tip_ref))
    }
}

/// The integrator with its workspace.
enum Stepper {
    Rk4(Rk4, f64),
    DormandPrince(DormandPrince),
}

impl Stepper {
    fn new(integrator: Integrator, dim: usize) -> Self {
        match integrator {
            Integrator::Rk4 { dt } => Stepper::Rk4(Rk4::new(dim), dt),
            Integrator::DormandPrince(tol) => Stepper::DormandPrince(DormandPrince::new(dim, tol)),
        }
    }
}

/// One controller sample: what the controller saw and did at time `t`. Its buffers are sized
/// when the simulation is built and reused at every sample.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlSample {
    /// The sample time (s).
    pub t: f64,
    /// The true state at `t`.
    pub state: ModalState,
    /// The noise-free reference at `t`.
    pub reference: ReferenceSample,
    /// The reference as the controller received it (reference noise on `a`).
    pub command: ReferenceSample,
    /// The state as the controller measured it (sensor noise included).
    pub measured: ModalState,
    /// The modal torques `tau*` held from `t` to the next sample (N m): the controller's
    /// output, clamped to the actuator limits if there are any.
    pub tau_star: Vec<f64>,
    /// The modal force `f = J^T tau_d` (N m, eqs 14-15) of the external joint torques `tau_d` a
    /// [`LoopHooks::disturbance`] applies from `t` to the next sample, on top of `tau*`; zeros
    /// without one.
    pub disturbance: Vec<f64>,
    /// Per coordinate, whether the actuator limit clamped the controller's output (all `false`
    /// without limits).
    pub clamped: Vec<bool>,
    /// The acceleration at `t` under `tau*` (rad/s^2): the integrator's first stage, or the
    /// forward dynamics for a sample that is not integrated.
    pub a_ddot: Vec<f64>,
    /// Accepted and rejected integrator steps from `t` to the next sample.
    pub steps: (usize, usize),
    /// Whether the enforced joint limits ([`LoopSettings::joint_torque_limits`],
    /// [`LoopSettings::joint_angle_limits`]) moved the controller's `tau*`.
    pub projected: bool,
}

impl ControlSample {
    fn zeros(m: usize) -> Self {
        Self {
            t: 0.0,
            state: ModalState::zeros(m),
            reference: ReferenceSample::zeros(m),
            command: ReferenceSample::zeros(m),
            measured: ModalState::zeros(m),
            tau_star: vec![0.0; m],
            disturbance: vec![0.0; m],
            clamped: vec![false; m],
            a_ddot: vec![0.0; m],
            steps: (0, 0),
            projected: false,
        }
    }
}

/// The recorded view of a controller sample ([`Simulation::observe`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation<'a> {
    /// Joint torques `tau = M J a_dd + C + G` (eq 13) at the sample (N m).
    pub joint_torques: &'a [f64],
    /// The tip of the discrete chain, `[x, y, z]` (m; `z = 0` for a planar arm).
    pub tip: [f64; 3],
    /// The reference tip at the noise-free reference (m): the backbone curve's end point for a
    /// planar arm, the chain's tip for a spatial one.
    pub tip_ref: [f64; 3],
}

/// A closed-loop simulation of `m` modal coordinates, built once and run any number of times
/// (each [`run`](Self::run) starts afresh from the initial state with the noise re-seeded).
///
/// A caller may also own the loop: [`step`](Self::step) takes one controller sample and
/// integrates one controller period, [`time`](Self::time) and [`state`](Self::state) give where
/// the loop is, [`last_sample`](Self::last_sample) and [`observe`](Self::observe) what happened
/// at the sample just taken, and [`reset`](Self::reset) starts over. [`run`](Self::run) is built
/// on these.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::ReducedModel;
/// use sim_core::controller::FuzzyController;
/// use sim_core::reference::Step;
/// use sim_core::{Integrator, LoopSettings, Simulation};
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2)?)?;
/// let reference = Step::new(&[0.0, 0.0], &[0.2, -0.1], 0.0)?;
/// let controller = FuzzyController::new(fuzzy_sugeno::paper_controller(), 2)?;
/// let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-4, 0.5);
/// let mut sim = Simulation::new(model, Box::new(reference), Box::new(controller), settings, None)?;
/// let run = sim.run()?;
/// assert_eq!(run.summary.controller_samples, 5001);
/// assert!(run.summary.modal_error_rms_rad[0] < 0.2);
///
/// // The same loop, stepped by hand for 0.1 s.
/// sim.reset();
/// while sim.time() < 0.1 - 1e-12 {
///     let sample = sim.step()?;
///     assert!(sample.tau_star.iter().all(|t| t.is_finite()));
/// }
/// assert_eq!(sim.samples_taken(), 1000);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Simulation {
    plant: Dynamics,
    reference: Box<dyn Reference>,
    controller: Box<dyn Controller>,
    settings: LoopSettings,
    initial: ModalState,
    /// The tips' geometry and the chain's points.
    tips: Tips,
    /// The projection onto the joint limits, with [`LoopSettings::joint_torque_limits`] or
    /// [`LoopSettings::joint_angle_limits`].
    limits: Option<LimitProjection>,
    /// The clearance's working memory, with [`LoopSettings::clearance`], and the joint axes
    /// it is placed with.
    clearance: Option<(ClearanceData, Vec<[f64; 3]>)>,
    joint_torques: Vec<f64>,
    /// Controller samples taken since the last reset.
    taken: usize,
    /// The state `[a, a_dot]` at the current time.
    y: Vec<f64>,
    /// The current state as a [`ModalState`] (kept in step with `y`).
    current: ModalState,
    stepper: Stepper,
    reference_noise: Option<GaussianNoise>,
    sensor_noise: Option<GaussianNoise>,
    /// Scratch for the measured `[a, a_dot]`.
    measured: Vec<f64>,
    sample: ControlSample,
    /// The external joint torques `tau_d` of the last [`LoopHooks::disturbance`] (`n` entries),
    /// and whether they act on the current sample.
    tau_disturbance: Vec<f64>,
    disturbed: bool,
    /// The run's estimated work ([`work`](Self::work)).
    work: f64,
}

impl Simulation {
    /// A closed loop of `model` (any modal family: `m = 2K` coordinates with `alpha0` fixed, or
    /// `2K + 1` with `alpha0` free) tracking `reference` with `controller`. `initial` defaults
    /// to rest at the reference's value at `t = 0`.
    ///
    /// Fails with [`SimError::InvalidSetting`] for a reference, controller, initial state, noise
    /// or torque limits whose size does not match the model, and for settings out of their
    /// domain: non-positive periods or duration, periods that are not whole multiples
    /// (controller period of the RK4 step, duration and recording period of the controller
    /// period), a duration of more than [`MAX_CONTROLLER_SAMPLES`] periods or [`MAX_RK4_STEPS`] RK4
    /// steps, a record of more than [`MAX_RECORDED_VALUES`] numbers, negative or non-finite noise, a non-positive error
    /// bound, or torque limits of the wrong sign.
    pub fn new(
        model: impl Into<PlantModel>,
        mut reference: Box<dyn Reference>,
        controller: Box<dyn Controller>,
        settings: LoopSettings,
        initial: Option<ModalState>,
    ) -> Result<Self, SimError> {
        let model = model.into();
        let plant = model.plant();
        let m = plant.n_coords();
        check_parts(reference.as_ref(), controller.as_ref(), m)?;
        validate(&settings, plant)?;
        let initial = initial_state(reference.as_mut(), initial, m)?;
        Self::assemble(Arc::new(model), reference, controller, settings, initial)
    }

    /// The simulation of checked parts: `settings` validated for `model`, `initial` of its size.
    /// Sizes the per-run buffers (the run's Data).
    fn assemble(
        model: Arc<PlantModel>,
        reference: Box<dyn Reference>,
        controller: Box<dyn Controller>,
        settings: LoopSettings,
        initial: ModalState,
    ) -> Result<Self, SimError> {
        let plant = model.plant();
        let (m, n) = (plant.n_coords(), plant.n_joints());
        let work = check_run_work(&settings, n, m, controller.work(settings.duration, n))?;
        let tips = Tips::new(&model)?;
        let mut limits = LimitProjection::new(
            plant,
            settings.joint_torque_limits.as_deref(),
            settings.joint_angle_limits.as_deref(),
            settings.tau_star_limits.as_deref(),
            settings.controller_period,
        )?;
        if let Some(limits) = &mut limits {
            limits.check_start(plant, &initial.a)?;
        }
        let clearance = match &settings.clearance {
            None => None,
            Some(c) => Some((
                ClearanceData::new(c, 0).map_err(|e| {
                    SimError::setting("obstacles", format!("cannot be measured: {e}"))
                })?,
                vec![[0.0, 0.0, 1.0]; c.n_links()],
            )),
        };
        let data = PlantData::try_new(plant).map_err(SimError::workspace)?;
        let stepper = Stepper::new(settings.integrator, 2 * m);
        let mut simulation = Self {
            plant: Dynamics {
                model,
                data,
                tau_star: vec![0.0; m],
            },
            reference,
            controller,
            settings,
            initial,
            tips,
            limits,
            clearance,
            joint_torques: vec![0.0; n],
            taken: 0,
            y: vec![0.0; 2 * m],
            current: ModalState::zeros(m),
            stepper,
            reference_noise: None,
            sensor_noise: None,
            measured: vec![0.0; 2 * m],
            sample: ControlSample::zeros(m),
            tau_disturbance: vec![0.0; n],
            disturbed: false,
            work,
        };
        simulation.reset();
        Ok(simulation)
    }

    /// The whole run's estimated work, in the units of [`MAX_RUN_WORK`] (which bounds it): what
    /// a caller running many simulations sums to bound them all.
    pub fn work(&self) -> f64 {
        self.work
    }

    /// The reduced model being simulated, planar or spatial.
    pub fn model(&self) -> Plant<'_> {
        self.plant.model.plant()
    }

    /// The settings of the loop.
    pub fn settings(&self) -> &LoopSettings {
        &self.settings
    }

    /// The initial state.
    pub fn initial_state(&self) -> &ModalState {
        &self.initial
    }

    /// The number of modal coordinates `m`.
    pub fn n_coords(&self) -> usize {
        self.plant.tau_star.len()
    }

    /// The current time: the time of the next controller sample (s).
    pub fn time(&self) -> f64 {
        self.taken as f64 * self.settings.controller_period
    }

    /// The controller samples taken since the last reset.
    pub fn samples_taken(&self) -> usize {
        self.taken
    }

    /// The true state at the current time.
    pub fn state(&self) -> &ModalState {
        &self.current
    }

    /// The controller sample taken last ([`ControlSample::t`] is its time); zeros before the
    /// first.
    pub fn last_sample(&self) -> &ControlSample {
        &self.sample
    }

    /// Back to the initial state at `t = 0`, with the noise re-seeded and the integrator
    /// restarted. Allocates the noise sources and the integrator's workspace (once per run).
    pub fn reset(&mut self) {
        let s = &self.settings;
        let m = self.n_coords();
        self.taken = 0;
        self.y[..m].copy_from_slice(&self.initial.a);
        self.y[m..].copy_from_slice(&self.initial.a_dot);
        self.current.a.copy_from_slice(&self.initial.a);
        self.current.a_dot.copy_from_slice(&self.initial.a_dot);
        self.stepper = Stepper::new(s.integrator, 2 * m);
        self.reference_noise =
            GaussianNoise::new(s.seed, REFERENCE_NOISE_STREAM, &s.reference_noise_std);
        self.sensor_noise = GaussianNoise::new(s.seed, SENSOR_NOISE_STREAM, &s.sensor_noise_std);
        self.sample = ControlSample::zeros(m);
        self.tau_disturbance.fill(0.0);
        self.disturbed = false;
    }

    /// Advances one controller period: takes the controller sample at the current time `t_k`
    /// (reference, noise, `tau*`), then integrates the dynamics to `t_{k+1}` with `tau*` held.
    /// Returns the sample taken (its state is the one at `t_k`).
    ///
    /// Fails if the reference, the controller or the integration fails, or the controller's
    /// torque is not finite; the simulation then stays at `t_k`.
    pub fn step(&mut self) -> Result<&ControlSample, SimError> {
        self.step_with(&mut NoHooks)
    }

    /// [`step`](Self::step) with `hooks`: their disturbance acts from `t_k` to `t_{k+1}` and
    /// their observer sees the sample once it is integrated.
    pub fn step_with<H: LoopHooks + ?Sized>(
        &mut self,
        hooks: &mut H,
    ) -> Result<&ControlSample, SimError> {
        self.take_sample(None, hooks)?;
        self.integrate()?;
        hooks.observe(&self.sample);
        Ok(&self.sample)
    }

    /// The joint torques `tau = M J a_dd + C + G` (eq 13), the chain's tip and the reference tip
    /// of the last sample. Allocation-free.
    pub fn observe(&mut self) -> Result<Observation<'_>, SimError> {
        self.sample_joint_torques()?;
        let (tip, tip_ref) = self.sample_tips()?;
        Ok(Observation {
            joint_torques: &self.joint_torques,
            tip,
            tip_ref,
        })
    }

    /// The joint torques of the last sample (eq 13) into `self.joint_torques`.
    fn sample_joint_torques(&mut self) -> Result<(), SimError> {
        let t = self.sample.t;
        let plant = &mut self.plant;
        let state = &self.sample.state;
        plant
            .model
            .plant()
            .joint_torques(
                &mut plant.data,
                &state.a,
                &state.a_dot,
                &self.sample.a_ddot,
                &mut self.joint_torques,
            )
            .map_err(|source| SimError::Dynamics { t, source })?;
        // The actuators deliver eq 13's torques less the push.
        if self.disturbed {
            for (tau, d) in self.joint_torques.iter_mut().zip(&self.tau_disturbance) {
                *tau -= d;
            }
        }
        Ok(())
    }

    /// The chain's tip and the reference tip of the last sample.
    fn sample_tips(&mut self) -> Result<([f64; 3], [f64; 3]), SimError> {
        self.tips.at(
            &self.plant.model,
            &self.sample.state.a,
            &self.sample.reference.a,
        )
    }

    /// Runs the loop from the initial state for the whole duration (it [`reset`](Self::reset)s
    /// first).
    ///
    /// At each controller sample `t_k = k * period` it samples the reference, adds the noise,
    /// asks the controller for `tau*`, checks the tracking error against the runaway bound and
    /// integrates the dynamics to `t_{k+1}` with `tau*` held ([`step`](Self::step)); the final
    /// sample is taken but not integrated. Every `record_period` it records the sample (state,
    /// reference, `tau*`, tips, joint torques `tau = M J a_dd + C + G` with `a_dd` the
    /// acceleration at the sample under `tau*`, [`observe`](Self::observe)). A runaway error, a
    /// non-finite torque, a failing reference, controller or integration stops the run with a
    /// [`RunFailure`] that says when and why and keeps the data recorded so far (the runaway
    /// sample included).
    pub fn run(&mut self) -> Result<Run, Box<RunFailure>> {
        self.run_with(&mut NoHooks)
    }

    /// [`run`](Self::run) with `hooks`: their disturbance acts on the arm and their observer
    /// sees every controller sample, in order ([`LoopHooks`]).
    pub fn run_with<H: LoopHooks + ?Sized>(
        &mut self,
        hooks: &mut H,
    ) -> Result<Run, Box<RunFailure>> {
        let (mut progress, refused) = self.start_run();
        if let Some(error) = refused {
            return Err(progress.fail(error));
        }
        for k in 0..=progress.samples {
            let last = k == progress.samples;
            let taken = self
                .take_sample(None, hooks)
                .and_then(|()| {
                    if last {
                        self.acceleration()
                    } else {
                        self.integrate()
                    }
                })
                .and_then(|()| {
                    hooks.observe(&self.sample);
                    self.conclude_sample(&mut progress, k)
                });
            if let Err(error) = taken {
                return Err(progress.fail(error));
            }
        }
        Ok(progress.finish())
    }

    /// Resets the loop and sizes what a [`run`](Self::run) accumulates; the error is a record
    /// whose memory the system refused ([`SimError::OutOfMemory`]: the run fails before its
    /// first sample).
    fn start_run(&mut self) -> (Progress, Option<SimError>) {
        self.reset();
        let s = &self.settings;
        let (samples, record_every) = sample_counts(s);
        let plant = self.plant.model.plant();
        let (m, n) = (self.n_coords(), plant.n_joints());
        let mut record = Record::empty(m, n, plant.n_links() + 1);
        let refused = record
            .reserve(recorded_samples(s))
            .err()
            .map(SimError::from);
        let progress = Progress {
            record,
            metrics: Metrics::new(m, n, s.joint_torque_limits.clone(), self.limits.is_some()),
            steps: 0,
            rejected: 0,
            samples,
            record_every,
        };
        (progress, refused)
    }

    /// Adds sample `k` of a run, taken and then integrated (or, the last, given its
    /// acceleration), to `progress`: the sample, [`observe`](Self::observe)d, to the metrics
    /// (torques, every sample), to the record and its tracking errors every recording period
    /// (and the last and a runaway one), then the runaway check.
    fn conclude_sample(&mut self, progress: &mut Progress, k: usize) -> Result<(), SimError> {
        let last = k == progress.samples;
        let m = self.n_coords();
        let max_error = self.settings.max_modal_error;
        let sample = &self.sample;
        let t = sample.t;
        progress.steps += sample.steps.0;
        progress.rejected += sample.steps.1;
        let held = if last {
            0.0
        } else {
            self.settings.controller_period
        };
        let runaway = (0..m)
            .map(|i| (i, (sample.state.a[i] - sample.reference.a[i]).abs()))
            .find(|&(_, e)| e > max_error || e.is_nan());
        progress.metrics.add_projection(sample.projected);
        if runaway.is_none()
            && let (Some(model), Some((data, axes))) =
                (&self.settings.clearance, &mut self.clearance)
        {
            self.tips.place(&self.plant.model, &self.sample.state.a)?;
            measure_clearance(
                model,
                data,
                (&self.tips.points, axes),
                &mut progress.metrics,
            )?;
        }
        self.sample_joint_torques()?;
        let sample = &self.sample;
        progress.metrics.add_control(
            t,
            &sample.tau_star,
            &sample.clamped,
            &self.joint_torques,
            held,
        )?;
        if k.is_multiple_of(progress.record_every) || last || runaway.is_some() {
            let (tip, tip_ref) = self.sample_tips()?;
            let sample = &self.sample;
            let row = Sample {
                t,
                a: &sample.state.a,
                a_dot: &sample.state.a_dot,
                a_ref: &sample.reference.a,
                a_ref_dot: &sample.reference.a_dot,
                a_cmd: &sample.command.a,
                tau_star: &sample.tau_star,
                clamped: &sample.clamped,
                tip,
                tip_ref,
            };
            progress.metrics.add_recorded(&row);
            progress
                .record
                .push(&row, &self.joint_torques, &self.tips.points);
        }
        match runaway {
            Some((i, error)) => Err(SimError::RunawayError {
                t,
                coordinate: i + 1,
                error,
                bound: max_error,
            }),
            None => Ok(()),
        }
    }

    /// The controller sample at the current time: state, reference, noise, `tau*` and the
    /// disturbance of `hooks` (into `self.sample`; its acceleration and steps are set by
    /// [`integrate`](Self::integrate) or [`acceleration`](Self::acceleration)). The reference
    /// at the current time is `shared` when another run of a lock-step group (of the same
    /// [`Prepared`] simulation, so the same reference) has sampled it, or sampled here (`None`).
    fn take_sample<H: LoopHooks + ?Sized>(
        &mut self,
        shared: Option<&ReferenceSample>,
        hooks: &mut H,
    ) -> Result<(), SimError> {
        let m = self.n_coords();
        let t = self.time();
        let sample = &mut self.sample;
        sample.t = t;
        sample.steps = (0, 0);
        sample.state.a.copy_from_slice(&self.y[..m]);
        sample.state.a_dot.copy_from_slice(&self.y[m..]);
        match shared {
            Some(reference) => sample.reference.copy_from(reference),
            None => self.reference.sample(t, &mut sample.reference)?,
        }
        check_reference(t, &sample.reference)?;
        // Before the controller sees them: at 1e20 rad every step would round away.
        if let Some((i, value)) = (0..m)
            .map(|i| (i, sample.state.a[i].abs().max(sample.reference.a[i].abs())))
            .find(|&(_, v)| v > MAX_MODAL_MAGNITUDE)
        {
            return Err(SimError::OutOfScale {
                t,
                coordinate: i + 1,
                value,
                bound: MAX_MODAL_MAGNITUDE,
            });
        }
        sample.command.copy_from(&sample.reference);
        if let Some(noise) = &mut self.reference_noise {
            noise.perturb(&mut sample.command.a);
        }
        self.measured.copy_from_slice(&self.y);
        if let Some(noise) = &mut self.sensor_noise {
            noise.perturb(&mut self.measured);
        }
        sample.measured.a.copy_from_slice(&self.measured[..m]);
        sample.measured.a_dot.copy_from_slice(&self.measured[m..]);
        let ctx = ControlContext {
            t,
            measured: &sample.measured,
            reference: &sample.command,
            model: self.plant.model.plant(),
            tau_star_limits: self.settings.tau_star_limits.as_deref(),
        };
        self.controller
            .control(&ctx, &mut sample.tau_star)
            .map_err(|error| SimError::from_controller(t, error))?;
        if !sample.tau_star.iter().all(|v| v.is_finite()) {
            return Err(SimError::NonFiniteControl {
                t,
                tau_star: sample.tau_star.clone(),
            });
        }
        match &self.settings.tau_star_limits {
            Some(limits) => saturate(&mut sample.tau_star, limits, &mut sample.clamped),
            None => sample.clamped.fill(false),
        }
        sample.projected = match &mut self.limits {
            Some(limits) => limits.apply(
                self.plant.model.plant(),
                &mut self.plant.data,
                t,
                (&sample.state.a, &sample.state.a_dot),
                &mut sample.tau_star,
            )?,
            None => false,
        };
        self.plant.tau_star.copy_from_slice(&sample.tau_star);
        if hooks.disturbance(t, &sample.state, &mut self.tau_disturbance) {
            if !self.tau_disturbance.iter().all(|v| v.is_finite()) {
                return Err(SimError::NonFiniteDisturbance {
                    t,
                    tau: self.tau_disturbance.clone(),
                });
            }
            // eqs 14-15: the modal force of the joint torques, f = J^T tau_d.
            self.plant
                .model
                .plant()
                .project_torques(&self.tau_disturbance, &mut sample.disturbance)
                .map_err(|source| SimError::Dynamics { t, source })?;
            for (tau, f) in self.plant.tau_star.iter_mut().zip(&sample.disturbance) {
                *tau += f;
            }
            if !self.plant.tau_star.iter().all(|v| v.is_finite()) {
                return Err(SimError::DisturbanceOverflow {
                    t,
                    force: self.plant.tau_star.clone(),
                });
            }
            self.disturbed = true;
        } else if self.disturbed {
            sample.disturbance.fill(0.0);
            self.disturbed = false;
        }
        Ok(())
    }

    /// Integrates from the sample just taken to the next one under its held `tau*`; the
    /// integrator's first stage is the acceleration at the sample.
    fn integrate(&mut self) -> Result<(), SimError> {
        let t = self.sample.t;
        let t1 = t + self.settings.controller_period;
        let plant = &mut self.plant;
        let stats = match &mut self.stepper {
            Stepper::Rk4(rk4, dt) => rk4.integrate(plant, t, t1, &mut self.y, *dt),
            Stepper::DormandPrince(dp) => dp.integrate(plant, t, t1, &mut self.y),
        };
        let stats = stats.map_err(|source| SimError::Integration {
            tau_star: self.plant.tau_star.clone(),
            source,
        })?;
        self.advance(stats);
        Ok(())
    }

    /// Moves the loop to the next sample once the integrator has brought `y` there with `stats`:
    /// the sample gets its acceleration (the integrator's first stage) and step counts.
    fn advance(&mut self, stats: Stats) {
        let m = self.n_coords();
        let start = match &self.stepper {
            Stepper::Rk4(rk4, _) => rk4.start_derivative(),
            Stepper::DormandPrince(dp) => dp.start_derivative(),
        };
        self.sample.a_ddot.copy_from_slice(&start[m..]);
        self.sample.steps = (stats.accepted, stats.rejected);
        self.taken += 1;
        self.current.a.copy_from_slice(&self.y[..m]);
        self.current.a_dot.copy_from_slice(&self.y[m..]);
    }

    /// The acceleration at the sample just taken under its `tau*`, without integrating.
    fn acceleration(&mut self) -> Result<(), SimError> {
        let t = self.sample.t;
        let plant = &mut self.plant;
        let state = &self.sample.state;
        plant
            .model
            .plant()
            .forward_dynamics(
                &mut plant.data,
                &state.a,
                &state.a_dot,
                &plant.tau_star,
                &mut self.sample.a_ddot,
            )
            .map_err(|source| SimError::Dynamics { t, source })
    }
}

/// The clearance of the chain at `points` (its `n + 1` points) into `metrics`: every pair's
/// signed distance ([`clearance::distances`]), the smallest to the obstacles and to the arm
/// itself. Distances do not use the joint `axes` (gradients would): they are `z`, a planar
/// chain's, for either family.
fn measure_clearance(
    model: &ClearanceModel,
    data: &mut ClearanceData,
    (points, axes): (&[[f64; 3]], &[[f64; 3]]),
    metrics: &mut Metrics,
) -> Result<(), SimError> {
    clearance::place(model, data, points, axes)
        .map_err(|e| SimError::setting("obstacles", format!("cannot be measured: {e}")))?;
    let (to_obstacles, to_itself) = clearance::distances(model, data);
    let pairs = model.pairs().len();
    metrics.add_clearance(
        (model.n_obstacle_pairs() > 0).then_some(to_obstacles),
        (pairs > model.n_obstacle_pairs()).then_some(to_itself),
    );
    Ok(())
}

/// Actuator saturation: clamps every `tau_i*` to `[-limits_i, limits_i]` (exactly `+-limits_i`
/// when it is beyond), setting `clamped_i` to whether it was.
fn saturate(tau_star: &mut [f64], limits: &[f64], clamped: &mut [bool]) {
    for ((tau, &limit), clamped) in tau_star.iter_mut().zip(limits).zip(clamped) {
        *clamped = tau.abs() > limit;
        *tau = tau.clamp(-limit, limit);
    }
}

/// `numerator / denominator` if it is a whole number (up to [`PERIOD_SLACK`]).
fn whole_ratio(numerator: f64, denominator: f64) -> Option<usize> {
    let ratio = numerator / denominator;
    let rounded = ratio.round();
    ((ratio - rounded).abs() <= PERIOD_SLACK * rounded.max(1.0) && rounded >= 1.0)
        .then_some(rounded as usize)
}

/// The most controller samples a run may take: a guard against typos like `1e300` for `1e3`,
/// whose run would never end and whose sample count would not fit a `usize`. Every period
/// takes at least one integrator step, so this also bounds a Dormand-Prince run to hours, as
/// [`MAX_RK4_STEPS`] bounds an RK4 run.
pub const MAX_CONTROLLER_SAMPLES: f64 = 1e9;

/// The most work `n m^2` one evaluation of the reduced dynamics may take in a closed-loop run
/// (`n` links, `m` modal coordinates: building `M* = J^T M J` is `n m^2` multiply-adds, and every
/// integrator stage does it): `2^24`, about a hundredth of a second, so 4096 links take at most
/// 64 coordinates (`K = 32` with `alpha0` fixed). Beyond it one RK4 step takes seconds to
/// minutes (512 links with `K = 256`: 26 s a step), and a run is refused before it starts.
pub const MAX_LOOP_WORK: f64 = 16_777_216.0;

/// Refuses a run whose reduced dynamics would take more than [`MAX_LOOP_WORK`] per evaluation.
pub fn check_loop_work(n_links: usize, m: usize) -> Result<(), SimError> {
    let work = n_links as f64 * (m as f64).powi(2);
    if work > MAX_LOOP_WORK {
        return Err(SimError::setting(
            "modal.harmonics",
            format!(
                "is too many for {n_links} links: {m} modal coordinates take an estimated \
                 {work:.3e} multiply-adds per evaluation of the reduced dynamics (n m^2), more than the \
                 {MAX_LOOP_WORK:e} a closed-loop run may take (seconds to minutes a step): use \
                 fewer harmonics or fewer links"
            ),
        ));
    }
    Ok(())
}

/// The smallest joint-torque limit (N m) a loop enforces: the projection onto the limits and
/// the checks of the torques it realises resolve torques to about `1e-10` N m (a limit of
/// `1e-10` was exceeded 2.5 times over, silently), so limits are refused below a margin of that.
pub const MIN_JOINT_TORQUE_LIMIT_NM: f64 = 1e-6;

/// Refuses a joint-torque limit that is not positive and finite, or below
/// [`MIN_JOINT_TORQUE_LIMIT_NM`], naming `limits.joint_torque_nm`.
fn check_joint_torque_limit(limit: f64) -> Result<(), SimError> {
    check_positive("limits.joint_torque_nm", limit)?;
    if limit < MIN_JOINT_TORQUE_LIMIT_NM {
        return Err(SimError::setting(
            "limits.joint_torque_nm",
            format!(
                "must be at least {} N m (the loop resolves joint torques no finer), got {}",
                Compact(MIN_JOINT_TORQUE_LIMIT_NM),
                Compact(limit)
            ),
        ));
    }
    Ok(())
}

/// Refuses a reference sample with a NaN or infinite entry, naming the first.
fn check_reference(t: f64, reference: &ReferenceSample) -> Result<(), SimError> {
    for (name, values) in [
        ("a", &reference.a),
        ("a_dot", &reference.a_dot),
        ("a_ddot", &reference.a_ddot),
    ] {
        if let Some((index, value)) = lane_math::first_non_finite(values) {
            return Err(SimError::NonFiniteReference {
                t,
                name,
                index,
                value,
            });
        }
    }
    Ok(())
}

/// The largest magnitude of a modal coordinate or its reference a run resolves (rad): at `1e6`
/// double precision still keeps `1e-10` rad, at `1e20` every step of a run rounds away. A run
/// reaching beyond stops ([`SimError::OutOfScale`]).
pub const MAX_MODAL_MAGNITUDE: f64 = 1e6;

/// The most work a whole run may take, in the units of [`MAX_LOOP_WORK`] (multiply-adds of the
/// reduced dynamics, about 1.4e9 a second here): about ten minutes of computing. Each bound on
/// its own (the work of one evaluation, the steps, the records) lets through runs whose product
/// would take hours (4,096 links with `K = 32` for 100 s: eleven hours).
pub const MAX_RUN_WORK: f64 = 1e12;

/// The work of one link in an evaluation of the reduced dynamics beyond its share `m^2` of
/// `M* = J^T M J`, in [`MAX_LOOP_WORK`]'s units: its angle, sine and cosine, position and
/// velocity terms, and its share of the controller sample (the reference, the tip, the joint
/// torques). Measured with `K = 1` and `alpha0` fixed (`m = 2`): 90-100 ns a link an RK4 step at
/// 10^4-10^5 links and 166 ns at 10^6 (out of cache), where `4 n m^2` alone counted 16 units
/// (11 ns).
const LINK_WORK: f64 = 64.0;

/// The work of one clearance pair measured at a controller sample, in [`MAX_LOOP_WORK`]'s units
/// (about 30 ns against 0.7 ns a multiply-add of the dynamics).
const CLEARANCE_PAIR_WORK: f64 = 64.0;

/// Refuses a run whose estimated work exceeds [`MAX_RUN_WORK`]: the evaluations of the reduced
/// dynamics (four an RK4 step, at least seven a Dormand-Prince step of `h_max`) times their
/// `n (m^2 + LINK_WORK)`, the clearance pairs measured at every controller sample, and the controller's own
/// `controller_work` ([`Controller::work`]: an MPC's solves; 0 before the controller is built).
/// Returns the estimate.
fn check_run_work(
    s: &LoopSettings,
    n_joints: usize,
    m: usize,
    controller_work: f64,
) -> Result<f64, SimError> {
    let evaluations = match s.integrator {
        Integrator::Rk4 { dt } => 4.0 * (s.duration / dt).ceil(),
        Integrator::DormandPrince(tol) => 7.0 * (s.duration / tol.h_max).ceil(),
    };
    let per_evaluation = (n_joints as f64) * ((m as f64).powi(2) + LINK_WORK);
    let samples = sample_counts(s).0 as f64;
    let pairs = s.clearance.as_ref().map_or(0, |c| c.pairs().len()) as f64;
    let work =
        evaluations * per_evaluation + samples * pairs * CLEARANCE_PAIR_WORK + controller_work;
    if work > MAX_RUN_WORK {
        let mut parts = format!(
            "{evaluations:.2e} evaluations of the reduced dynamics of {per_evaluation:.2e} each"
        );
        if pairs > 0.0 {
            parts += &format!(", {samples:.2e} clearance measures of {pairs} pairs");
        }
        if controller_work > 0.0 {
            parts += &format!(", {controller_work:.2e} of the controller's own");
        }
        let advice = if controller_work > 0.0 {
            "fewer links, harmonics or obstacles, or a controller of less work (another kind \
             than this MPC, or in Rust MpcSettings of a shorter horizon or fewer iterations)"
        } else {
            "fewer links, harmonics or obstacles"
        };
        return Err(run_work_refusal(s.duration, work, &parts, advice));
    }
    Ok(work)
}

/// The refusal of a run of `duration` seconds whose estimated `work` (made of `parts`) exceeds
/// [`MAX_RUN_WORK`], with `advice` on what to use instead (the modal loop's and the joint-space
/// loop's).
pub(crate) fn run_work_refusal(duration: f64, work: f64, parts: &str, advice: &str) -> SimError {
    SimError::setting(
        "duration",
        format!(
            "= {} s would take an estimated {work:.2e} operations ({parts}), more than the \
             {MAX_RUN_WORK:e} a run may take (about ten minutes): simulate less, or use {advice}",
            Compact(duration),
        ),
    )
}

/// The most numbers a run may record (1 GiB of `f64`): [`Simulation::new`] refuses a duration and
/// recording period that would record more, instead of failing to allocate during the run.
pub const MAX_RECORDED_VALUES: usize = 1 << 27;

/// How many samples a run of valid settings records (the `+ 2` covers the initial sample and
/// a failing one).
fn recorded_samples(s: &LoopSettings) -> usize {
    let (samples, record_every) = sample_counts(s);
    (samples / record_every).saturating_add(2)
}

/// The controller samples of a run and how many of them make one recording period.
fn sample_counts(s: &LoopSettings) -> (usize, usize) {
    let samples = whole_ratio(s.duration, s.controller_period).unwrap_or(0);
    let record_every = whole_ratio(s.record_period, s.controller_period)
        .unwrap_or(1)
        .max(1);
    (samples, record_every)
}

/// Checks the noise of the settings of a loop of `m` coordinates: `m` reference and `2m` sensor
/// standard deviations (or none), non-negative and at most [`MAX_MODAL_MAGNITUDE`]; an entry out
/// of its domain is named by the scenario's key (`noise.sensor_a_dot_std[1]`).
fn validate_noise(s: &LoopSettings, m: usize) -> Result<(), SimError> {
    for (name, values, len) in [
        ("noise.reference_std", &s.reference_noise_std, m),
        ("noise.sensor_std", &s.sensor_noise_std, 2 * m),
    ] {
        if !values.is_empty() && values.len() != len {
            return Err(SimError::setting(
                name,
                format!(
                    "has {} entries, the loop needs {len} (or none)",
                    values.len()
                ),
            ));
        }
        for (i, &v) in values.iter().enumerate() {
            // The scenario's key of the entry: the sensors' first `m` are the coordinates'.
            let name = match (name, i.checked_sub(m)) {
                ("noise.sensor_std", None) => format!("noise.sensor_a_std[{i}]"),
                ("noise.sensor_std", Some(rate)) => format!("noise.sensor_a_dot_std[{rate}]"),
                _ => format!("{name}[{i}]"),
            };
            check_non_negative(&name, v)?;
            // Noise of the scale a run resolves at most (`1e308` overflowed in the controller).
            if v > MAX_MODAL_MAGNITUDE {
                return Err(SimError::setting(
                    name,
                    format!(
                        "must be at most {} (rad, rad/s), got {}",
                        Compact(MAX_MODAL_MAGNITUDE),
                        Compact(v)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Checks that `reference` and `controller` are built for the `m` coordinates of the model.
fn check_parts(
    reference: &dyn Reference,
    controller: &dyn Controller,
    m: usize,
) -> Result<(), SimError> {
    if reference.n_coords() != m {
        return Err(SimError::setting(
            "reference",
            format!(
                "sets {} coordinates, the model has {m}",
                reference.n_coords()
            ),
        ));
    }
    if let Some(c) = controller.n_coords()
        && c != m
    {
        return Err(SimError::setting(
            "controller",
            format!("is built for {c} coordinates, the model has {m}"),
        ));
    }
    Ok(())
}

/// The initial state of a loop of `m` coordinates: `initial`, checked to have `m` finite
/// entries per field ([`check_initial`]), or rest at the reference's value at `t = 0`.
fn initial_state(
    reference: &mut dyn Reference,
    initial: Option<ModalState>,
    m: usize,
) -> Result<ModalState, SimError> {
    let initial = match initial {
        Some(state) => state,
        None => {
            let mut sample = ReferenceSample::zeros(m);
            reference.sample(0.0, &mut sample)?;
            ModalState {
                a: sample.a,
                a_dot: vec![0.0; m],
            }
        }
    };
    check_initial(&initial, m)?;
    Ok(initial)
}

/// Checks that an initial state has `m` finite entries per field, its rates within
/// [`MAX_MODAL_MAGNITUDE`].
fn check_initial(initial: &ModalState, m: usize) -> Result<(), SimError> {
    for (name, values) in [("initial.a", &initial.a), ("initial.a_dot", &initial.a_dot)] {
        if values.len() != m {
            return Err(SimError::setting(
                name,
                format!(
                    "has {} entries, the model has {m} coordinates",
                    values.len()
                ),
            ));
        }
        check_all_finite(name, values)?;
    }
    // A coordinate beyond the scale stops the run at its first sample (`SimError::OutOfScale`).
    check_rates("initial.a_dot", &initial.a_dot, m)
}

/// The names under which the front ends (`hrm eval`'s fields, Python's arguments) take joint or
/// modal rates, each checked by [`check_rates`].
pub const RATE_NAMES: [&str; 2] = ["theta_dot", "a_dot"];

/// Refuses rates that are not finite or beyond [`MAX_MODAL_MAGNITUDE`] in magnitude, the scale a
/// run resolves (`1e300` overflowed the Coriolis terms): `rates` holds states of `width` entries
/// (joint or modal rates), and the error names the first such entry, `name[i]` in one state and `name[k, i]`
/// in state `k` of several. For a run's initial state and the rates the front ends are given
/// (`hrm eval`'s and Python's `theta_dot` and `a_dot`).
///
/// # Errors
/// [`SimError::InvalidSetting`] naming the entry.
pub fn check_rates(name: &str, rates: &[f64], width: usize) -> Result<(), SimError> {
    check_scale(name, rates, width, "rad/s, m/s for a prismatic joint")
}

/// Refuses modal coordinates that are not finite or beyond [`MAX_MODAL_MAGNITUDE`] in magnitude,
/// where a run stops
/// ([`SimError::OutOfScale`]): in `J a` (eq 8) a coordinate of `1e17` rounds the others away.
/// Named as [`check_rates`] names its entries; for the coordinates the front ends are given
/// (`hrm eval`'s and Python's `a`). A base angle `alpha0` that a front end reduces to
/// `(-pi, pi]` first is not a coordinate this bounds.
///
/// # Errors
/// [`SimError::InvalidSetting`] naming the entry.
pub fn check_coordinates(name: &str, coordinates: &[f64], width: usize) -> Result<(), SimError> {
    check_scale(name, coordinates, width, "rad")
}

/// [`check_rates`] and [`check_coordinates`]: the first entry not finite or beyond
/// [`MAX_MODAL_MAGNITUDE`], its unit named in the message.
fn check_scale(name: &str, values: &[f64], width: usize, unit: &str) -> Result<(), SimError> {
    let Some((flat, value)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite() || v.abs() > MAX_MODAL_MAGNITUDE)
    else {
        return Ok(());
    };
    let entry = if values.len() <= width {
        format!("{name}[{flat}]")
    } else {
        format!("{name}[{}, {}]", flat / width.max(1), flat % width.max(1))
    };
    let requirement = if value.is_finite() {
        format!(
            "must be at most {} in magnitude ({unit}), got {}",
            Compact(MAX_MODAL_MAGNITUDE),
            Compact(*value)
        )
    } else {
        format!("must be finite, got {value}")
    };
    Err(SimError::setting(entry, requirement))
}

/// Checks the settings of a loop of `m` coordinates for a chain of `n_joints` (`n` planar, `2n`
/// spatial: the joint torques recorded, and the work of one evaluation, [`check_loop_work`]).
fn validate(s: &LoopSettings, plant: Plant<'_>) -> Result<(), SimError> {
    let (m, n_joints, n_links) = (plant.n_coords(), plant.n_joints(), plant.n_links());
    check_positive("controller.period", s.controller_period)?;
    check_positive("duration", s.duration)?;
    check_positive("record_period", s.record_period)?;
    if s.duration / s.controller_period > MAX_CONTROLLER_SAMPLES {
        return Err(SimError::setting(
            "duration",
            format!(
                "must be at most {MAX_CONTROLLER_SAMPLES:e} controller periods \
                 (controller.period = {} s), got {:e} s",
                Compact(s.controller_period),
                s.duration
            ),
        ));
    }
    if whole_ratio(s.duration, s.controller_period).is_none() {
        return Err(SimError::setting(
            "duration",
            format!(
                "must be a whole number of controller periods ({} s), got {} s",
                Compact(s.controller_period),
                Compact(s.duration)
            ),
        ));
    }
    if whole_ratio(s.record_period, s.controller_period).is_none() {
        return Err(SimError::setting(
            "record_period",
            format!(
                "must be a whole number of controller periods ({} s), got {} s",
                Compact(s.controller_period),
                Compact(s.record_period)
            ),
        ));
    }
    match s.integrator {
        Integrator::Rk4 { dt } => {
            check_positive("integrator.dt", dt)?;
            // Before the periods' ratio: a step of `5e-324` makes no whole number of steps.
            let steps = s.duration / dt;
            if steps > MAX_RK4_STEPS {
                return Err(SimError::setting(
                    "integrator.dt",
                    format!(
                        "= {} s would take {steps:.3e} RK4 steps over {} s, more than the \
                         {MAX_RK4_STEPS:e} a run may take (hours of computing): use a larger \
                         step or simulate less",
                        Compact(dt),
                        Compact(s.duration)
                    ),
                ));
            }
            if whole_ratio(s.controller_period, dt).is_none() {
                return Err(SimError::setting(
                    "controller.period",
                    format!(
                        "must be a whole number of RK4 steps (integrator.dt = {} s), got {} s",
                        Compact(dt),
                        Compact(s.controller_period)
                    ),
                ));
            }
        }
        Integrator::DormandPrince(tol) => tol.check().map_err(|(name, requirement)| {
            SimError::setting(format!("integrator.{name}"), requirement)
        })?,
    }
    validate_noise(s, m)?;
    if s.max_modal_error.is_nan() || s.max_modal_error <= 0.0 {
        return Err(SimError::setting(
            "limits.max_modal_error",
            format!("must be positive, got {}", Compact(s.max_modal_error)),
        ));
    }
    let recorded =
        recorded_samples(s).saturating_mul(Record::values_per_sample(m, n_joints, n_links + 1));
    if recorded > MAX_RECORDED_VALUES {
        return Err(SimError::setting(
            "record_period",
            format!(
                "would record {recorded} numbers over {} s, more than the {MAX_RECORDED_VALUES} \
                 a run may hold: record less often or simulate less",
                Compact(s.duration)
            ),
        ));
    }
    // Dormand-Prince steps no longer than h_max: a step typed `1e-300` would fall below the
    // resolution of t at once and read as a stiff problem, one of `1e-12` would run for days.
    if let Integrator::DormandPrince(tol) = s.integrator {
        let steps = s.duration / tol.h_max;
        if steps > MAX_RK4_STEPS {
            return Err(SimError::setting(
                "integrator.h_max",
                format!(
                    "= {} s would take at least {} steps over {} s, more than the \
                     {MAX_RK4_STEPS:e} a run may take (hours of computing): use a larger h_max \
                     or simulate less",
                    Compact(tol.h_max),
                    Compact(steps.round()),
                    Compact(s.duration)
                ),
            ));
        }
    }
    check_loop_work(n_joints, m)?;
    if let Some(limits) = &s.joint_torque_limits {
        if limits.len() != n_joints {
            return Err(SimError::setting(
                "limits.joint_torque_nm",
                format!(
                    "has {} entries, the arm has {n_joints} joints",
                    limits.len()
                ),
            ));
        }
        for (i, &l) in limits.iter().enumerate() {
            check_joint_torque_limit(l).map_err(|e| e.with_entry(limits, i))?;
        }
    }
    if let Some(limits) = &s.joint_angle_limits {
        if limits.len() != n_joints {
            return Err(SimError::setting(
                "limits.joint_angle_rad",
                format!(
                    "has {} entries, the arm has {n_joints} joints",
                    limits.len()
                ),
            ));
        }
        for (i, &l) in limits.iter().enumerate() {
            check_positive("limits.joint_angle_rad", l).map_err(|e| e.with_entry(limits, i))?;
        }
    }
    if let Some(model) = &s.clearance
        && model.n_links() != n_links
    {
        return Err(SimError::setting(
            "obstacles",
            format!(
                "are measured against {} links, the arm has {n_links}",
                model.n_links()
            ),
        ));
    }
    check_run_work(s, n_joints, m, 0.0)?;
    if let Some(limits) = &s.tau_star_limits {
        if limits.len() != m {
            return Err(SimError::setting(
                "limits.tau_star",
                format!(
                    "has {} entries, the modal family has {m} coordinates (one limit each, or \
                     one number for all)",
                    limits.len()
                ),
            ));
        }
        for &l in limits {
            check_positive("limits.tau_star", l)?;
        }
    }
    Ok(())
}
