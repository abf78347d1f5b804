//! Controllers of the two modal coordinates `(a1, a2)`, behind one trait: the paper's fuzzy
//! controller (eqs 19-24, Figure 8), its linearisation at the origin (PD), computed torque with
//! the exact reduced model, and the fuzzy controller plus gravity compensation `G*`.
//!
//! The closed loop samples a controller at its own period and holds its output in between
//! (zero-order hold).

mod computed_torque;
mod fuzzy;
mod pd;

pub use computed_torque::ComputedTorque;
pub use fuzzy::FuzzyController;
pub use pd::PdController;

use crate::error::SimError;
use crate::reference::ReferenceSample;

/// The modal state as the controller measures it (possibly with sensor noise).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ModalState {
    /// `(a1, a2)` (rad).
    pub a: [f64; 2],
    /// `(a1_dot, a2_dot)` (rad/s).
    pub a_dot: [f64; 2],
}

/// A feedback law producing the modal generalized forces `tau* = (tau1*, tau2*)` (N m).
pub trait Controller: Send {
    /// The modal torques at time `t` for the measured state and the (possibly noisy) reference.
    fn control(
        &mut self,
        t: f64,
        measured: &ModalState,
        reference: &ReferenceSample,
    ) -> Result<[f64; 2], SimError>;
}

/// The fuzzy controller's input vector `[a1 - a1_ref, a2 - a2_ref, a1_dot, a2_dot]`: measured
/// minus desired, the sign that makes Table 1 stabilising (model notes).
fn fuzzy_inputs(measured: &ModalState, reference: &ReferenceSample) -> [f64; 4] {
    [
        measured.a[0] - reference.a[0],
        measured.a[1] - reference.a[1],
        measured.a_dot[0],
        measured.a_dot[1],
    ]
}
