//! Allocation-free evaluation of a fuzzy system: singleton fuzzification, rule firing (product
//! or minimum AND, probabilistic sum or maximum OR, rule weights) and the centre-average
//! defuzzifier of eq 21.

use crate::error::FuzzyError;
use crate::membership::MembershipFn;
use crate::system::{AndMethod, Compiled, Defuzzification, FuzzySystem, OrMethod, affine};

/// What to do with an input outside its variable's range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutOfRange {
    /// Evaluate at the nearest end of the range (the default). For a controller this is the
    /// safe choice: bell and Gaussian sets decay on both sides, so evaluated as given a very
    /// large error would *weaken* the action of the rule base instead of saturating it.
    #[default]
    Clamp,
    /// Evaluate the membership functions at the value as given (MATLAB's `evalfis` does this,
    /// with a warning).
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

/// Evaluates a [`FuzzySystem`] with its own scratch space: after [`Evaluator::new`], evaluating
/// allocates nothing. Clone it to evaluate on several threads.
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
    /// The inputs after the range policy.
    x: Vec<f64>,
    /// Membership degrees of every input set, then (if any rule negates) their complements.
    degrees: Vec<f64>,
    /// Each rule's firing strength (weight included).
    strengths: Vec<f64>,
    /// Each output term's value at `x`.
    term_values: Vec<f64>,
    /// The outputs, copied to the caller's buffer only once all of them are valid.
    y: Vec<f64>,
}

impl Evaluator {
    /// An evaluator with the default [`EvalOptions`] (clamp inputs, middle of range when no
    /// rule fires).
    pub fn new(system: FuzzySystem) -> Self {
        let c = system.compiled();
        let mut degrees = vec![0.0; c.degree_count];
        // The neutral elements of AND and OR, which "don't care" antecedents point at.
        degrees[c.degree_count - 2] = 1.0;
        let strengths = vec![0.0; c.weights.len()];
        let term_values = c.term_values.clone();
        let x = vec![0.0; system.inputs().len()];
        let y = vec![0.0; system.outputs().len()];
        Self {
            system,
            options: EvalOptions::default(),
            x,
            degrees,
            strengths,
            term_values,
            y,
        }
    }

