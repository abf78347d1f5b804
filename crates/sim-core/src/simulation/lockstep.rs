//! Several closed-loop runs of one model stepped side by side ("lock-step"), their reduced
//! forward dynamics (eq 15) evaluated together at every integrator stage by
//! [`Plant::forward_dynamics_batch`](modal_reduce::Plant::forward_dynamics_batch) (the planar arm's
//! [`forward_dynamics_batch`](modal_reduce::forward_dynamics_batch) or the spatial arm's
//! [`spatial_forward_dynamics_batch`](modal_reduce::spatial::spatial_forward_dynamics_batch)),
//! SIMD across the runs.
//!
//! Each run keeps everything of its own: controller, noise streams, reference, integrator
//! workspace, record. What is shared is the right-hand side of the RK4 stages: at stage `s` of a
//! step, every run's stage state is gathered into the batch's arrays, the batch evaluates them
//! (each state's result the same bits as one [`Plant::forward_dynamics`](modal_reduce::Plant::forward_dynamics) call), and each run gets its
//! derivative back. The stages themselves are [`Rk4`]'s own code ([`Rk4::stage`],
//! [`Rk4::finish_step`]), the code of a run integrated alone, so a run gives the same bits in a
//! group as alone.
//!
//! The runs of a group come from one [`Prepared`](crate::Prepared) simulation and differ only in noise and seed,
//! so they also share their reference samples: the reference is a function of time, so the
//! first run sampled at a controller sample hands its sample to the others instead of each
//! computing it again (for a path followed by inverse kinematics, about a quarter of a run
//! alone).
//!
//! Adaptive Dormand-Prince runs choose their own step sizes, so their stages do not line up:
//! a group of them integrates each run alone (the group still steps them together). So does a
//! group on a processor without SIMD or of a model whose batches run one state at a time
//! ([`Plant::batch_lanes`](modal_reduce::Plant::batch_lanes) is 1), where lock-step would gain nothing.

use super::{LoopHooks, NoHooks, Progress, Run, RunFailure, Simulation, Stepper};
use crate::error::SimError;
use crate::ode::{OdeError, Rk4, Stats};
use crate::reference::ReferenceSample;
use crate::simulation::{Integrator, Observation};
use modal_reduce::{PlantBatchData, PlantData, PlantModel};
use std::sync::Arc;

