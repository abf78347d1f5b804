//! A validated Takagi-Sugeno fuzzy system: variables, fuzzy sets, rules and inference methods
//! (section 4 of the paper, eqs 19-21).

use crate::compiled_mf::CompiledMf;
use crate::error::{FuzzyError, SystemProblem};
use crate::membership::MembershipFn;
pub use crate::rules::{
    AndMethod, Antecedent, Connective, Defuzzification, Methods, OrMethod, Rule,
};
use crate::separable::Separable;
use std::collections::HashSet;

/// An input variable: a name, the range it was designed for, and its fuzzy sets.
#[derive(Debug, Clone, PartialEq)]
pub struct InputVariable {
    /// The variable's name (unique among all variables of a system).
    pub name: String,
    /// `[min, max]`, with `min < max`.
    pub range: [f64; 2],
    /// The fuzzy sets ("terms") of the variable, in the order rules index them. It may be empty
    /// (MATLAB's `NumMFs=0`): such an input takes part only in first-order consequents, and
    /// every rule must say "don't care" for it.
    pub sets: Vec<FuzzySet>,
}

/// A named fuzzy set of an input variable.
#[derive(Debug, Clone, PartialEq)]
pub struct FuzzySet {
    /// The set's name, e.g. `"N"`. Names may repeat within a variable, as MATLAB allows (rules
    /// refer to sets by index); [`SystemBuilder`](crate::SystemBuilder)'s named rules then
    /// refuse the ambiguous name.
    pub name: String,
    /// Its membership function.
    pub membership: MembershipFn,
}

/// An output variable: a name, a range and its consequent functions.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputVariable {
    /// The variable's name (unique among all variables of a system).
    pub name: String,
    /// `[min, max]`, with `min <= max` (MATLAB's examples include `[0 0]`); its middle is the
    /// default output when no rule fires.
    pub range: [f64; 2],
    /// The consequent functions ("terms") of the variable, in the order rules index them.
    pub terms: Vec<OutputTerm>,
}

/// A named consequent function of an output variable.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputTerm {
    /// The term's name, e.g. `"VP"`. Names may repeat within a variable, as for [`FuzzySet`].
    pub name: String,
    /// The consequent `z = f(x)`.
    pub function: OutputFn,
}

/// The consequent of a Sugeno rule (eq 19): a constant (zero order) or an affine function of all
/// inputs (first order).
#[derive(Debug, Clone, PartialEq)]
pub enum OutputFn {
    /// `z = c` (MATLAB `'constant'`, `[c]`).
    Constant(f64),
    /// `z = sum_i p_i x_i + r` (MATLAB `'linear'`, `[p_1 ... p_n r]`).
    Linear {
        /// `p_i`, one per input variable.
        coefficients: Vec<f64>,
        /// `r`.
        constant: f64,
    },
}

impl OutputFn {
    /// The consequent's value at `inputs` (one value per input variable); a linear consequent
    /// refuses a slice of another length with [`FuzzyError::InputCount`]. Non-finite inputs give
    /// a non-finite value ([`Evaluator`](crate::Evaluator) refuses those before it gets here).
    pub fn value(&self, inputs: &[f64]) -> Result<f64, FuzzyError> {
        match self {
            Self::Constant(c) => Ok(*c),
            Self::Linear {
                coefficients,
                constant,
            } => {
                if coefficients.len() != inputs.len() {
                    return Err(FuzzyError::InputCount {
                        expected: coefficients.len(),
                        found: inputs.len(),
                    });
                }
                Ok(affine(coefficients, *constant, inputs))
            }
        }
    }
}

/// `r + sum_i p_i x_i`, summed in input order.
#[inline]
pub(crate) fn affine(coefficients: &[f64], constant: f64, inputs: &[f64]) -> f64 {
    coefficients
        .iter()
        .zip(inputs)
        .fold(constant, |acc, (p, x)| acc + p * x)
}

