//! Allocation-free evaluation of a fuzzy system: singleton fuzzification, rule firing (product
//! or minimum AND, probabilistic sum or maximum OR, rule weights) and the centre-average
//! defuzzifier of eq 21.

use lane_math::Lane;

use crate::batch::BatchWorkspace;
use crate::error::FuzzyError;
use crate::kernel::{self, Workspace};
use crate::membership::MembershipFn;
use crate::system::{Defuzzification, FuzzySystem};

/// What to do with an input outside its variable's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutOfRange {
    /// Evaluate at the nearest end of the range. For a controller this saturates the action:
    /// bell and Gaussian sets decay on both sides, so evaluated as given a very large error
    /// *weakens* the action of the rule base (the paper's controller at
    /// `[-0.414, -0.263, 0.904, 0.246]`: 71.32 clamped, 75.94 as given; far enough out, every
    /// output tends to the average of the rules' conclusions).
    Clamp,
    /// Evaluate the membership functions at the value as given (the default): what MATLAB's
    /// `evalfis` and Simulink's Fuzzy Logic Controller block do, with a warning.
    /// [`Evaluator::first_outside_range`] tells the caller when this happened, so that it can
    /// warn as MATLAB does.
    #[default]
    AsGiven,
    /// Refuse with [`FuzzyError::InputOutOfRange`].
    Error,
}

/// What an output is when none of the rules that conclude on it fires (total strength 0).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum NoRuleFired {
    /// The middle of the output's range (the default). MATLAB's `evalfis` does the same: "No
    /// rules fired for Output 1. Defuzzified output value set to its mean range value", a
    /// warning by default (`evalfisOptions`' `NoRuleFiredMessage`).
    #[default]
    MiddleOfRange,
    /// One fixed value per output.
    Values(Vec<f64>),
    /// Refuse with [`FuzzyError::NoRuleFired`].
    Error,
}

/// The evaluation policies of an [`Evaluator`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EvalOptions {
    /// Inputs outside their range.
    pub out_of_range: OutOfRange,
    /// Outputs on which no rule fires.
    pub no_rule_fired: NoRuleFired,
}

impl EvalOptions {
    /// Checks the options for a system of `n_outputs` outputs: [`NoRuleFired::Values`] must hold
    /// one finite value per output.
    pub(crate) fn check(&self, n_outputs: usize) -> Result<(), FuzzyError> {
        if let NoRuleFired::Values(values) = &self.no_rule_fired {
            if values.len() != n_outputs {
                return Err(FuzzyError::FallbackCount {
                    expected: n_outputs,
                    found: values.len(),
                });
            }
            if let Some(&value) = values.iter().find(|v| !v.is_finite()) {
                return Err(FuzzyError::NonFiniteFallback { value });
            }
        }
        Ok(())
    }
}

/// Evaluates a [`FuzzySystem`] with its own scratch space: after [`Evaluator::new`], evaluating
/// allocates nothing. Clone it to evaluate on several threads.
///
/// One point at a time ([`eval`](Self::eval)) or many at once ([`eval_batch`](Self::eval_batch),
/// SIMD across points): both run the same kernel, so a point gives the same outputs either way.
///
/// ```
/// use fuzzy_sugeno::{paper_controller, Evaluator};
///
/// let mut controller = Evaluator::new(paper_controller());
/// let mut torques = [0.0; 2];
/// // [da1, da2, a1_dot, a2_dot] -> [tau1*, tau2*]
/// controller.eval(&[0.3, 0.0, 0.0, 0.0], &mut torques)?;
/// assert!((torques[0] + 80.0).abs() < 1e-12); // see the crate's tests for the hand calculation
/// assert_eq!(torques[1], 0.0);
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Evaluator {
    system: FuzzySystem,
    options: EvalOptions,
    /// The kernel's buffers for one point.
    one: Workspace<1>,
    /// The kernel's buffers for a group of points, and the instruction set.
    batch: BatchWorkspace,
    /// The first input evaluated outside its range under [`OutOfRange::AsGiven`].
    outside: Option<OutsideRange>,
}

