//! `hrm fis train` end to end: a CSV in, a `.fis` out that `hrm fis eval` loads and that
//! reproduces the data; bad files are one-line errors.

use crate::common::{hrm, scratch};
use std::path::PathBuf;

fn target(x1: f64, x2: f64) -> f64 {
    (2.0 * x1).sin() + 0.5 * x2 * x2
}

fn write_csv(path: &PathBuf, rows: usize, seed: usize, header: bool) {
    let mut text = if header {
        "e,de,u\n".to_string()
    } else {
        String::new()
    };
    for k in 0..rows {
        let x1 = -1.0 + 2.0 * ((k * 37 + seed) % 101) as f64 / 100.0;
        let x2 = -1.0 + 2.0 * ((k * 13 + seed) % 17) as f64 / 16.0;
        text.push_str(&format!("{x1},{x2},{}\n", target(x1, x2)));
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn trains_writes_and_evaluates() {
    let dir = scratch("fis-train-round-trip");
    let (train, check, out) = (
        dir.join("train.csv"),
        dir.join("check.csv"),
        dir.join("learned.fis"),
    );
    write_csv(&train, 200, 0, true);
    write_csv(&check, 60, 5, false);
    let run = hrm(&[
        "fis",
        "train",
        "--data",
        train.to_str().unwrap(),
        "--check",
        check.to_str().unwrap(),
        "--mfs",
        "3",
        "--epochs",
        "30",
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
        stdout.starts_with("2 inputs, 9 rules, 200 training samples, 60 check samples\n"),
        "{stdout}"
    );
    assert_eq!(stdout.matches(", check RMSE ").count(), 30);
    assert!(stdout.contains("kept the system of epoch "));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("Name='de'") && text.contains("NumRules=9"));
    let eval = hrm(&["fis", "eval", out.to_str().unwrap(), "0.3", "-0.5"]);
    let line = String::from_utf8_lossy(&eval.stdout);
    let value: f64 = line.trim().strip_prefix("u = ").unwrap().parse().unwrap();
    assert!((value - target(0.3, -0.5)).abs() < 0.01, "{line}");
}

#[test]
fn out_replaces_its_own_system_and_never_a_file_of_the_users() {
    let dir = scratch("fis-train-foreign-out");
    let (train, out, notes) = (
        dir.join("train.csv"),
        dir.join("learned.fis"),
        dir.join("notes.txt"),
    );
    write_csv(&train, 60, 0, false);
    let train_into = |out: &PathBuf| {
        hrm(&[
            "fis",
            "train",
            "--data",
            train.to_str().unwrap(),
            "--mfs",
            "2",
            "--epochs",
            "2",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    // Twice into the same file: the second run replaces what the first wrote.
    for _ in 0..2 {
        let run = train_into(&out);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    // A file hrm did not write (notes, a .fis written by hand, the user's copy of the shipped
    // controller, which hrm's writer reproduces but which lacks hrm's signature) stays as it was.
    let hand_written = std::fs::read_to_string(&out)
        .unwrap()
        .replace("Version=2.0", "Version=2.0 ");
    let copy = dir.join("my-controller.fis");
    let shipped = include_str!("../../../fuzzy-sugeno/data/paper.fis");
    assert_eq!(
        fuzzy_sugeno::FuzzySystem::from_fis(shipped)
            .unwrap()
            .to_fis(),
        shipped
    );
    for (path, text) in [
        (&notes, "the user's notes\n"),
        (&out, hand_written.as_str()),
        (&copy, shipped),
    ] {
        std::fs::write(path, text).unwrap();
        let run = train_into(path);
        assert_eq!(run.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            stderr.contains("exists and hrm did not write it"),
            "{stderr}"
        );
        assert_eq!(std::fs::read_to_string(path).unwrap(), text);
    }
    // A FIFO is refused at once (opening it to read would wait for a writer).
    let fifo = dir.join("fifo.fis");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    let run = train_into(&fifo);
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("exists and hrm did not write it"));
}

#[test]
fn bad_input_is_one_line() {
    let dir = scratch("fis-train-bad");
    let (csv, out) = (dir.join("bad.csv"), dir.join("x.fis"));
    let refused = |args: &[&str]| {
        let output = hrm(args);
        assert_eq!(output.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&output.stderr).to_string();
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        stderr
    };
    std::fs::write(&csv, "1,2\n3,oops\n").unwrap();
    let args = [
        "fis",
        "train",
        "--data",
        csv.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    assert!(
        refused(&args).ends_with("bad.csv: line 2 column 2: expected a number, found 'oops'\n")
    );
    std::fs::write(&csv, "1,2\n1,3\n").unwrap();
    assert!(
        refused(&args)
            .ends_with("input 1 is constant (1) over the data; a fuzzy partition needs a range\n")
    );
    write_csv(&csv, 20, 0, false);
    let with = |extra: [&'static str; 2]| {
        let mut a = args.to_vec();
        a.extend(extra);
        refused(&a)
    };
    assert_eq!(
        with(["--mfs", "100"]),
        "hrm: --mfs must be at least 1 and at most 64, got 100\n"
    );
    // Negative counts reach the options' own checks, not a parse error.
    assert_eq!(
        with(["--mfs", "-1"]),
        "hrm: --mfs must be at least 1 and at most 64, got -1\n"
    );
    assert_eq!(
        with(["--epochs", "-1"]),
        "hrm: --epochs must be at least 0 and at most 100000, got -1\n"
    );
    assert_eq!(
        with(["--order", "2"]),
        "hrm: --order must be 0 or 1, got 2\n"
    );
    assert_eq!(
        with(["--order", "-1"]),
        "hrm: --order must be 0 or 1, got -1\n"
    );
    // The learning library's refusals of a setting name the option that gave it, before any
    // system is built (nothing on standard output).
    for (option, value, message) in [
        (
            "--ridge",
            "-1",
            "hrm: --ridge must be finite and at least 0, got -1\n",
        ),
        (
            "--ridge",
            "1e308",
            "hrm: --ridge must be at most 1e6, got 1e308\n",
        ),
        (
            "--step",
            "NaN",
            "hrm: --step must be finite and at least 0, got NaN\n",
        ),
        (
            "--cluster-radius",
            "2",
            "hrm: --cluster-radius must lie in (0, 1], got 2\n",
        ),
    ] {
        let mut a = args.to_vec();
        a.extend([option, value]);
        let output = hrm(&a);
        assert_eq!(String::from_utf8_lossy(&output.stderr), message);
        assert!(output.stdout.is_empty(), "{option} {value}");
    }
    let mut a = args.to_vec();
    a.extend(["--mf-type", "sigmf", "--mfs", "3"]);
    assert!(refused(&a).starts_with("hrm: --mfs: sigmf partitions have exactly 2 sets per input"));
    // An endless stream (its size reads 0) stops at the 64 MiB limit instead of filling memory.
    if std::path::Path::new("/dev/zero").exists() {
        let endless = [
            "fis",
            "train",
            "--data",
            "/dev/zero",
            "--out",
            out.to_str().unwrap(),
        ];
        assert!(refused(&endless).contains("is not a regular file"));
    }
    assert!(!out.exists());
}
