//! The paper's fuzzy controller (Figure 8), optionally with gravity compensation.

use super::{Controller, ModalState, fuzzy_inputs};
use crate::error::SimError;
use crate::reference::ReferenceSample;
use fuzzy_sugeno::{Evaluator, FuzzySystem};
use modal_reduce::{ReducedData, ReducedModel};

/// A Takagi-Sugeno system with inputs `[a1 - a1_ref, a2 - a2_ref, a1_dot, a2_dot]` and outputs
/// `[tau1*, tau2*]`: the paper's controller ([`fuzzy_sugeno::paper_controller`]) or any system
/// of that shape, e.g. loaded from a `.fis` file. Inputs outside a variable's range are clamped
/// to it (the evaluator's default), so large errors saturate the action.
///
/// With gravity compensation ("fuzzy-gc") the reduced gravity vector `G*(a)` of the measured
/// configuration is added to the fuzzy output.
#[derive(Debug, Clone)]
pub struct FuzzyController {
    evaluator: Evaluator,
    gravity: Option<(ReducedModel, ReducedData)>,
}

impl FuzzyController {
    /// The fuzzy controller `system`; fails unless it has 4 inputs and 2 outputs.
    ///
    /// ```
    /// use sim_core::controller::{Controller, FuzzyController, ModalState};
    /// use sim_core::reference::ReferenceSample;
    /// let mut fuzzy = FuzzyController::new(fuzzy_sugeno::paper_controller())?;
    /// // Above the reference in a1: push back.
    /// let measured = ModalState { a: [0.1, 0.0], a_dot: [0.0, 0.0] };
    /// let tau = fuzzy.control(0.0, &measured, &ReferenceSample::default())?;
    /// assert!(tau[0] < 0.0 && tau[1].abs() < 1e-12);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(system: FuzzySystem) -> Result<Self, SimError> {
        check_shape(&system)?;
        Ok(Self {
            evaluator: Evaluator::new(system),
            gravity: None,
        })
    }

    /// The same controller plus the gravity compensation `G*(a)` of `model` (two coordinates,
    /// `alpha0` fixed).
    pub fn with_gravity_compensation(mut self, model: ReducedModel) -> Result<Self, SimError> {
        super::computed_torque::check_two_coordinates(&model)?;
        let data = ReducedData::new(&model);
        self.gravity = Some((model, data));
        Ok(self)
    }

    /// The fuzzy system.
    pub fn system(&self) -> &FuzzySystem {
        self.evaluator.system()
    }
}

impl Controller for FuzzyController {
    fn control(
        &mut self,
        t: f64,
        measured: &ModalState,
        reference: &ReferenceSample,
    ) -> Result<[f64; 2], SimError> {
        let mut tau = [0.0; 2];
        self.evaluator
            .eval(&fuzzy_inputs(measured, reference), &mut tau)?;
        if let Some((model, data)) = &mut self.gravity {
            modal_reduce::reduced_terms(model, data, &measured.a, &measured.a_dot)
                .map_err(|source| SimError::Dynamics { t, source })?;
            tau[0] += data.gravity()[0];
            tau[1] += data.gravity()[1];
        }
        Ok(tau)
    }
}

/// Checks that `system` maps `[da1, da2, a1_dot, a2_dot]` to `[tau1*, tau2*]`.
pub(super) fn check_shape(system: &FuzzySystem) -> Result<(), SimError> {
    let (inputs, outputs) = (system.inputs().len(), system.outputs().len());
    if (inputs, outputs) == (4, 2) {
        Ok(())
    } else {
        Err(SimError::setting(
            "controller.fis",
            format!(
                "must have 4 inputs [da1, da2, a1_dot, a2_dot] and 2 outputs [tau1, tau2], \
                 '{}' has {inputs} inputs and {outputs} outputs",
                system.name()
            ),
        ))
    }
}
