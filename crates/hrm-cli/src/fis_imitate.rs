//! `hrm fis imitate`: a fuzzy controller learned from a teacher controller on training scenarios
//! (`sim_study::imitation`), written as a MATLAB `.fis` file that any scenario with the same
//! modal coordinates takes as its `controller.fis`.

use crate::{args, console, fis_input, output_dir, progress};
use clap::Args;
use sim_study::imitation::{self, ImitationOptions, MAX_EPOCHS, MAX_SETS, MAX_STRIDE};
use sim_study::{ControllerKind, Scenario};
use std::path::PathBuf;

/// From this many epochs in all, a progress bar shows on a terminal.
const LONG_RUN_EPOCHS: usize = 50;
/// The most training scenarios.
const MAX_SCENARIOS: usize = 64;

/// The library's names of the imitation's settings and the options that give them.
const OPTIONS: &[(&str, &str)] = &[
    ("imitation.margin", "--margin"),
    ("imitation.step", "--step"),
    ("imitation.offsets", "--offsets"),
    ("imitation.stride", "--stride"),
    ("imitation.sets", "--sets"),
    ("imitation.epochs", "--epochs"),
    ("imitation.scenarios", "--scenario"),
];

/// The arguments of `hrm fis imitate`.
#[derive(Debug, Args)]
pub struct ImitateArgs {
    /// The controller to imitate: fuzzy, pd, computed-torque, fuzzy-gc, lqr or mpc.
    #[arg(long, default_value = "computed-torque")]
    teacher: String,
    /// Training scenarios (shipped names or TOML files), all with the same modal coordinates.
    #[arg(long = "scenario", required = true, num_args = 1.., value_delimiter = ',')]
    scenarios: Vec<String>,
    /// Repeat every scenario about a grid of operating points: one comma-separated list of offsets (rad) per modal coordinate, the lists separated by '/', e.g. -1.5,0,1.5/-0.5,0.5.
    #[arg(long, allow_hyphen_values = true)]
    offsets: Option<String>,
    /// Record one training pair every this many controller samples.
    #[arg(long, default_value_t = 50, allow_negative_numbers = true)]
    stride: i128,
    /// Bell sets on each modal coordinate (the rules partition the coordinates: sets^m rules).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true)]
    sets: i128,
    /// ANFIS epochs per output torque.
    #[arg(long, default_value_t = 20, allow_negative_numbers = true)]
    epochs: i128,
    /// The initial premise step size (Jang's kappa); 0 fits the consequents only.
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    step: f64,
    /// How far the input ranges reach beyond the data, as a fraction of each range on either side.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    margin: f64,
    /// The learned controller, a MATLAB .fis file (written whole, or not at all).
    #[arg(long)]
    out: PathBuf,
}

