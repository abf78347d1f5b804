//! A builder whose rules read like a rule table.

use crate::AndMethod;
use crate::error::{FuzzyError, SystemProblem};
use crate::membership::MembershipFn;
use crate::system::{
    Antecedent, Connective, Defuzzification, FuzzySet, FuzzySystem, InputVariable, Methods,
    OrMethod, OutputFn, OutputTerm, OutputVariable, Rule,
};

/// Builds a [`FuzzySystem`]; everything is validated by [`SystemBuilder::build`].
///
/// Rules name their sets positionally, one token per input and one per output, in the order the
/// variables were declared: a set name (`"N"`), `"not N"`, or `"-"` for "don't care" (inputs)
/// or "no conclusion" (outputs).
///
/// ```
/// use fuzzy_sugeno::{Evaluator, FuzzySystem, MembershipFn, OutputFn};
///
/// let system = FuzzySystem::builder("tipper")
///     .input("service", [0.0, 10.0], [("poor", MembershipFn::gaussian(1.5, 0.0)), ("good", MembershipFn::gaussian(1.5, 10.0))])
///     .output("tip", [0.0, 30.0], [("low", OutputFn::Constant(5.0)), ("high", OutputFn::Constant(25.0))])
///     .rule(["poor"], ["low"])
///     .rule(["good"], ["high"])
///     .build()?;
/// let mut evaluator = Evaluator::new(system);
/// let mut tip = [0.0];
/// evaluator.eval(&[5.0], &mut tip)?;
/// assert!((tip[0] - 15.0).abs() < 1e-12); // symmetric sets: the centre average of 5 and 25
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SystemBuilder {
    name: String,
    inputs: Vec<InputVariable>,
    outputs: Vec<OutputVariable>,
    rules: Vec<PendingRule>,
    methods: Methods,
}

/// A rule as given, resolved against the variables when the system is built.
#[derive(Debug, Clone)]
enum PendingRule {
    Named {
        when: Vec<String>,
        then: Vec<String>,
        weight: f64,
        connective: Connective,
    },
    Indexed(Rule),
}

impl FuzzySystem {
    /// Starts a [`SystemBuilder`].
    pub fn builder(name: impl Into<String>) -> SystemBuilder {
        SystemBuilder::new(name)
    }
}

impl SystemBuilder {
    /// An empty system with product AND, probabilistic-sum OR and the centre-average
    /// defuzzifier (the paper's methods).
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            inputs: Vec::new(),
            outputs: Vec::new(),
            rules: Vec::new(),
            methods: Methods::default(),
        }
    }

    /// Sets the AND method.
    pub fn and_method(mut self, and: AndMethod) -> Self {
        self.methods.and = and;
        self
    }

    /// Sets the OR method.
    pub fn or_method(mut self, or: OrMethod) -> Self {
        self.methods.or = or;
        self
    }

    /// Sets the defuzzifier.
    pub fn defuzzification(mut self, defuzzification: Defuzzification) -> Self {
        self.methods.defuzzification = defuzzification;
        self
    }

    /// Adds an input variable with its named sets.
    pub fn input<S: Into<String>>(
        mut self,
        name: impl Into<String>,
        range: [f64; 2],
        sets: impl IntoIterator<Item = (S, MembershipFn)>,
    ) -> Self {
        let sets = sets
            .into_iter()
            .map(|(name, membership)| FuzzySet {
                name: name.into(),
                membership,
            })
            .collect();
        self.inputs.push(InputVariable {
            name: name.into(),
            range,
            sets,
        });
        self
    }

    /// Adds an output variable with its named consequent functions.
    pub fn output<S: Into<String>>(
        mut self,
        name: impl Into<String>,
        range: [f64; 2],
        terms: impl IntoIterator<Item = (S, OutputFn)>,
    ) -> Self {
        let terms = terms
            .into_iter()
            .map(|(name, function)| OutputTerm {
                name: name.into(),
                function,
            })
            .collect();
        self.outputs.push(OutputVariable {
            name: name.into(),
            range,
            terms,
        });
        self
    }

    /// Adds an AND rule of weight 1: `when` has one token per input, `then` one per output.
    pub fn rule<'a>(
        self,
        when: impl IntoIterator<Item = &'a str>,
        then: impl IntoIterator<Item = &'a str>,
    ) -> Self {
        self.weighted_rule(when, then, 1.0, Connective::And)
    }

    /// Adds a rule with a weight in `[0, 1]` and a connective.
    pub fn weighted_rule<'a>(
        mut self,
        when: impl IntoIterator<Item = &'a str>,
        then: impl IntoIterator<Item = &'a str>,
        weight: f64,
        connective: Connective,
    ) -> Self {
        let when = when.into_iter().map(str::to_string).collect();
        let then = then.into_iter().map(str::to_string).collect();
        self.rules.push(PendingRule::Named {
            when,
            then,
            weight,
            connective,
        });
        self
    }

    /// Adds a rule given by set and term indices (MATLAB's rule-list form, 0-based).
    pub fn indexed_rule(mut self, rule: Rule) -> Self {
        self.rules.push(PendingRule::Indexed(rule));
        self
    }

    /// Resolves the rules, validates everything and compiles the system.
    pub fn build(self) -> Result<FuzzySystem, FuzzyError> {
        let mut rules = Vec::with_capacity(self.rules.len());
        for (r, pending) in self.rules.into_iter().enumerate() {
            rules.push(match pending {
                PendingRule::Indexed(rule) => rule,
                PendingRule::Named {
                    when,
                    then,
                    weight,
                    connective,
                } => resolve(
                    &when,
                    &then,
                    weight,
                    connective,
                    &self.inputs,
                    &self.outputs,
                )
                .map_err(|problem| FuzzyError::InvalidSystem {
                    context: format!("rule {}", r + 1),
                    problem,
                })?,
            });
        }
        FuzzySystem::new(self.name, self.inputs, self.outputs, rules, self.methods)
    }
}

