//! Hooks into the closed loop, in the style of rapier's `PhysicsHooks` and `EventHandler`: code
//! the loop calls at every controller sample, so that a user can push the arm or watch the run
//! without writing a controller or owning the loop.

use super::ControlSample;
use crate::controller::ModalState;

/// What the loop calls at every controller sample, beside the controller: an external
/// disturbance and an observer. Every method has a default that does nothing, so a hook
/// implements only what it needs; [`NoHooks`] implements none, and the loop run with it (what
/// [`Simulation::run`](crate::Simulation::run) and [`step`](crate::Simulation::step) do) is the
/// loop without hooks, bit for bit and at the same cost (the calls are resolved at compile time
/// and vanish).
///
/// A disturbance is a **joint-space** torque `tau_d` (N m, one entry per joint): what a push on
/// the real arm is. The loop projects it onto the modal coordinates as every joint torque is,
/// `f = J^T tau_d` (eqs 14-15, [`modal_reduce::project_torques`]), and the plant integrates
/// `M* a_dd + C* + G* = tau* + f` (eq 15 with the disturbance added to the controller's
/// clamped `tau*`). Like `tau*`, the disturbance is sampled at the controller sample `t_k` and
/// held until `t_{k+1}` (zero-order hold). It does not count as control: the recorded `tau*`,
/// the effort and the clamping are the controller's; the sample's
/// [`disturbance`](ControlSample::disturbance) holds `f`, and the recorded joint torques are
/// the actuators' `M J a_dd + C + G - tau_d` (eq 13 less the push).
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::ReducedModel;
/// use sim_core::controller::{ModalState, PdController};
/// use sim_core::reference::Step;
/// use sim_core::{ControlSample, Integrator, LoopHooks, LoopSettings, Simulation};
///
/// /// A push of 0.05 N m on the tip joint from 0.1 s to 0.15 s, and the largest `|a1|` seen.
/// struct Push {
///     peak: f64,
/// }
///
/// impl LoopHooks for Push {
///     fn disturbance(&mut self, t: f64, _state: &ModalState, tau: &mut [f64]) -> bool {
///         let on = (0.1..0.15).contains(&t);
///         if on {
///             tau.fill(0.0);
///             *tau.last_mut().unwrap() = 0.05;
///         }
///         on
///     }
///
///     fn observe(&mut self, sample: &ControlSample) {
///         self.peak = self.peak.max(sample.state.a[0].abs());
///     }
/// }
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2)?)?;
/// let reference = Step::constant(&[0.2, -0.1])?;
/// let pd = PdController::new(&[0.0; 2], &[20.0, 20.0], &[2.0, 2.0])?;
/// let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 0.3);
/// let mut sim = Simulation::new(model, Box::new(reference), Box::new(pd), settings, None)?;
/// let mut push = Push { peak: 0.0 };
/// let pushed = sim.run_with(&mut push)?;
/// let still = sim.run()?;
/// assert!(pushed.summary.modal_error_max_rad[0] > still.summary.modal_error_max_rad[0]);
/// assert!(push.peak > 0.2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait LoopHooks {
    /// The external joint torques `tau_d` (N m, one entry per joint) acting on the arm from the
    /// controller sample at `t` (s) to the next, given the true state at `t`: write them into
    /// `tau` and return `true`, or return `false` (the default) for none, in which case `tau` is
    /// ignored. `tau` holds what was written last (zeros at first). A non-finite torque stops
    /// the run with [`SimError::NonFiniteDisturbance`](crate::SimError::NonFiniteDisturbance).
    fn disturbance(&mut self, t: f64, state: &ModalState, tau: &mut [f64]) -> bool {
        let _ = (t, state, tau);
        false
    }

    /// Called once for every controller sample, in order, when it is complete: its state,
    /// reference, noise, `tau*`, disturbance, and the acceleration at the sample and the
    /// integrator steps to the next (the last sample of a run is not integrated: its steps are
    /// zero). A run that stops at a sample (a runaway error) has shown it first.
    fn observe(&mut self, sample: &ControlSample) {
        let _ = sample;
    }
}

/// No hooks: the loop alone.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NoHooks;

impl LoopHooks for NoHooks {}
