//! Runs a scenario (default: the paper's `paper-tracking`) with every controller and prints the
//! comparison table of the paper's experiment.
//!
//! ```text
//! cargo run --release -p sim-core --example compare_controllers [NAME_OR_FILE]
//! ```

use sim_study::{ControllerKind, Scenario};

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
        let list = |values: &[f64], scale: f64, digits: usize| {
            values
                .iter()
                .map(|v| format!("{:.digits$}", scale * v))
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!(
            "{:<16} {:>13.3} {:>13.3} {:>20} {:>18} {:>15.3} {:>10.2}",
            kind.name(),
            1e3 * s.tip_error_rms_m,
            1e3 * s.tip_error_max_m,
            list(&s.modal_error_rms_rad, 1e3, 3),
            list(&s.peak_modal_torques_nm, 1.0, 2),
            s.peak_joint_torque_nm,
            s.control_effort_n2m2s
        );
    }
    Ok(())
}