/// A validated Takagi-Sugeno fuzzy system.
///
/// Build one with [`FuzzySystem::builder`], read one with [`FuzzySystem::from_fis`], or take
/// the paper's controller from [`paper_controller`](crate::paper_controller). Evaluate it with an
/// [`Evaluator`](crate::Evaluator).
#[derive(Debug, Clone, PartialEq)]
pub struct FuzzySystem {
    name: String,
    inputs: Vec<InputVariable>,
    outputs: Vec<OutputVariable>,
    rules: Vec<Rule>,
    methods: Methods,
    compiled: Compiled,
}

impl FuzzySystem {
    /// Validates every part and compiles the evaluation tables.
    pub(crate) fn new(
        name: String,
        inputs: Vec<InputVariable>,
        outputs: Vec<OutputVariable>,
        rules: Vec<Rule>,
        methods: Methods,
    ) -> Result<Self, FuzzyError> {
        check_name("system", &name).map_err(|problem| invalid("system", problem))?;
        if inputs.is_empty() || outputs.is_empty() {
            return Err(invalid("system", SystemProblem::NoVariables));
        }
        let mut variable_names: HashSet<&str> = HashSet::new();
        for input in &inputs {
            let context = format!("input '{}'", input.name);
            check_variable(
                &input.name,
                input.range,
                input.sets.iter().map(|s| s.name.as_str()),
                &mut variable_names,
                VariableKind::Input,
            )
            .map_err(|problem| invalid(&context, problem))?;
            for set in &input.sets {
                set.membership.validate().map_err(|e| {
                    invalid(
                        &format!("{context} set '{}'", set.name),
                        SystemProblem::Membership(Box::new(e)),
                    )
                })?;
            }
        }
        for output in &outputs {
            let context = format!("output '{}'", output.name);
            check_variable(
                &output.name,
                output.range,
                output.terms.iter().map(|t| t.name.as_str()),
                &mut variable_names,
                VariableKind::Output,
            )
            .map_err(|problem| invalid(&context, problem))?;
            for term in &output.terms {
                check_output_fn(&term.function, inputs.len()).map_err(|problem| {
                    invalid(&format!("{context} term '{}'", term.name), problem)
                })?;
            }
        }
        for (r, rule) in rules.iter().enumerate() {
            check_rule(rule, &inputs, &outputs)
                .map_err(|problem| invalid(&format!("rule {}", r + 1), problem))?;
        }
        let compiled = Compiled::new(&inputs, &outputs, &rules, methods)?;
        Ok(Self {
            name,
            inputs,
            outputs,
            rules,
            methods,
            compiled,
        })
    }

    /// The system's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The input variables, in evaluation order.
    pub fn inputs(&self) -> &[InputVariable] {
        &self.inputs
    }

    /// The output variables, in evaluation order.
    pub fn outputs(&self) -> &[OutputVariable] {
        &self.outputs
    }

    /// The rules, in order (messages and reports number them from 1, like MATLAB).
    pub fn rules(&self) -> &[Rule] {
        &self.rules
    }

    /// The inference methods.
    pub fn methods(&self) -> Methods {
        self.methods
    }

    pub(crate) fn compiled(&self) -> &Compiled {
        &self.compiled
    }

    /// The system without its separable form, evaluated by the general kernel (for tests).
    #[cfg(test)]
    pub(crate) fn without_separable_form(mut self) -> Self {
        self.compiled.separable = None;
        self
    }

    /// The system with its separable form read through the factor tables, as if its inputs had
    /// different numbers of sets (for tests).
    #[cfg(test)]
    pub(crate) fn without_uniform_sets(mut self) -> Self {
        if let Some(s) = &mut self.compiled.separable {
            s.sets_per_input = None;
        }
        self
    }
}

fn invalid(context: &str, problem: SystemProblem) -> FuzzyError {
    FuzzyError::InvalidSystem {
        context: context.to_string(),
        problem,
    }
}

