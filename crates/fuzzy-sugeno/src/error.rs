//! The crate's error type.

use lane_math::{Classify, ErrorClass};

/// Everything that can go wrong when building, evaluating, reading or analysing a fuzzy system.
/// Every message says which condition failed and where. The fields hold 0-based positions, as
/// the API takes them; the messages count inputs, outputs, rules and rows from 1, as a `.fis`
/// file (`[Input3]`) and the analysis report do.
///
/// [`ErrorClass::Numerical`] and [`ErrorClass::InvalidInput`] are the two classes
/// ([`Classify::class`]) its variants fall into.
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
    #[error("input {} ('{name}') is not finite: {value}", .index + 1)]
    NonFiniteInput {
        /// The input's position (0-based).
        index: usize,
        /// The input's name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// An input lies outside its range under [`OutOfRange::Error`](crate::OutOfRange::Error).
    #[error(
        "input {} ('{name}') = {value} lies outside its range [{min}, {max}]",
        .index + 1
    )]
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
    #[error("no rule fired for output {} ('{name}')", .index + 1)]
    NoRuleFired {
        /// The output's position (0-based).
        index: usize,
        /// The output's name.
        name: String,
    },
    /// An output came out NaN or infinite (a first-order consequent overflowed).
    #[error("output {} ('{name}') came out non-finite ({value})", .index + 1)]
    NonFiniteOutput {
        /// The output's position (0-based).
        index: usize,
        /// The output's name.
        name: String,
        /// The offending value.
        value: f64,
    },
    /// Two neighbouring rules' consequents on an output differ by more than double precision
    /// holds (constants of `1e308` and `-1e308`), so the continuity check has no finite jump.
    #[error(
        "analysis: the consequents of rules {} and {} on output {} ('{name}') differ by more \
         than double precision holds",
        .rules[0] + 1,
        .rules[1] + 1,
        .index + 1
    )]
    JumpOverflow {
        /// The output's position (0-based).
        index: usize,
        /// The output's name.
        name: String,
        /// The two rules (0-based).
        rules: [usize; 2],
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
    #[error("batch row {}: {source}", .row + 1)]
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
    #[error("analysis: {name} must {requirement}, got {}", lane_math::Compact(*.value))]
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
    /// with 2 samples per input: the breakpoints of the inputs' sets alone are too many.
    #[error(
        "analysis: the completeness grid needs {} points ({} along its inputs, each with 2 \
         even samples, its sets' landmarks and the midpoints between them), more than the \
         {max_grid_points} the check evaluates (AnalysisOptions::max_grid_points); a system \
         with fewer inputs or sets can be checked",
        crate::error::grid_size(axes),
        axes.iter().map(usize::to_string).collect::<Vec<_>>().join(" x ")
    )]
    AnalysisGrid {
        /// The limit in force.
        max_grid_points: usize,
        /// The points of each input's axis with 2 samples (its ends and its sets' breakpoints).
        axes: Vec<usize>,
    },
    /// The rule pairs plus the smallest completeness grid times the rules exceed
    /// [`AnalysisOptions::max_work`](crate::AnalysisOptions::max_work).
    #[error(
        "analysis: {rules} rules need more than the limit of {max_work} rule evaluations \
         (rule pairs plus grid points times rules, with 2 samples per input)"
    )]
    AnalysisWork {
        /// The system's rule count.
        rules: usize,
        /// The limit in force.
        max_work: u64,
    },
    /// Learning from data (`genfis`, ANFIS, [`merge_outputs`](crate::learn::merge_outputs))
    /// cannot proceed: bad data or options, a system that ANFIS cannot train or merge, or a
    /// least-squares problem the data do not determine.
    #[error("learning: {0}")]
    Learning(LearningProblem),
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
         underscores, starting with a letter; got {prefix:?}"
    )]
    CPrefix {
        /// The prefix given.
        prefix: String,
        /// The longest prefix allowed.
        max: usize,
    },
    /// A C export's prefix that names its header like a C standard header (`math.h`, which the
    /// source includes; any, in any case, which a compiler given the export's folder with `-I`
    /// would take instead of the system's).
    #[error(
        "export: the prefix {prefix:?} would write {prefix}.h, which shadows the C standard \
         header <{standard}.h> for code compiled with the export's folder on its include path; \
         choose another prefix"
    )]
    CPrefixShadowsHeader {
        /// The prefix given.
        prefix: String,
        /// The standard header's name without `.h`.
        standard: &'static str,
    },
    /// A name of the system cannot be written in FCL.
    #[error(
        "export: the {kind} name '{name}' cannot be written in FCL: a name must be ASCII \
         letters, digits and _, not start with a digit, and not be a keyword of FCL or of \
         fuzzylite's rules (END_VAR, RANGE, then, any, very, ...); rename it"
    )]
    FclName {
        /// `"system"`, `"input"`, `"output"`, `"set"` or `"term"`.
        kind: &'static str,
        /// The name.
        name: String,
    },
    /// Two sets of an input, or two terms of an output, share a name (a `.fis` file allows it;
    /// FCL rules name terms, so the second could not be told from the first).
    #[error("export: {variable} has two terms named '{name}'; FCL rules name terms, so rename one")]
    FclDuplicateTerm {
        /// `input 'x'` or `output 'y'`.
        variable: String,
        /// The shared name.
        name: String,
    },
    /// A set is one of MATLAB's steps (`smf`, `zmf` or `pimf` with a foot at or past its
    /// shoulder), which fuzzylite's `SShape`, `ZShape` and `PiShape` evaluate otherwise.
    #[error(
        "export: the set '{set}' of input '{input}' is MATLAB's step ({shape} with its foot at or \
         past its shoulder), which fuzzylite evaluates otherwise; FCL cannot carry it"
    )]
    FclStep {
        /// The input's name.
        input: String,
        /// The set's name.
        set: String,
        /// `"smf"`, `"zmf"` or `"pimf"`.
        shape: &'static str,
    },
}

