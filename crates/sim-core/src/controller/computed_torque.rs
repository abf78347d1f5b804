//! Computed torque (inverse dynamics) with the exact reduced model.

use super::{Controller, ModalState};
use crate::error::{SimError, check_non_negative};
use crate::reference::ReferenceSample;
use modal_reduce::{ReducedData, ReducedModel};

/// `tau* = M*(a) (a_ref_dd - kp (a - a_ref) - kd (a_dot - a_ref_dot)) + C*(a, a_dot) + G*(a)`
/// (eq 15 solved for the torque), with the exact reduced model: with a perfect model and
/// continuous control the error obeys `e'' + kd e' + kp e = 0` in each coordinate.
#[derive(Debug, Clone)]
pub struct ComputedTorque {
    model: ReducedModel,
    data: ReducedData,
    kp: [f64; 2],
    kd: [f64; 2],
}

impl ComputedTorque {
    /// Computed torque on `model` (two coordinates, `alpha0` fixed) with stiffness `kp` (1/s^2)
    /// and damping `kd` (1/s) per coordinate, both non-negative.
    pub fn new(model: ReducedModel, kp: [f64; 2], kd: [f64; 2]) -> Result<Self, SimError> {
        check_two_coordinates(&model)?;
        for k in kp {
            check_non_negative("controller.kp", k)?;
        }
        for k in kd {
            check_non_negative("controller.kd", k)?;
        }
        let data = ReducedData::new(&model);
        Ok(Self {
            model,
            data,
            kp,
            kd,
        })
    }
}

impl Controller for ComputedTorque {
    fn control(
        &mut self,
        t: f64,
        measured: &ModalState,
        reference: &ReferenceSample,
    ) -> Result<[f64; 2], SimError> {
        modal_reduce::reduced_terms(&self.model, &mut self.data, &measured.a, &measured.a_dot)
            .map_err(|source| SimError::Dynamics { t, source })?;
        let desired: [f64; 2] = std::array::from_fn(|i| {
            reference.a_ddot[i]
                - self.kp[i] * (measured.a[i] - reference.a[i])
                - self.kd[i] * (measured.a_dot[i] - reference.a_dot[i])
        });
        let mass = self.data.mass_matrix();
        let (c, g) = (self.data.coriolis(), self.data.gravity());
        Ok(std::array::from_fn(|i| {
            mass[(i, 0)] * desired[0] + mass[(i, 1)] * desired[1] + c[i] + g[i]
        }))
    }
}

/// Checks that `model` has the two coordinates `(a1, a2)` the controllers act on.
pub(super) fn check_two_coordinates(model: &ReducedModel) -> Result<(), SimError> {
    if model.n_coords() == 2 {
        Ok(())
    } else {
        Err(SimError::setting(
            "model",
            format!(
                "must have the two coordinates (a1, a2) with alpha0 fixed, it has {}",
                model.n_coords()
            ),
        ))
    }
}