/// An input evaluated outside its variable's range, as given ([`OutOfRange::AsGiven`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutsideRange {
    /// The input's index.
    pub index: usize,
    /// The value evaluated.
    pub value: f64,
}

impl Evaluator {
    /// An evaluator with the default [`EvalOptions`] (inputs as given, as MATLAB's `evalfis`
    /// evaluates them; middle of range when no rule fires).
    pub fn new(system: FuzzySystem) -> Self {
        let one = Workspace::new(&system);
        let batch = BatchWorkspace::new(&system);
        Self {
            system,
            options: EvalOptions::default(),
            one,
            batch,
            outside: None,
        }
    }

    /// An evaluator with the given options; fails if [`NoRuleFired::Values`] does not hold one
    /// finite value per output.
    pub fn with_options(system: FuzzySystem, options: EvalOptions) -> Result<Self, FuzzyError> {
        options.check(system.outputs().len())?;
        let mut evaluator = Self::new(system);
        evaluator.options = options;
        Ok(evaluator)
    }

    /// The system being evaluated.
    pub fn system(&self) -> &FuzzySystem {
        &self.system
    }

    /// The evaluation options.
    pub fn options(&self) -> &EvalOptions {
        &self.options
    }

    /// Evaluates the system: `inputs` has one value per input variable, `outputs` one slot per
    /// output variable. On error `outputs` is left untouched.
    pub fn eval(&mut self, inputs: &[f64], outputs: &mut [f64]) -> Result<(), FuzzyError> {
        eval_point(&self.system, &self.options, &mut self.one, inputs, outputs)?;
        self.note_outside(inputs);
        Ok(())
    }

    /// The first input this evaluator evaluated outside its range under
    /// [`OutOfRange::AsGiven`] (by [`eval`](Self::eval), [`eval_batch`](Self::eval_batch) or
    /// [`fire`](Self::fire)), if any: where MATLAB's `evalfis` warns that an input left its
    /// range. `None` under the other policies.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, Evaluator, OutsideRange};
    ///
    /// let mut controller = Evaluator::new(paper_controller());
    /// let mut torques = [0.0; 2];
    /// controller.eval(&[0.1, 0.0, 0.0, 0.0], &mut torques)?;
    /// assert_eq!(controller.first_outside_range(), None);
    /// // da1 = -0.414 is outside [-0.3, 0.3]: evaluated as given, as MATLAB does.
    /// controller.eval(&[-0.414, -0.263, 0.904, 0.246], &mut torques)?;
    /// assert_eq!(controller.first_outside_range(), Some(OutsideRange { index: 0, value: -0.414 }));
    /// assert!((torques[0] - 75.93).abs() < 0.01);
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn first_outside_range(&self) -> Option<OutsideRange> {
        self.outside
    }

    /// Records the first input of `rows` (rows of one value per input) outside its range, under
    /// [`OutOfRange::AsGiven`], until one is found.
    fn note_outside(&mut self, rows: &[f64]) {
        if self.outside.is_some() || self.options.out_of_range != OutOfRange::AsGiven {
            return;
        }
        let variables = self.system.inputs();
        self.outside = rows
            .iter()
            .zip(variables.iter().cycle())
            .enumerate()
            .find(|(_, (v, var))| **v < var.range[0] || **v > var.range[1])
            .map(|(k, (&value, _))| OutsideRange {
                index: k % variables.len(),
                value,
            });
    }

