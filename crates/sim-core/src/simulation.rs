//! The closed loop of the paper's Figures 6 and 8: reference -> controller -> modal torques ->
//! reduced dynamics (eq 15) -> state, with the controller sampled at its own period and its
//! output held in between (zero-order hold).

use crate::controller::{Controller, ModalState};
use crate::error::{Readable, SimError, check_finite, check_non_negative, check_positive};
use crate::noise::GaussianNoise;
use crate::ode::{DormandPrince, OdeSystem, Rk4, Tolerances};
use crate::record::{Metrics, Record, Sample, Summary};
use crate::reference::{Reference, ReferenceSample};
use backbone_kin::BaseAngle;
use modal_reduce::{ReduceError, ReducedData, ReducedModel};

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
    /// Recording period (s): a whole number of controller periods. The summary's errors and
    /// peaks are taken over the recorded samples, the runaway check over every sample.
    pub record_period: f64,
    /// Seed of the noise sources.
    pub seed: u64,
    /// Standard deviation of the Gaussian noise added to `(a1_ref, a2_ref)` at each sample (rad).
    pub reference_noise_std: [f64; 2],
    /// Standard deviation of the Gaussian sensor noise on the measured
    /// `(a1, a2, a1_dot, a2_dot)` (rad, rad/s).
    pub sensor_noise_std: [f64; 4],
    /// A run stops with [`SimError::RunawayError`] when `|a_i - a_i_ref|` exceeds this (rad).
    pub max_modal_error: f64,
    /// Optional per-joint torque limits (N m): exceeding one is reported in the summary.
    pub joint_torque_limits: Option<Vec<f64>>,
}

impl LoopSettings {
    /// Settings without noise or limits, recording every sample, with a runaway bound of pi rad.
    pub fn new(integrator: Integrator, controller_period: f64, duration: f64) -> Self {
        Self {
            integrator,
            controller_period,
            duration,
            record_period: controller_period,
            seed: 0,
            reference_noise_std: [0.0; 2],
            sensor_noise_std: [0.0; 4],
            max_modal_error: std::f64::consts::PI,
            joint_torque_limits: None,
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
#[error("{error} (data kept up to t = {} s)", summary.simulated_s)]
pub struct RunFailure {
    /// Why and when the run stopped.
    pub error: SimError,
    /// The time series up to the last good sample.
    pub record: Record,
    /// The metrics up to the last good sample.
    pub summary: Summary,
}

/// The reduced dynamics with a held modal torque: `y = [a1, a2, a1_dot, a2_dot]`.
struct Plant {
    model: ReducedModel,
    data: ReducedData,
    tau_star: [f64; 2],
}

impl OdeSystem for Plant {
    type Error = ReduceError;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), ReduceError> {
        dy[..2].copy_from_slice(&y[2..]);
        modal_reduce::forward_dynamics(
            &self.model,
            &mut self.data,
            &y[..2],
            &y[2..],
            &self.tau_star,
            &mut dy[2..],
        )
    }
}

/// The integrator with its workspace.
enum Stepper {
    Rk4(Rk4, f64),
    DormandPrince(DormandPrince),
}

/// A closed-loop simulation, built once and run any number of times (each run starts afresh
/// from the initial state with the noise re-seeded; controllers keep no state between samples).
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
/// let reference = Step::new([0.0, 0.0], [0.2, -0.1], 0.0)?;
/// let controller = FuzzyController::new(fuzzy_sugeno::paper_controller())?;
/// let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-4, 0.5);
/// let mut sim = Simulation::new(model, Box::new(reference), Box::new(controller), settings, None)?;
/// let run = sim.run()?;
/// assert_eq!(run.summary.controller_samples, 5001);
/// assert!(run.summary.modal_error_rms[0] < 0.2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Simulation {
    plant: Plant,
    reference: Box<dyn Reference>,
    controller: Box<dyn Controller>,
    settings: LoopSettings,
    initial: ModalState,
    alpha0: f64,
    curve_length: f64,
    link_lengths: Vec<f64>,
    theta: Vec<f64>,
    joint_torques: Vec<f64>,
}

impl Simulation {
    /// A closed loop of `model` (two coordinates `(a1, a2)`, `alpha0` fixed) tracking `reference`
    /// with `controller`. `initial` defaults to rest at the reference's value at `t = 0`.
    ///
    /// Fails with [`SimError::InvalidSetting`] for a model with another coordinate set, and for
    /// settings out of their domain: non-positive periods or duration, periods that are not
    /// whole multiples (controller period of the RK4 step, duration and recording period of the
    /// controller period), a duration of more than [`MAX_CONTROLLER_SAMPLES`] periods or
    /// [`MAX_RK4_STEPS`] RK4 steps, a record of more than [`MAX_RECORDED_VALUES`] numbers,
    /// negative or non-finite noise, a
    /// non-positive error bound, or torque limits of the wrong length or sign.
    pub fn new(
        model: ReducedModel,
        reference: Box<dyn Reference>,
        controller: Box<dyn Controller>,
        settings: LoopSettings,
        initial: Option<ModalState>,
    ) -> Result<Self, SimError> {
        let alpha0 = match (model.n_coords(), model.map().base_angle()) {
            (2, BaseAngle::Fixed(alpha0)) => alpha0,
            _ => {
                return Err(SimError::setting(
                    "model",
                    "must have the two coordinates (a1, a2) with alpha0 fixed",
                ));
            }
        };
        validate(&settings, model.n_links())?;
        let initial = match initial {
            Some(state) => state,
            None => ModalState {
                a: reference.sample(0.0)?.a,
                a_dot: [0.0; 2],
            },
        };
        check_finite("initial.a", &initial.a)?;
        check_finite("initial.a_dot", &initial.a_dot)?;
        let n = model.n_links();
        let link_lengths: Vec<f64> = model.chain().link_lengths().collect();
        let curve_length = link_lengths.iter().sum();
        let data = ReducedData::new(&model);
        Ok(Self {
            plant: Plant {
                model,
                data,
                tau_star: [0.0; 2],
            },
            reference,
            controller,
            settings,
            initial,
            alpha0,
            curve_length,
            link_lengths,
            theta: vec![0.0; n],
            joint_torques: vec![0.0; n],
        })
    }

