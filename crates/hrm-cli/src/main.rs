//! `hrm`: the command line of the hyper-redundant manipulator toolkit.

mod arm;
mod eval;
mod fis_cmd;
mod plot;

use clap::{Parser, Subcommand};
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
    /// Answer JSON-lines requests on stdin, one JSON answer per line on stdout (docs/eval-protocol.md).
    Eval,
    /// Check, evaluate and plot Takagi-Sugeno systems stored as MATLAB .fis files.
    Fis(fis_cmd::FisArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Eval) => eval::run_stdio(),
        Some(Command::Fis(args)) => fis_cmd::run(args),
        None => {
            use clap::CommandFactory;
            Cli::command().print_help().map_err(|e| e.to_string())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("hrm: {message}");
            ExitCode::FAILURE
        }
    }
}