    /// Evaluates many input vectors: `inputs` holds rows of one value per input variable,
    /// `outputs` the matching rows of one slot per output, and row `i` of `outputs` gets what
    /// [`eval`](Self::eval) gives for row `i` of `inputs`, bit for bit.
    ///
    /// The rows are evaluated `W` at a time, SIMD across rows, `W` the number of `f64` lanes of
    /// the widest instruction set of the processor (8 with AVX-512, 4 with AVX2, chosen at run
    /// time); a group with a refused row, and the rows after the last whole group, are evaluated
    /// one at a time. An error names the failing row; the rows before it hold their results, that
    /// row and the ones after it are left untouched.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, Evaluator};
    ///
    /// let mut controller = Evaluator::new(paper_controller());
    /// let points: Vec<f64> = (0..4 * 13).map(|k| 0.1 * (k as f64).sin()).collect();
    /// let mut torques = vec![0.0; 2 * 13];
    /// controller.eval_batch(&points, &mut torques)?;
    /// let mut one = [0.0; 2];
    /// controller.eval(&points[4 * 12..], &mut one)?;
    /// assert_eq!(&torques[2 * 12..], one.as_slice());
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn eval_batch(&mut self, inputs: &[f64], outputs: &mut [f64]) -> Result<(), FuzzyError> {
        let (n_in, n_out) = (self.system.inputs().len(), self.system.outputs().len());
        let rows = inputs.len() / n_in;
        if rows * n_in != inputs.len() {
            return Err(FuzzyError::BatchLength {
                len: inputs.len(),
                inputs: n_in,
            });
        }
        if outputs.len() != rows * n_out {
            return Err(FuzzyError::OutputCount {
                expected: rows * n_out,
                found: outputs.len(),
            });
        }
        let (system, options, one) = (&self.system, &self.options, &mut self.one);
        let point = |x: &[f64], y: &mut [f64]| eval_point(system, options, one, x, y);
        let result = self.batch.run(system, options, inputs, outputs, point);
        // The rows evaluated: all of them, or those before the failing one.
        let done = match &result {
            Ok(()) => rows,
            Err(FuzzyError::Batch { row, .. }) => *row,
            Err(_) => 0,
        };
        self.note_outside(&inputs[..done * n_in]);
        result
    }

    /// Computes and returns every rule's firing strength at `inputs` (antecedents combined by
    /// the rule's AND/OR, times the rule's weight), in rule order.
    pub fn fire(&mut self, inputs: &[f64]) -> Result<&[f64], FuzzyError> {
        fire_point(&self.system, &self.options, &mut self.one, inputs)?;
        self.note_outside(inputs);
        Ok(self.firing_strengths())
    }

    /// The firing strengths computed by the last [`fire`](Self::fire) (zeros before the first).
    /// [`eval`](Self::eval) computes them too, except for a system whose rules are a complete
    /// grid with a separable form (such as the paper's controller), which it evaluates without
    /// them: call `fire` to read the strengths at a point.
    pub fn firing_strengths(&self) -> &[f64] {
        let c = self.system.compiled();
        self.one.values[c.strength_base..c.slot_count].as_flattened()
    }
}

/// Checks one point's inputs, applies the range policy into `work.x` and fires the rules.
#[inline]
fn fire_point(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
) -> Result<(), FuzzyError> {
    load_inputs(system, options, work, inputs)?;
    let methods = system.methods();
    kernel::fire::<f64, 1>(
        (),
        system.compiled(),
        methods.and,
        methods.or,
        &mut work.slots(),
    );
    Ok(())
}

/// Checks one point's inputs and applies the range policy into `work.x`.
#[inline(always)]
fn load_inputs(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
) -> Result<(), FuzzyError> {
    let variables = system.inputs();
    if inputs.len() != variables.len() {
        return Err(FuzzyError::InputCount {
            expected: variables.len(),
            found: inputs.len(),
        });
    }
    for (index, (slot, &value)) in work.x.iter_mut().zip(inputs).enumerate() {
        slot[0] = load_input(system, options, index, value)?;
    }
    Ok(())
}

