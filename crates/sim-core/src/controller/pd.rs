//! A linear controller with the fuzzy controller's inputs: its linearisation at the origin.

use super::fuzzy::Layout;
use super::{
    ControlContext, Controller, ControllerError, ModalState, check_context, check_coordinate_count,
};
use crate::error::SimError;
use crate::reference::ReferenceSample;
use fuzzy_sugeno::{Evaluator, FuzzySystem};
use lane_math::check_all_finite;

/// Relative step of the central differences that linearise a fuzzy system, as a fraction of
/// each input's range width.
const SLOPE_STEP: f64 = 1e-6;

/// `tau_i* = offset_i - kp_i (a_i - a_i_ref) - kd_i a_i_dot` for each coordinate `i`: a PD law
/// on the fuzzy controller's own inputs, with per-coordinate gains.
///
/// [`from_fuzzy_slope`](Self::from_fuzzy_slope) takes the offsets and gains from a fuzzy
/// system's value and slope at the origin, so the two controllers agree for small errors and
/// rates and differ only by the fuzzy system's nonlinearity (saturation). For the paper's
/// controller `kp = (600, 300)` N m/rad, `kd = (20, 10)` N m s/rad and the offset is zero.
#[derive(Debug, Clone, PartialEq)]
pub struct PdController {
    offset: Vec<f64>,
    kp: Vec<f64>,
    kd: Vec<f64>,
}

impl PdController {
    /// A PD law with the given offsets (N m) and gains (N m/rad, N m s/rad), one per coordinate;
    /// all finite, of equal lengths.
    ///
    /// ```
    /// use sim_core::controller::PdController;
    /// let pd = PdController::new(&[0.0; 3], &[50.0, 50.0, 80.0], &[5.0, 5.0, 8.0])?;
    /// assert_eq!(pd.kp(), &[50.0, 50.0, 80.0]);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(offset: &[f64], kp: &[f64], kd: &[f64]) -> Result<Self, SimError> {
        check_coordinate_count("controller", kp.len())?;
        for (name, values) in [
            ("controller offset", offset),
            ("controller.pd_kp", kp),
            ("controller.pd_kd", kd),
        ] {
            check_all_finite(name, values)?;
            if values.len() != kp.len() {
                return Err(SimError::setting(
                    name,
                    format!(
                        "has {} entries, the controller has {}",
                        values.len(),
                        kp.len()
                    ),
                ));
            }
        }
        Ok(Self {
            offset: offset.to_vec(),
            kp: kp.to_vec(),
            kd: kd.to_vec(),
        })
    }

    /// The linearisation of the fuzzy controller `system` on `m` coordinates (see
    /// [`FuzzyController`](super::FuzzyController) for the shapes it accepts) at the origin:
    /// each coordinate's offset and its own error and rate slopes (the diagonal of the
    /// Jacobian), by central differences with steps of `1e-6` of each input's range width.
    /// The state is perturbed with the reference at rest at zero, so for a scheduled (learned)
    /// system the error slope includes the slope in the coordinate input `a_i`.
    ///
    /// ```
    /// use sim_core::controller::PdController;
    /// let pd = PdController::from_fuzzy_slope(&fuzzy_sugeno::paper_controller(), 2)?;
    /// // d tau1 / d da1 = -180 / 0.3 N m/rad for the paper's bells (see the type's docs).
    /// assert!((pd.kp()[0] - 600.0).abs() < 1e-6);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn from_fuzzy_slope(system: &FuzzySystem, m: usize) -> Result<Self, SimError> {
        let layout = Layout::of(system, m)?;
        let mut evaluator = Evaluator::new(system.clone());
        let mut scratch = vec![0.0; layout.n_inputs(m)];
        let mut tau = vec![0.0; m];
        // At the origin: the reference at rest at zero, the state perturbed.
        let reference = ReferenceSample::zeros(m);
        let mut state = ModalState::zeros(m);
        let mut eval = |evaluator: &mut Evaluator, state: &ModalState, tau: &mut [f64]| {
            layout.eval(evaluator, state, &reference, &mut scratch, tau)
        };
        eval(&mut evaluator, &state, &mut tau)?;
        let offset = tau.clone();
        let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
        let mut slopes = [vec![0.0; m], vec![0.0; m]];
        for (r, slope) in slopes.iter_mut().enumerate() {
            let rate = r == 1;
            for i in 0..m {
                let range = system.inputs()[layout.input_index(i, m, rate)].range;
                let h = SLOPE_STEP * (range[1] - range[0]);
                let set = |state: &mut ModalState, v: f64| {
                    if rate {
                        state.a_dot[i] = v;
                    } else {
                        state.a[i] = v;
                    }
                };
                set(&mut state, h);
                eval(&mut evaluator, &state, &mut plus)?;
                set(&mut state, -h);
                eval(&mut evaluator, &state, &mut minus)?;
                set(&mut state, 0.0);
                slope[i] = -(plus[i] - minus[i]) / (2.0 * h);
            }
        }
        let [kp, kd] = slopes;
        Self::new(&offset, &kp, &kd)
    }

    /// The stiffness per coordinate (N m/rad).
    pub fn kp(&self) -> &[f64] {
        &self.kp
    }

    /// The damping per coordinate (N m s/rad).
    pub fn kd(&self) -> &[f64] {
        &self.kd
    }

    /// The constant term per coordinate (N m).
    pub fn offset(&self) -> &[f64] {
        &self.offset
    }
}

impl Controller for PdController {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        check_context(ctx, self.kp.len(), tau_star)?;
        let (measured, reference) = (ctx.measured, ctx.reference);
        for (i, tau) in tau_star.iter_mut().enumerate() {
            *tau = self.offset[i]
                - self.kp[i] * (measured.a[i] - reference.a[i])
                - self.kd[i] * measured.a_dot[i];
        }
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.kp.len())
    }
}