/// Names are written between single quotes in a `.fis` file, one per line.
pub(crate) fn check_name(kind: &'static str, name: &str) -> Result<(), SystemProblem> {
    if name.is_empty() {
        Err(SystemProblem::EmptyName { kind })
    } else if name.contains('\'') || name.chars().any(char::is_control) {
        Err(SystemProblem::UnwritableName {
            kind,
            name: name.to_string(),
        })
    } else if name == "-" {
        Err(SystemProblem::ReservedName { kind })
    } else {
        Ok(())
    }
}

/// Whether a variable is an input or an output, for [`check_variable`].
#[derive(Clone, Copy, PartialEq, Eq)]
enum VariableKind {
    /// May have no sets (`NumMFs=0`); its range must have `min < max`.
    Input,
    /// Needs at least one term; its range may be a point (`min = max`).
    Output,
}

/// Checks a variable's name (new among `variable_names`), range and term names.
fn check_variable<'a>(
    name: &'a str,
    range: [f64; 2],
    term_names: impl Iterator<Item = &'a str>,
    variable_names: &mut HashSet<&'a str>,
    kind: VariableKind,
) -> Result<(), SystemProblem> {
    check_name("variable", name)?;
    if !variable_names.insert(name) {
        return Err(SystemProblem::DuplicateVariable);
    }
    let [min, max] = range;
    let ordered = match kind {
        VariableKind::Input => min < max,
        VariableKind::Output => min <= max,
    };
    if !(min.is_finite() && max.is_finite() && ordered) {
        let order = match kind {
            VariableKind::Input => "min < max",
            VariableKind::Output => "min <= max",
        };
        return Err(SystemProblem::Range { order, min, max });
    }
    if !(max - min).is_finite() {
        return Err(SystemProblem::Range {
            order: "a width max - min within double precision",
            min,
            max,
        });
    }
    let mut count = 0;
    for term in term_names {
        check_name("set", term)?;
        count += 1;
    }
    if count == 0 && kind == VariableKind::Output {
        return Err(SystemProblem::NoTerms);
    }
    Ok(())
}

fn check_output_fn(function: &OutputFn, n_inputs: usize) -> Result<(), SystemProblem> {
    match function {
        OutputFn::Constant(c) if !c.is_finite() => {
            Err(SystemProblem::NonFiniteConstant { value: *c })
        }
        OutputFn::Linear {
            coefficients,
            constant,
        } => {
            if coefficients.len() != n_inputs {
                Err(SystemProblem::CoefficientCount {
                    expected: n_inputs,
                    found: coefficients.len(),
                })
            } else if !constant.is_finite() || coefficients.iter().any(|p| !p.is_finite()) {
                Err(SystemProblem::NonFiniteCoefficient)
            } else {
                Ok(())
            }
        }
        OutputFn::Constant(_) => Ok(()),
    }
}

/// Checks one rule against the variables; the problem is phrased for a `rule N: ...` prefix.
pub(crate) fn check_rule(
    rule: &Rule,
    inputs: &[InputVariable],
    outputs: &[OutputVariable],
) -> Result<(), SystemProblem> {
    if rule.antecedents.len() != inputs.len() {
        return Err(SystemProblem::AntecedentCount {
            expected: inputs.len(),
            found: rule.antecedents.len(),
        });
    }
    if rule.consequents.len() != outputs.len() {
        return Err(SystemProblem::ConsequentCount {
            expected: outputs.len(),
            found: rule.consequents.len(),
        });
    }
    for (antecedent, input) in rule.antecedents.iter().zip(inputs) {
        if let Antecedent::Is(k) | Antecedent::IsNot(k) = *antecedent
            && k >= input.sets.len()
        {
            return Err(SystemProblem::NoSuchSet {
                input: input.name.clone(),
                count: input.sets.len(),
                set: k + 1,
            });
        }
    }
    for (consequent, output) in rule.consequents.iter().zip(outputs) {
        if let Some(k) = *consequent
            && k >= output.terms.len()
        {
            return Err(SystemProblem::NoSuchTerm {
                output: output.name.clone(),
                count: output.terms.len(),
                term: k + 1,
            });
        }
    }
    if rule.antecedents.iter().all(|a| *a == Antecedent::Any) {
        return Err(SystemProblem::NoAntecedent);
    }
    if rule.consequents.iter().all(Option::is_none) {
        return Err(SystemProblem::NoConsequent);
    }
    if !(0.0..=1.0).contains(&rule.weight) {
        return Err(SystemProblem::Weight {
            weight: rule.weight,
        });
    }
    Ok(())
}