/// [`Evaluator::eval`] with the evaluator's parts.
#[inline]
fn eval_point(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
    outputs: &mut [f64],
) -> Result<(), FuzzyError> {
    let n_out = system.outputs().len();
    if outputs.len() != n_out {
        return Err(FuzzyError::OutputCount {
            expected: n_out,
            found: outputs.len(),
        });
    }
    load_inputs(system, options, work, inputs)?;
    let c = system.compiled();
    if !kernel::separable_sums::<f64, 1>((), c, &mut work.slots()) {
        let methods = system.methods();
        kernel::fire::<f64, 1>((), c, methods.and, methods.or, &mut work.slots());
        kernel::sums::<f64, 1>((), c, &mut work.slots());
    }
    // Every output is checked before the first is written; each replaces its weighted sum.
    for (o, pair) in work.sums.chunks_exact_mut(2).enumerate() {
        pair[0][0] = output_value(system, options, o, pair[0][0], pair[1][0])?;
    }
    for (out, pair) in outputs.iter_mut().zip(work.sums.chunks_exact(2)) {
        *out = pair[0][0];
    }
    Ok(())
}

/// Input `index` after the range policy; refuses a non-finite value, and one out of range under
/// [`OutOfRange::Error`].
#[inline(always)]
pub(crate) fn load_input(
    system: &FuzzySystem,
    options: &EvalOptions,
    index: usize,
    value: f64,
) -> Result<f64, FuzzyError> {
    let variable = &system.inputs()[index];
    if !value.is_finite() {
        return Err(FuzzyError::NonFiniteInput {
            index,
            name: variable.name.clone(),
            value,
        });
    }
    let [min, max] = variable.range;
    Ok(match options.out_of_range {
        OutOfRange::Clamp => value.clamp(min, max),
        OutOfRange::AsGiven => value,
        OutOfRange::Error if value < min || value > max => {
            return Err(FuzzyError::InputOutOfRange {
                index,
                name: variable.name.clone(),
                value,
                min,
                max,
            });
        }
        OutOfRange::Error => value,
    })
}

/// Output `o` from the weighted sum and the total strength of the rules that conclude on it
/// (eq 21, or the weighted sum), with the policy when no rule fires; refuses a non-finite value.
#[inline(always)]
pub(crate) fn output_value(
    system: &FuzzySystem,
    options: &EvalOptions,
    o: usize,
    weighted: f64,
    total: f64,
) -> Result<f64, FuzzyError> {
    let value = if total > 0.0 {
        match system.methods().defuzzification {
            Defuzzification::WeightedAverage => weighted / total,
            Defuzzification::WeightedSum => weighted,
        }
    } else {
        let variable = &system.outputs()[o];
        match &options.no_rule_fired {
            NoRuleFired::MiddleOfRange => 0.5 * (variable.range[0] + variable.range[1]),
            NoRuleFired::Values(values) => values[o],
            NoRuleFired::Error => {
                return Err(FuzzyError::NoRuleFired {
                    index: o,
                    name: variable.name.clone(),
                });
            }
        }
    };
    if !value.is_finite() {
        return Err(FuzzyError::NonFiniteOutput {
            index: o,
            name: system.outputs()[o].name.clone(),
            value,
        });
    }
    Ok(value)
}

/// The largest exponent `2 b` evaluated by repeated squaring; larger or non-integer ones use `powf`.
const MAX_INTEGER_BELL_EXPONENT: f64 = 64.0;