impl Classify for FuzzyError {
    /// [`Numerical`](ErrorClass::Numerical) when a computation on valid input failed: an output
    /// that came out non-finite ([`NonFiniteOutput`](FuzzyError::NonFiniteOutput)), also inside a
    /// batch, or a training whose least-squares problem or premise gradient failed
    /// ([`LearningProblem`]'s class); otherwise the input (a system, a file, options or values to
    /// evaluate) was malformed or outside its domain. No fuzzy error is
    /// [`Unreachable`](ErrorClass::Unreachable).
    fn class(&self) -> ErrorClass {
        match self {
            Self::NonFiniteOutput { .. } | Self::JumpOverflow { .. } => ErrorClass::Numerical,
            Self::Learning(problem) => problem.class(),
            Self::Batch { source, .. } => source.class(),
            _ => ErrorClass::InvalidInput,
        }
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
    #[error("range must be finite with {order}, got [{}, {}]", lane_math::Compact(*min), lane_math::Compact(*max))]
    Range {
        /// `"min < max"` (inputs) or `"min <= max"` (outputs), or the width's bound.
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

/// Why learning from data cannot proceed: the problem of [`FuzzyError::Learning`], one variant
/// per condition, with the numbers and names it reports as fields.
///
/// Indices (rows, columns, inputs, outputs, rules, systems, terms) are 0-based, as the API takes
/// them; the messages count from 1, as a spreadsheet or a `.fis` file does.
/// Its class ([`ErrorClass::Numerical`] or not) tells the problems of a computation on valid input
/// (least squares the data do not determine, a gradient that overflows) from bad data, options
/// or systems.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LearningProblem {
    /// A count (of the data's inputs or outputs, of sets per input, of epochs) outside
    /// `1..=max`.
    #[error("{name} must lie in 1..={max}, got {count}")]
    CountOutOfRange {
        /// `"the number of inputs"`, `"the number of outputs"` (of
        /// [`TrainingData::new`](crate::learn::TrainingData::new)), `"sets per input"` (of
        /// [`GridPartition`](crate::learn::GridPartition)) or `"epochs"` (of
        /// [`AnfisOptions`](crate::learn::AnfisOptions)).
        name: &'static str,
        /// The count given.
        count: usize,
        /// The largest count allowed.
        max: usize,
    },
    /// The data's values are empty or not a whole number of rows.
    #[error("{values} values are not a whole, non-zero number of rows of {width}")]
    RowLength {
        /// The number of values given.
        values: usize,
        /// The row width: inputs plus outputs.
        width: usize,
    },
    /// The data have more rows than [`MAX_ROWS`](crate::learn::MAX_ROWS).
    #[error("{rows} rows exceed the limit of {limit}")]
    TooManyRows {
        /// The number of rows.
        rows: usize,
        /// The limit.
        limit: usize,
    },
    /// A value of the data is NaN or infinite (the first one, row by row).
    #[error("row {} column {} is not finite ({value})", .row + 1, .column + 1)]
    NonFiniteValue {
        /// The row (0-based).
        row: usize,
        /// The column (0-based: inputs, then outputs).
        column: usize,
        /// The offending value.
        value: f64,
    },
    /// A value of the data beyond [`MAX_MAGNITUDE`](crate::learn::MAX_MAGNITUDE) (the first one,
    /// row by row).
    #[error(
        "row {} column {} is {}, beyond the {} in magnitude that learning handles",
        .row + 1, .column + 1, lane_math::Compact(*.value), lane_math::Compact(*.limit)
    )]
    HugeValue {
        /// The row (0-based).
        row: usize,
        /// The column (0-based: inputs, then outputs).
        column: usize,
        /// The offending value.
        value: f64,
        /// The largest magnitude.
        limit: f64,
    },
    /// The data's column names are not one per column.
    #[error("{names} column names for {columns} columns")]
    ColumnNameCount {
        /// The number of names given.
        names: usize,
        /// The number of columns.
        columns: usize,
    },
    /// A column name cannot name a variable (empty, quoted, `-`, ...).
    #[error("column {}: {problem}", .column + 1)]
    ColumnName {
        /// The column (0-based).
        column: usize,
        /// What is wrong with the name, as a variable name.
        problem: SystemProblem,
    },
    /// A column name repeats an earlier column's.
    #[error("column {}: another column is also named '{name}'", .column + 1)]
    DuplicateColumnName {
        /// The later column (0-based).
        column: usize,
        /// The shared name.
        name: String,
    },
    /// The output index asked for is not one of the data's outputs.
    #[error("output {} asked of data with {outputs} outputs", .output + 1)]
    NoSuchOutput {
        /// The output asked for (0-based).
        output: usize,
        /// The data's number of outputs.
        outputs: usize,
    },
    /// [`SetShape::from_matlab_name`](crate::learn::SetShape::from_matlab_name) does not know
    /// the type.
    #[error(
        "unknown set type '{name}' for a grid partition; expected one of gbellmf, gaussmf, \
         gauss2mf, trimf, trapmf, sigmf, dsigmf, psigmf, pimf"
    )]
    UnknownSetShape {
        /// The type asked for.
        name: String,
    },
    /// The inputs of [`genfis_grid_over`](crate::learn::genfis_grid_over) are empty, not
    /// increasing, or name an input the data lack.
    #[error(
        "the partitioned inputs must be a non-empty increasing list of indices below {inputs}, \
         got {partitioned:?}"
    )]
    PartitionedInputs {
        /// The list given.
        partitioned: Vec<usize>,
        /// The data's number of inputs.
        inputs: usize,
    },
    /// A `sigmf` grid partition with other than 2 sets per input.
    #[error("sigmf partitions have exactly 2 sets per input (one open to each side), got {sets}")]
    SigmoidSets {
        /// The sets per input asked for.
        sets: usize,
    },
    /// A grid partition would have more than [`MAX_RULES`](crate::learn::MAX_RULES) rules.
    #[error("{sets} sets on each of {inputs} inputs make more than {limit} rules")]
    TooManyRules {
        /// Sets per input.
        sets: usize,
        /// Partitioned inputs.
        inputs: usize,
        /// The rule limit.
        limit: usize,
    },
    /// A real option outside `(0, 1]`.
    #[error("{name} must lie in (0, 1], got {value}")]
    OutsideUnitInterval {
        /// `"the cluster radius"` (of
        /// [`SubtractiveClustering`](crate::learn::SubtractiveClustering)) or `"the step
        /// decrease"` (of [`AnfisOptions`](crate::learn::AnfisOptions)).
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A real option of [`AnfisOptions`](crate::learn::AnfisOptions) that is not finite or
    /// below its minimum.
    #[error("{name} must be finite and at least {min}, got {value}")]
    BelowMinimum {
        /// `"the initial step"`, `"the step increase"`, `"the ridge"` or `"the target RMSE"`.
        name: &'static str,
        /// The smallest value allowed.
        min: f64,
        /// The offending value.
        value: f64,
    },
    /// A real option of [`AnfisOptions`](crate::learn::AnfisOptions) above its maximum.
    #[error("{name} must be at most {max:e}, got {value:e}")]
    AboveMaximum {
        /// `"the ridge"`.
        name: &'static str,
        /// The largest value allowed.
        max: f64,
        /// The offending value.
        value: f64,
    },
    /// Subtractive clustering was given more than
    /// [`MAX_CLUSTER_ROWS`](crate::learn::MAX_CLUSTER_ROWS) rows.
    #[error("subtractive clustering takes at most {limit} rows, got {rows}")]
    TooManyClusterRows {
        /// The number of rows.
        rows: usize,
        /// The limit.
        limit: usize,
    },
    /// Subtractive clustering found more than [`MAX_RULES`](crate::learn::MAX_RULES) clusters.
    #[error("a cluster radius of {radius} finds more than {limit} clusters; use a larger radius")]
    TooManyClusters {
        /// The cluster radius.
        radius: f64,
        /// The cluster (rule) limit.
        limit: usize,
    },
    /// An input column spans less than [`MIN_INPUT_RANGE`](crate::learn::MIN_INPUT_RANGE): a
    /// partition of it would divide by that width beyond double precision.
    #[error(
        "input {} spans only [{}, {}] over the data; a fuzzy partition needs a range of at least {}",
        .input + 1, lane_math::Compact(*.lo), lane_math::Compact(*.hi), lane_math::Compact(*.min)
    )]
    NarrowInput {
        /// The input (0-based).
        input: usize,
        /// Its smallest value.
        lo: f64,
        /// Its largest value.
        hi: f64,
        /// The narrowest range.
        min: f64,
    },
    /// An input column takes one value over the data, so no partition of it exists.
    #[error(
        "input {} is constant ({value}) over the data; a fuzzy partition needs a range",
        .input + 1
    )]
    ConstantInput {
        /// The input (0-based).
        input: usize,
        /// Its only value.
        value: f64,
    },
    /// The output column takes one value over the data.
    #[error(
        "output {} is constant ({value}) over the data; there is nothing to learn",
        .output + 1
    )]
    ConstantOutput {
        /// The output (0-based).
        output: usize,
        /// Its only value.
        value: f64,
    },
    /// The data given to ANFIS do not have the system's number of inputs.
    #[error("the {data} data have {found} inputs, the system {expected}")]
    DataInputs {
        /// `"training"` or `"check"`.
        data: &'static str,
        /// The system's number of inputs.
        expected: usize,
        /// The data's number of inputs.
        found: usize,
    },
    /// The system's sets cannot be indexed with 32 bits.
    #[error("too many sets to index with 32 bits")]
    TooManySets,
    /// The least-squares matrix (samples plus consequent parameters, its ridge rows, times
    /// consequent parameters) would exceed its limit.
    #[error(
        "{samples} samples and {unknowns} consequent parameters exceed the least-squares \
         limit of {limit} entries ((samples + parameters) x parameters)"
    )]
    LeastSquaresTooLarge {
        /// The number of training samples.
        samples: usize,
        /// The number of consequent parameters.
        unknowns: usize,
        /// The largest number of entries allowed.
        limit: usize,
    },
    /// The least-squares solve (a QR of `(samples + parameters) x parameters`, about
    /// `(samples + parameters) parameters^2` multiply-adds) would exceed its limit of work.
    #[error(
        "{samples} samples and {unknowns} consequent parameters make a least-squares solve of \
         more than {limit} multiply-adds ((samples + parameters) x parameters^2): use fewer \
         sets per input or fewer inputs"
    )]
    LeastSquaresTooSlow {
        /// The number of training samples.
        samples: usize,
        /// The number of consequent parameters.
        unknowns: usize,
        /// The most multiply-adds allowed.
        limit: usize,
    },
    /// The epochs of a training, each a least-squares solve and an evaluation of the training
    /// and check rows of `per_epoch` multiply-adds, would exceed the limit of a whole training's
    /// work.
    #[error(
        "{epochs} epochs of {per_epoch} multiply-adds each (the least-squares solve and the \
         evaluation of the training and check rows) exceed the {limit} multiply-adds a training \
         may take (about six minutes): use fewer epochs, fewer check rows, or fewer sets per \
         input or inputs"
    )]
    TrainingTooSlow {
        /// The epochs asked for.
        epochs: usize,
        /// The multiply-adds of one epoch: its least-squares solve and its evaluations.
        per_epoch: usize,
        /// The most multiply-adds allowed.
        limit: usize,
    },
    /// The least-squares problem of the consequents (Jang's eq 15) holds a NaN or an infinity
    /// (its entries or their squares overflowed).
    #[error(
        "the least-squares problem for the consequents holds a non-finite value: the data's \
         scales overflow double precision; rescale the columns"
    )]
    NonFiniteLeastSquares,
    /// Without a ridge, the data do not determine a consequent parameter (the least-squares
    /// matrix of eq 15 is rank deficient): too few samples where its rules fire, or collinear
    /// inputs.
    #[error(
        "the data do not determine {parameter} of output term '{name}' (least squares is rank \
         deficient: too few samples where its rules fire, or collinear inputs); use a ridge > 0"
    )]
    RankDeficient {
        /// The output term (0-based).
        term: usize,
        /// Its name.
        name: String,
        /// The parameter of its consequent.
        parameter: ConsequentParameter,
    },
    /// The premise gradient (Jang's eqs 5-8) came out NaN or infinite.
    #[error(
        "the premise gradient is not finite at epoch {epoch}: the data's scales overflow double \
         precision (outputs large against narrow input ranges); rescale the columns"
    )]
    NonFiniteGradient {
        /// The epoch (1-based, as [`EpochReport::epoch`](crate::learn::EpochReport::epoch)).
        epoch: usize,
    },
    /// The premise step (Jang's `kappa`, the initial step grown by the step increase) moved a
    /// set's parameters beyond double precision.
    #[error(
        "the premise step {} at epoch {epoch} moves the sets' parameters beyond double \
         precision; use a smaller initial step (or step increase)",
        lane_math::Compact(*step)
    )]
    StepOverflow {
        /// The epoch (1-based).
        epoch: usize,
        /// The step length at that epoch.
        step: f64,
    },
    /// ANFIS was given a system with other than one output.
    #[error(
        "ANFIS trains single-output systems; this one has {outputs} outputs (train one system \
         per output)"
    )]
    NotSingleOutput {
        /// The system's number of outputs.
        outputs: usize,
    },
    /// ANFIS was given a system whose AND is not the product.
    #[error("ANFIS needs the product AND (AndMethod='prod')")]
    NotProductAnd,
    /// ANFIS was given a system whose defuzzifier is not the weighted average.
    #[error("ANFIS needs the weighted-average defuzzifier (DefuzzMethod='wtaver')")]
    NotWeightedAverage,
    /// ANFIS was given a system without rules.
    #[error("the system has no rules")]
    NoRules,
    /// ANFIS was given an OR rule.
    #[error("rule {} is an OR rule; ANFIS needs AND rules", .rule + 1)]
    OrRule {
        /// The rule (0-based).
        rule: usize,
    },
    /// ANFIS was given a rule with a negated antecedent.
    #[error("rule {} negates an antecedent; ANFIS needs plain sets", .rule + 1)]
    NegatedAntecedent {
        /// The rule (0-based).
        rule: usize,
    },
    /// ANFIS was given a rule without a consequent.
    #[error("rule {} has no consequent", .rule + 1)]
    NoConsequent {
        /// The rule (0-based).
        rule: usize,
    },
    /// [`merge_outputs`](crate::learn::merge_outputs) was given no system.
    #[error("no systems to merge")]
    NothingToMerge,
    /// [`merge_outputs`](crate::learn::merge_outputs) was given a system with other than one
    /// output.
    #[error(
        "system {} ('{name}') has {outputs} outputs; merge single-output systems",
        .system + 1
    )]
    MergeOutputs {
        /// The system (0-based).
        system: usize,
        /// Its name.
        name: String,
        /// Its number of outputs.
        outputs: usize,
    },
    /// [`merge_outputs`](crate::learn::merge_outputs) was given a system whose inference
    /// methods differ from the first system's.
    #[error("system {} ('{name}') uses other inference methods than system 1", .system + 1)]
    MergeMethods {
        /// The system (0-based).
        system: usize,
        /// Its name.
        name: String,
    },
    /// [`merge_outputs`](crate::learn::merge_outputs) was given a system whose inputs (names
    /// and ranges) differ from the first system's.
    #[error(
        "system {} ('{name}') does not have system 1's inputs (names and ranges)",
        .system + 1
    )]
    MergeInputs {
        /// The system (0-based).
        system: usize,
        /// Its name.
        name: String,
    },
}