/// Closed-loop runs of one [`Prepared`](crate::Prepared) simulation that differ in seed or noise level (the
/// runs of a Monte Carlo sweep: `sim_study::study` runs its sweeps this way), stepped together
/// ([`Prepared::lockstep`](crate::Prepared::lockstep) forms a group). Each run is a [`Simulation`] with its own
/// controller, noise and record; the runs share the model and the reference's samples, and
/// with RK4 the reduced dynamics of all of them are evaluated at once at every integrator
/// stage, SIMD across the runs ([`Plant::forward_dynamics_batch`](modal_reduce::Plant::forward_dynamics_batch)), for planar and spatial arms
/// alike. Each run's results are bit for bit
/// those of the run alone.
///
/// As with one [`Simulation`], a caller may own the loop: [`step`](Self::step) advances every
/// running run by one controller period, [`simulation`](Self::simulation) and
/// [`observe`](Self::observe) show where each is, and [`stopped`](Self::stopped) why a run
/// stopped (a run that fails stops alone; the others go on). [`run`](Self::run) runs them all
/// from the start, as [`Simulation::run`] runs one; [`run_with`](Self::run_with) and
/// [`step_with`](Self::step_with) take one set of [`LoopHooks`] per run. Stepping allocates
/// nothing.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::ReducedModel;
/// use sim_core::controller::FuzzyController;
/// use sim_core::reference::Step;
/// use sim_core::{Integrator, LoopSettings, Prepared, RunNoise};
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2)?)?;
/// let step = Step::new(&[0.0, 0.0], &[0.2, -0.1], 0.0)?;
/// let fuzzy = FuzzyController::new(fuzzy_sugeno::paper_controller(), 2)?;
/// let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-4, 0.05);
/// let prepared = Prepared::new(
///     model,
///     Prepared::reference_clones(step),
///     Prepared::controller_clones(fuzzy),
///     settings,
///     None,
/// )?;
/// let noise = |seed| RunNoise { seed, reference_std: vec![], sensor_std: vec![0.01; 4] };
/// let noises: Vec<RunNoise> = (1..=5).map(noise).collect();
/// let results = prepared.lockstep(&noises)?.run();
/// // The same runs, one at a time: the same numbers.
/// let alone = prepared.simulation(&noise(3))?.run()?;
/// assert_eq!(results[2].as_ref().map(|run| &run.summary), Ok(&alone.summary));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Lockstep {
    runs: Vec<Simulation>,
    /// Why each run stopped; `None` while it runs.
    stopped: Vec<Option<SimError>>,
    /// The model every run simulates (planar or spatial), and the batch's workspaces for it.
    model: Arc<PlantModel>,
    batch: PlantBatchData,
    single: PlantData,
    /// The RK4 step when the runs' stages are evaluated together; `None` when each run is
    /// integrated alone.
    together: Option<f64>,
    /// States per SIMD group of the batch ([`Plant::batch_lanes`](modal_reduce::Plant::batch_lanes)).
    lanes: usize,
    /// The reference sample of the current controller sample, shared by the runs.
    reference: ReferenceSample,
    /// The runs evaluated at the current stage, slot by slot.
    slots: Vec<usize>,
    /// Per slot, `m` values each (the slots padded to whole SIMD groups): the stage's
    /// coordinates and rates, the held torques, and the accelerations.
    a: Vec<f64>,
    a_dot: Vec<f64>,
    tau_star: Vec<f64>,
    a_ddot: Vec<f64>,
}

impl Lockstep {
    /// A group of `runs` of `model`, each [`reset`](Simulation::reset) to its start: the
    /// simulations of one [`Prepared`](crate::Prepared) simulation ([`Prepared::lockstep`](crate::Prepared::lockstep)), so the same model,
    /// reference, controller, integrator and periods. Fails with [`SimError::InvalidSetting`]
    /// for no run.
    pub(super) fn new(model: Arc<PlantModel>, mut runs: Vec<Simulation>) -> Result<Self, SimError> {
        let Some(first) = runs.first() else {
            return Err(SimError::setting(
                "runs",
                "a lock-step group needs at least one simulation",
            ));
        };
        let plant = model.plant();
        let lanes = plant.batch_lanes();
        let together = match first.settings().integrator {
            Integrator::Rk4 { dt } if lanes > 1 => Some(dt),
            _ => None,
        };
        let values = runs.len().div_ceil(lanes) * lanes * plant.n_coords();
        for run in &mut runs {
            run.reset();
        }
        Ok(Self {
            stopped: vec![None; runs.len()],
            batch: PlantBatchData::try_new(plant).map_err(SimError::workspace)?,
            single: PlantData::try_new(plant).map_err(SimError::workspace)?,
            slots: Vec::with_capacity(runs.len()),
            a: vec![0.0; values],
            a_dot: vec![0.0; values],
            tau_star: vec![0.0; values],
            a_ddot: vec![0.0; values],
            reference: ReferenceSample::zeros(plant.n_coords()),
            runs,
            model,
            together,
            lanes,
        })
    }

    /// The number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether the group has no run (never: [`Prepared::lockstep`](crate::Prepared::lockstep)
    /// refuses that).
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Whether the runs' integrator stages are evaluated together (RK4 on a processor with
    /// SIMD), rather than each run integrated alone.
    pub fn is_lockstep(&self) -> bool {
        self.together.is_some()
    }

    /// Run `i` (its time, state, last sample).
    ///
    /// # Panics
    /// If `i >= len()`, like slice indexing.
    pub fn simulation(&self, i: usize) -> &Simulation {
        &self.runs[i]
    }

    /// Why run `i` stopped, or `None` while it runs. Panics as [`simulation`](Self::simulation).
    pub fn stopped(&self, i: usize) -> Option<&SimError> {
        self.stopped[i].as_ref()
    }

