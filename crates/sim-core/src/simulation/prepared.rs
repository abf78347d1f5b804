//! Build once, vary per run: a closed loop prepared once per model, reference, controller and
//! settings, whose runs differ only in their noise and its seed.

use super::{
    Lockstep, LoopSettings, Simulation, check_initial, check_parts, initial_state, validate,
    validate_noise,
};
use crate::controller::{Controller, ModalState};
use crate::error::SimError;
use crate::reference::Reference;
use modal_reduce::{Plant, PlantModel};
use std::sync::Arc;

/// Makes a run's reference: every call the same function of time, with its own workspace (a
/// reference samples through `&mut self`). Typically a clone of a reference built once
/// ([`Prepared::reference_clones`]).
pub type ReferenceFactory = Arc<dyn Fn() -> Result<Box<dyn Reference>, SimError> + Send + Sync>;

/// Makes a run's controller in its initial state: every call the same controller. Typically a
/// clone of a controller built once ([`Prepared::controller_clones`]).
pub type ControllerFactory = Arc<dyn Fn() -> Result<Box<dyn Controller>, SimError> + Send + Sync>;

/// What varies between the runs of a [`Prepared`] simulation: the seed of the noise sources and
/// the standard deviations of the noise (as [`LoopSettings`]' fields of the same names).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunNoise {
    /// Seed of the noise sources.
    pub seed: u64,
    /// Standard deviation of the noise on the reference `a_ref` (rad): `m` entries, or none.
    pub reference_std: Vec<f64>,
    /// Standard deviation of the sensor noise on `(a, a_dot)` (rad, rad/s): `2m` entries, or
    /// none.
    pub sensor_std: Vec<f64>,
}

impl LoopSettings {
    /// The settings' noise and seed.
    pub fn noise(&self) -> RunNoise {
        RunNoise {
            seed: self.seed,
            reference_std: self.reference_noise_std.clone(),
            sensor_std: self.sensor_noise_std.clone(),
        }
    }

    /// These settings with `noise`'s seed and noise instead.
    pub fn with_noise(&self, noise: &RunNoise) -> Self {
        Self {
            seed: noise.seed,
            reference_noise_std: noise.reference_std.clone(),
            sensor_noise_std: noise.sensor_std.clone(),
            ..self.clone()
        }
    }
}

/// A closed loop built once and run many times with different noise: the model, the reference
/// and controller factories, the settings and the initial state, checked when it is prepared.
/// A run ([`simulation`](Self::simulation)) takes its seed and noise and
/// creates only what is its own: the reference's and the controller's state (one call of each
/// factory), the integrator's workspace, the noise streams, the buffers and the record. The
/// model is shared, not copied. The runs of a [`Lockstep`] group come from one prepared
/// simulation ([`lockstep`](Self::lockstep)), so they share the reference and its samples.
///
/// A prepared simulation is `Send + Sync`: a sweep's threads run its runs side by side.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::ReducedModel;
/// use sim_core::controller::PdController;
/// use sim_core::reference::Step;
/// use sim_core::{Integrator, LoopSettings, Prepared, RunNoise};
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2)?)?;
/// let step = Step::new(&[0.0, 0.0], &[0.2, -0.1], 0.0)?;
/// let pd = PdController::new(&[0.0; 2], &[20.0, 20.0], &[2.0, 2.0])?;
/// let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 0.2);
/// let prepared = Prepared::new(
///     model,
///     Prepared::reference_clones(step),
///     Prepared::controller_clones(pd),
///     settings,
///     None,
/// )?;
/// let noisy = |seed| RunNoise { seed, reference_std: vec![], sensor_std: vec![1e-3; 4] };
/// let first = prepared.simulation(&noisy(1))?.run()?;
/// assert_eq!(prepared.simulation(&noisy(1))?.run()?, first);
/// assert_ne!(prepared.simulation(&noisy(2))?.run()?, first);
/// // The same runs side by side, bit for bit.
/// let together = prepared.lockstep(&[noisy(1), noisy(2)])?.run();
/// assert_eq!(together[0].as_ref().ok(), Some(&first));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Prepared {
    model: Arc<PlantModel>,
    reference: ReferenceFactory,
    controller: ControllerFactory,
    settings: LoopSettings,
    initial: Option<ModalState>,
}

impl Prepared {
    /// The loop of `model` tracking the references `reference` makes with the controllers
    /// `controller` makes, under `settings` (whose seed and noise are the runs' default,
    /// [`LoopSettings::noise`]); `initial` defaults to rest at the reference's value at `t = 0`.
    ///
    /// Checks `settings` and `initial` as [`Simulation::new`] does; the sizes of the reference
    /// and controller a factory makes are checked at each run.
    pub fn new(
        model: impl Into<PlantModel>,
        reference: ReferenceFactory,
        controller: ControllerFactory,
        settings: LoopSettings,
        initial: Option<ModalState>,
    ) -> Result<Self, SimError> {
        let model = model.into();
        let m = model.plant().n_coords();
        validate(&settings, model.plant())?;
        if let Some(initial) = &initial {
            check_initial(initial, m)?;
        }
        Ok(Self {
            model: Arc::new(model),
            reference,
            controller,
            settings,
            initial,
        })
    }

    /// A factory of clones of `controller` (as built, in its initial state).
    pub fn controller_clones<C: Controller + Clone + Sync + 'static>(
        controller: C,
    ) -> ControllerFactory {
        Arc::new(move || Ok(Box::new(controller.clone())))
    }

    /// A factory of clones of `reference` (built once: a path's inverse kinematics is solved
    /// once, not per run).
    pub fn reference_clones<R: Reference + Clone + Sync + 'static>(
        reference: R,
    ) -> ReferenceFactory {
        Arc::new(move || Ok(Box::new(reference.clone())))
    }

    /// The reduced model every run simulates, planar or spatial.
    pub fn model(&self) -> Plant<'_> {
        self.model.plant()
    }

    /// The settings, with the default noise and seed.
    pub fn settings(&self) -> &LoopSettings {
        &self.settings
    }

    /// A run's simulation, with `noise`: fresh reference and controller from the factories, the
    /// model shared. Fails for noise of the wrong size or sign (as [`Simulation::new`]), or a
    /// factory's error, or a reference or controller built for another number of coordinates.
    pub fn simulation(&self, noise: &RunNoise) -> Result<Simulation, SimError> {
        let m = self.model.plant().n_coords();
        let settings = self.settings.with_noise(noise);
        validate_noise(&settings, m)?;
        let mut reference = (self.reference)()?;
        let controller = (self.controller)()?;
        check_parts(reference.as_ref(), controller.as_ref(), m)?;
        let initial = initial_state(reference.as_mut(), self.initial.clone(), m)?;
        Simulation::assemble(
            Arc::clone(&self.model),
            reference,
            controller,
            settings,
            initial,
        )
    }

    /// The runs with `noises`, in that order, as one lock-step group (see [`Lockstep`]): they
    /// share this simulation's model and reference (sampled once per controller sample for all
    /// of them). Fails, for no run or a run that cannot be built, with the error of the first.
    pub fn lockstep(&self, noises: &[RunNoise]) -> Result<Lockstep, SimError> {
        let runs = noises
            .iter()
            .map(|noise| self.simulation(noise))
            .collect::<Result<Vec<_>, _>>()?;
        Lockstep::new(Arc::clone(&self.model), runs)
    }
}
