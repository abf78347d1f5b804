//! `hrm fis train`: a Sugeno system learned from a CSV file by `genfis` and ANFIS
//! (`fuzzy_sugeno::learn`), written as a MATLAB `.fis` file.
//!
//! The CSV holds one sample per line, the inputs and then the one output, comma-separated,
//! with an optional header line of column names (taken as the variables' names). Every size is
//! bounded before it is used: the file, its rows and columns, the epochs and the rule count.

use crate::{console, fis_input, output_dir, progress};
use clap::Args;
use fuzzy_sugeno::learn::{
    Anfis, AnfisOptions, ConsequentOrder, GridPartition, MAX_INPUTS, MAX_ROWS, MAX_SETS_PER_INPUT,
    SetShape, SubtractiveClustering, TrainingData, genfis_cluster, genfis_grid,
};
use fuzzy_sugeno::{FuzzyError, LearningProblem};
use std::path::{Path, PathBuf};

/// The largest CSV file read, in bytes.
const MAX_CSV_BYTES: u64 = 64 << 20;

/// The learning library's names of the settings `hrm fis train` takes and their options.
const OPTIONS: &[(&str, &str)] = &[
    ("learning: the cluster radius", "--cluster-radius"),
    ("learning: the initial step", "--step"),
    ("learning: the ridge", "--ridge"),
    ("learning: sigmf partitions", "--mfs: sigmf partitions"),
];
/// The most epochs a training may run from the command line.
const MAX_EPOCHS: usize = 100_000;
/// From this many epochs on, a progress bar shows on a terminal.
const LONG_RUN_EPOCHS: usize = 50;

/// The arguments of `hrm fis train`.
#[derive(Debug, Args)]
pub struct TrainArgs {
    /// Training samples: CSV, the inputs then the output on each line, optional header.
    #[arg(long)]
    data: PathBuf,
    /// Check samples in the same layout; the system with the smallest check error is kept.
    #[arg(long)]
    check: Option<PathBuf>,
    /// Grid partition: sets per input (the rule count is this to the power of the inputs).
    #[arg(long, default_value_t = 2, allow_negative_numbers = true)]
    mfs: i128,
    /// Grid partition: the sets' MATLAB type (gbellmf, gaussmf, gauss2mf, trimf, trapmf, sigmf, dsigmf, psigmf, pimf).
    #[arg(long, default_value = "gbellmf")]
    mf_type: String,
    /// The consequents' order: 0 (constant) or 1 (linear).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    order: i128,
    /// ANFIS epochs (0: the genfis system with least-squares consequents, untrained).
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    epochs: i128,
    /// Subtractive clustering with this radius (in (0, 1], of each column's range) instead of a grid partition.
    #[arg(long, conflicts_with_all = ["mfs", "mf_type"], allow_negative_numbers = true)]
    cluster_radius: Option<f64>,
    /// The initial premise step size (Jang's kappa).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    step: f64,
    /// The least-squares ridge, relative to the mean squared column norm (0: plain least squares).
    #[arg(long, default_value_t = 1e-10, allow_negative_numbers = true)]
    ridge: f64,
    /// The learned system, a MATLAB .fis file.
    #[arg(long)]
    out: PathBuf,
}

