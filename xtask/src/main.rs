//! Project automation in the cargo-xtask pattern: `cargo xtask <command>`.
//!
//! - `ci`: what `.ci/run` runs: formatting, clippy with `-D warnings`, `tidy`, `test`, and a
//!   compile-only pass over the benches.
//! - `tidy`: the repository's rules checked by machine ([`mod@tidy`]): the tests `docs/bad-input.md`
//!   names exist, crate READMEs are crate docs, no README cites a file outside the repository,
//!   invariants of `docs/architecture.md`, and `cargo doc` without warnings.
//! - `test`: the whole Rust test suite, the `hrm` crate's `custom_controller` example, then the
//!   Python package: a virtual environment under `target/python-venv` with numpy, pytest, maturin
//!   and Pinocchio (`pin`) from PyPI, the extension built once in release mode and installed by
//!   `pip install ./crates/hrm-py`, pytest over `crates/hrm-py/tests`, and every script of
//!   `examples/python/`.
//! - `props [--cases N]`: the test suite with `PROPTEST_CASES=N` (default 2048), so every property
//!   test (energy conservation, Jacobian consistency, ...) runs many more cases than in CI.
//! - `bench [FILTER]`: the Criterion benches, then `target/bench-summary.json` (bench id -> median
//!   nanoseconds per iteration, or per element for a bench with Criterion's throughput set, such
//!   as the states of a batch) printed as a table.
//! - `bench --check [--rounds N] [--measurement-time SECONDS] [--only TEXT]`: the targets of
//!   `benches/targets.toml`, measured in this invocation: the anchors' harnesses (Pinocchio,
//!   fuzzylite, Crocoddyl) and hrm's benches interleaved over rounds, ratios checked on the
//!   medians ([`mod@bench_check`]); fails if a target falls short. Not part of CI (CI compiles the
//!   benches, never runs them).

mod bench_check;
mod imports;
mod tidy;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("ci") => ci(),
        Some("test") => test(),
        Some("tidy") => tidy(),
        Some("props") => props(&args[1..]),
        Some("bench") if args.get(1).is_some_and(|a| a == "--check") => check(&args[2..]),
        Some("bench") => bench(&args[1..]),
        _ => Err(USAGE.to_string()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::FAILURE
        }
    }
}

const USAGE: &str = "usage: cargo xtask ci | test | tidy | props [--cases N] | bench [FILTER] \
     | bench --check [--rounds N] [--measurement-time SECONDS] [--only TEXT]";