    /// The reduced model being simulated.
    pub fn model(&self) -> &ReducedModel {
        &self.plant.model
    }

    /// The settings of the loop.
    pub fn settings(&self) -> &LoopSettings {
        &self.settings
    }

    /// The initial state.
    pub fn initial_state(&self) -> ModalState {
        self.initial
    }

    /// Runs the loop from the initial state for the whole duration.
    ///
    /// At each controller sample `t_k = k * period` it samples the reference, adds the noise,
    /// asks the controller for `tau*`, checks the tracking error against the runaway bound and
    /// integrates the dynamics to `t_{k+1}` with `tau*` held. Every `record_period` it records
    /// the sample (state, reference, `tau*`, tips, joint torques `tau = M J a_dd + C + G` with
    /// `a_dd` the acceleration at the sample under `tau*`). A runaway error, a non-finite torque,
    /// a failing reference, controller or integration stops the run with a [`RunFailure`] that
    /// says when and why and keeps the data recorded so far (the runaway sample included).
    pub fn run(&mut self) -> Result<Run, Box<RunFailure>> {
        let s = &self.settings;
        let period = s.controller_period;
        let (samples, record_every) = sample_counts(s);
        let mut stepper = match s.integrator {
            Integrator::Rk4 { dt } => Stepper::Rk4(Rk4::new(4), dt),
            Integrator::DormandPrince(tol) => Stepper::DormandPrince(DormandPrince::new(4, tol)),
        };
        let mut reference_noise =
            GaussianNoise::new(s.seed, REFERENCE_NOISE_STREAM, s.reference_noise_std);
        let mut sensor_noise = GaussianNoise::new(s.seed, SENSOR_NOISE_STREAM, s.sensor_noise_std);
        let n = self.plant.model.n_links();
        let mut record = Record::with_capacity(n, recorded_samples(s));
        let mut metrics = Metrics::new(n, s.joint_torque_limits.clone());
        let (mut steps, mut rejected) = (0, 0);
        let mut y = [
            self.initial.a[0],
            self.initial.a[1],
            self.initial.a_dot[0],
            self.initial.a_dot[1],
        ];
        let max_error = s.max_modal_error;
        let fail = |error, record, metrics: &Metrics, steps, rejected| {
            Box::new(RunFailure {
                error,
                record,
                summary: metrics.summary(steps, rejected),
            })
        };
        for k in 0..=samples {
            let t = k as f64 * period;
            let last = k == samples;
            let control = match self.control(
                t,
                &mut y,
                &mut stepper,
                &mut reference_noise,
                &mut sensor_noise,
                !last,
            ) {
                Ok(control) => control,
                Err(error) => return Err(fail(error, record, &metrics, steps, rejected)),
            };
            steps += control.steps.0;
            rejected += control.steps.1;
            metrics.add_control(t, control.tau_star, if last { 0.0 } else { period });
            let runaway = (0..2)
                .map(|i| (i, (control.state.a[i] - control.reference.a[i]).abs()))
                .find(|&(_, e)| e > max_error || e.is_nan());
            if k % record_every == 0 || last || runaway.is_some() {
                match self.observe(t, &control) {
                    Ok(sample) => {
                        metrics.add(&sample, &self.joint_torques);
                        record.push(&sample, &self.joint_torques);
                    }
                    Err(error) => return Err(fail(error, record, &metrics, steps, rejected)),
                }
            }
            if let Some((i, error)) = runaway {
                let error = SimError::RunawayError {
                    t,
                    coordinate: i + 1,
                    error,
                    bound: max_error,
                };
                return Err(fail(error, record, &metrics, steps, rejected));
            }
        }
        Ok(Run {
            record,
            summary: metrics.summary(steps, rejected),
        })
    }