/// Flat evaluation tables, built once from a validated system.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Compiled {
    /// Every input set's compiled membership function, input by input.
    pub mfs: Vec<CompiledMf>,
    /// The input that each of `mfs` reads.
    pub mf_inputs: Vec<usize>,
    /// Whether any rule negates an antecedent (then the degree table holds `1 - mu` too).
    pub has_complements: bool,
    /// The length of the degree table: the memberships, their complements if any rule negates,
    /// then the constants 1 and 0 (the neutral elements of AND and OR, for "don't care").
    pub degree_count: usize,
    /// One row per rule, one entry per input: the index of the antecedent in the degree table.
    pub antecedents: Vec<u32>,
    /// Each rule's weight.
    pub weights: Vec<f64>,
    /// Whether each rule is an OR rule.
    pub is_or: Vec<bool>,
    /// Each output term's value with constants filled in (first-order terms are recomputed).
    pub term_values: Vec<f64>,
    /// First-order terms: (index into `term_values`, offset of `[p_1 .. p_n r]` in `coefficients`).
    pub linear_terms: Vec<(usize, usize)>,
    /// The coefficients of the first-order terms, `n_inputs + 1` each.
    pub coefficients: Vec<f64>,
    /// The number of input variables.
    pub n_inputs: usize,
    /// The first node slot of the value slots of `kernel.rs` (the degree table comes first:
    /// `node_base = degree_count`).
    pub node_base: usize,
    /// The AND nodes, in slots `node_base..`: each combines two earlier slots (a degree or an
    /// AND node, then a degree), so that a rule's antecedents are combined left to right and
    /// rules with the same leading antecedents share their partial results.
    pub and_nodes: Vec<[u32; 2]>,
    /// The OR nodes, in the slots after the AND nodes, built the same way.
    pub or_nodes: Vec<[u32; 2]>,
    /// The slot holding each rule's combined antecedents (a degree for a rule of one antecedent).
    pub rule_slots: Vec<u32>,
    /// The first of the rules' strength slots, one per rule in rule order: after the nodes, or,
    /// when every weight is 1 and the rules' combined antecedents already sit in consecutive
    /// slots in rule order (`weights_folded`), those slots themselves.
    pub strength_base: usize,
    /// Whether the strengths are the combined antecedents in place (no weight to apply).
    pub weights_folded: bool,
    /// When every rule concludes on every output: the outputs in pairs `(2p, 2p + 1)`, and for
    /// each pair, rule after rule, the rule's terms for both (the second repeating the first
    /// when the last pair has one output), so that two outputs are summed side by side.
    pub dense_terms: Option<DenseTerms>,
    /// The number of value slots: degrees, complements, 1 and 0, nodes, strengths.
    pub slot_count: usize,
    /// `[rule, term]` for every rule that concludes on an output, output after output and in
    /// rule order within one output; `term` indexes `term_values`.
    pub conclusions: Vec<[u32; 2]>,
    /// Output `o`'s conclusions are `conclusions[conclusion_offsets[o]..conclusion_offsets[o + 1]]`.
    pub conclusion_offsets: Vec<usize>,
    /// The separable form of a complete grid of product rules, when the system has one
    /// (`separable.rs`): what [`Evaluator::eval`](crate::Evaluator::eval) takes.
    pub separable: Option<Separable>,
}