fn ci() -> Result<(), String> {
    cargo(&["fmt", "--all", "--", "--check"], &[])?;
    cargo(
        &[
            "clippy",
            "--workspace",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
        &[],
    )?;
    tidy()?;
    test()?;
    // Benches are compiled, never run, in CI.
    cargo(&["test", "--workspace", "--benches", "--no-run"], &[])
}

/// The repository's rules ([`mod@tidy`]); every problem is printed, then the command fails.
fn tidy() -> Result<(), String> {
    let problems = tidy::run(&workspace_root(), || {
        cargo(
            &["doc", "--workspace", "--no-deps"],
            &[("RUSTDOCFLAGS", "-D warnings")],
        )
    });
    for problem in &problems {
        eprintln!("tidy: {problem}");
    }
    match problems.len() {
        0 => Ok(()),
        n => Err(format!("tidy found {n} problem(s)")),
    }
}

/// The Rust tests, then the Python package's tests and examples in a virtual environment under
/// `target/` (created on first use; needs `python3` (or `$PYTHON`) with `venv` and network
/// access to PyPI). pytest's "no tests collected" (exit code 5) fails like any other failure.
fn test() -> Result<(), String> {
    cargo(&["test", "--workspace"], &[])?;
    // The first program of the `hrm` crate's docs must run.
    cargo(&["run", "-p", "hrm", "--example", "custom_controller"], &[])?;
    let root = workspace_root();
    let venv = target_dir().join("python-venv");
    let python = venv
        .join(if cfg!(windows) { "Scripts" } else { "bin" })
        .join(if cfg!(windows) {
            "python.exe"
        } else {
            "python"
        });
    if !python.exists() {
        let system = std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_string());
        run(Path::new(&system), &["-m", "venv", &venv.to_string_lossy()])?;
    }
    let pip = [
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ];
    // The packages the Python tests need, one a line in crates/hrm-py/tests/requirements.txt.
    let requirements = root
        .join("crates")
        .join("hrm-py")
        .join("tests")
        .join("requirements.txt");
    run(
        &python,
        &[&pip[..], &["-r", &requirements.to_string_lossy()]].concat(),
    )?;
    // The same command a user runs; maturin builds the extension in release mode, once.
    let package = root.join("crates").join("hrm-py");
    let install = ["--force-reinstall", "--no-deps", &package.to_string_lossy()];
    run(&python, &[&pip[..], &install[..]].concat())?;
    let tests = package.join("tests");
    match status(&python, &["-m", "pytest", "-q", &tests.to_string_lossy()])?.code() {
        Some(0) => {}
        Some(5) => return Err(format!("pytest collected no tests in {}", tests.display())),
        code => return Err(format!("pytest failed (exit code {code:?})")),
    }
    let examples = root.join("examples").join("python");
    let mut scripts: Vec<PathBuf> = std::fs::read_dir(&examples)
        .map_err(|e| format!("{}: {e}", examples.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "py"))
        .collect();
    scripts.sort();
    if scripts.is_empty() {
        return Err(format!("no example scripts in {}", examples.display()));
    }
    for script in &scripts {
        run(&python, &[&*script.to_string_lossy()])?;
    }
    // Like the Criterion benches, the Python benchmarks are compiled, not run.
    let benches = root.join("benches").join("python");
    let mut compile = vec!["-m".to_string(), "py_compile".to_string()];
    for entry in std::fs::read_dir(&benches).map_err(|e| format!("{}: {e}", benches.display()))? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.extension().is_some_and(|ext| ext == "py") {
            compile.push(path.to_string_lossy().into_owned());
        }
    }
    run(
        &python,
        &compile.iter().map(String::as_str).collect::<Vec<_>>(),
    )
}

/// Runs `program args...` in the workspace root and returns its exit status.
fn status(program: &Path, args: &[&str]) -> Result<std::process::ExitStatus, String> {
    println!("xtask: {} {}", program.display(), args.join(" "));
    Command::new(program)
        .args(args)
        .current_dir(workspace_root())
        .status()
        .map_err(|e| format!("cannot run {}: {e}", program.display()))
}

/// Runs `program args...` in the workspace root; fails unless it succeeds.
fn run(program: &Path, args: &[&str]) -> Result<(), String> {
    let status = status(program, args)?;
    if status.success() {
        Ok(())
    } else {
        Err(format!(
            "`{} {}` failed ({status})",
            program.display(),
            args.join(" ")
        ))
    }
}

/// `bench --check [--rounds N] [--measurement-time SECONDS] [--only TEXT]` ([`mod@bench_check`]).
fn check(args: &[String]) -> Result<(), String> {
    let mut options = bench_check::Options {
        rounds: 3,
        measurement_seconds: 2.0,
        only: None,
    };
    let mut rest = args.iter();
    while let Some(flag) = rest.next() {
        let value = rest
            .next()
            .ok_or_else(|| format!("{flag} needs a value; {USAGE}"))?;
        match flag.as_str() {
            "--rounds" => {
                options.rounds = value
                    .parse()
                    .ok()
                    .filter(|n| (1..=bench_check::MAX_ROUNDS).contains(n))
                    .ok_or_else(|| {
                        format!(
                            "--rounds must be 1 to {}, not {value}",
                            bench_check::MAX_ROUNDS
                        )
                    })?;
            }
            "--measurement-time" => {
                options.measurement_seconds = value
                    .parse()
                    .ok()
                    .filter(|s: &f64| (0.1..=600.0).contains(s))
                    .ok_or_else(|| {
                        format!("--measurement-time must be 0.1 to 600 seconds, not {value}")
                    })?;
            }
            "--only" => options.only = Some(value.clone()),
            _ => return Err(USAGE.to_string()),
        }
    }
    bench_check::run(&workspace_root(), &target_dir(), &options)
}

