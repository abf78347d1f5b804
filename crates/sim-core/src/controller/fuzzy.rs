//! The paper's fuzzy controller (Figure 8), for any number of modal coordinates, optionally with
//! gravity compensation; and the input layout of controllers learned by imitation.

use super::{
    ControlContext, Controller, ControllerError, ModalState, check_context, check_coordinate_count,
};
use crate::error::SimError;
use crate::reference::ReferenceSample;
use fuzzy_sugeno::{EvalOptions, Evaluator, FuzzySystem, OutOfRange, OutsideRange};
use modal_reduce::{Plant, PlantData};

/// How a fuzzy system's inputs and outputs sit on the `m` coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Layout {
    /// One system over all coordinates: inputs `[a_1 - a_1_ref, ..., a_m - a_m_ref, a_1_dot,
    /// ..., a_m_dot]`, outputs `[tau_1*, ..., tau_m*]`.
    Whole,
    /// A two-coordinate system (4 inputs, 2 outputs, the paper's shape) applied to the pairs
    /// `(a_1, a_2), (a_3, a_4), ...`; with `m` odd the last coordinate takes the first slot of a
    /// pair whose second slot is zero.
    Pairs,
    /// One system over all coordinates with the [`scheduled_inputs`] (`4m` inputs), outputs
    /// `[tau_1*, ..., tau_m*]`: the layout of controllers learned by imitation.
    Scheduled,
}

/// The number of inputs per modal coordinate of a scheduled `.fis`, the `4m`-input layout of a
/// learned controller.
pub const SCHEDULED_INPUTS_PER_COORDINATE: usize = 4;

/// Writes the `4m` inputs of a scheduled fuzzy controller into `out`: per coordinate the error
/// `a_i - a_i_ref`, the error rate `a_i_dot - a_i_ref_dot`, the coordinate `a_i` and the reference
/// acceleration `a_i_ref_ddot`, in four blocks of `m`:
/// `[da_1..da_m, da_1_dot..da_m_dot, a_1..a_m, a_1_ref_ddot..a_m_ref_ddot]`.
///
/// They are the quantities computed torque (eq 15 solved for `tau*`) is made of: its torque
/// `M*(a) (a_ref_ddot - kp da - kd da_dot) + C*(a, a_dot) + G*(a)` is linear in the errors and
/// the reference acceleration with coefficients that depend on the configuration `a`, so a
/// first-order Sugeno system whose rules partition `a` and whose linear consequents take all four
/// blocks can reproduce it (gain scheduling).
pub fn scheduled_inputs(measured: &ModalState, reference: &ReferenceSample, out: &mut [f64]) {
    let m = measured.a.len();
    for i in 0..m {
        out[i] = measured.a[i] - reference.a[i];
        out[m + i] = measured.a_dot[i] - reference.a_dot[i];
        out[2 * m + i] = measured.a[i];
        out[3 * m + i] = reference.a_ddot[i];
    }
}

impl Layout {
    /// The layout of `system` on `m` coordinates.
    pub(super) fn of(system: &FuzzySystem, m: usize) -> Result<Self, SimError> {
        check_coordinate_count("controller", m)?;
        let (inputs, outputs) = (system.inputs().len(), system.outputs().len());
        if (inputs, outputs) == (2 * m, m) {
            Ok(Layout::Whole)
        } else if (inputs, outputs) == (4, 2) {
            Ok(Layout::Pairs)
        } else if (inputs, outputs) == (SCHEDULED_INPUTS_PER_COORDINATE * m, m) {
            Ok(Layout::Scheduled)
        } else {
            Err(SimError::setting(
                "controller.fis",
                format!(
                    "must have {} inputs [da_1..da_{m}, a_1_dot..a_{m}_dot] and {m} outputs \
                     [tau_1..tau_{m}] for {m} modal coordinates (or 4 inputs and 2 outputs, \
                     applied per coordinate pair, or {} inputs [da, da_dot, a, a_ref_ddot] of a \
                     learned controller), '{}' has {inputs} inputs and {outputs} outputs",
                    2 * m,
                    SCHEDULED_INPUTS_PER_COORDINATE * m,
                    system.name()
                ),
            ))
        }
    }