    /// The controller sample at time `t`: reference, noise, `tau*`; then (if `integrate`) the
    /// dynamics from `y` to the next sample under the held `tau*`, else the acceleration at `y`.
    fn control(
        &mut self,
        t: f64,
        y: &mut [f64; 4],
        stepper: &mut Stepper,
        reference_noise: &mut Option<GaussianNoise<2>>,
        sensor_noise: &mut Option<GaussianNoise<4>>,
        integrate: bool,
    ) -> Result<Control, SimError> {
        let state = ModalState {
            a: [y[0], y[1]],
            a_dot: [y[2], y[3]],
        };
        let reference = self.reference.sample(t)?;
        let mut command = reference;
        if let Some(noise) = reference_noise {
            noise.perturb(&mut command.a);
        }
        let mut measured = *y;
        if let Some(noise) = sensor_noise {
            noise.perturb(&mut measured);
        }
        let measured = ModalState {
            a: [measured[0], measured[1]],
            a_dot: [measured[2], measured[3]],
        };
        let tau_star = self.controller.control(t, &measured, &command)?;
        if !tau_star.iter().all(|v| v.is_finite()) {
            return Err(SimError::NonFiniteControl { t, tau_star });
        }
        let plant = &mut self.plant;
        plant.tau_star = tau_star;
        let mut a_ddot = [0.0; 2];
        let mut steps = (0, 0);
        if integrate {
            let period = self.settings.controller_period;
            // The integrator's first stage is the acceleration at this sample under tau*.
            let (stats, start) = match stepper {
                Stepper::Rk4(rk4, dt) => {
                    let stats = rk4.integrate(plant, t, t + period, y, *dt);
                    (stats, rk4.start_derivative())
                }
                Stepper::DormandPrince(dp) => {
                    let stats = dp.integrate(plant, t, t + period, y);
                    (stats, dp.start_derivative())
                }
            };
            let stats = stats.map_err(SimError::Integration)?;
            a_ddot.copy_from_slice(&start[2..]);
            steps = (stats.accepted, stats.rejected);
        } else {
            modal_reduce::forward_dynamics(
                &plant.model,
                &mut plant.data,
                &state.a,
                &state.a_dot,
                &tau_star,
                &mut a_ddot,
            )
            .map_err(|source| SimError::Dynamics { t, source })?;
        }
        Ok(Control {
            state,
            reference,
            command: command.a,
            tau_star,
            a_ddot,
            steps,
        })
    }

