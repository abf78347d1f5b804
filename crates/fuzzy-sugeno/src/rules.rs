//! A rule base's parts: the rules in index form and the inference methods that combine them
//! (the product inference and eq 21's weighted average by default), apart from the system that
//! validates and compiles them.

/// One antecedent of a rule, for one input variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Antecedent {
    /// "Don't care": the input does not take part in the rule (MATLAB `0`).
    Any,
    /// "input is set `k`" (0-based set index; MATLAB `k + 1`).
    Is(usize),
    /// "input is not set `k`", membership `1 - mu` (MATLAB `-(k + 1)`).
    IsNot(usize),
}

/// How a rule combines its antecedents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Connective {
    /// All antecedents, combined with the system's [`AndMethod`] (MATLAB `1`).
    #[default]
    And,
    /// Any antecedent, combined with the system's [`OrMethod`] (MATLAB `2`).
    Or,
}

/// A fuzzy IF-THEN rule in index form (MATLAB's rule-list row).
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    /// One antecedent per input variable.
    pub antecedents: Vec<Antecedent>,
    /// One entry per output variable: the 0-based index of the output term, or `None` when the
    /// rule says nothing about that output (MATLAB `0`; the rule then does not enter that
    /// output's weighted average at all).
    pub consequents: Vec<Option<usize>>,
    /// The rule's weight in `[0, 1]`; it multiplies the firing strength.
    pub weight: f64,
    /// AND or OR of the antecedents.
    pub connective: Connective,
}

/// The fuzzy AND (t-norm) of a rule's antecedents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AndMethod {
    /// `a * b` (MATLAB `'prod'`): the paper's product inference engine.
    #[default]
    Product,
    /// `min(a, b)` (MATLAB `'min'`).
    Minimum,
}

/// The fuzzy OR (s-norm) of a rule's antecedents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OrMethod {
    /// `a + b - a b` (MATLAB `'probor'`).
    #[default]
    ProbabilisticSum,
    /// `max(a, b)` (MATLAB `'max'`).
    Maximum,
}

/// How rule outputs combine into the crisp output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Defuzzification {
    /// `sum w_r z_r / sum w_r`, the centre-average defuzzifier (eq 21; MATLAB `'wtaver'`).
    #[default]
    WeightedAverage,
    /// `sum w_r z_r` (MATLAB `'wtsum'`).
    WeightedSum,
}

/// The inference methods of a system.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Methods {
    /// The AND of antecedents.
    pub and: AndMethod,
    /// The OR of antecedents.
    pub or: OrMethod,
    /// The defuzzifier.
    pub defuzzification: Defuzzification,
}
