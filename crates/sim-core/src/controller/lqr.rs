//! The linear-quadratic regulator about the reference, re-linearised along it: the classical
//! model-based baseline the paper never ran.

use super::{ControlContext, Controller, ControllerError, check_context, check_coordinate_count};
use crate::error::{SimError, check_positive};
use lane_math::Compact;
use lane_math::dense::symmetrise;
use modal_reduce::{Plant, PlantData};
use optimal_ctl::{Linearisation, Lqr, LqrSettings};

/// The largest design frequency `omega` (rad/s): `omega^4` scales the state weight.
const MAX_FREQUENCY: f64 = 1e4;

/// LQR about the reference: `tau* = u_ref - K (x - x_ref)` with `x = (a, a_dot)`,
/// `x_ref = (a_ref, a_ref_dot)`, the feedforward `u_ref = M*(a_ref) a_ref_ddot + C*(a_ref,
/// a_ref_dot) + G*(a_ref)` (eq 15 along the reference: the torque that keeps the model on it),
/// and `K` the discrete infinite-horizon LQR gain ([`Lqr`]) of the zero-order-hold linearisation
/// ([`Linearisation`]) of eq 15 about `(x_ref, u_ref)` over the controller period.
///
/// **Re-linearisation.** The gain is recomputed at the first sample of every
/// `relinearise_period` seconds of time (`floor(t / relinearise_period)` changes), about the
/// reference sample of that moment, and held in between; the feedforward is recomputed at every
/// sample. A Riccati solve takes thousands of iterations at a 0.1 ms period (its convergence
/// rate is the closed-loop pole `exp(-omega h / sqrt 2)` squared), so solving at every sample
/// would cost about a millisecond each; the reference moves little in 10 ms (the default), so
/// the gain of its linearisation changes little.
///
/// **Weights.** `Q = diag(omega^4 M0^2, 0)` on `(a - a_ref, a_dot - a_ref_dot)` and `R = I` on
/// `tau*`, with `M0 = M*(0)` the reduced mass matrix at `a = 0` (the straight backbone, any
/// `alpha0`). For the double integrator `M0 a_ddot = tau*` (eq 15 at rest without gravity) the
/// substitution `z = M0 e`, `w = M0 a_ddot` makes the cost `omega^4 |z|^2 + |w|^2`, whose
/// continuous optimum is `w = -omega^2 z - sqrt(2) omega z_dot` per coordinate: the gain
/// `K = M0 [omega^2 I, sqrt(2) omega I]`, a Butterworth pair of poles of radius `omega` in
/// every coordinate, whatever the coupling of `M0`. Gravity, the configuration dependence of
/// `M*` and the discretisation move the poles from there, and the LQR accounts for them.
///
/// Every buffer is sized at construction; [`control`](Controller::control) allocates nothing.
#[derive(Debug, Clone)]
pub struct LqrController {
    m: usize,
    period: f64,
    relinearise_period: f64,
    data: PlantData,
    linearisation: Linearisation,
    lqr: Lqr,
    settings: LqrSettings,
    /// `floor(t / relinearise_period)` of the gain in use; `None` before the first solve.
    slot: Option<f64>,
    x: Vec<f64>,
    x_ref: Vec<f64>,
    u_ref: Vec<f64>,
}

impl LqrController {
    /// The default design frequency `omega` (rad/s): the computed-torque default's 50 rad/s.
    pub const DEFAULT_FREQUENCY: f64 = 50.0;
    /// The default re-linearisation period (s).
    pub const DEFAULT_RELINEARISE_PERIOD: f64 = 0.01;

    /// Checks the settings [`new`](Self::new) takes, naming the scenario key that fails: a
    /// design frequency positive and at most `1e4` rad/s, a re-linearisation period positive and
    /// at least the controller period (itself positive). A scenario checks them whichever
    /// controller it runs, since a sweep may run this one on it.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming `controller.period`, `controller.lqr_frequency` or
    /// `controller.lqr_relinearise`.
    pub fn check_settings(
        period: f64,
        frequency: f64,
        relinearise_period: f64,
    ) -> Result<(), SimError> {
        check_positive("controller.period", period)?;
        check_positive("controller.lqr_frequency", frequency)?;
        if frequency > MAX_FREQUENCY {
            return Err(SimError::setting(
                "controller.lqr_frequency",
                format!(
                    "must be at most {MAX_FREQUENCY:e} rad/s, got {}",
                    Compact(frequency)
                ),
            ));
        }
        check_positive("controller.lqr_relinearise", relinearise_period)?;
        if relinearise_period < period {
            return Err(SimError::setting(
                "controller.lqr_relinearise",
                format!(
                    "must be at least the controller period ({} s), got {} s",
                    Compact(period),
                    Compact(relinearise_period)
                ),
            ));
        }
        Ok(())
    }