    /// An evaluator with the given options; fails if [`NoRuleFired::Values`] does not hold one
    /// finite value per output.
    pub fn with_options(system: FuzzySystem, options: EvalOptions) -> Result<Self, FuzzyError> {
        if let NoRuleFired::Values(values) = &options.no_rule_fired {
            let n = system.outputs().len();
            if values.len() != n {
                return Err(FuzzyError::InvalidOptions(format!(
                    "no-rule-fired values have {} entries for {n} outputs",
                    values.len()
                )));
            }
            if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                return Err(FuzzyError::InvalidOptions(format!(
                    "no-rule-fired values must be finite, got {v}"
                )));
            }
        }
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
        let n_out = self.system.outputs().len();
        if outputs.len() != n_out {
            return Err(FuzzyError::OutputCount {
                expected: n_out,
                got: outputs.len(),
            });
        }
        self.fire(inputs)?;
        self.defuzzify(outputs)
    }

    /// Evaluates many input vectors: `inputs` holds rows of one value per input variable,
    /// `outputs` the matching rows of one slot per output. An error names the failing row; the
    /// rows before it hold their results, that row and the ones after it are left untouched.
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
                got: outputs.len(),
            });
        }
        for (row, (x, y)) in inputs
            .chunks_exact(n_in)
            .zip(outputs.chunks_exact_mut(n_out))
            .enumerate()
        {
            self.eval(x, y).map_err(|e| FuzzyError::Batch {
                row,
                source: Box::new(e),
            })?;
        }
        Ok(())
    }

    /// Computes and returns every rule's firing strength at `inputs` (antecedents combined by
    /// the rule's AND/OR, times the rule's weight), in rule order.
    pub fn fire(&mut self, inputs: &[f64]) -> Result<&[f64], FuzzyError> {
        self.load_inputs(inputs)?;
        let c = self.system.compiled();
        let n_mf = c.mfs.len();
        for ((degree, mf), &i) in self.degrees.iter_mut().zip(&c.mfs).zip(&c.mf_inputs) {
            *degree = mf.eval(self.x[i]);
        }
        if c.has_complements {
            let (degrees, complements) = self.degrees.split_at_mut(n_mf);
            for (complement, degree) in complements.iter_mut().zip(degrees.iter()) {
                *complement = 1.0 - degree;
            }
        }
        let methods = self.system.methods();
        let (degrees, strengths, n_in) = (&self.degrees[..], &mut self.strengths[..], self.x.len());
        // One monomorphised loop per pair of methods.
        let probor = |s: f64, d: f64| s + d - s * d;
        let product = |s: f64, d: f64| s * d;
        match (methods.and, methods.or) {
            (AndMethod::Product, OrMethod::ProbabilisticSum) => {
                fire_rules(c, degrees, strengths, n_in, product, probor)
            }
            (AndMethod::Product, OrMethod::Maximum) => {
                fire_rules(c, degrees, strengths, n_in, product, f64::max)
            }
            (AndMethod::Minimum, OrMethod::ProbabilisticSum) => {
                fire_rules(c, degrees, strengths, n_in, f64::min, probor)
            }
            (AndMethod::Minimum, OrMethod::Maximum) => {
                fire_rules(c, degrees, strengths, n_in, f64::min, f64::max)
            }
        }
        Ok(&self.strengths)
    }

    /// The firing strengths computed by the last [`eval`](Self::eval) or [`fire`](Self::fire)
    /// (zeros before the first).
    pub fn firing_strengths(&self) -> &[f64] {
        &self.strengths
    }

    /// Checks the inputs and applies the range policy into `self.x`.
    fn load_inputs(&mut self, inputs: &[f64]) -> Result<(), FuzzyError> {
        let variables = self.system.inputs();
        if inputs.len() != variables.len() {
            return Err(FuzzyError::InputCount {
                expected: variables.len(),
                got: inputs.len(),
            });
        }
        for (index, ((slot, &value), variable)) in
            self.x.iter_mut().zip(inputs).zip(variables).enumerate()
        {
            if !value.is_finite() {
                return Err(FuzzyError::NonFiniteInput {
                    index,
                    name: variable.name.clone(),
                    value,
                });
            }
            let [min, max] = variable.range;
            *slot = match self.options.out_of_range {
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
            };
        }
        Ok(())
    }

    /// Eq 21 (or the weighted sum) for every output, from the strengths of the last firing;
    /// `outputs` is written only if every output is valid.
    fn defuzzify(&mut self, outputs: &mut [f64]) -> Result<(), FuzzyError> {
        let c = self.system.compiled();
        let n_in = self.x.len();
        for &(term, offset) in &c.linear_terms {
            let p = &c.coefficients[offset..offset + n_in + 1];
            self.term_values[term] = affine(&p[..n_in], p[n_in], &self.x);
        }
        let defuzzification = self.system.methods().defuzzification;
        let strengths = &self.strengths[..];
        let n_rules = strengths.len();
        let total_of_all: f64 = strengths.iter().sum();
        for (o, output) in self.y.iter_mut().enumerate() {
            let row = o * n_rules..(o + 1) * n_rules;
            let weighted = strengths
                .iter()
                .zip(&c.consequents[row.clone()])
                .fold(0.0, |acc, (w, &term)| {
                    acc + w * self.term_values[term as usize]
                });
            let total = if c.every_rule_concludes[o] {
                total_of_all
            } else {
                strengths
                    .iter()
                    .zip(&c.concludes[row])
                    .fold(0.0, |acc, (w, m)| acc + w * m)
            };
            let value = if total > 0.0 {
                match defuzzification {
                    Defuzzification::WeightedAverage => weighted / total,
                    Defuzzification::WeightedSum => weighted,
                }
            } else {
                let variable = &self.system.outputs()[o];
                match &self.options.no_rule_fired {
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
                let name = self.system.outputs()[o].name.clone();
                return Err(FuzzyError::NonFiniteOutput {
                    index: o,
                    name,
                    value,
                });
            }
            *output = value;
        }
        outputs.copy_from_slice(&self.y);
        Ok(())
    }
}

/// Each rule's strength: its weight times the AND (or OR) of its row of the antecedent matrix.
#[inline]
fn fire_rules(
    c: &Compiled,
    degrees: &[f64],
    strengths: &mut [f64],
    n_inputs: usize,
    and: impl Fn(f64, f64) -> f64,
    or: impl Fn(f64, f64) -> f64,
) {
    let rules = strengths
        .iter_mut()
        .zip(c.antecedents.chunks_exact(n_inputs))
        .zip(c.weights.iter().zip(&c.is_or));
    for ((strength, row), (&weight, &is_or)) in rules {
        let terms = row.iter().map(|&t| degrees[t as usize]);
        let combined = if is_or {
            terms.fold(0.0, &or)
        } else {
            terms.fold(1.0, &and)
        };
        *strength = weight * combined;
    }
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

    /// The degree of membership of `x` (finite `x`; never NaN for finite `x`).
    #[inline]
    pub(crate) fn eval(&self, x: f64) -> f64 {
        match *self {
            Self::BellSquare { center, width } => {
                let u = (x - center) / width;
                1.0 / (1.0 + u * u)
            }
            Self::BellQuartic { center, width } => {
                let u = (x - center) / width;
                let u2 = u * u;
                1.0 / (1.0 + u2 * u2)
            }
            Self::BellInteger {
                center,
                width,
                exponent,
            } => 1.0 / (1.0 + integer_power(((x - center) / width).abs(), exponent)),
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

/// `base^exponent` by repeated squaring (exponentiation by squaring), no `powf`.
#[inline]
fn integer_power(mut base: f64, mut exponent: u32) -> f64 {
    let mut result = 1.0;
    while exponent > 0 {
        if exponent & 1 == 1 {
            result *= base;
        }
        base *= base;
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
        assert_eq!(integer_power(1.5, 0), 1.0);
        assert_eq!(integer_power(1.5, 5), 7.59375);
        assert_eq!(integer_power(2.0, 64), 2f64.powi(64));
    }
}