/// A validated membership function in evaluation form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CompiledMf {
    /// Bell with `b = 1`: `1 / (1 + u^2)`, `u = (x - c) / a`.
    BellSquare { center: f64, width: f64 },
    /// Bell with `b = 2` (the paper's): `1 / (1 + (u^2)^2)`.
    BellQuartic { center: f64, width: f64 },
    /// Bell with an integer exponent `2 b <= 64`: `|u|^(2b)` by repeated squaring.
    BellInteger {
        center: f64,
        width: f64,
        exponent: u32,
    },
    /// Any other bell: `|u|^(2b)` by `powf`.
    BellReal {
        center: f64,
        width: f64,
        exponent: f64,
    },
    /// `exp(-(x - c)^2 * k)` with `k = 1 / (2 sigma^2)`.
    Gaussian { center: f64, k: f64 },
    /// Two-sided Gaussian (MATLAB's `gauss2mf`).
    Gaussian2 {
        center1: f64,
        k1: f64,
        center2: f64,
        k2: f64,
    },
    /// `trimf`.
    Triangle { left: f64, peak: f64, right: f64 },
    /// `trapmf`.
    Trapezoid { a: f64, b: f64, c: f64, d: f64 },
    /// `sigmf`.
    Sigmoid { slope: f64, center: f64 },
    /// `dsigmf`.
    SigmoidDifference {
        slope1: f64,
        center1: f64,
        slope2: f64,
        center2: f64,
    },
    /// `psigmf`.
    SigmoidProduct {
        slope1: f64,
        center1: f64,
        slope2: f64,
        center2: f64,
    },
    /// `smf`, or its step when `a >= b`.
    SShape { start: f64, end: f64 },
    /// `zmf`, or its step when `a >= b`.
    ZShape { start: f64, end: f64 },
    /// `pimf`: `smf(x, [a b]) * zmf(x, [c d])`.
    PiShape { a: f64, b: f64, c: f64, d: f64 },
    /// `constant`.
    Constant(f64),
}

impl CompiledMf {
    /// Validates `mf` and picks its evaluation form.
    pub(crate) fn new(mf: &MembershipFn) -> Result<Self, FuzzyError> {
        mf.validate()?;
        let gauss_k = |sigma: f64| 1.0 / (2.0 * sigma * sigma);
        Ok(match *mf {
            MembershipFn::Bell {
                width,
                slope,
                center,
            } => {
                let exponent = 2.0 * slope;
                if exponent == 2.0 {
                    Self::BellSquare { center, width }
                } else if exponent == 4.0 {
                    Self::BellQuartic { center, width }
                } else if exponent.fract() == 0.0 && exponent <= MAX_INTEGER_BELL_EXPONENT {
                    Self::BellInteger {
                        center,
                        width,
                        exponent: exponent as u32,
                    }
                } else {
                    Self::BellReal {
                        center,
                        width,
                        exponent,
                    }
                }
            }
            MembershipFn::Gaussian { sigma, center } => Self::Gaussian {
                center,
                k: gauss_k(sigma),
            },
            MembershipFn::Gaussian2 {
                sigma1,
                center1,
                sigma2,
                center2,
            } => Self::Gaussian2 {
                center1,
                k1: gauss_k(sigma1),
                center2,
                k2: gauss_k(sigma2),
            },
            MembershipFn::Triangle { left, peak, right } => Self::Triangle { left, peak, right },
            MembershipFn::Trapezoid {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => Self::Trapezoid {
                a: left_foot,
                b: left_shoulder,
                c: right_shoulder,
                d: right_foot,
            },
            MembershipFn::Sigmoid { slope, center } => Self::Sigmoid { slope, center },
            MembershipFn::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            } => Self::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            },
            MembershipFn::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            } => Self::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            },
            MembershipFn::SShape { start, end } => Self::SShape { start, end },
            MembershipFn::ZShape { start, end } => Self::ZShape { start, end },
            MembershipFn::PiShape {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => Self::PiShape {
                a: left_foot,
                b: left_shoulder,
                c: right_shoulder,
                d: right_foot,
            },
            MembershipFn::Constant { value } => Self::Constant(value),
        })
    }

    /// The degrees of membership of the points of `x` (one or a SIMD register of them): the
    /// integer bells branch-free on all lanes at once, the other kinds by [`eval`](Self::eval)
    /// lane by lane. Either way each lane gets exactly what `eval` gives for it.
    #[inline(always)]
    pub(crate) fn eval_lane<L: Lane>(&self, cx: L::Context, x: L) -> L {
        match *self {
            Self::BellSquare { center, width } => bell(cx, x, center, width, |u| u * u),
            Self::BellQuartic { center, width } => bell(cx, x, center, width, |u| {
                let u2 = u * u;
                u2 * u2
            }),
            Self::BellInteger {
                center,
                width,
                exponent,
            } => bell(cx, x, center, width, |u| {
                integer_power(cx, u.abs(), exponent)
            }),
            _ => x.map(|x| self.eval(x)),
        }
    }

    /// The degree of membership of `x` (finite `x`; never NaN for finite `x`).
    #[inline]
    pub(crate) fn eval(&self, x: f64) -> f64 {
        match *self {
            Self::BellSquare { .. } | Self::BellQuartic { .. } | Self::BellInteger { .. } => {
                self.eval_lane((), x)
            }
            Self::BellReal {
                center,
                width,
                exponent,
            } => 1.0 / (1.0 + ((x - center) / width).abs().powf(exponent)),
            Self::Gaussian { center, k } => gaussian(x, center, k),
            Self::Gaussian2 {
                center1,
                k1,
                center2,
                k2,
            } => {
                let left = if x <= center1 {
                    gaussian(x, center1, k1)
                } else {
                    1.0
                };
                let right = if x >= center2 {
                    gaussian(x, center2, k2)
                } else {
                    1.0
                };
                left * right
            }
            Self::Triangle { left, peak, right } => {
                if x == peak {
                    1.0
                } else if x <= left || x >= right {
                    0.0
                } else if x < peak {
                    (x - left) / (peak - left)
                } else {
                    (right - x) / (right - peak)
                }
            }
            Self::Trapezoid { a, b, c, d } => {
                let (rising, falling) = trapezoid_sides(x, a, b, c, d);
                rising.min(falling)
            }
            Self::Sigmoid { slope, center } => sigmoid(x, slope, center),
            Self::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            } => (sigmoid(x, slope1, center1) - sigmoid(x, slope2, center2)).abs(),
            Self::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            } => sigmoid(x, slope1, center1) * sigmoid(x, slope2, center2),
            Self::SShape { start, end } => s_shape(x, start, end),
            Self::ZShape { start, end } => z_shape(x, start, end),
            Self::PiShape { a, b, c, d } => s_shape(x, a, b) * z_shape(x, c, d),
            Self::Constant(value) => value,
        }
    }
}

