//! `hrm fis imitate` end to end: the file it writes is the library's learned system, it loads
//! back as a scenario's fuzzy controller, and bad options are one-line errors that leave an
//! earlier file alone.

use sim_study::Scenario;
use sim_study::imitation::{self, ImitationOptions};
use std::path::PathBuf;
use std::process::{Command, Output};

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrm-fis-imitate-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn hrm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .output()
        .expect("the hrm binary runs")
}

/// The paper's step and sine responses, shortened to `duration` s, written as TOML files.
fn short_scenarios(dir: &std::path::Path, duration: f64) -> Vec<(PathBuf, Scenario)> {
    ["paper-responses-step", "paper-responses-sine"]
        .iter()
        .map(|name| {
            let mut scenario = Scenario::builtin(name).unwrap();
            scenario.duration = duration;
            let path = dir.join(format!("{name}.toml"));
            std::fs::write(&path, scenario.to_toml()).unwrap();
            (path, scenario)
        })
        .collect()
}

#[test]
fn writes_the_library_system_and_it_drives_a_scenario() {
    let dir = scratch("round-trip");
    let scenarios = short_scenarios(&dir, 0.4);
    let out = dir.join("learned.fis");
    let list = format!("{},{}", scenarios[0].0.display(), scenarios[1].0.display());
    let run = hrm(&[
        "fis",
        "imitate",
        "--teacher",
        "computed-torque",
        "--scenario",
        &list,
        "--offsets=0,0.5/-0.25",
        "--epochs",
        "3",
        "--stride",
        "4",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.starts_with(&format!(
            "4000 training pairs from 4 runs of {} with computed-torque; 8 inputs, 9 rules per output\n",
            list.replace(',', ", ")
        )),
        "{stdout}"
    );
    assert_eq!(stdout.matches(": training RMSE ").count(), 2 * 3);
    assert_eq!(stdout.matches(", RMSE against the teacher ").count(), 2);
    let options = ImitationOptions {
        epochs: 3,
        stride: 4,
        ..ImitationOptions::default()
    };
    let library: Vec<Scenario> = scenarios.into_iter().map(|(_, s)| s).collect();
    let grid = [vec![0.0, 0.5], vec![-0.25]];
    let shifted = imitation::shifted_grid(&library, &grid).unwrap();
    let learned = imitation::imitate(&shifted, &options, |_, _| {}).unwrap();
    // The library's system, after hrm's signature (a comment).
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        format!("% written by hrm\n{}", learned.system.to_fis())
    );
    // A scenario file pointing at it runs.
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = 0.05;
    scenario.controller.fis = Some(out.clone());
    let file = dir.join("tracking.toml");
    std::fs::write(&file, scenario.to_toml()).unwrap();
    let sim = hrm(&[
        "simulate",
        "--scenario",
        file.to_str().unwrap(),
        "--out",
        dir.join("sim").to_str().unwrap(),
    ]);
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_options_are_one_line_errors_and_leave_the_old_file() {
    let dir = scratch("bad");
    let out = dir.join("learned.fis");
    std::fs::write(&out, "earlier").unwrap();
    let out = out.to_str().unwrap();
    let unknown_teacher = format!(
        "hrm: --teacher: controller must be one of {}, got 'bang-bang'",
        sim_study::ControllerKind::names(", ")
    );
    for (args, message) in [
        (vec!["--teacher", "bang-bang"], unknown_teacher.as_str()),
        (
            vec!["--stride", "0"],
            "hrm: --stride must be at least 1 and at most 1000000, got 0",
        ),
        (
            vec!["--sets", "-3"],
            "hrm: --sets must be at least 1 and at most 9, got -3",
        ),
        (
            vec!["--epochs", "1000000"],
            "hrm: --epochs must be at least 1 and at most 10000, got 1000000",
        ),
        (
            vec!["--margin", "nan"],
            "hrm: --margin must lie in [0, 100], got NaN",
        ),
        (
            vec!["--offsets", "0,1"],
            "hrm: --offsets has 1 lists, 'paper-responses-step' has 2 modal coordinates (one list each)",
        ),
    ] {
        let mut full = vec!["fis", "imitate", "--scenario", "paper-responses-step"];
        full.extend(args);
        full.extend(["--out", out]);
        let run = hrm(&full);
        assert!(!run.status.success());
        assert_eq!(String::from_utf8_lossy(&run.stderr), format!("{message}\n"));
    }
    let run = hrm(&["fis", "imitate", "--scenario", "no-such", "--out", out]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.starts_with("hrm: 'no-such' is neither a built-in scenario")
            && stderr.lines().count() == 1,
        "{stderr}"
    );
    // A file hrm did not write is never replaced, whatever the options.
    let run = hrm(&[
        "fis",
        "imitate",
        "--scenario",
        "paper-responses-step",
        "--out",
        out,
    ]);
    assert_eq!(
        String::from_utf8_lossy(&run.stderr),
        format!(
            "hrm: {out}: exists and hrm did not write it; choose another file or remove this one\n"
        )
    );
    assert_eq!(std::fs::read_to_string(out).unwrap(), "earlier");
    std::fs::remove_dir_all(&dir).unwrap();
}