impl Classify for LearningProblem {
    /// [`Numerical`](ErrorClass::Numerical) when a computation on valid data and options failed:
    /// a least-squares problem that is non-finite or that the data do not determine, or a
    /// non-finite premise gradient. Every other problem is bad data, options or systems.
    fn class(&self) -> ErrorClass {
        match self {
            Self::NonFiniteLeastSquares
            | Self::RankDeficient { .. }
            | Self::NonFiniteGradient { .. } => ErrorClass::Numerical,
            _ => ErrorClass::InvalidInput,
        }
    }
}

impl From<LearningProblem> for FuzzyError {
    fn from(problem: LearningProblem) -> Self {
        Self::Learning(problem)
    }
}

/// A parameter of a consequent, as [`LearningProblem::RankDeficient`] names it.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConsequentParameter {
    /// The constant (of a constant or linear consequent).
    Constant,
    /// The coefficient of an input in a linear consequent.
    Coefficient {
        /// The input (0-based).
        input: usize,
        /// Its name.
        name: String,
    },
}

impl std::fmt::Display for ConsequentParameter {
    /// `the constant` or `the coefficient of input 'x'`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Constant => f.write_str("the constant"),
            Self::Coefficient { name, .. } => write!(f, "the coefficient of input '{name}'"),
        }
    }
}