/// The terms of [`Compiled::dense_terms`], one pair per rule and pair of outputs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum DenseTerms {
    /// Every term is a constant (a zero-order system): their values.
    Constants(Vec<[f64; 2]>),
    /// Some term is first order, computed at each point: their indices in the term slots.
    Slots(Vec<[u32; 2]>),
}

impl Compiled {
    fn new(
        inputs: &[InputVariable],
        outputs: &[OutputVariable],
        rules: &[Rule],
        methods: Methods,
    ) -> Result<Self, FuzzyError> {
        let mut mfs = Vec::new();
        let mut mf_inputs = Vec::new();
        let mut set_offsets = Vec::with_capacity(inputs.len());
        for (i, input) in inputs.iter().enumerate() {
            set_offsets.push(mfs.len());
            for set in &input.sets {
                mfs.push(set.membership.compile()?);
                mf_inputs.push(i);
            }
        }
        let mut term_offsets = Vec::with_capacity(outputs.len());
        let mut term_values = Vec::new();
        let mut linear_terms = Vec::new();
        let mut coefficients = Vec::new();
        for output in outputs {
            term_offsets.push(term_values.len());
            for term in &output.terms {
                match &term.function {
                    OutputFn::Constant(c) => term_values.push(*c),
                    OutputFn::Linear {
                        coefficients: p,
                        constant,
                    } => {
                        linear_terms.push((term_values.len(), coefficients.len()));
                        coefficients.extend_from_slice(p);
                        coefficients.push(*constant);
                        term_values.push(*constant);
                    }
                }
            }
        }
        let has_complements = rules
            .iter()
            .flat_map(|r| &r.antecedents)
            .any(|a| matches!(a, Antecedent::IsNot(_)));
        let n_mf = mfs.len();
        let degree_count = n_mf * if has_complements { 2 } else { 1 } + 2;
        let (one, zero) = (degree_count - 2, degree_count - 1);
        let index = |k: usize| {
            u32::try_from(k).map_err(|_| invalid("system", SystemProblem::TooLarge { entries: k }))
        };
        let mut antecedents = Vec::with_capacity(rules.len() * inputs.len());
        for rule in rules {
            for (i, antecedent) in rule.antecedents.iter().enumerate() {
                antecedents.push(index(match *antecedent {
                    Antecedent::Any if rule.connective == Connective::Or => zero,
                    Antecedent::Any => one,
                    Antecedent::Is(k) => set_offsets[i] + k,
                    Antecedent::IsNot(k) => n_mf + set_offsets[i] + k,
                })?);
            }
        }
        let mut conclusions = Vec::new();
        let mut conclusion_offsets = vec![0];
        for (o, &first_term) in term_offsets.iter().enumerate() {
            for (r, rule) in rules.iter().enumerate() {
                if let Some(k) = rule.consequents[o] {
                    conclusions.push([index(r)?, index(first_term + k)?]);
                }
            }
            conclusion_offsets.push(conclusions.len());
        }
        // The nodes: AND rules first, so that every AND node precedes every OR node. Within one
        // connective they are built level by level (every rule's first pair, then every rule's
        // second, ...), so that when the rules all combine the same number of antecedents their
        // last nodes are consecutive and in rule order: the strengths are then read in place
        // (`weights_folded`) instead of being copied out.
        let node_base = degree_count;
        let mut rule_slots = vec![0; rules.len()];
        let mut and_nodes = Vec::new();
        let mut or_nodes = Vec::new();
        for connective in [Connective::And, Connective::Or] {
            let (nodes, first) = match connective {
                Connective::And => (&mut and_nodes, node_base),
                Connective::Or => (&mut or_nodes, node_base + and_nodes.len()),
            };
            // Each rule's antecedents that are not "don't care", in input order.
            let mut chains = Vec::new();
            for (r, rule) in rules.iter().enumerate() {
                if rule.connective != connective {
                    continue;
                }
                let row = &antecedents[r * inputs.len()..(r + 1) * inputs.len()];
                let cared: Vec<u32> = row
                    .iter()
                    .zip(&rule.antecedents)
                    .filter(|(_, a)| **a != Antecedent::Any)
                    .map(|(&slot, _)| slot)
                    .collect();
                // `check_rule` refuses a rule whose antecedents are all "don't care".
                rule_slots[r] = *cared.first().ok_or_else(|| {
                    invalid(&format!("rule {}", r + 1), SystemProblem::NoAntecedent)
                })?;
                chains.push((r, cared));
            }
            let mut known: std::collections::HashMap<[u32; 2], u32> = Default::default();
            let depth = chains.iter().map(|(_, cared)| cared.len()).max();
            for level in 1..depth.unwrap_or(0) {
                for (r, cared) in &chains {
                    let Some(&next) = cared.get(level) else {
                        continue;
                    };
                    let pair = [rule_slots[*r], next];
                    rule_slots[*r] = match known.get(&pair) {
                        Some(&node) => node,
                        None => {
                            let node = index(first + nodes.len())?;
                            nodes.push(pair);
                            known.insert(pair, node);
                            node
                        }
                    };
                }
            }
        }
        let node_end = node_base + and_nodes.len() + or_nodes.len();
        // A system without rules (a `.fis` file may have none) has no strengths to read in place.
        let folded_base = rule_slots.first().filter(|&&first| {
            rules.iter().all(|r| r.weight == 1.0)
                && (0..).zip(&rule_slots).all(|(r, &slot)| slot == first + r)
        });
        let weights_folded = folded_base.is_some();
        let strength_base = folded_base.map_or(node_end, |&first| first as usize);
        // When every rule concludes on every output, its conclusions are one per rule in rule
        // order: each rule's terms, output pair by pair.
        let every_rule_concludes = !rules.is_empty()
            && conclusion_offsets
                .windows(2)
                .all(|bounds| bounds[1] - bounds[0] == rules.len());
        let dense_terms = every_rule_concludes.then(|| {
            let term = |o: usize, r: usize| conclusions[conclusion_offsets[o] + r][1];
            let n_out = outputs.len();
            let pairs: Vec<[u32; 2]> = (0..n_out)
                .step_by(2)
                .flat_map(|o| {
                    (0..rules.len()).map(move |r| [term(o, r), term((o + 1).min(n_out - 1), r)])
                })
                .collect();
            if linear_terms.is_empty() {
                DenseTerms::Constants(
                    pairs
                        .iter()
                        .map(|p| p.map(|t| term_values[t as usize]))
                        .collect(),
                )
            } else {
                DenseTerms::Slots(pairs)
            }
        });
        let constant_terms: Vec<Vec<Option<f64>>> = outputs
            .iter()
            .map(|output| {
                (output.terms.iter())
                    .map(|term| match term.function {
                        OutputFn::Constant(c) => Some(c),
                        OutputFn::Linear { .. } => None,
                    })
                    .collect()
            })
            .collect();
        let separable = Separable::new(&mfs, &mf_inputs, &constant_terms, rules, methods);
        let compiled = Self {
            separable,
            mfs,
            mf_inputs,
            has_complements,
            degree_count,
            antecedents,
            weights: rules.iter().map(|r| r.weight).collect(),
            is_or: rules
                .iter()
                .map(|r| r.connective == Connective::Or)
                .collect(),
            term_values,
            linear_terms,
            coefficients,
            n_inputs: inputs.len(),
            node_base,
            and_nodes,
            or_nodes,
            rule_slots,
            strength_base,
            weights_folded,
            dense_terms,
            slot_count: if weights_folded {
                node_end
            } else {
                node_end + rules.len()
            },
            conclusions,
            conclusion_offsets,
        };
        // The kernel indexes its buffers without bounds checks on this (`kernel::get`).
        assert!(
            compiled.slots_in_bounds(),
            "fuzzy-sugeno: compiled tables out of bounds"
        );
        Ok(compiled)
    }