/// Runs `hrm fis imitate`: records the teacher, trains, prints the RMSE per epoch and output
/// and the kept epochs, writes the `.fis` file.
pub fn run(args: ImitateArgs) -> Result<(), String> {
    let teacher: ControllerKind = args
        .teacher
        .parse()
        .map_err(|e: sim_core::SimError| format!("--teacher: {e}"))?;
    if args.scenarios.len() > MAX_SCENARIOS {
        return Err(format!(
            "--scenario: at most {MAX_SCENARIOS} training scenarios, got {}",
            args.scenarios.len()
        ));
    }
    let options = ImitationOptions {
        teacher,
        stride: args::count("--stride", args.stride, 1, MAX_STRIDE)?,
        sets: args::count("--sets", args.sets, 1, MAX_SETS)?,
        epochs: args::count("--epochs", args.epochs, 1, MAX_EPOCHS)?,
        step: args.step,
        margin: args.margin,
    };
    options
        .validate()
        .map_err(|e| args::as_option(e.to_string(), OPTIONS))?;
    let mut scenarios = args
        .scenarios
        .iter()
        .map(|name| Scenario::resolve(name).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(text) = &args.offsets {
        let grid = parse_offsets(text)?;
        scenarios = imitation::shifted_grid(&scenarios, &grid)
            .map_err(|e| args::as_option(e.to_string(), OPTIONS))?;
    }
    output_dir::refuse_foreign_file(
        &args.out,
        fis_input::RECOGNISED_BYTES,
        fis_input::written_by_hrm,
    )?;
    let data = imitation::record(&scenarios, &options)
        .map_err(|e| args::as_option(e.to_string(), OPTIONS))?;
    let m = data.n_outputs();
    console::print(&format!(
        "{} training pairs from {} runs of {} with {teacher}; {} inputs, {} rules per output\n",
        data.rows(),
        scenarios.len(),
        args.scenarios.join(", "),
        data.n_inputs(),
        options.sets.pow(m as u32)
    ))?;
    let total = options.epochs * m;
    let bar = (total >= LONG_RUN_EPOCHS).then(|| progress::bar(total as u64, "epochs"));
    // The first failure to write a line (not a reader gone away), reported once training ends.
    let mut printed = Ok(());
    let learned = imitation::train(&data, &options, |output, report| {
        let line = format!(
            "{} epoch {}: training RMSE {:.6e}",
            data.column_name(data.n_inputs() + output),
            report.epoch,
            report.training_rmse
        );
        let line = format!("{line}\n");
        let result = match &bar {
            Some(bar) => {
                let result = bar.suspend(|| console::print(&line));
                bar.inc(1);
                result
            }
            None => console::print(&line),
        };
        if printed.is_ok() {
            printed = result;
        }
    })
    .map_err(|e| e.to_string())?;
    printed?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    for (output, (epoch, rmse)) in learned
        .best_epoch
        .iter()
        .zip(&learned.training_rmse)
        .enumerate()
    {
        console::print(&format!(
            "{}: kept epoch {epoch}, RMSE against the teacher {rmse:.6e} N m\n",
            data.column_name(data.n_inputs() + output)
        ))?;
    }
    let text = fis_input::signed_fis(&learned.system);
    output_dir::write_file(&args.out, &text, "fis imitate")?;
    console::print(&format!("wrote {}\n", console::shown(&args.out)))?;
    Ok(())
}

/// The most offsets per coordinate `--offsets` takes.
const MAX_OFFSETS: usize = 1000;

/// Parses `--offsets`: lists separated by `/`, numbers by `,`; errors name the option.
fn parse_offsets(text: &str) -> Result<Vec<Vec<f64>>, String> {
    let lists: Vec<&str> = text.split('/').collect();
    if lists.len() > sim_core::MAX_COORDINATES {
        return Err(format!(
            "--offsets: at most {} lists (one per modal coordinate), got {}",
            sim_core::MAX_COORDINATES,
            lists.len()
        ));
    }
    lists
        .iter()
        .enumerate()
        .map(|(k, list)| {
            let values: Vec<&str> = list.split(',').map(str::trim).collect();
            if values.len() > MAX_OFFSETS {
                return Err(format!(
                    "--offsets: list {} has {} values, at most {MAX_OFFSETS}",
                    k + 1,
                    values.len()
                ));
            }
            values
                .iter()
                .map(|v| match v.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    _ => Err(format!(
                        "--offsets: list {}: expected a finite number, found '{v}'",
                        k + 1
                    )),
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_parse_per_coordinate_and_refuse_by_name() {
        assert_eq!(
            parse_offsets("-1.5, 0,1.5/-0.5").unwrap(),
            [vec![-1.5, 0.0, 1.5], vec![-0.5]]
        );
        assert_eq!(
            parse_offsets("0/x").unwrap_err(),
            "--offsets: list 2: expected a finite number, found 'x'"
        );
        assert_eq!(
            parse_offsets("0,inf").unwrap_err(),
            "--offsets: list 1: expected a finite number, found 'inf'"
        );
        assert!(
            parse_offsets(&"0/".repeat(5000))
                .unwrap_err()
                .contains("at most")
        );
        assert!(
            parse_offsets(&"0,".repeat(2000))
                .unwrap_err()
                .contains("at most 1000")
        );
    }
}
