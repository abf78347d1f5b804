//! Samples to learn from: rows of input values followed by output values.

use crate::system::check_name;
use crate::{FuzzyError, LearningProblem};

/// The most rows a data set may hold.
pub const MAX_ROWS: usize = 1_000_000;
/// The most inputs a data set may have.
pub const MAX_INPUTS: usize = 64;
/// The most outputs a data set may have.
const MAX_OUTPUTS: usize = 64;
/// The largest magnitude of a value: the least-squares fit sums products of values and the
/// premise gradients divide by input ranges, all within double precision below it.
pub const MAX_MAGNITUDE: f64 = 1e100;

/// Rows of `n_inputs` input values followed by `n_outputs` output values, all finite and at most
/// [`MAX_MAGNITUDE`] in magnitude.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainingData {
    n_inputs: usize,
    n_outputs: usize,
    values: Vec<f64>,
    /// Column names (inputs, then outputs), if given.
    names: Option<Vec<String>>,
}

impl TrainingData {
    /// Takes `values` row by row; refuses an empty set, a length that is not a whole number of
    /// rows, a non-finite value (naming its row and column), more than [`MAX_ROWS`] rows or more
    /// than [`MAX_INPUTS`] inputs.
    pub fn new(n_inputs: usize, n_outputs: usize, values: Vec<f64>) -> Result<Self, FuzzyError> {
        if n_inputs == 0 || n_inputs > MAX_INPUTS {
            return Err(LearningProblem::CountOutOfRange {
                name: "the number of inputs",
                count: n_inputs,
                max: MAX_INPUTS,
            }
            .into());
        }
        if n_outputs == 0 || n_outputs > MAX_OUTPUTS {
            return Err(LearningProblem::CountOutOfRange {
                name: "the number of outputs",
                count: n_outputs,
                max: MAX_OUTPUTS,
            }
            .into());
        }
        let width = n_inputs + n_outputs;
        if values.is_empty() || !values.len().is_multiple_of(width) {
            return Err(LearningProblem::RowLength {
                values: values.len(),
                width,
            }
            .into());
        }
        let rows = values.len() / width;
        if rows > MAX_ROWS {
            return Err(LearningProblem::TooManyRows {
                rows,
                limit: MAX_ROWS,
            }
            .into());
        }
        if let Some((k, value)) = lane_math::first_non_finite(&values) {
            return Err(LearningProblem::NonFiniteValue {
                row: k / width,
                column: k % width,
                value,
            }
            .into());
        }
        if let Some(k) = values.iter().position(|v| v.abs() > MAX_MAGNITUDE) {
            return Err(LearningProblem::HugeValue {
                row: k / width,
                column: k % width,
                value: values[k],
                limit: MAX_MAGNITUDE,
            }
            .into());
        }
        Ok(Self {
            n_inputs,
            n_outputs,
            values,
            names: None,
        })
    }

    /// Names the columns (inputs, then outputs; for example a CSV header), which systems built
    /// by `genfis` give their variables. Names must be distinct and valid in a `.fis` file (not
    /// empty, no quote or control character).
    pub fn with_names(mut self, names: Vec<String>) -> Result<Self, FuzzyError> {
        let width = self.n_inputs + self.n_outputs;
        if names.len() != width {
            return Err(LearningProblem::ColumnNameCount {
                names: names.len(),
                columns: width,
            }
            .into());
        }
        for (k, name) in names.iter().enumerate() {
            check_name("variable", name)
                .map_err(|problem| LearningProblem::ColumnName { column: k, problem })?;
            if names[..k].contains(name) {
                return Err(LearningProblem::DuplicateColumnName {
                    column: k,
                    name: name.clone(),
                }
                .into());
            }
        }
        self.names = Some(names);
        Ok(self)
    }

    /// The name of column `column` (inputs first, then outputs): the given name, or `in1`,
    /// `in2`, ... and `out1`, ... (MATLAB's defaults).
    pub fn column_name(&self, column: usize) -> String {
        match &self.names {
            Some(names) => names[column].clone(),
            None if column < self.n_inputs => format!("in{}", column + 1),
            None => format!("out{}", column - self.n_inputs + 1),
        }
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.values.len() / (self.n_inputs + self.n_outputs)
    }

    /// The number of inputs per row.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// The number of outputs per row.
    pub fn n_outputs(&self) -> usize {
        self.n_outputs
    }

    /// The whole of row `row` (0-based): its inputs, then its outputs.
    pub fn row(&self, row: usize) -> &[f64] {
        let width = self.n_inputs + self.n_outputs;
        &self.values[row * width..(row + 1) * width]
    }

    /// The inputs of row `row`.
    pub fn inputs(&self, row: usize) -> &[f64] {
        &self.row(row)[..self.n_inputs]
    }