    /// The recorded view of a controller sample: joint torques `tau = M J a_dd + C + G` (into
    /// `self.joint_torques`), the chain's tip and the reference tip.
    fn observe(&mut self, t: f64, control: &Control) -> Result<Sample, SimError> {
        let plant = &mut self.plant;
        let state = &control.state;
        modal_reduce::joint_torques(
            &plant.model,
            &mut plant.data,
            &state.a,
            &state.a_dot,
            &control.a_ddot,
            &mut self.joint_torques,
        )
        .map_err(|source| SimError::Dynamics { t, source })?;
        plant.model.map().joint_angles(&state.a, &mut self.theta)?;
        let tip = backbone_kin::tip_position(&self.link_lengths, &self.theta)?;
        let tip_ref = backbone_kin::end_point(self.curve_length, control.reference.a, self.alpha0)?;
        Ok(Sample {
            t,
            a: state.a,
            a_dot: state.a_dot,
            a_ref: control.reference.a,
            a_ref_dot: control.reference.a_dot,
            a_cmd: control.command,
            tau_star: control.tau_star,
            tip,
            tip_ref,
        })
    }
}

/// One controller sample before it is observed.
struct Control {
    /// The true state at the sample.
    state: ModalState,
    /// The noise-free reference.
    reference: ReferenceSample,
    /// The reference as the controller saw it.
    command: [f64; 2],
    tau_star: [f64; 2],
    /// The acceleration at the sample under `tau_star`.
    a_ddot: [f64; 2],
    /// Accepted and rejected integrator steps to the next sample.
    steps: (usize, usize),
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

/// The most fixed steps an RK4 run may take (`duration / integrator.dt`): about half an hour of
/// computing for a 10-link arm, so a step typed `1e-12` for `1e-4` is refused up front rather
/// than running for days.
pub const MAX_RK4_STEPS: f64 = 1e9;

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

/// Checks the settings of a loop for a chain of `n_links`.
fn validate(s: &LoopSettings, n_links: usize) -> Result<(), SimError> {
    check_positive("controller.period", s.controller_period)?;
    check_positive("duration", s.duration)?;
    check_positive("record_period", s.record_period)?;
    if s.duration / s.controller_period > MAX_CONTROLLER_SAMPLES {
        return Err(SimError::setting(
            "duration",
            format!(
                "must be at most {MAX_CONTROLLER_SAMPLES:e} controller periods ({} s), got {:e} s",
                Readable(s.controller_period),
                s.duration
            ),
        ));
    }
    if whole_ratio(s.duration, s.controller_period).is_none() {
        return Err(SimError::setting(
            "duration",
            format!(
                "must be a whole number of controller periods ({} s), got {} s",
                Readable(s.controller_period),
                Readable(s.duration)
            ),
        ));
    }
    if whole_ratio(s.record_period, s.controller_period).is_none() {
        return Err(SimError::setting(
            "record_period",
            format!(
                "must be a whole number of controller periods ({} s), got {} s",
                Readable(s.controller_period),
                Readable(s.record_period)
            ),
        ));
    }
    match s.integrator {
        Integrator::Rk4 { dt } => {
            check_positive("integrator.dt", dt)?;
            if whole_ratio(s.controller_period, dt).is_none() {
                return Err(SimError::setting(
                    "controller.period",
                    format!(
                        "must be a whole number of RK4 steps ({} s), got {} s",
                        Readable(dt),
                        Readable(s.controller_period)
                    ),
                ));
            }
        }
        Integrator::DormandPrince(tol) => tol
            .check()
            .map_err(|reason| SimError::setting("integrator", format!("setting: {reason}")))?,
    }
    for v in s.reference_noise_std {
        check_non_negative("noise.reference_std", v)?;
    }
    for v in s.sensor_noise_std {
        check_non_negative("noise.sensor_std", v)?;
    }
    if s.max_modal_error.is_nan() || s.max_modal_error <= 0.0 {
        return Err(SimError::setting(
            "limits.max_modal_error",
            format!("must be positive, got {}", s.max_modal_error),
        ));
    }
    let recorded = recorded_samples(s).saturating_mul(Record::values_per_sample(n_links));
    if recorded > MAX_RECORDED_VALUES {
        return Err(SimError::setting(
            "record_period",
            format!(
                "would record {recorded} numbers over {} s, more than the {MAX_RECORDED_VALUES} \
                 a run may hold: record less often or simulate less",
                s.duration
            ),
        ));
    }
    if let Integrator::Rk4 { dt } = s.integrator {
        let steps = s.duration / dt;
        if steps > MAX_RK4_STEPS {
            return Err(SimError::setting(
                "integrator.dt",
                format!(
                    "would take {steps:.3e} RK4 steps over {} s, more than the \
                     {MAX_RK4_STEPS:e} a run may take (hours of computing): use a larger step \
                     or simulate less",
                    Readable(s.duration)
                ),
            ));
        }
    }
    if let Some(limits) = &s.joint_torque_limits {
        if limits.len() != n_links {
            return Err(SimError::setting(
                "limits.joint_torque_nm",
                format!("has {} entries, the arm has {n_links} joints", limits.len()),
            ));
        }
        for &l in limits {
            check_positive("limits.joint_torque_nm", l)?;
        }
    }
    Ok(())
}
