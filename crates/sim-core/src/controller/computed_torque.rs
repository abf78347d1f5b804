//! Computed torque (inverse dynamics) with the exact reduced model.

use super::{ControlContext, Controller, ControllerError, check_context};
use crate::error::{SimError, check_non_negative};
use modal_reduce::{Plant, PlantData};

/// `tau* = M*(a) (a_ref_dd - kp (a - a_ref) - kd (a_dot - a_ref_dot)) + C*(a, a_dot) + G*(a)`
/// (eq 15 solved for the torque), with the reduced model of the loop
/// ([`ControlContext::model`]): with a perfect model and continuous control the error obeys
/// `e'' + kd e' + kp e = 0` in each coordinate.
#[derive(Debug, Clone)]
pub struct ComputedTorque {
    data: PlantData,
    kp: Vec<f64>,
    kd: Vec<f64>,
    desired: Vec<f64>,
}

impl ComputedTorque {
    /// Computed torque for `model`'s `m` coordinates with stiffness `kp` (1/s^2) and damping
    /// `kd` (1/s) per coordinate, `m` entries each, non-negative. The model only sizes the
    /// controller's workspace; the loop lends it at every sample.
    ///
    /// ```
    /// use backbone_kin::{BaseAngle, ModalMap};
    /// use manip_dyn::ChainModel;
    /// use modal_reduce::ReducedModel;
    /// use sim_core::controller::{ComputedTorque, ControlContext, Controller, ModalState};
    /// use sim_core::reference::ReferenceSample;
    ///
    /// // Two harmonics, alpha0 free: m = 5.
    /// let map = ModalMap::uniform(10, 2, BaseAngle::Free)?;
    /// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, map)?;
    /// let mut ct = ComputedTorque::new(&model, &[2500.0; 5], &[100.0; 5])?;
    /// let (measured, reference) = (ModalState::zeros(5), ReferenceSample::zeros(5));
    /// let ctx = ControlContext {
    ///     t: 0.0,
    ///     measured: &measured,
    ///     reference: &reference,
    ///     model: (&model).into(),
    ///     tau_star_limits: None,
    /// };
    /// let mut tau = [0.0; 5];
    /// ct.control(&ctx, &mut tau)?;
    /// // At rest on the reference, computed torque holds the arm against gravity: tau* = G*.
    /// assert!(tau[4].abs() > 1.0);
    /// # Ok::<(), sim_core::controller::ControllerError>(())
    /// ```
    pub fn new<'p>(model: impl Into<Plant<'p>>, kp: &[f64], kd: &[f64]) -> Result<Self, SimError> {
        let model = model.into();
        let m = model.n_coords();
        for (name, gains) in [("controller.kp", kp), ("controller.kd", kd)] {
            if gains.len() != m {
                return Err(SimError::setting(
                    name,
                    format!("has {} entries, the model has {m} coordinates", gains.len()),
                ));
            }
            for &k in gains {
                check_non_negative(name, k)?;
            }
        }
        Ok(Self {
            data: PlantData::new(model),
            kp: kp.to_vec(),
            kd: kd.to_vec(),
            desired: vec![0.0; m],
        })
    }
}

impl Controller for ComputedTorque {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        let m = self.kp.len();
        check_context(ctx, m, tau_star)?;
        let (measured, reference) = (ctx.measured, ctx.reference);
        ctx.model
            .terms(&mut self.data, &measured.a, &measured.a_dot)
            .map_err(|source| SimError::Dynamics { t: ctx.t, source })?;
        for i in 0..m {
            self.desired[i] = reference.a_ddot[i]
                - self.kp[i] * (measured.a[i] - reference.a[i])
                - self.kd[i] * (measured.a_dot[i] - reference.a_dot[i]);
        }
        let mass = self.data.mass_matrix();
        let (c, g) = (self.data.coriolis(), self.data.gravity());
        for (i, tau) in tau_star.iter_mut().enumerate() {
            // Summed in coordinate order, as eq 15 is written.
            let mut sum = 0.0;
            for (j, d) in self.desired.iter().enumerate() {
                sum += mass[(i, j)] * d;
            }
            *tau = sum + c[i] + g[i];
        }
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.kp.len())
    }
}
