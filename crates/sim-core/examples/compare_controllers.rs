//! Runs a scenario (default: the paper's `paper-tracking`) with every controller and prints the
//! comparison table of the paper's experiment.
//!
//! ```text
//! cargo run --release -p sim-core --example compare_controllers [NAME_OR_FILE]
//! ```

use sim_core::{ControllerKind, Scenario};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "paper-tracking".into());
    let mut scenario = Scenario::resolve(&name)?;
    println!("{}: {}\n", scenario.name, scenario.description);
    println!(
        "{:<16} {:>13} {:>13} {:>20} {:>18} {:>15} {:>10}",
        "controller",
        "tip RMS (mm)",
        "tip max (mm)",
        "modal RMS (mrad)",
        "peak tau* (N m)",
        "peak tau (N m)",
        "effort"
    );
    for kind in ControllerKind::ALL {
        scenario.controller.kind = kind;
        let s = match scenario.build()?.run() {
            Ok(run) => run.summary,
            Err(failure) => {
                println!("{kind:<16} stopped: {failure}");
                continue;
            }
        };
        println!(
            "{:<16} {:>13.3} {:>13.3} {:>9.3} {:>10.3} {:>8.2} {:>9.2} {:>15.3} {:>10.2}",
            kind.name(),
            1e3 * s.tip_error_rms_m,
            1e3 * s.tip_error_max_m,
            1e3 * s.modal_error_rms[0],
            1e3 * s.modal_error_rms[1],
            s.peak_modal_torque[0],
            s.peak_modal_torque[1],
            s.peak_joint_torque_nm,
            s.control_effort
        );
    }
    Ok(())
}
