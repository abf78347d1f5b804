#![doc = include_str!("../README.md")]

mod args;
mod arm_cmd;
mod chain_simulate;
mod console;
mod deploy_simulate;
mod eval;
mod experiment;
mod figure_parts;
mod figures;
mod fis_cmd;
mod fis_export;
mod fis_imitate;
mod fis_input;
mod fis_train;
mod output_dir;
mod plot;
mod progress;
mod report;
mod signals;
mod spatial_figures;
mod sweep;
mod view_cmd;
mod view_sweep;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Models, controls and simulates hyper-redundant planar manipulators.
#[derive(Parser)]
#[command(name = "hrm", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// The main job (also what `hrm` alone runs): every shipped scenario with every controller.
    Run {
        /// Output folder.
        #[arg(long, default_value = "hrm-output")]
        out: PathBuf,
        /// Run each scenario for at most this many seconds, rounded down to whole controller
        /// periods: a quick look at the report (the paper's numbers need the full durations).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
    },
    /// Run one scenario (a shipped name such as `paper-tracking`, or a TOML file).
    Simulate {
        /// Scenario name or path.
        #[arg(long)]
        scenario: String,
        #[arg(
            long,
            help = args::CONTROLLER_HELP.as_str(),
            long_help = args::CONTROLLER_LONG_HELP.as_str()
        )]
        controller: Option<String>,
        /// Output folder.
        #[arg(long, default_value = "hrm-output/simulate")]
        out: PathBuf,
    },
    /// Answer JSON-lines requests on stdin, one JSON answer per line on stdout (docs/eval-protocol.md).
    Eval,
    /// Check, evaluate, plot, train and export Takagi-Sugeno systems (MATLAB .fis or FCL files).
    Fis(fis_cmd::FisArgs),
    /// Robot descriptions: check a URDF chain, export one (or a scenario's arm) as URDF or MJCF.
    Arm(arm_cmd::ArmArgs),
    /// Monte Carlo over noise levels and seeds: mean and spread of the errors per controller (docs/sweep.md).
    Sweep(sweep::SweepCli),
    /// The interactive page of a run (an `hrm simulate`, `hrm run` or `hrm sweep` output
    /// folder), and with --gif an animated GIF of it.
    View(view_cmd::ViewArgs),
}

fn main() -> ExitCode {
    signals::install();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Run { out, duration }) => experiment::main_job(&out, duration),
        Some(Command::Simulate {
            scenario,
            controller,
            out,
        }) => experiment::simulate(&scenario, controller.as_deref(), &out),
        Some(Command::Eval) => eval::run_stdio(),
        Some(Command::Fis(args)) => fis_cmd::run(args),
        Some(Command::Sweep(args)) => sweep::run(args),
        Some(Command::Arm(args)) => arm_cmd::run(args),
        Some(Command::View(args)) => view_cmd::run(args),
        None => experiment::main_job(std::path::Path::new("hrm-output"), None),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            console::to_stderr(&console::error_line(&message));
            ExitCode::FAILURE
        }
    }
}
