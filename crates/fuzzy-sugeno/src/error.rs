//! The crate's error type.

/// Everything that can go wrong when building, evaluating, reading or analysing a fuzzy system.
/// Every message says which condition failed and where.
///
/// [`FuzzyError::is_numerical`] and [`FuzzyError::is_invalid_input`] sort the variants into the
/// two classes a caller acts on; exactly one holds for every error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FuzzyError {
    /// A membership function's parameters are invalid (zero width, unordered corners, ...).
    #[error("{function}: {reason}")]
    InvalidMembership {
        /// MATLAB's name of the function type (`gbellmf`, ...).
        function: String,
        /// The condition that failed.
        reason: String,
    },
    /// A system definition is invalid (bad range, unknown set name, rule of the wrong length, ...).
    #[error("{context}: {problem}")]
    InvalidSystem {
        /// Where: `input 'da1'`, `rule 3`, ...
        context: String,
        /// The condition that failed.
        problem: SystemProblem,
    },
    /// The input slice does not have one value per input variable.
    #[error("expected {expected} inputs, got {found}")]
    InputCount {
        /// The system's number of inputs.
        expected: usize,
        /// The slice's length.
        found: usize,
    },
    /// The output slice does not have one slot per output variable.
    #[error("the output buffer has {found} slots but the system has {expected} outputs")]
    OutputCount {
        /// The system's number of outputs.
        expected: usize,
        /// The slice's length.
        found: usize,
    },
    /// An input is NaN or infinite.
    #[error("input {index} ('{name}') is not finite: {value}")]
    NonFiniteInput {
        /// The input's position (0-based).
        index: usize,
        /// The input's name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// An input lies outside its range under [`OutOfRange::Error`](crate::OutOfRange::Error).
    #[error("input {index} ('{name}') = {value} lies outside its range [{min}, {max}]")]
    InputOutOfRange {
        /// The input's position (0-based).
        index: usize,
        /// The input's name.
        name: String,
        /// The offending value.
        value: f64,
        /// The range's lower end.
        min: f64,
        /// The range's upper end.
        max: f64,
    },
    /// No rule contributing to an output fired, under [`NoRuleFired::Error`](crate::NoRuleFired::Error).
    #[error("no rule fired for output {index} ('{name}')")]
    NoRuleFired {
        /// The output's position (0-based).
        index: usize,
        /// The output's name.
        name: String,
    },
    /// An output came out NaN or infinite (a first-order consequent overflowed).
    #[error("output {index} ('{name}') came out non-finite ({value})")]
    NonFiniteOutput {
        /// The output's position (0-based).
        index: usize,
        /// The output's name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// The fallback values of [`NoRuleFired::Values`](crate::NoRuleFired::Values) do not hold
    /// one value per output.
    #[error("evaluation options: no-rule-fired values have {found} entries for {expected} outputs")]
    FallbackCount {
        /// The system's number of outputs.
        expected: usize,
        /// The number of values given.
        found: usize,
    },
    /// A fallback value of [`NoRuleFired::Values`](crate::NoRuleFired::Values) is NaN or
    /// infinite.
    #[error("evaluation options: no-rule-fired values must be finite, got {value}")]
    NonFiniteFallback {
        /// The offending value.
        value: f64,
    },
    /// A batch's input slice is not a whole number of rows.
    #[error("a batch of inputs has {len} values, not a multiple of the {inputs} inputs")]
    BatchLength {
        /// The slice's length.
        len: usize,
        /// The system's number of inputs.
        inputs: usize,
    },
    /// One row of a batch evaluation failed.
    #[error("batch row {row}: {source}")]
    Batch {
        /// The row (0-based).
        row: usize,
        /// What failed in that row.
        source: Box<FuzzyError>,
    },
    /// A malformed or unsupported `.fis` file.
    #[error("line {line}: {message}")]
    Fis {
        /// The 1-based line number.
        line: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// An option of a rule-base analysis is out of its domain.
    #[error("analysis: {name} must {requirement}, got {value}")]
    AnalysisOption {
        /// Which option of [`AnalysisOptions`](crate::AnalysisOptions).
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The completeness grid would need more points than
    /// [`AnalysisOptions::max_grid_points`](crate::AnalysisOptions::max_grid_points) allows even
    /// with 2 samples per input.
    #[error(
        "analysis: the completeness grid needs more than max_grid_points = {max_grid_points} \
         points even with 2 samples per input; raise max_grid_points"
    )]
    AnalysisGrid {
        /// The limit in force.
        max_grid_points: usize,
    },
    /// Learning from data (`genfis`, ANFIS) cannot proceed: bad data or options, a system that
    /// ANFIS cannot train, or a least-squares problem the data do not determine.
    #[error("learning: {0}")]
    Learning(String),
    /// A malformed or unsupported IEC 61131-7 FCL file.
    #[error("FCL line {line}: {message}")]
    Fcl {
        /// The 1-based line number.
        line: usize,
        /// What was found and what was expected.
        message: String,
    },
    /// The prefix of a C export is not a C identifier of at most `max` characters.
    #[error(
        "export: the prefix must be a C identifier of 1 to {max} ASCII letters, digits and \
         underscores, not starting with a digit or two underscores; got {prefix:?}"
    )]
    CPrefix {
        /// The prefix given.
        prefix: String,
        /// The longest prefix allowed.
        max: usize,
    },
    /// A name of the system cannot be written in FCL.
    #[error(
        "export: the {kind} name '{name}' is not an FCL identifier (letters, digits and _, \
         not starting with a digit, not a keyword)"
    )]
    FclName {
        /// `"system"`, `"input"`, `"output"`, `"set"` or `"term"`.
        kind: &'static str,
        /// The name.
        name: String,
    },
}