    /// The runs still running.
    pub fn running(&self) -> usize {
        self.stopped.iter().filter(|s| s.is_none()).count()
    }

    /// [`Simulation::observe`] of run `i`. Panics as [`simulation`](Self::simulation).
    pub fn observe(&mut self, i: usize) -> Result<Observation<'_>, SimError> {
        self.runs[i].observe()
    }

    /// The simulations, each where it stands.
    pub fn into_simulations(self) -> Vec<Simulation> {
        self.runs
    }

    /// Every run back to its start ([`Simulation::reset`]), none stopped.
    pub fn reset(&mut self) {
        for (run, stopped) in self.runs.iter_mut().zip(&mut self.stopped) {
            run.reset();
            *stopped = None;
        }
    }

    /// Advances every running run by one controller period, as [`Simulation::step`] advances
    /// one: each takes its controller sample, then all are integrated to the next sample. A run
    /// whose reference, controller or integration fails stops there ([`stopped`](Self::stopped)
    /// says why; it stays at its last sample) and the others go on. Returns the number of runs
    /// still running. Allocation-free (but for the error of a run that stops).
    pub fn step(&mut self) -> usize {
        self.step_hooked::<NoHooks>(&mut [])
    }

    /// [`step`](Self::step) with the hooks of each run (`hooks[i]` for run `i`; empty for none):
    /// their disturbances act on their runs and their observers see their runs' samples.
    ///
    /// Fails, and steps no run, if `hooks` is neither empty nor one per run.
    pub fn step_with<H: LoopHooks>(&mut self, hooks: &mut [H]) -> Result<usize, SimError> {
        self.check_hooks(hooks)?;
        Ok(self.step_hooked(hooks))
    }

    /// [`step_with`](Self::step_with) with hooks already checked.
    fn step_hooked<H: LoopHooks>(&mut self, hooks: &mut [H]) -> usize {
        self.take_samples(hooks);
        self.integrate();
        self.observe_samples(hooks);
        self.running()
    }

    /// Runs every run from its start for the whole duration, as [`Simulation::run`] runs one
    /// (it [`reset`](Self::reset)s first): the results in run order, each the same as the run
    /// alone would give.
    pub fn run(&mut self) -> Vec<Result<Run, Box<RunFailure>>> {
        self.run_hooked::<NoHooks>(&mut [])
    }

    /// [`run`](Self::run) with the hooks of each run, as [`step_with`](Self::step_with) takes
    /// them: each run's results are those of [`Simulation::run_with`] with its hooks.
    ///
    /// Fails, and runs nothing, if `hooks` is neither empty nor one per run.
    pub fn run_with<H: LoopHooks>(
        &mut self,
        hooks: &mut [H],
    ) -> Result<Vec<Result<Run, Box<RunFailure>>>, SimError> {
        self.check_hooks(hooks)?;
        Ok(self.run_hooked(hooks))
    }

    /// [`run_with`](Self::run_with) with hooks already checked.
    fn run_hooked<H: LoopHooks>(&mut self, hooks: &mut [H]) -> Vec<Result<Run, Box<RunFailure>>> {
        self.reset();
        let (mut progress, refused): (Vec<Progress>, Vec<Option<SimError>>) =
            self.runs.iter_mut().map(|r| r.start_run()).unzip();
        for (stopped, refused) in self.stopped.iter_mut().zip(refused) {
            *stopped = refused;
        }
        let samples = progress[0].samples;
        for k in 0..=samples {
            self.take_samples(hooks);
            if k == samples {
                for (run, stopped) in self.runs.iter_mut().zip(&mut self.stopped) {
                    if stopped.is_none() {
                        *stopped = run.acceleration().err();
                    }
                }
            } else {
                self.integrate();
            }
            self.observe_samples(hooks);
            for ((run, stopped), progress) in self
                .runs
                .iter_mut()
                .zip(&mut self.stopped)
                .zip(&mut progress)
            {
                if stopped.is_none() {
                    *stopped = run.conclude_sample(progress, k).err();
                }
            }
        }
        progress
            .into_iter()
            .zip(&mut self.stopped)
            .map(|(progress, stopped)| match stopped.take() {
                Some(error) => Err(progress.fail(error)),
                None => Ok(progress.finish()),
            })
            .collect()
    }

    /// Refuses hooks that are neither none nor one per run.
    fn check_hooks<H>(&self, hooks: &[H]) -> Result<(), SimError> {
        if hooks.is_empty() || hooks.len() == self.runs.len() {
            Ok(())
        } else {
            Err(SimError::setting(
                "hooks",
                format!(
                    "must be none or one per run of the lock-step group ({} runs), got {}",
                    self.runs.len(),
                    hooks.len()
                ),
            ))
        }
    }

    /// The controller sample of every running run ([`Simulation::take_sample`], with its hooks
    /// if any); the first run whose sample succeeds samples the reference for the others.
    fn take_samples<H: LoopHooks>(&mut self, hooks: &mut [H]) {
        let mut shared = false;
        for (r, (run, stopped)) in self.runs.iter_mut().zip(&mut self.stopped).enumerate() {
            if stopped.is_some() {
                continue;
            }
            let reference = shared.then_some(&self.reference);
            let result = match hooks.get_mut(r) {
                Some(hooks) => run.take_sample(reference, hooks),
                None => run.take_sample(reference, &mut NoHooks),
            };
            if result.is_ok() && !shared {
                self.reference.copy_from(&run.sample.reference);
                shared = true;
            }
            *stopped = result.err();
        }
    }

    /// Shows each running run's sample, complete, to its observer.
    fn observe_samples<H: LoopHooks>(&mut self, hooks: &mut [H]) {
        for ((run, stopped), hooks) in self.runs.iter().zip(&self.stopped).zip(hooks) {
            if stopped.is_none() {
                hooks.observe(&run.sample);
            }
        }
    }

    /// Integrates every running run to its next sample: together, or each alone.
    fn integrate(&mut self) {
        match self.together {
            Some(dt) => self.integrate_together(dt),
            None => {
                for (run, stopped) in self.runs.iter_mut().zip(&mut self.stopped) {
                    if stopped.is_none() {
                        *stopped = run.integrate().err();
                    }
                }
            }
        }
    }

    /// One controller period of RK4 for every running run, the stages of all of them evaluated
    /// together: for each run the calls of [`Rk4::integrate`], with the right-hand side of each
    /// stage evaluated as a batch.
    fn integrate_together(&mut self, dt: f64) {
        self.slots.clear();
        let (runs, stopped) = (&mut self.runs, &mut self.stopped);
        let mut plan = None;
        for (r, (run, stopped)) in runs.iter_mut().zip(stopped.iter_mut()).enumerate() {
            if stopped.is_some() {
                continue;
            }
            let t0 = run.sample.t;
            let t1 = t0 + run.settings.controller_period;
            match rk4(&mut run.stepper).begin(t0, t1, &run.y, dt) {
                Ok(p) => {
                    plan = Some((t0, p));
                    self.slots.push(r);
                }
                Err(source) => {
                    *stopped = Some(SimError::Integration {
                        tau_star: run.plant.tau_star.clone(),
                        source,
                    })
                }
            }
        }
        let Some((t0, plan)) = plan else {
            return;
        };
        let (steps, h) = plan.unwrap_or((0, 0.0));
        for i in 0..steps {
            let t = Rk4::step_time(t0, i, h);
            for s in 0..Rk4::STAGES {
                let t_s = self.gather(s, t, h);
                self.evaluate(s, t_s);
            }
            let (runs, stopped) = (&mut self.runs, &mut self.stopped);
            self.slots.retain(|&r| {
                let run = &mut runs[r];
                match rk4(&mut run.stepper).finish_step(i, t, &mut run.y, h) {
                    Ok(()) => true,
                    Err(source) => {
                        stopped[r] = Some(SimError::Integration {
                            tau_star: run.plant.tau_star.clone(),
                            source,
                        });
                        false
                    }
                }
            });
        }
        let stats = Stats {
            accepted: steps,
            rejected: 0,
            evaluations: Rk4::STAGES * steps,
        };
        for &r in &self.slots {
            self.runs[r].advance(stats);
        }
    }

    /// Gathers stage `s` of the step of size `h` from `t` of every run in the slots into the
    /// batch's arrays, padded to whole SIMD groups by copies of the first; returns the stage's
    /// time.
    fn gather(&mut self, s: usize, t: f64, h: f64) -> f64 {
        let m = self.model.plant().n_coords();
        let mut t_s = t;
        for (j, &r) in self.slots.iter().enumerate() {
            let run = &mut self.runs[r];
            let (time, y, _) = rk4(&mut run.stepper).stage(s, t, &run.y, h);
            t_s = time;
            let slot = j * m..(j + 1) * m;
            self.a[slot.clone()].copy_from_slice(&y[..m]);
            self.a_dot[slot.clone()].copy_from_slice(&y[m..]);
            self.tau_star[slot].copy_from_slice(&run.plant.tau_star);
        }
        let (filled, padded) = (self.slots.len(), self.padded());
        for values in [&mut self.a, &mut self.a_dot, &mut self.tau_star] {
            for j in filled..padded {
                values.copy_within(0..m, j * m);
            }
        }
        t_s
    }

    /// The slots evaluated: the runs, rounded up to whole SIMD groups when at least two runs
    /// are left over (a group of `lanes` states costs about two states evaluated one at a
    /// time; a single one left over is cheaper alone).
    fn padded(&self) -> usize {
        let filled = self.slots.len();
        match filled % self.lanes {
            0 | 1 => filled,
            _ => filled.next_multiple_of(self.lanes),
        }
    }

    /// Evaluates stage `s` (time `t_s`) of every run in the slots as one batch and hands each
    /// run its derivative. If the batch fails, each run is evaluated alone, so that each run
    /// that fails stops with its own error (as alone) and the others go on.
    fn evaluate(&mut self, s: usize, t_s: f64) {
        let plant = self.model.plant();
        let m = plant.n_coords();
        let values = self.padded() * m;
        let together = plant
            .forward_dynamics_batch(
                &mut self.batch,
                &self.a[..values],
                &self.a_dot[..values],
                &self.tau_star[..values],
                &mut self.a_ddot[..values],
            )
            .is_ok();
        let (runs, stopped) = (&mut self.runs, &mut self.stopped);
        let single = &mut self.single;
        let (a, a_dot, tau_star, a_ddot) = (&self.a, &self.a_dot, &self.tau_star, &mut self.a_ddot);
        let mut j = 0;
        self.slots.retain(|&r| {
            let slot = j * m..(j + 1) * m;
            j += 1;
            if !together {
                let evaluated = plant.forward_dynamics(
                    single,
                    &a[slot.clone()],
                    &a_dot[slot.clone()],
                    &tau_star[slot.clone()],
                    &mut a_ddot[slot.clone()],
                );
                if let Err(source) = evaluated {
                    stopped[r] = Some(SimError::Integration {
                        tau_star: tau_star[slot].to_vec(),
                        source: OdeError::Rhs { t: t_s, source },
                    });
                    return false;
                }
            }
            let k = rk4(&mut runs[r].stepper).derivative_mut(s);
            k[..m].copy_from_slice(&a_dot[slot.clone()]);
            k[m..].copy_from_slice(&a_ddot[slot]);
            true
        });
    }
}

/// The RK4 integrator of a run of a group whose runs are integrated together (all of them
/// RK4: the runs of one [`Prepared`](crate::Prepared) simulation share the integrator, and a simulation's
/// stepper is the one its settings name).
fn rk4(stepper: &mut Stepper) -> &mut Rk4 {
    match stepper {
        Stepper::Rk4(rk4, _) => rk4,
        Stepper::DormandPrince(_) => {
            unreachable!("the runs of a lock-step group integrated together are RK4 runs")
        }
    }
}