    /// The system input that receives the error (`rate = false`) or the rate (the error rate
    /// for [`Layout::Scheduled`]) of coordinate `i` of `m`.
    pub(super) fn input_index(self, i: usize, m: usize, rate: bool) -> usize {
        match self {
            Layout::Whole | Layout::Scheduled => i + if rate { m } else { 0 },
            Layout::Pairs => i % 2 + if rate { 2 } else { 0 },
        }
    }

    /// The number of system inputs for `m` coordinates (the size of [`eval`](Self::eval)'s
    /// scratch).
    pub(super) fn n_inputs(self, m: usize) -> usize {
        match self {
            Layout::Whole => 2 * m,
            Layout::Pairs => 4,
            Layout::Scheduled => SCHEDULED_INPUTS_PER_COORDINATE * m,
        }
    }

    /// Evaluates `evaluator` on the `measured` state and the `reference` (the inputs measured
    /// minus desired, the sign that makes Table 1 stabilising), using `inputs` as scratch
    /// ([`n_inputs`](Self::n_inputs) entries).
    pub(super) fn eval(
        self,
        evaluator: &mut Evaluator,
        measured: &ModalState,
        reference: &ReferenceSample,
        inputs: &mut [f64],
        tau: &mut [f64],
    ) -> Result<(), fuzzy_sugeno::FuzzyError> {
        let m = tau.len();
        let da = |i: usize| measured.a[i] - reference.a[i];
        match self {
            Layout::Whole => {
                for i in 0..m {
                    inputs[i] = da(i);
                    inputs[m + i] = measured.a_dot[i];
                }
                evaluator.eval(&inputs[..2 * m], tau)
            }
            Layout::Pairs => {
                for (p, pair) in tau.chunks_mut(2).enumerate() {
                    let (i, j) = (2 * p, 2 * p + 1);
                    let mut out = [0.0; 2];
                    let second = |f: &dyn Fn(usize) -> f64| if j < m { f(j) } else { 0.0 };
                    let a_dot = |i: usize| measured.a_dot[i];
                    let x = [da(i), second(&da), a_dot(i), second(&a_dot)];
                    evaluator.eval(&x, &mut out)?;
                    pair.copy_from_slice(&out[..pair.len()]);
                }
                Ok(())
            }
            Layout::Scheduled => {
                let inputs = &mut inputs[..SCHEDULED_INPUTS_PER_COORDINATE * m];
                scheduled_inputs(measured, reference, inputs);
                evaluator.eval(inputs, tau)
            }
        }
    }
}

/// A Takagi-Sugeno controller of `m` modal coordinates: the paper's
/// ([`fuzzy_sugeno::paper_controller`]) or any system of the right shape, e.g. loaded from a
/// `.fis` file. Inputs outside a variable's range are clamped to it (the evaluator's default), so
/// large errors saturate the action.
///
/// A system with `2m` inputs `[a_1 - a_1_ref, ..., a_m - a_m_ref, a_1_dot, ..., a_m_dot]` and `m`
/// outputs is evaluated once per sample. A system of the paper's shape (4 inputs, 2 outputs) is
/// applied per coordinate pair: `(tau_{2k-1}*, tau_{2k}*)` from `(da_{2k-1}, da_{2k}, a_{2k-1}_dot,
/// a_{2k}_dot)`, so the paper's rule base (where each output depends on its own pair
/// `(da_i, a_i_dot)`) acts on the sine-type coordinates `a_{2k-1}` as on `a1` and on the
/// cosine-type `a_{2k}` as on `a2`; a free `alpha0` (the last of an odd `m`) is treated like `a1`.
/// For `m = 2` the two readings coincide: the paper's controller.
///
/// A system with `4m` inputs and `m` outputs, such as one learned by imitation
/// (`sim_study::imitation`), is evaluated once per sample on the errors, error rates, coordinates
/// and reference accelerations (`[da_1..da_m, da_1_dot..da_m_dot, a_1..a_m,
/// a_1_ref_ddot..a_m_ref_ddot]`).
///
/// With gravity compensation ("fuzzy-gc") the reduced gravity vector `G*(a)` of the measured
/// configuration is added to the fuzzy output.
#[derive(Debug, Clone)]
pub struct FuzzyController {
    evaluator: Evaluator,
    layout: Layout,
    m: usize,
    inputs: Vec<f64>,
    gravity: Option<PlantData>,
}