impl FuzzyError {
    /// Whether a computation on valid input failed numerically: an output that came out
    /// non-finite ([`NonFiniteOutput`](FuzzyError::NonFiniteOutput)), also inside a batch.
    pub fn is_numerical(&self) -> bool {
        match self {
            Self::NonFiniteOutput { .. } => true,
            Self::Batch { source, .. } => source.is_numerical(),
            _ => false,
        }
    }

    /// Whether the input (a system, a file, options or values to evaluate) was malformed or
    /// outside its domain: every error that is not [`is_numerical`](Self::is_numerical).
    pub fn is_invalid_input(&self) -> bool {
        !self.is_numerical()
    }
}

/// What is wrong with a system definition: the `problem` of [`FuzzyError::InvalidSystem`], one
/// variant per condition, each phrased to follow its context (`rule 3: has no consequent`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SystemProblem {
    /// A name is empty.
    #[error("the {kind} name is empty")]
    EmptyName {
        /// `"system"`, `"variable"` or `"set"`.
        kind: &'static str,
    },
    /// A name holds a quote or a control character (a `.fis` file writes it between quotes).
    #[error("the {kind} name {name:?} contains a quote or a control character")]
    UnwritableName {
        /// `"system"`, `"variable"` or `"set"`.
        kind: &'static str,
        /// The name.
        name: String,
    },
    /// A name is `-`, which rules use for "don't care".
    #[error("\"-\" is reserved for \"don't care\" and cannot be a {kind} name")]
    ReservedName {
        /// `"system"`, `"variable"` or `"set"`.
        kind: &'static str,
    },
    /// The system has no input or no output.
    #[error("needs at least one input and one output")]
    NoVariables,
    /// Two variables share a name.
    #[error("another variable has the same name")]
    DuplicateVariable,
    /// A variable's range is not finite, or not ordered.
    #[error("range must be finite with {order}, got [{min}, {max}]")]
    Range {
        /// `"min < max"` (inputs) or `"min <= max"` (outputs).
        order: &'static str,
        /// The range's lower end.
        min: f64,
        /// The range's upper end.
        max: f64,
    },
    /// An output has no terms.
    #[error("has no sets")]
    NoTerms,
    /// A membership function's parameters are invalid (its [`FuzzyError::InvalidMembership`]).
    #[error("{0}")]
    Membership(Box<FuzzyError>),
    /// A constant consequent is NaN or infinite.
    #[error("constant must be finite, got {value}")]
    NonFiniteConstant {
        /// The constant.
        value: f64,
    },
    /// A first-order consequent does not have one coefficient per input.
    #[error("linear consequent has {found} coefficients for {expected} inputs")]
    CoefficientCount {
        /// The number of inputs.
        expected: usize,
        /// The number of coefficients.
        found: usize,
    },
    /// A first-order consequent has a NaN or infinite coefficient.
    #[error("linear consequent coefficients must be finite")]
    NonFiniteCoefficient,
    /// A rule does not have one antecedent per input.
    #[error("has {found} antecedents for {expected} inputs")]
    AntecedentCount {
        /// The number of inputs.
        expected: usize,
        /// The number of antecedents.
        found: usize,
    },
    /// A rule does not have one consequent per output.
    #[error("has {found} consequents for {expected} outputs")]
    ConsequentCount {
        /// The number of outputs.
        expected: usize,
        /// The number of consequents.
        found: usize,
    },
    /// A rule names a set (by 1-based number) that its input does not have.
    #[error("input '{input}' has {count} sets, there is no set {set}")]
    NoSuchSet {
        /// The input's name.
        input: String,
        /// Its number of sets.
        count: usize,
        /// The set asked for (1-based).
        set: usize,
    },
    /// A rule names a term (by 1-based number) that its output does not have.
    #[error("output '{output}' has {count} terms, there is no term {term}")]
    NoSuchTerm {
        /// The output's name.
        output: String,
        /// Its number of terms.
        count: usize,
        /// The term asked for (1-based).
        term: usize,
    },
    /// A rule names a set that its input does not have.
    #[error("input '{input}' has no set '{set}' (its sets: {available})")]
    UnknownSet {
        /// The input's name.
        input: String,
        /// The name asked for.
        set: String,
        /// The input's set names, comma-separated.
        available: String,
    },
    /// A rule names a term that its output does not have.
    #[error("output '{output}' has no term '{term}' (its terms: {available})")]
    UnknownTerm {
        /// The output's name.
        output: String,
        /// The name asked for.
        term: String,
        /// The output's term names, comma-separated.
        available: String,
    },
    /// A rule names a set or term that several of its variable's share.
    #[error(
        "'{variable}' has several {kind} named '{name}' ({first} and {second}); use an indexed rule"
    )]
    AmbiguousName {
        /// The variable's name.
        variable: String,
        /// `"sets"` or `"terms"`.
        kind: &'static str,
        /// The shared name.
        name: String,
        /// The first two 1-based positions with that name.
        first: usize,
        /// The second.
        second: usize,
    },
    /// Every antecedent of a rule is "don't care".
    #[error("has no antecedent (every input is \"don't care\")")]
    NoAntecedent,
    /// Every consequent of a rule is "don't care".
    #[error("has no consequent")]
    NoConsequent,
    /// A rule's weight lies outside `[0, 1]`.
    #[error("weight must lie in [0, 1], got {weight}")]
    Weight {
        /// The weight.
        weight: f64,
    },
    /// The evaluation tables would need indices beyond 32 bits.
    #[error("too large to index with 32 bits ({entries} entries)")]
    TooLarge {
        /// The index that does not fit.
        entries: usize,
    },
}