/// Runs `hrm fis train`.
pub fn run(args: TrainArgs) -> Result<(), String> {
    let epochs = crate::args::count("--epochs", args.epochs, 0, MAX_EPOCHS)?;
    let mfs = crate::args::count("--mfs", args.mfs, 1, MAX_SETS_PER_INPUT)?;
    let order = match args.order {
        0 => ConsequentOrder::Zero,
        1 => ConsequentOrder::First,
        other => return Err(format!("--order must be 0 or 1, got {other}")),
    };
    let options = AnfisOptions {
        epochs: epochs.max(1),
        initial_step: args.step,
        ridge: args.ridge,
        ..AnfisOptions::default()
    };
    options
        .validate()
        .map_err(|e| crate::args::as_option(e.to_string(), OPTIONS))?;
    let mut inputs = vec![("--data", args.data.as_path())];
    inputs.extend(args.check.as_deref().map(|check| ("--check", check)));
    output_dir::refuse_input_as_output(&args.out, &inputs)?;
    output_dir::refuse_foreign_file(
        &args.out,
        fis_input::RECOGNISED_BYTES,
        fis_input::written_by_hrm,
    )?;
    let train = read_csv(&args.data)?;
    let check = args.check.as_deref().map(read_csv).transpose()?;
    if let Some(check) = &check
        && check.n_inputs() != train.n_inputs()
    {
        return Err(format!(
            "{}: {} columns, but the training data have {}",
            path(args.check.as_deref()),
            check.n_inputs() + 1,
            train.n_inputs() + 1
        ));
    }
    let initial = match args.cluster_radius {
        Some(radius) => genfis_cluster(&train, 0, &SubtractiveClustering { radius, order }),
        None => SetShape::from_matlab_name(&args.mf_type).and_then(|shape| {
            let grid = GridPartition {
                sets_per_input: mfs,
                shape,
                order,
            };
            genfis_grid(&train, 0, &grid)
        }),
    }
    .map_err(|e| crate::args::as_option(e.to_string(), OPTIONS))?;
    console::print(&format!(
        "{} inputs, {} rules, {} training samples{}\n",
        initial.inputs().len(),
        initial.rules().len(),
        train.rows(),
        check
            .as_ref()
            .map_or(String::new(), |c| format!(", {} check samples", c.rows()))
    ))?;
    let system = if epochs == 0 {
        initial
    } else {
        let options = AnfisOptions { epochs, ..options };
        let bar = (epochs >= LONG_RUN_EPOCHS).then(|| progress::bar(epochs as u64, "epochs"));
        let mut trainer = Anfis::new(initial, &train, check.as_ref(), 0, options)
            .map_err(|e| crate::args::as_option(e.to_string(), OPTIONS))?;
        for _ in 0..epochs {
            let report = trainer.epoch().map_err(|e| e.to_string())?;
            let line = match report.check_rmse {
                Some(check) => format!(
                    "epoch {}: training RMSE {:.6e}, check RMSE {check:.6e}",
                    report.epoch, report.training_rmse
                ),
                None => format!(
                    "epoch {}: training RMSE {:.6e}",
                    report.epoch, report.training_rmse
                ),
            };
            match &bar {
                Some(bar) => {
                    bar.suspend(|| console::print(&format!("{line}\n")))?;
                    bar.inc(1);
                }
                None => console::print(&format!("{line}\n"))?,
            }
        }
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        console::print(&format!(
            "kept the system of epoch {} (smallest {} error)\n",
            trainer.best_epoch(),
            if check.is_some() { "check" } else { "training" }
        ))?;
        trainer.best_system().map_err(|e| e.to_string())?
    };
    let text = fis_input::signed_fis(&system);
    output_dir::write_file(&args.out, &text, "fis train")?;
    console::print(&format!("wrote {}\n", console::shown(&args.out)))?;
    Ok(())
}

fn path(p: Option<&Path>) -> String {
    p.map_or(String::new(), |p| p.display().to_string())
}

/// Reads a CSV file of samples (see the module documentation).
fn read_csv(file: &Path) -> Result<TrainingData, String> {
    let fail = |message: String| format!("{}: {message}", file.display());
    // Read with the limit, not by the size alone: `/dev/zero` or a pipe reports size 0.
    let text = sim_study::read_text_file(file, MAX_CSV_BYTES).map_err(|e| fail(e.to_string()))?;
    parse_csv(&text).map_err(fail)
}