impl FuzzyController {
    /// The fuzzy controller `system` for `m` coordinates; fails unless it has `2m` inputs and
    /// `m` outputs, 4 inputs and 2 outputs (applied per pair), or `4m` inputs and `m` outputs
    /// (scheduled).
    ///
    /// ```
    /// use backbone_kin::ModalMap;
    /// use manip_dyn::ChainModel;
    /// use modal_reduce::ReducedModel;
    /// use sim_core::controller::{ControlContext, Controller, FuzzyController, ModalState};
    /// use sim_core::reference::ReferenceSample;
    ///
    /// let map = ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2)?;
    /// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, map)?;
    /// let mut fuzzy = FuzzyController::new(fuzzy_sugeno::paper_controller(), 2)?;
    /// // Above the reference in a1: push back.
    /// let measured = ModalState::new(&[0.1, 0.0], &[0.0, 0.0])?;
    /// let reference = ReferenceSample::zeros(2);
    /// let ctx = ControlContext {
    ///     t: 0.0,
    ///     measured: &measured,
    ///     reference: &reference,
    ///     model: (&model).into(),
    ///     tau_star_limits: None,
    /// };
    /// let mut tau = [0.0; 2];
    /// fuzzy.control(&ctx, &mut tau)?;
    /// assert!(tau[0] < 0.0 && tau[1].abs() < 1e-12);
    /// # Ok::<(), sim_core::controller::ControllerError>(())
    /// ```
    pub fn new(system: FuzzySystem, m: usize) -> Result<Self, SimError> {
        let layout = Layout::of(&system, m)?;
        Ok(Self {
            evaluator: Evaluator::new(system),
            layout,
            m,
            inputs: vec![0.0; layout.n_inputs(m)],
            gravity: None,
        })
    }

    /// The same controller plus the gravity compensation `G*(a)` of the loop's model; `model`
    /// (with the controller's `m` coordinates) sizes the workspace.
    pub fn with_gravity_compensation<'p>(
        mut self,
        model: impl Into<Plant<'p>>,
    ) -> Result<Self, SimError> {
        let (m, model) = (self.m, model.into());
        if model.n_coords() != m {
            return Err(SimError::setting(
                "model",
                format!(
                    "has {} coordinates, the fuzzy controller is built for {m}",
                    model.n_coords()
                ),
            ));
        }
        self.gravity = Some(PlantData::new(model));
        Ok(self)
    }

    /// The same controller evaluating inputs outside their ranges by `policy`; the default is
    /// MATLAB's [`OutOfRange::AsGiven`] (`evalfis`, Simulink's Fuzzy Logic Controller block).
    pub fn with_out_of_range(mut self, policy: OutOfRange) -> Result<Self, SimError> {
        let options = EvalOptions {
            out_of_range: policy,
            ..self.evaluator.options().clone()
        };
        self.evaluator = Evaluator::with_options(self.evaluator.system().clone(), options)?;
        Ok(self)
    }

    /// The first input evaluated outside its range, as given, if any (where MATLAB warns).
    pub fn first_outside_range(&self) -> Option<OutsideRange> {
        self.evaluator.first_outside_range()
    }

    /// The fuzzy system.
    pub fn system(&self) -> &FuzzySystem {
        self.evaluator.system()
    }
}

impl Controller for FuzzyController {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        check_context(ctx, self.m, tau_star)?;
        let (measured, reference) = (ctx.measured, ctx.reference);
        self.layout
            .eval(
                &mut self.evaluator,
                measured,
                reference,
                &mut self.inputs,
                tau_star,
            )
            .map_err(SimError::from)?;
        if let Some(data) = &mut self.gravity {
            ctx.model
                .terms(data, &measured.a, &measured.a_dot)
                .map_err(|source| SimError::Dynamics { t: ctx.t, source })?;
            for (tau, g) in tau_star.iter_mut().zip(data.gravity()) {
                *tau += g;
            }
        }
        Ok(())
    }

    fn n_coords(&self) -> Option<usize> {
        Some(self.m)
    }
}