    /// Output `output` of row `row`.
    pub fn target(&self, row: usize, output: usize) -> f64 {
        self.row(row)[self.n_inputs + output]
    }

    /// `[min, max]` of column `column` (inputs first, then outputs).
    pub fn column_range(&self, column: usize) -> [f64; 2] {
        (0..self.rows()).fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], r| {
            let v = self.row(r)[column];
            [lo.min(v), hi.max(v)]
        })
    }

    /// Refuses an output index this data set does not have.
    pub(crate) fn check_output(&self, output: usize) -> Result<(), FuzzyError> {
        if output >= self.n_outputs {
            return Err(LearningProblem::NoSuchOutput {
                output,
                outputs: self.n_outputs,
            }
            .into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SystemProblem;
    use lane_math::Classify;

    #[test]
    fn rows_and_columns() {
        let data = TrainingData::new(2, 1, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        assert_eq!(data.rows(), 2);
        assert_eq!(data.inputs(1), [4.0, 5.0]);
        assert_eq!(data.target(0, 0), 3.0);
        assert_eq!(data.column_range(1), [2.0, 5.0]);
    }

    #[test]
    fn bad_data_is_refused_with_its_place() {
        let refuse = |n, m, v: Vec<f64>| match TrainingData::new(n, m, v).unwrap_err() {
            FuzzyError::Learning(problem) => problem,
            other => panic!("not a learning error: {other}"),
        };
        let problem = refuse(2, 1, vec![1.0, 2.0, 3.0, 4.0, f64::NAN, 6.0]);
        assert!(matches!(
            problem,
            LearningProblem::NonFiniteValue { row: 1, column: 1, value } if value.is_nan()
        ));
        assert_eq!(
            FuzzyError::from(problem).to_string(),
            "learning: row 2 column 2 is not finite (NaN)"
        );
        let problem = refuse(2, 1, vec![1.0; 4]);
        assert_eq!(
            problem,
            LearningProblem::RowLength {
                values: 4,
                width: 3
            }
        );
        assert_eq!(
            problem.to_string(),
            "4 values are not a whole, non-zero number of rows of 3"
        );
        assert_eq!(
            refuse(2, 1, Vec::new()),
            LearningProblem::RowLength {
                values: 0,
                width: 3
            }
        );
        let problem = refuse(0, 1, vec![1.0]);
        assert_eq!(
            problem,
            LearningProblem::CountOutOfRange {
                name: "the number of inputs",
                count: 0,
                max: MAX_INPUTS
            }
        );
        assert_eq!(
            FuzzyError::from(problem).to_string(),
            "learning: the number of inputs must lie in 1..=64, got 0"
        );
        assert_eq!(
            refuse(1, 65, vec![1.0; 66]),
            LearningProblem::CountOutOfRange {
                name: "the number of outputs",
                count: 65,
                max: MAX_OUTPUTS
            }
        );
        let problem = refuse(1, 1, vec![0.0; 2 * (MAX_ROWS + 1)]);
        assert_eq!(
            problem,
            LearningProblem::TooManyRows {
                rows: MAX_ROWS + 1,
                limit: MAX_ROWS
            }
        );
        assert_eq!(
            problem.to_string(),
            "1000001 rows exceed the limit of 1000000"
        );
        // Malformed data are the caller's input, not a numerical failure.
        let error = TrainingData::new(2, 1, vec![f64::INFINITY; 3]).unwrap_err();
        assert!(error.is_invalid_input() && !error.is_numerical());
    }

    #[test]
    fn bad_column_names_are_refused_with_their_column() {
        let data = || TrainingData::new(1, 1, vec![1.0, 2.0]).unwrap();
        let names = |names: &[&str]| {
            let names = names.iter().map(|n| n.to_string()).collect();
            match data().with_names(names).unwrap_err() {
                FuzzyError::Learning(problem) => problem,
                other => panic!("not a learning error: {other}"),
            }
        };
        let problem = names(&["x"]);
        assert_eq!(
            problem,
            LearningProblem::ColumnNameCount {
                names: 1,
                columns: 2
            }
        );
        assert_eq!(problem.to_string(), "1 column names for 2 columns");
        let problem = names(&["x", "x"]);
        assert_eq!(
            problem,
            LearningProblem::DuplicateColumnName {
                column: 1,
                name: "x".to_string()
            }
        );
        assert_eq!(
            problem.to_string(),
            "column 2: another column is also named 'x'"
        );
        let problem = names(&["x", ""]);
        assert_eq!(
            problem,
            LearningProblem::ColumnName {
                column: 1,
                problem: SystemProblem::EmptyName { kind: "variable" }
            }
        );
        assert_eq!(problem.to_string(), "column 2: the variable name is empty");
        assert!(matches!(
            names(&["it's", "y"]),
            LearningProblem::ColumnName {
                column: 0,
                problem: SystemProblem::UnwritableName { .. }
            }
        ));
    }
}