/// The rising and falling sides of `trapmf [a b c d]` at `x`: the degree is their minimum.
#[inline]
pub(crate) fn trapezoid_sides(x: f64, a: f64, b: f64, c: f64, d: f64) -> (f64, f64) {
    let rising = if x >= b {
        1.0
    } else if x < a {
        0.0
    } else {
        (x - a) / (b - a)
    };
    let falling = if x <= c {
        1.0
    } else if x > d {
        0.0
    } else {
        (d - x) / (d - c)
    };
    (rising, falling)
}

/// MATLAB's `smf(x, [a b])`: the quadratic spline from 0 at `a` to 1 at `b` (value 1/2 at the
/// midpoint), or the step `x >= (a + b) / 2` when `a >= b`.
#[inline]
pub(crate) fn s_shape(x: f64, a: f64, b: f64) -> f64 {
    let middle = 0.5 * (a + b);
    if a >= b {
        return if x >= middle { 1.0 } else { 0.0 };
    }
    if x <= a {
        0.0
    } else if x <= middle {
        let t = (x - a) / (b - a);
        2.0 * t * t
    } else if x <= b {
        let t = (b - x) / (b - a);
        1.0 - 2.0 * t * t
    } else {
        1.0
    }
}

/// MATLAB's `zmf(x, [a b])`: the quadratic spline from 1 at `a` to 0 at `b`, or the step
/// `x <= (a + b) / 2` when `a >= b`.
#[inline]
pub(crate) fn z_shape(x: f64, a: f64, b: f64) -> f64 {
    let middle = 0.5 * (a + b);
    if a >= b {
        return if x <= middle { 1.0 } else { 0.0 };
    }
    if x <= a {
        1.0
    } else if x <= middle {
        let t = (x - a) / (b - a);
        1.0 - 2.0 * t * t
    } else if x <= b {
        let t = (b - x) / (b - a);
        2.0 * t * t
    } else {
        0.0
    }
}