/// Turns a named rule into index form.
fn resolve(
    when: &[String],
    then: &[String],
    weight: f64,
    connective: Connective,
    inputs: &[InputVariable],
    outputs: &[OutputVariable],
) -> Result<Rule, SystemProblem> {
    if when.len() != inputs.len() {
        return Err(SystemProblem::AntecedentCount {
            expected: inputs.len(),
            found: when.len(),
        });
    }
    if then.len() != outputs.len() {
        return Err(SystemProblem::ConsequentCount {
            expected: outputs.len(),
            found: then.len(),
        });
    }
    let antecedents = when
        .iter()
        .zip(inputs)
        .map(|(token, input)| {
            let token = token.trim();
            if token == "-" {
                return Ok(Antecedent::Any);
            }
            let named = |wanted: &str| {
                unique_position(
                    input.sets.iter().map(|s| s.name.as_str()),
                    wanted,
                    &input.name,
                    "sets",
                )
            };
            if let Some(k) = named(token)? {
                return Ok(Antecedent::Is(k));
            }
            if let Some(rest) = token.strip_prefix("not ")
                && let Some(k) = named(rest.trim())?
            {
                return Ok(Antecedent::IsNot(k));
            }
            let names: Vec<&str> = input.sets.iter().map(|s| s.name.as_str()).collect();
            Err(SystemProblem::UnknownSet {
                input: input.name.clone(),
                set: token.to_string(),
                available: names.join(", "),
            })
        })
        .collect::<Result<Vec<_>, SystemProblem>>()?;
    let consequents = then
        .iter()
        .zip(outputs)
        .map(|(token, output)| {
            let token = token.trim();
            if token == "-" {
                return Ok(None);
            }
            match unique_position(
                output.terms.iter().map(|t| t.name.as_str()),
                token,
                &output.name,
                "terms",
            )? {
                Some(k) => Ok(Some(k)),
                None => {
                    let names: Vec<&str> = output.terms.iter().map(|t| t.name.as_str()).collect();
                    Err(SystemProblem::UnknownTerm {
                        output: output.name.clone(),
                        term: token.to_string(),
                        available: names.join(", "),
                    })
                }
            }
        })
        .collect::<Result<Vec<_>, SystemProblem>>()?;
    Ok(Rule {
        antecedents,
        consequents,
        weight,
        connective,
    })
}

