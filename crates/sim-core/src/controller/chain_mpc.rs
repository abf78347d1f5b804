//! Model-predictive control of a full chain in joint space ([`ChainMpc`]) for the joint-space
//! loop ([`run_chain_loop_mpc`](crate::run_chain_loop_mpc)): re-planned every model step from
//! the measured joints over a preview of the reference, with the plan's feedback in between.

use crate::error::{ControllerError, SimError};
use crate::reference::{Reference, ReferencePreview, ReferenceSample};
use manip_dyn::spatial::SpatialModel;
use optimal_ctl::{ChainMpc, MpcSettings};

/// Receding-horizon MPC of a spatial chain, as [`MpcController`](super::MpcController) is for
/// modal coordinates: at the first sample and then at the first sample at least one model step
/// `h` after the last plan, it previews the reference over the horizon (node 0 the loop's
/// sample), shifts the previous plan as the warm start and re-plans by control-limited iLQR
/// ([`ChainMpc`]); at every sample it applies the plan's first effort with its feedback about
/// the planned state, within the box. Nothing allocates per sample.
#[derive(Debug)]
pub struct ChainMpcController {
    mpc: ChainMpc,
    preview: ReferencePreview,
    plan_time: f64,
}

/// Slack on "at least one step after the last plan" (relative to the step).
const PLAN_SLACK: f64 = 1e-9;

impl ChainMpcController {
    /// MPC of `model`'s joints with `settings` (`tau_star_limits`: the box on the joint
    /// efforts), previewing `reference` (a copy of the loop's).
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] named `controller.mpc` for settings out of their domain or a
    /// reference with another number of coordinates than joints.
    pub fn new(
        model: &SpatialModel,
        settings: &MpcSettings,
        reference: Box<dyn Reference>,
    ) -> Result<Self, SimError> {
        let n = model.n_links();
        let (mpc, preview) = super::mpc::solver_and_preview(
            settings,
            reference,
            (n, &format!("the chain has {n} joints")),
            || ChainMpc::new(model, settings),
        )?;
        Ok(Self {
            mpc,
            preview,
            plan_time: 0.0,
        })
    }

    /// The estimated work of its solves over `duration` seconds of a run (one a model step),
    /// in the units of [`MAX_RUN_WORK`](crate::MAX_RUN_WORK) ([`ChainMpc::solve_work`]).
    pub fn work(&self, duration: f64) -> f64 {
        ((duration / self.mpc.step()).ceil() + 1.0) * self.mpc.solve_work()
    }

    /// The MPC workspace: the last plan.
    pub fn mpc(&self) -> &ChainMpc {
        &self.mpc
    }

    /// The effort at time `t` for the measured `(q, v)`, with `sample` the loop's reference at
    /// `t`, into `tau`; re-plans when a model step has passed since the last plan.
    ///
    /// # Errors
    /// The preview's, the solver's and the dynamics' errors.
    pub fn command(
        &mut self,
        model: &SpatialModel,
        t: f64,
        q: &[f64],
        v: &[f64],
        sample: &ReferenceSample,
        tau: &mut [f64],
    ) -> Result<(), ControllerError> {
        let h = self.mpc.step();
        let due = self.plan_time + h * (1.0 - PLAN_SLACK);
        if !self.mpc.planned() || t >= due || t < self.plan_time {
            if self.mpc.planned() {
                if t < self.plan_time {
                    self.mpc.reset();
                } else {
                    let steps = ((t - self.plan_time) / h).round().max(1.0);
                    self.mpc.shift(steps.min(usize::MAX as f64) as usize);
                }
            }
            let samples = self.preview.advance(t)?;
            for (k, node) in samples.iter().enumerate() {
                let node = if k == 0 { sample } else { node };
                self.mpc
                    .set_reference(model, k, &node.a, &node.a_dot, &node.a_ddot)?;
            }
            self.mpc.solve(model, q, v)?;
            self.plan_time = t;
        }
        self.mpc.control(t - self.plan_time, q, v, tau)?;
        Ok(())
    }
}