fn props(args: &[String]) -> Result<(), String> {
    let cases = match args {
        [] => "2048".to_string(),
        [flag, n] if flag == "--cases" && n.parse::<u32>().is_ok() => n.clone(),
        _ => return Err(USAGE.to_string()),
    };
    println!("xtask: running the test suite with PROPTEST_CASES={cases}");
    cargo(
        &["test", "--workspace", "--release"],
        &[("PROPTEST_CASES", &cases)],
    )
}

fn bench(args: &[String]) -> Result<(), String> {
    let mut cmd = vec!["bench", "--package", "hrm-benches", "--", "--noplot"];
    cmd.extend(args.iter().map(String::as_str));
    cargo(&cmd, &[])?;
    let criterion = target_dir().join("criterion");
    let mut rows = Vec::new();
    collect_medians(&criterion, &mut rows, None)?;
    if rows.is_empty() {
        return Err(format!(
            "no Criterion results under {}",
            criterion.display()
        ));
    }
    rows.sort_by(|a, b| a.0.cmp(&b.0));
    let summary: serde_json::Map<String, serde_json::Value> = rows
        .iter()
        .map(|(id, ns)| (id.clone(), serde_json::Value::from(*ns)))
        .collect();
    let path = target_dir().join("bench-summary.json");
    let text = serde_json::to_string_pretty(&summary).map_err(|e| e.to_string())?;
    std::fs::write(&path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))?;
    let width = rows.iter().map(|r| r.0.len()).max().unwrap_or(0).max(5);
    println!("\n{:<width$}  {:>14}", "bench", "median");
    for (id, ns) in &rows {
        println!("{id:<width$}  {:>14}", human_time(*ns));
    }
    println!("\nwrote {}", path.display());
    Ok(())
}

/// Walks Criterion's output folder and collects `(full id, median ns)` from every
/// `new/benchmark.json` + `new/estimates.json` pair (only those written at or after `since`, if
/// given).
fn collect_medians(
    dir: &Path,
    rows: &mut Vec<(String, f64)>,
    since: Option<std::time::SystemTime>,
) -> Result<(), String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if !path.is_dir() {
            continue;
        }
        if path.file_name().is_some_and(|n| n == "new") {
            let fresh = since.is_none_or(|since| {
                std::fs::metadata(path.join("estimates.json"))
                    .and_then(|m| m.modified())
                    .is_ok_and(|modified| modified >= since)
            });
            if !fresh {
                continue;
            }
            if let (Some(id), Some(median)) = (
                read_json(&path.join("benchmark.json"), &["full_id"])
                    .and_then(|v| v.as_str().map(str::to_owned)),
                read_json(&path.join("estimates.json"), &["median", "point_estimate"])
                    .and_then(|v| v.as_f64()),
            ) {
                // A bench with Criterion's throughput set counts per element (a batch's states).
                let elements = read_json(&path.join("benchmark.json"), &["throughput", "Elements"])
                    .and_then(|v| v.as_f64())
                    .filter(|&e| e > 0.0)
                    .unwrap_or(1.0);
                rows.push((id, median / elements));
            }
        } else {
            collect_medians(&path, rows, since)?;
        }
    }
    Ok(())
}

fn read_json(path: &Path, keys: &[&str]) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut value: serde_json::Value = serde_json::from_str(&text).ok()?;
    for key in keys {
        value = value.get(key)?.clone();
    }
    Some(value)
}

fn human_time(ns: f64) -> String {
    match ns {
        ns if ns < 1e3 => format!("{ns:.1} ns"),
        ns if ns < 1e6 => format!("{:.2} us", ns / 1e3),
        ns if ns < 1e9 => format!("{:.2} ms", ns / 1e6),
        ns => format!("{:.2} s", ns / 1e9),
    }
}

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives in the workspace")
        .to_path_buf()
}

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| workspace_root().join("target"), PathBuf::from)
}

fn cargo(args: &[&str], envs: &[(&str, &str)]) -> Result<(), String> {
    let program = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    println!("xtask: cargo {}", args.join(" "));
    let status = Command::new(program)
        .args(args)
        .envs(envs.iter().copied())
        .current_dir(workspace_root())
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`cargo {}` failed ({status})", args.join(" ")))
    }
}
