//! A linear controller with the fuzzy controller's inputs: its linearisation at the origin.

use super::{Controller, ModalState, fuzzy_inputs};
use crate::error::SimError;
use crate::reference::ReferenceSample;
use fuzzy_sugeno::{Evaluator, FuzzySystem};

/// Relative step of the central differences that linearise a fuzzy system, as a fraction of
/// each input's range width.
const SLOPE_STEP: f64 = 1e-6;

/// `tau* = offset + K x` with `x = [a1 - a1_ref, a2 - a2_ref, a1_dot, a2_dot]` and a 2 x 4 gain
/// matrix `K`: a PD law on the fuzzy controller's own inputs.
///
/// [`from_fuzzy_slope`](Self::from_fuzzy_slope) takes `offset` and `K` from a fuzzy system's
/// value and slope at the origin, so the two controllers agree for small errors and rates and
/// differ only by the fuzzy system's nonlinearity (saturation). For the paper's controller
/// `K = [[-600, 0, -20, 0], [0, -300, 0, -10]]` (N m/rad, N m s/rad) and the offset is zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PdController {
    offset: [f64; 2],
    gains: [[f64; 4]; 2],
}

impl PdController {
    /// A PD law with the given offset (N m) and gains; all must be finite.
    pub fn new(offset: [f64; 2], gains: [[f64; 4]; 2]) -> Result<Self, SimError> {
        crate::error::check_finite("controller offset", &offset)?;
        crate::error::check_finite("controller gains", gains.as_flattened())?;
        Ok(Self { offset, gains })
    }

    /// The linearisation of `system` (4 inputs, 2 outputs) at the origin, by central differences
    /// with steps of `1e-6` of each input's range width.
    ///
    /// ```
    /// use sim_core::controller::PdController;
    /// let pd = PdController::from_fuzzy_slope(&fuzzy_sugeno::paper_controller())?;
    /// // d tau1 / d da1 = -180 / 0.3 N m/rad for the paper's bells (see the type's docs).
    /// assert!((pd.gains()[0][0] + 600.0).abs() < 1e-6);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn from_fuzzy_slope(system: &FuzzySystem) -> Result<Self, SimError> {
        super::fuzzy::check_shape(system)?;
        let mut evaluator = Evaluator::new(system.clone());
        let mut offset = [0.0; 2];
        evaluator.eval(&[0.0; 4], &mut offset)?;
        let mut gains = [[0.0; 4]; 2];
        for (j, input) in system.inputs().iter().enumerate() {
            let h = SLOPE_STEP * (input.range[1] - input.range[0]);
            let (mut x, mut plus, mut minus) = ([0.0; 4], [0.0; 2], [0.0; 2]);
            x[j] = h;
            evaluator.eval(&x, &mut plus)?;
            x[j] = -h;
            evaluator.eval(&x, &mut minus)?;
            for i in 0..2 {
                gains[i][j] = (plus[i] - minus[i]) / (2.0 * h);
            }
        }
        Self::new(offset, gains)
    }

    /// The gain matrix `K` (row `i` gives `tau_i*`).
    pub fn gains(&self) -> [[f64; 4]; 2] {
        self.gains
    }

    /// The constant term (N m).
    pub fn offset(&self) -> [f64; 2] {
        self.offset
    }
}

impl Controller for PdController {
    fn control(
        &mut self,
        _t: f64,
        measured: &ModalState,
        reference: &ReferenceSample,
    ) -> Result<[f64; 2], SimError> {
        let x = fuzzy_inputs(measured, reference);
        Ok(std::array::from_fn(|i| {
            self.offset[i] + (0..4).map(|j| self.gains[i][j] * x[j]).sum::<f64>()
        }))
    }
}