    /// An LQR for `model`'s `m` coordinates sampled every `period` seconds, with design
    /// frequency `frequency` (rad/s, at most 1e4) and a new linearisation every
    /// `relinearise_period` seconds (at least `period`).
    ///
    /// ```
    /// use backbone_kin::{BaseAngle, ModalMap};
    /// use manip_dyn::ChainModel;
    /// use modal_reduce::ReducedModel;
    /// use sim_core::controller::{ControlContext, Controller, LqrController, ModalState};
    /// use sim_core::reference::ReferenceSample;
    ///
    /// let map = ModalMap::uniform(10, 1, BaseAngle::Fixed(1.5))?;
    /// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, map)?;
    /// let mut lqr = LqrController::new(&model, 1e-3, 50.0, 0.01)?;
    /// let (measured, reference) = (ModalState::zeros(2), ReferenceSample::zeros(2));
    /// let ctx = ControlContext {
    ///     t: 0.0,
    ///     measured: &measured,
    ///     reference: &reference,
    ///     model: (&model).into(),
    ///     tau_star_limits: None,
    /// };
    /// let mut tau = [0.0; 2];
    /// lqr.control(&ctx, &mut tau)?;
    /// // On the reference, at rest: the feedforward alone, which holds the arm (G*).
    /// assert!(tau.iter().any(|t| t.abs() > 1e-3));
    /// # Ok::<(), sim_core::controller::ControllerError>(())
    /// ```
    pub fn new<'p>(
        model: impl Into<Plant<'p>>,
        period: f64,
        frequency: f64,
        relinearise_period: f64,
    ) -> Result<Self, SimError> {
        let model = model.into();
        let m = model.n_coords();
        check_coordinate_count("controller", m)?;
        Self::check_settings(period, frequency, relinearise_period)?;
        let mut data = PlantData::new(model);
        model
            .terms(&mut data, &vec![0.0; m], &vec![0.0; m])
            .map_err(|source| SimError::Dynamics { t: 0.0, source })?;
        let (n, w4) = (2 * m, frequency.powi(4));
        let mass = data.mass_matrix();
        let mut q = vec![0.0; n * n];
        for i in 0..m {
            for j in 0..m {
                let square: f64 = (0..m).map(|k| mass[(i, k)] * mass[(k, j)]).sum();
                q[i * n + j] = w4 * square;
            }
        }
        symmetrise(&mut q, n);
        let mut r = vec![0.0; m * m];
        for i in 0..m {
            r[i * m + i] = 1.0;
        }
        let lqr = Lqr::new(m, &q, &r)
            .map_err(|e| SimError::setting("controller", format!("cannot weigh the LQR: {e}")))?;
        Ok(Self {
            m,
            period,
            relinearise_period,
            data,
            linearisation: Linearisation::new(model),
            lqr,
            settings: LqrSettings {
                max_iterations: 1_000_000,
                ..LqrSettings::default()
            },
            slot: None,
            x: vec![0.0; n],
            x_ref: vec![0.0; n],
            u_ref: vec![0.0; m],
        })
    }

    /// The gain `K` (`m x 2m`, row-major as [`Lqr::gain`]) in use; zeros before the first sample.
    pub fn gain(&self) -> manip_dyn::faer::MatRef<'_, f64> {
        self.lqr.gain()
    }
}

impl Controller for LqrController {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        let m = self.m;
        check_context(ctx, m, tau_star)?;
        let (measured, reference) = (ctx.measured, ctx.reference);
        let t = ctx.t;
        // The feedforward: eq 15 along the reference.
        ctx.model
            .terms(&mut self.data, &reference.a, &reference.a_dot)
            .map_err(|source| SimError::Dynamics { t, source })?;
        let mass = self.data.mass_matrix();
        let (c, g) = (self.data.coriolis(), self.data.gravity());
        for i in 0..m {
            let mut sum = 0.0;
            for j in 0..m {
                sum += mass[(i, j)] * reference.a_ddot[j];
            }
            self.u_ref[i] = sum + c[i] + g[i];
        }
        let slot = (t / self.relinearise_period).floor();
        if self.slot != Some(slot) {
            self.linearisation
                .linearise(
                    ctx.model,
                    &reference.a,
                    &reference.a_dot,
                    &self.u_ref,
                    self.period,
                )
                .and_then(|()| self.lqr.solve(&self.linearisation, &self.settings))?;
            self.slot = Some(slot);
        }
        self.x[..m].copy_from_slice(&measured.a);
        self.x[m..].copy_from_slice(&measured.a_dot);
        self.x_ref[..m].copy_from_slice(&reference.a);
        self.x_ref[m..].copy_from_slice(&reference.a_dot);
        self.lqr
            .control(&self.u_ref, &self.x, &self.x_ref, tau_star)?;
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.m)
    }
}