/// The index of the one name equal to `wanted`, `None` if there is none, an error if several
/// share it (MATLAB allows that; such sets can only be used by index).
fn unique_position<'a>(
    names: impl Iterator<Item = &'a str>,
    wanted: &str,
    variable: &str,
    kind: &'static str,
) -> Result<Option<usize>, SystemProblem> {
    let matches: Vec<usize> = names
        .enumerate()
        .filter(|(_, name)| *name == wanted)
        .map(|(k, _)| k)
        .collect();
    match matches[..] {
        [] => Ok(None),
        [k] => Ok(Some(k)),
        [first, second, ..] => Err(SystemProblem::AmbiguousName {
            variable: variable.to_string(),
            kind,
            name: wanted.to_string(),
            first: first + 1,
            second: second + 1,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_two() -> SystemBuilder {
        let sets = [
            ("N", MembershipFn::bell(1.0, 2.0, -1.0)),
            ("P", MembershipFn::bell(1.0, 2.0, 1.0)),
        ];
        FuzzySystem::builder("t")
            .input("e", [-1.0, 1.0], sets)
            .input("de", [-1.0, 1.0], sets)
            .output(
                "u",
                [-1.0, 1.0],
                [
                    ("lo", OutputFn::Constant(-1.0)),
                    ("hi", OutputFn::Constant(1.0)),
                ],
            )
    }

    #[test]
    fn named_rules_resolve_to_indices() {
        let system = two_by_two()
            .rule(["N", "not P"], ["hi"])
            .rule(["-", "P"], ["lo"])
            .build()
            .unwrap();
        assert_eq!(
            system.rules()[0].antecedents,
            [Antecedent::Is(0), Antecedent::IsNot(1)]
        );
        assert_eq!(system.rules()[0].consequents, [Some(1)]);
        assert_eq!(
            system.rules()[1].antecedents,
            [Antecedent::Any, Antecedent::Is(1)]
        );
        assert_eq!(system.rules()[1].weight, 1.0);
    }

    #[test]
    fn builder_errors_name_the_rule_and_the_problem() {
        let message = |b: SystemBuilder| b.build().unwrap_err().to_string();
        assert_eq!(
            message(two_by_two().rule(["N", "Z"], ["hi"])),
            "rule 1: input 'de' has no set 'Z' (its sets: N, P)"
        );
        assert_eq!(
            message(two_by_two().rule(["N"], ["hi"])),
            "rule 1: has 1 antecedents for 2 inputs"
        );
        assert_eq!(
            message(
                two_by_two()
                    .rule(["N", "N"], ["hi"])
                    .rule(["P", "P"], ["mid"])
            ),
            "rule 2: output 'u' has no term 'mid' (its terms: lo, hi)"
        );
        assert_eq!(
            message(two_by_two().rule(["-", "-"], ["hi"])),
            "rule 1: has no antecedent (every input is \"don't care\")"
        );
        assert_eq!(
            message(two_by_two().rule(["N", "N"], ["-"])),
            "rule 1: has no consequent"
        );
        assert_eq!(
            message(two_by_two().weighted_rule(["N", "N"], ["lo"], 1.5, Connective::And)),
            "rule 1: weight must lie in [0, 1], got 1.5"
        );
        let bad_set = two_by_two().input(
            "x",
            [0.0, 1.0],
            [("A", MembershipFn::triangle(1.0, 0.0, 2.0))],
        );
        assert_eq!(
            message(bad_set),
            "input 'x' set 'A': trimf: corners must satisfy a <= b <= c, got [1 0 2]"
        );
        let bad_range =
            two_by_two().input("x", [1.0, 1.0], [("A", MembershipFn::gaussian(1.0, 0.0))]);
        assert_eq!(
            message(bad_range),
            "input 'x': range must be finite with min < max, got [1, 1]"
        );
        let wide_range = two_by_two().input(
            "x",
            [-1e308, 1e308],
            [("A", MembershipFn::gaussian(1.0, 0.0))],
        );
        assert_eq!(
            message(wide_range),
            "input 'x': range must be finite with a width max - min within double precision, \
             got [-1e308, 1e308]"
        );
        let duplicate =
            two_by_two().input("e", [0.0, 1.0], [("A", MembershipFn::gaussian(1.0, 0.0))]);
        assert_eq!(
            message(duplicate),
            "input 'e': another variable has the same name"
        );
        let linear = OutputFn::Linear {
            coefficients: vec![1.0],
            constant: 0.0,
        };
        assert_eq!(
            message(two_by_two().output("v", [0.0, 1.0], [("l", linear)])),
            "output 'v' term 'l': linear consequent has 1 coefficients for 2 inputs"
        );
        assert_eq!(
            message(FuzzySystem::builder("it's")),
            "system: the system name \"it's\" contains a quote or a control character"
        );
    }
}