/// The number of points of a grid with `axes` points along each axis, compactly (`1.048576e6`
/// when it exceeds what a `usize` counts).
fn grid_size(axes: &[usize]) -> String {
    axes.iter()
        .try_fold(1usize, |total, &n| total.checked_mul(n))
        .map_or_else(
            || lane_math::Compact(axes.iter().map(|&n| n as f64).product()).to_string(),
            |total| total.to_string(),
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The messages of the learning problems that no test reaches cheaply (a system the
    /// builder refuses, 2^32 sets, more than 4096 clusters) are the texts written before the
    /// problems were typed; every other problem's message is checked where it is raised.
    #[test]
    fn unreached_learning_problems_keep_their_messages() {
        let cases = [
            (
                LearningProblem::TooManySets,
                "too many sets to index with 32 bits",
            ),
            (
                LearningProblem::TooManyClusters {
                    radius: 0.01,
                    limit: 4096,
                },
                "a cluster radius of 0.01 finds more than 4096 clusters; use a larger radius",
            ),
            (LearningProblem::NoRules, "the system has no rules"),
            (
                LearningProblem::NoConsequent { rule: 2 },
                "rule 3 has no consequent",
            ),
            (
                LearningProblem::NotSingleOutput { outputs: 2 },
                "ANFIS trains single-output systems; this one has 2 outputs (train one system \
                 per output)",
            ),
        ];
        for (problem, message) in cases {
            let error = FuzzyError::from(problem);
            assert_eq!(error.to_string(), format!("learning: {message}"));
            assert!(error.is_invalid_input() && !error.is_numerical());
        }
    }
}