    /// Whether every slot that the kernel reads from these tables is within the buffer sizes
    /// that the tables give (`n_inputs` inputs, `slot_count` values, the terms, two sums per
    /// output): each node reads slots before its own, and the rules' strengths, conclusions
    /// and dense terms stay within their counts.
    pub(crate) fn slots_in_bounds(&self) -> bool {
        let (n_terms, n_rules) = (self.term_values.len(), self.weights.len());
        let n_out = self.conclusion_offsets.len() - 1;
        let n_nodes = self.and_nodes.len() + self.or_nodes.len();
        let degrees = self.mfs.len() * if self.has_complements { 2 } else { 1 };
        let nodes_in_bounds = self
            .and_nodes
            .iter()
            .chain(&self.or_nodes)
            .zip(self.node_base..)
            .all(|(&[a, b], slot)| (a as usize) < slot && (b as usize) < slot);
        let dense_in_bounds = match &self.dense_terms {
            None => true,
            Some(DenseTerms::Constants(pairs)) => pairs.len() == n_out.div_ceil(2) * n_rules,
            Some(DenseTerms::Slots(pairs)) => {
                pairs.len() == n_out.div_ceil(2) * n_rules
                    && pairs.iter().flatten().all(|&t| (t as usize) < n_terms)
            }
        };
        self.mfs.len() == self.mf_inputs.len()
            && self.mf_inputs.iter().all(|&i| i < self.n_inputs)
            && degrees + 2 == self.degree_count
            && self.node_base == self.degree_count
            && nodes_in_bounds
            && self.node_base + n_nodes <= self.slot_count
            && self.rule_slots.len() == n_rules
            && self
                .rule_slots
                .iter()
                .all(|&s| (s as usize) < self.slot_count)
            && self.strength_base + n_rules <= self.slot_count
            && self.linear_terms.iter().all(|&(term, _)| term < n_terms)
            && self
                .conclusions
                .iter()
                .all(|&[rule, term]| (rule as usize) < n_rules && (term as usize) < n_terms)
            && dense_in_bounds
            && self.separable.as_ref().is_none_or(|s| {
                s.slots_in_bounds()
                    && s.sets.len() == self.mfs.len()
                    && s.set_offsets.len() == self.n_inputs + 1
            })
    }
}

