//! The crate's error type.

/// Everything that can go wrong when building, evaluating, reading or analysing a fuzzy system.
/// Every message says which condition failed and where.
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
    #[error("{context}: {reason}")]
    InvalidSystem {
        /// Where: `input 'da1'`, `rule 3`, ...
        context: String,
        /// The condition that failed.
        reason: String,
    },
    /// The input slice does not have one value per input variable.
    #[error("expected {expected} inputs, got {got}")]
    InputCount {
        /// The system's number of inputs.
        expected: usize,
        /// The slice's length.
        got: usize,
    },
    /// The output slice does not have one slot per output variable.
    #[error("the output buffer has {got} slots but the system has {expected} outputs")]
    OutputCount {
        /// The system's number of outputs.
        expected: usize,
        /// The slice's length.
        got: usize,
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
    /// Invalid evaluation options (for example fallback values of the wrong length).
    #[error("evaluation options: {0}")]
    InvalidOptions(String),
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
    /// A rule-base analysis that cannot be carried out as asked.
    #[error("analysis: {0}")]
    Analysis(String),
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
    /// A system that an export format cannot carry, or an invalid export option.
    #[error("export: {0}")]
    Export(String),
}