#[inline]
fn gaussian(x: f64, center: f64, k: f64) -> f64 {
    let d = x - center;
    (-(d * d) * k).exp()
}

/// MATLAB's `sigmf(x, [a c])`: `1 / (1 + exp(-a (x - c)))`.
#[inline]
pub(crate) fn sigmoid(x: f64, slope: f64, center: f64) -> f64 {
    1.0 / (1.0 + (-slope * (x - center)).exp())
}

/// The generalized bell `1 / (1 + power(u))`, `u = (x - center) / width`, `power(u)` standing
/// for `|u|^(2b)`.
#[inline(always)]
fn bell<L: Lane>(cx: L::Context, x: L, center: f64, width: f64, power: impl Fn(L) -> L) -> L {
    let u = (x - L::splat(cx, center)) / L::splat(cx, width);
    let one = L::splat(cx, 1.0);
    one / (one + power(u))
}

/// `base^exponent` by repeated squaring (exponentiation by squaring), no `powf`.
#[inline(always)]
pub(crate) fn integer_power<L: Lane>(cx: L::Context, mut base: L, mut exponent: u32) -> L {
    let mut result = L::splat(cx, 1.0);
    while exponent > 0 {
        if exponent & 1 == 1 {
            result = result * base;
        }
        base = base * base;
        exponent >>= 1;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_slopes_are_compiled_without_powf() {
        let compile = |b: f64| CompiledMf::new(&MembershipFn::bell(1.0, b, 0.0)).unwrap();
        assert!(matches!(compile(1.0), CompiledMf::BellSquare { .. }));
        assert!(matches!(compile(2.0), CompiledMf::BellQuartic { .. }));
        assert!(matches!(
            compile(1.5),
            CompiledMf::BellInteger { exponent: 3, .. }
        ));
        assert!(matches!(
            compile(32.0),
            CompiledMf::BellInteger { exponent: 64, .. }
        ));
        assert!(matches!(compile(32.5), CompiledMf::BellReal { .. }));
        assert!(matches!(compile(0.3), CompiledMf::BellReal { .. }));
        // Exponentiation by squaring is exact for powers of two and small integers.
        assert_eq!(integer_power((), 1.5, 0), 1.0);
        assert_eq!(integer_power((), 1.5, 5), 7.59375);
        assert_eq!(integer_power((), 2.0, 64), 2f64.powi(64));
    }

    /// Every instruction set gives every point the same bits, in a batch and alone (see
    /// [`lane_math::instruction_sets`]), inputs inside and outside their ranges.
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        let mut evaluator = Evaluator::new(crate::paper_controller());
        let n_in = evaluator.system.inputs().len();
        let n_out = evaluator.system.outputs().len();
        let points = 29;
        let inputs: Vec<f64> = (0..n_in * points)
            .map(|i| 3.0 * ((i as f64) * 0.37).sin())
            .collect();
        let mut alone = vec![0.0; n_out * points];
        for (x, y) in inputs.chunks_exact(n_in).zip(alone.chunks_exact_mut(n_out)) {
            evaluator.eval(x, y).unwrap();
        }
        let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for arch in lane_math::instruction_sets() {
            evaluator.batch.arch = arch;
            let mut batch = vec![0.0; n_out * points];
            evaluator.eval_batch(&inputs, &mut batch).unwrap();
            assert_eq!(bits(&batch), bits(&alone), "{arch:?}");
        }
    }
}