#[cfg(test)]
mod tests {
    use crate::paper_controller;

    /// The check the kernel's unchecked indexing rests on catches a table out of bounds.
    #[test]
    fn slots_in_bounds_catches_a_node_reading_a_later_slot() {
        let mut c = paper_controller().compiled().clone();
        assert!(c.slots_in_bounds());
        c.and_nodes[0] = [0, c.node_base as u32];
        assert!(!c.slots_in_bounds());
        let mut c = paper_controller().compiled().clone();
        c.conclusions[3][1] = c.term_values.len() as u32;
        assert!(!c.slots_in_bounds());
    }

    #[test]
    fn a_full_grid_of_rules_shares_its_prefixes_and_reads_its_strengths_in_place() {
        let system = paper_controller();
        let c = system.compiled();
        // 16 rules over 4 inputs: 4 + 8 + 16 products, the last 16 in rule order.
        assert_eq!(c.and_nodes.len(), 28);
        assert!(c.weights_folded);
        assert_eq!(c.strength_base, c.node_base + 12);
        let expected: Vec<u32> = (0..16).map(|r| (c.node_base + 12 + r) as u32).collect();
        assert_eq!(c.rule_slots, expected);
        // Level by level: every node reads slots of the levels before it.
        for (k, &[a, b]) in c.and_nodes.iter().enumerate() {
            let level_start = match k {
                0..4 => c.node_base,
                4..12 => c.node_base + 4,
                _ => c.node_base + 12,
            };
            assert!((a as usize) < level_start && (b as usize) < c.node_base);
        }
    }
}
