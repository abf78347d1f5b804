//! `hrm fis export` and FCL files in `hrm fis eval`: the paper's controller through FCL gives
//! the same outputs, the C files are written, bad options are one-line errors.

use crate::common::{hrm, scratch};
use std::process::Output;

const PAPER_FIS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../fuzzy-sugeno/data/paper.fis"
);
const FUZZYLITE_FCL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../fuzzy-sugeno/data/paper.fuzzylite.fcl"
);

/// `hrm fis export --format FORMAT PAPER_FIS --out OUT` and the `extra` options.
fn export_paper(format: &str, out: &str, extra: &[&str]) -> Output {
    let args = ["fis", "export", "--format", format, PAPER_FIS, "--out", out];
    hrm(&[&args[..], extra].concat())
}

fn stdout(output: &Output) -> String {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout.clone()).unwrap()
}

#[test]
fn fcl_export_evaluates_like_the_fis_file() {
    let dir = scratch("fis-export-fcl");
    let out = dir.to_str().unwrap();
    let written = stdout(&export_paper("fcl", out, &[]));
    let fcl = written.trim();
    assert!(fcl.ends_with("paper.fcl"));
    let x = ["0.15", "-0.1", "-0.5", "0.2"];
    let eval = |file: &str| stdout(&hrm(&[&["fis", "eval", file][..], &x[..]].concat()));
    let expected = eval(PAPER_FIS);
    assert!(expected.starts_with("tau1 = -56.14035087719"), "{expected}");
    assert_eq!(eval(fcl), expected);
    assert_eq!(eval(FUZZYLITE_FCL), expected);
}

/// Into a folder of the user's (no marker of hrm's), an export replaces the files a previous
/// export wrote (C by its opening comment, FCL by its text) and never a file of the user's.
#[test]
fn export_again_replaces_its_own_files_and_never_the_users() {
    let dir = scratch("fis-export-again");
    let out = dir.to_str().unwrap();
    for format in ["c", "fcl", "c", "fcl"] {
        stdout(&export_paper(format, out, &[]));
    }
    for (name, format) in [("hrm_fis.c", "c"), ("paper.fcl", "fcl")] {
        std::fs::write(dir.join(name), "/* the user's own */\n").unwrap();
        let refused = export_paper(format, out, &[]);
        assert_eq!(refused.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(stderr.contains("did not create"), "{stderr}");
        assert_eq!(
            std::fs::read_to_string(dir.join(name)).unwrap(),
            "/* the user's own */\n"
        );
    }
}

/// Not into another command's output folder (a `simulate` folder, replaced whole by the next
/// `simulate`, which would then find files it did not write): refused before anything is written.
#[test]
fn export_into_another_commands_output_is_refused() {
    let dir = scratch("fis-export-marked");
    let out = dir.join("sim");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join(".hrm-output"), "written by `hrm simulate`\n").unwrap();
    let refused = export_paper("c", out.to_str().unwrap(), &[]);
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("holds the output of `hrm simulate`, which replaces its folder whole"),
        "{stderr}"
    );
    assert!(!out.join("hrm_fis.c").exists());
}

/// A name FCL cannot carry (a variable named `END_VAR`) is a one-line error naming it, exit 1,
/// and nothing is written.
#[test]
fn fcl_export_refuses_a_keyword_name_and_writes_nothing() {
    let dir = scratch("fis-export-fcl-keyword");
    let fis = dir.join("keyword.fis");
    let text = std::fs::read_to_string(PAPER_FIS)
        .unwrap()
        .replace("Name='da1'", "Name='END_VAR'");
    std::fs::write(&fis, text).unwrap();
    let out = dir.join("out");
    let refused = hrm(&[
        "fis",
        "export",
        "--format",
        "fcl",
        fis.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("hrm: export: the input name 'END_VAR' cannot be written in FCL"),
        "{stderr}"
    );
    assert!(!out.join("keyword.fcl").exists());
}

#[test]
fn c_export_writes_the_header_and_source() {
    let dir = scratch("fis-export-c");
    let out = dir.to_str().unwrap();
    let written = stdout(&export_paper(
        "c",
        out,
        &["--prefix", "ctl", "--no-rule-fired", "error"],
    ));
    assert_eq!(written.lines().count(), 2);
    let header = std::fs::read_to_string(dir.join("ctl.h")).unwrap();
    assert!(header.contains("int ctl_eval(const double *in, double *out);"));
    assert!(header.contains("an output on which no rule fires is an error"));
    assert!(
        std::fs::read_to_string(dir.join("ctl.c"))
            .unwrap()
            .contains("#include <math.h>")
    );
    let refused = export_paper("c", out, &["--prefix", "a-b"]);
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(stderr.lines().count(), 1);
    assert!(stderr.starts_with("hrm: export: the prefix must be a C identifier"));
    // An --out that is a file is named as such, and left as it was.
    let file = dir.join("ctl.h");
    let refused = export_paper("c", file.to_str().unwrap(), &[]);
    assert_eq!(refused.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&refused.stderr),
        format!(
            "hrm: output folder {}: exists and is not a folder\n",
            file.display()
        )
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), header);
}

/// `hrm fis check` reads an FCL file: the same analysis as for the `.fis` file, without the
/// `.fis` reader's line of ignored items (the FCL reader keeps no such notes).
#[test]
fn check_reads_fcl_without_the_notes_line() {
    let from_fis = stdout(&hrm(&["fis", "check", PAPER_FIS]));
    let from_fcl = stdout(&hrm(&["fis", "check", FUZZYLITE_FCL]));
    let (notes, analysis) = from_fis.split_once('\n').unwrap();
    assert!(notes.ends_with("paper.fis: nothing ignored"), "{notes}");
    assert_eq!(from_fcl, analysis);
}

/// `hrm fis eval` evaluates an input outside its range as given, as MATLAB's evalfis does, with
/// one warning line on standard error; `--out-of-range clamp` evaluates it at the range's end.
#[test]
fn eval_takes_inputs_outside_their_ranges_as_given_with_a_warning() {
    let x = ["-0.414", "-0.263", "0.904", "0.246"];
    let as_given = hrm(&[&["fis", "eval", PAPER_FIS][..], &x[..]].concat());
    assert!(stdout(&as_given).starts_with("tau1 = 75.933"));
    let warning = String::from_utf8_lossy(&as_given.stderr);
    assert_eq!(warning.lines().count(), 1, "{warning}");
    assert!(
        warning
            .starts_with("hrm: warning: input 1 ('da1') = -0.414 is outside its range [-0.3, 0.3]"),
        "{warning}"
    );
    let clamped = hrm(&[
        &["fis", "eval", PAPER_FIS, "--out-of-range", "clamp"][..],
        &x[..],
    ]
    .concat());
    assert!(stdout(&clamped).starts_with("tau1 = 71.320"));
    assert!(clamped.stderr.is_empty());
    // Every input outside its range is named, in one line.
    let two = hrm(&[PAPER_FIS_EVAL, &["-0.414", "-0.263", "5", "0.246"][..]].concat());
    let warning = String::from_utf8_lossy(&two.stderr);
    assert_eq!(warning.lines().count(), 1, "{warning}");
    assert!(
        warning.contains("input 1 ('da1') = -0.414 is outside its range [-0.3, 0.3], input 3"),
        "{warning}"
    );
}

/// `hrm fis eval` of the paper's system, before its inputs.
const PAPER_FIS_EVAL: &[&str] = &["fis", "eval", PAPER_FIS];