/// Parses CSV text of samples; errors name the line and column.
fn parse_csv(text: &str) -> Result<TrainingData, String> {
    fn fields(line: &str) -> Vec<&str> {
        line.split(',').map(str::trim).collect()
    }
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Lines end in `\n` (or `\r\n`); a file without any `\n` may end them in `\r` alone
    // (classic Mac OS).
    let end = if text.contains('\n') { '\n' } else { '\r' };
    let mut lines = text
        .split(end)
        .map(|line| line.strip_suffix('\r').unwrap_or(line))
        .enumerate()
        .filter(|(_, line)| !line.trim().is_empty());
    let Some((first_number, first)) = lines.next() else {
        return Err("no samples: the file is empty".to_string());
    };
    let head = fields(first);
    let columns = head.len();
    if !(2..=MAX_INPUTS + 1).contains(&columns) {
        // A file of one column that holds tabs or semicolons was written with another separator.
        let separator = match first.find(['\t', ';']) {
            Some(_) if columns == 1 => " (columns are separated by commas, not tabs or semicolons)",
            _ => "",
        };
        return Err(format!(
            "line {}: {columns} column{}; expected 2 to {} (the inputs, then the output){separator}",
            first_number + 1,
            if columns == 1 { "" } else { "s" },
            MAX_INPUTS + 1
        ));
    }
    let is_header = head.iter().any(|f| f.parse::<f64>().is_err());
    let mut values = Vec::new();
    let mut rows = 0;
    // The file's line of every data row, for the library's errors that name a row.
    let mut row_lines = Vec::new();
    let body = (!is_header).then_some((first_number, first));
    for (index, line) in body.into_iter().chain(lines) {
        let row = fields(line);
        if row.len() != columns {
            return Err(format!(
                "line {}: {} column{}, expected {columns}",
                index + 1,
                row.len(),
                if row.len() == 1 { "" } else { "s" }
            ));
        }
        rows += 1;
        if rows > MAX_ROWS {
            return Err(format!("more than {MAX_ROWS} rows"));
        }
        row_lines.push(index + 1);
        for (c, field) in row.iter().enumerate() {
            let value: f64 = field.parse().map_err(|_| {
                format!(
                    "line {} column {}: expected a number, found '{field}'",
                    index + 1,
                    c + 1
                )
            })?;
            if !value.is_finite() {
                return Err(format!(
                    "line {} column {}: {field} is not finite",
                    index + 1,
                    c + 1
                ));
            }
            values.push(value);
        }
    }
    if rows == 0 {
        return Err("no samples: only a header line".to_string());
    }
    let data = TrainingData::new(columns - 1, 1, values).map_err(|e| match e {
        // Named by the file's line, as the parse errors above are.
        FuzzyError::Learning(LearningProblem::HugeValue {
            row,
            column,
            value,
            limit,
        }) => format!(
            "line {} column {}: {} is beyond the {} in magnitude that learning handles",
            row_lines[row],
            column + 1,
            lane_math::Compact(value),
            lane_math::Compact(limit)
        ),
        e => e.to_string(),
    })?;
    if is_header {
        let names = head.iter().map(|s| s.to_string()).collect();
        data.with_names(names)
            .map_err(|e| format!("line {}: {e}", first_number + 1))
    } else {
        Ok(data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_with_and_without_header() {
        let data = parse_csv("e, de, u\n0.1, 0.2, 0.3\n\n-1, 2e-3, 4\n").unwrap();
        assert_eq!(data.rows(), 2);
        assert_eq!(data.n_inputs(), 2);
        assert_eq!(data.column_name(2), "u");
        assert_eq!(data.inputs(1), [-1.0, 0.002]);
        let classic_mac = parse_csv("e,u\r0.5,1\r2,3\r").unwrap();
        assert_eq!(classic_mac.rows(), 2);
        assert_eq!(classic_mac.target(1, 0), 3.0);
        let windows = parse_csv("e,u\r\n0.5,1\r\n2,x\r\n").unwrap_err();
        assert_eq!(windows, "line 3 column 2: expected a number, found 'x'");
        let bare = parse_csv("1,2\n3,4").unwrap();
        assert_eq!(bare.column_name(0), "in1");
        assert_eq!(bare.target(1, 0), 4.0);
    }

    #[test]
    fn bad_csv_names_the_line_and_column() {
        let message = |text: &str| parse_csv(text).unwrap_err();
        assert_eq!(message(""), "no samples: the file is empty");
        assert_eq!(message("a,b\n"), "no samples: only a header line");
        assert_eq!(message("1,2\n3\n"), "line 2: 1 column, expected 2");
        assert_eq!(
            message("1,2\n3,x\n"),
            "line 2 column 2: expected a number, found 'x'"
        );
        assert_eq!(
            message("1,2\n3,inf\n"),
            "line 2 column 2: inf is not finite"
        );
        assert_eq!(
            message("7\n"),
            "line 1: 1 column; expected 2 to 65 (the inputs, then the output)"
        );
        assert_eq!(
            message("x\ty\n1\t2\n"),
            "line 1: 1 column; expected 2 to 65 (the inputs, then the output) (columns are \
             separated by commas, not tabs or semicolons)"
        );
        assert_eq!(
            message("a,a\n1,2\n"),
            "line 1: learning: column 2: another column is also named 'a'"
        );
        // A value too large to learn from: the file's line (past a header and a blank line),
        // not the data row.
        assert_eq!(
            message("x,y\n1,2\n\n3,1e200\n"),
            "line 4 column 2: 1e200 is beyond the 1e100 in magnitude that learning handles"
        );
    }
}
