//! The `hrm` command line on bad input (the "Command line" rows of `docs/bad-input.md`): a
//! non-zero exit status, exactly one readable line on stderr starting with `hrm:`, and never a
//! panic. Clap's own usage errors are the one exception: they are several lines, starting with
//! `error:`, and exit with status 2.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh scratch folder for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrm-cli-errors-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A regular file `blocker` in `dir`: `blocker/out` can never be created as a folder, even by
/// root (permission bits would not stop the tests, which run as root).
fn blocked_folder(dir: &Path) -> PathBuf {
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, "a file, not a folder").unwrap();
    blocker.join("out")
}

/// A short scenario file (a 0.01 s step response), so that a run costs nothing.
fn short_scenario(dir: &Path) -> PathBuf {
    let path = dir.join("short.toml");
    std::fs::write(
        &path,
        r#"name = "short"
duration = 0.01
alpha0 = 1.5707963267948966
record_period = 0.001

[reference]
kind = "step"
initial = [0.0, 0.0]
target = [0.2, -0.2]
time = 0.0

[controller]
kind = "fuzzy"
period = 0.001

[integrator]
method = "rk4"
dt = 0.0001
"#,
    )
    .unwrap();
    path
}

fn hrm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .output()
        .expect("the hrm binary runs")
}

/// Fails unless `output` is a clean refusal: non-zero status, one `hrm: ` line on stderr, no
/// panic. Returns that line.
fn refused(output: &Output) -> String {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "exit status {:?}", output.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "stderr is not one line: {stderr:?}");
    assert!(lines[0].starts_with("hrm: "), "{stderr:?}");
    lines[0].to_string()
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn simulate_out_folder_under_a_regular_file() {
    let dir = scratch("simulate-out");
    let (scenario, out) = (short_scenario(&dir), blocked_folder(&dir));
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&scenario),
        "--out",
        path(&out),
    ]));
    assert!(line.contains("blocker"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_surface_out_folder_under_a_regular_file() {
    let dir = scratch("surface-out");
    let out = blocked_folder(&dir);
    let fis = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fuzzy-sugeno/data/paper.fis"
    );
    let line = refused(&hrm(&[
        "fis",
        "surface",
        fis,
        "--out",
        path(&out),
        "--resolution",
        "3",
    ]));
    assert!(line.contains("blocker"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn simulate_unknown_scenario() {
    let line = refused(&hrm(&["simulate", "--scenario", "no-such-scenario"]));
    assert!(line.contains("no-such-scenario"), "{line}");
}

#[test]
fn simulate_unknown_controller() {
    let dir = scratch("controller");
    let scenario = short_scenario(&dir);
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&scenario),
        "--controller",
        "banana",
        "--out",
        path(&dir.join("out")),
    ]));
    assert!(line.contains("banana"), "{line}");
    assert!(
        !dir.join("out").exists(),
        "nothing is written for a refused run"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_missing_file() {
    let dir = scratch("fis-missing");
    let missing = dir.join("missing.fis");
    let line = refused(&hrm(&["fis", "check", path(&missing)]));
    assert!(line.contains("missing.fis"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_garbage_file() {
    let dir = scratch("fis-garbage");
    let garbage = dir.join("garbage.fis");
    std::fs::write(&garbage, b"\x00\xffnot a [fis] file\n=== ===\n").unwrap();
    refused(&hrm(&["fis", "check", path(&garbage)]));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unknown_subcommand() {
    // Clap's usage error: several lines (the error, a usage line, a hint), status 2.
    let output = hrm(&["frobnicate"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2));
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.starts_with("error: unrecognized subcommand 'frobnicate'"),
        "{stderr}"
    );
}
