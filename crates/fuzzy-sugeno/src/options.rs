//! The evaluation policies ([`EvalOptions`]) and how one input and one output obey them, for
//! one point ([`Evaluator::eval`](crate::Evaluator::eval)) and a batch alike.

use crate::error::FuzzyError;
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
    /// [`Evaluator::first_outside_range`](crate::Evaluator::first_outside_range) tells the caller when this happened, so that it can
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

/// The evaluation policies of an [`Evaluator`](crate::Evaluator).
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
            if let Some((_, value)) = lane_math::first_non_finite(values) {
                return Err(FuzzyError::NonFiniteFallback { value });
            }
        }
        Ok(())
    }
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
    let value = defuzzify(system.methods().defuzzification, weighted, total);
    fired_output(system, options, o, value, total)
}

/// The output from the weighted sum and the total strength by `method` (eq 21, or the weighted
/// sum); meaningful when `total > 0`.
#[inline(always)]
pub(crate) fn defuzzify(method: Defuzzification, weighted: f64, total: f64) -> f64 {
    match method {
        Defuzzification::WeightedAverage => weighted / total,
        Defuzzification::WeightedSum => weighted,
    }
}

/// Output `o` given `value`, its [`defuzzify`]d value when the total strength `total` is
/// positive: the policy when no rule fires; refuses a non-finite value.
#[inline(always)]
pub(crate) fn fired_output(
    system: &FuzzySystem,
    options: &EvalOptions,
    o: usize,
    value: f64,
    total: f64,
) -> Result<f64, FuzzyError> {
    let value = if total > 0.0 {
        value
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
