//! `hrm`: the command line of the hyper-redundant manipulator toolkit.

use clap::Parser;

/// Models, controls and simulates hyper-redundant planar manipulators.
#[derive(Parser)]
#[command(name = "hrm", version, about)]
struct Cli {}

fn main() {
    let _cli = Cli::parse();
}
