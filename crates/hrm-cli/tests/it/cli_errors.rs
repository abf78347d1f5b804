//! The `hrm` command line on bad input (the "Command line" rows of `docs/bad-input.md`): a
//! non-zero exit status, exactly one readable line on stderr starting with `hrm:`, and never a
//! panic. Clap's own usage errors are the one exception: they are several lines, starting with
//! `error:`, and exit with status 2.

use crate::common::{hrm, scratch};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The paper's controller as a `.fis` file.
const PAPER_FIS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../fuzzy-sugeno/data/paper.fis"
);

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
    let dir = scratch("errors-simulate-out");
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
    let dir = scratch("errors-surface-out");
    let out = blocked_folder(&dir);
    let line = refused(&paper_surface(&out, &[]));
    assert!(line.contains("blocker"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `hrm fis surface` of the paper's controller at resolution 3 into `out`, with `extra`.
fn paper_surface(out: &Path, extra: &[&str]) -> Output {
    let args = [
        "fis",
        "surface",
        PAPER_FIS,
        "--out",
        path(out),
        "--resolution",
        "3",
    ];
    hrm(&[&args[..], extra].concat())
}

/// A `--reference` value outside its input's range is drawn as given, with one warning line
/// naming it.
#[test]
fn fis_surface_warns_of_a_reference_outside_its_range() {
    let dir = scratch("surface-reference-range");
    let output = paper_surface(&dir.join("surface"), &["--reference=5,0,0,0"]);
    assert!(output.status.success(), "{output:?}");
    let warning = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        warning.trim_end(),
        "hrm: warning: --reference: input 1 ('da1') = 5 is outside its range [-0.3, 0.3]; the \
         surfaces hold it there, evaluated as given"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A surface that cannot be drawn (its outputs span beyond double precision) is named in the
/// folder the user gave, not the staging folder that the failure removes; nothing is written.
#[test]
fn fis_surface_names_the_file_in_the_out_folder() {
    let dir = scratch("errors-surface-span");
    let fis = dir.join("huge.fis");
    std::fs::write(
        &fis,
        "[System]\nName='b'\nType='sugeno'\nNumInputs=1\nNumOutputs=1\nNumRules=2\n\
         AndMethod='prod'\nOrMethod='probor'\nDefuzzMethod='wtsum'\n\n[Input1]\nName='x'\n\
         Range=[-1 1]\nNumMFs=2\nMF1='a':'gaussmf',[0.5 -1]\nMF2='b':'trimf',[-1 1 1]\n\n\
         [Output1]\nName='y'\nRange=[-1e307 1e307]\nNumMFs=2\nMF1='k':'constant',[1e308]\n\
         MF2='j':'constant',[1e308]\n\n[Rules]\n1, 1 (1) : 1\n2, 2 (1) : 1\n",
    )
    .unwrap();
    let out = dir.join("surface");
    let line = refused(&hrm(&["fis", "surface", path(&fis), "--out", path(&out)]));
    let expected = format!("hrm: {}: cannot plot", path(&out.join("curve_y_x.svg")));
    assert!(line.starts_with(&expected), "{line}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn simulate_unknown_scenario() {
    let line = refused(&hrm(&["simulate", "--scenario", "no-such-scenario"]));
    assert!(line.contains("no-such-scenario"), "{line}");
}

#[test]
fn simulate_unknown_controller() {
    let dir = scratch("errors-controller");
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
    // A controller the URDF arm's loop does not take is the option's, named so.
    let urdf = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/urdf-arm/step.toml"
    );
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        urdf,
        "--controller",
        "fuzzy",
        "--out",
        path(&dir.join("out")),
    ]));
    assert!(
        line.starts_with("hrm: --controller must be \"computed-torque\" with a URDF arm"),
        "{line}"
    );
    assert!(!dir.join("out").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_missing_file() {
    let dir = scratch("errors-fis-missing");
    let missing = dir.join("missing.fis");
    let line = refused(&hrm(&["fis", "check", path(&missing)]));
    assert!(line.contains("missing.fis"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_garbage_file() {
    let dir = scratch("errors-fis-garbage");
    let garbage = dir.join("garbage.fis");
    std::fs::write(&garbage, b"\x00\xffnot a [fis] file\n=== ===\n").unwrap();
    refused(&hrm(&["fis", "check", path(&garbage)]));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A 2-input `.fis` with `sets` triangles per input and a rule for every pair of sets.
fn grid_fis(sets: usize) -> String {
    let mut text = format!(
        "[System]\nName='big'\nType='sugeno'\nNumInputs=2\nNumOutputs=1\nNumRules={}\n\
         AndMethod='prod'\nOrMethod='max'\nDefuzzMethod='wtaver'\n",
        sets * sets
    );
    for input in 1..=2 {
        text.push_str(&format!(
            "\n[Input{input}]\nName='x{input}'\nRange=[0 {sets}]\nNumMFs={sets}\n"
        ));
        for k in 0..sets {
            text.push_str(&format!(
                "MF{}='s{k}':'trimf',[{} {k} {}]\n",
                k + 1,
                k as f64 - 1.0,
                k + 1
            ));
        }
    }
    text.push_str("\n[Output1]\nName='y'\nRange=[0 1]\nNumMFs=1\nMF1='c':'constant',[0.5]\n");
    text.push_str("\n[Rules]\n");
    for a in 1..=sets {
        for b in 1..=sets {
            text.push_str(&format!("{a} {b}, 1 (1) : 1\n"));
        }
    }
    text
}

#[test]
fn fis_check_of_40000_rules_is_refused_by_its_work_bound() {
    // 40,000 rules over a grid of the 2 x 200 sets' landmarks and midpoints: about 10^10 rule
    // evaluations (minutes) without the bound; refused before the work starts.
    let dir = scratch("errors-fis-work");
    let file = dir.join("big.fis");
    std::fs::write(&file, grid_fis(200)).unwrap();
    let started = std::time::Instant::now();
    let line = refused(&hrm(&["fis", "check", path(&file)]));
    assert!(
        line.contains("40000 rules") && line.contains("limit of 100000000 rule evaluations"),
        "{line}"
    );
    assert!(started.elapsed().as_secs() < 10, "{:?}", started.elapsed());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_of_a_grid_past_its_limit_says_what_the_system_needs() {
    // 4 inputs of 20 triangles: their landmarks and the midpoints between them alone make 41^4
    // (2.8 million) grid points, past a limit the command line does not offer to raise.
    let dir = scratch("errors-fis-grid");
    let mut text = String::from(
        "[System]\nName='wide'\nType='sugeno'\nNumInputs=4\nNumOutputs=1\nNumRules=1\n\
         AndMethod='prod'\nOrMethod='probor'\nImpMethod='prod'\nAggMethod='sum'\n\
         DefuzzMethod='wtaver'\n",
    );
    for input in 1..=4 {
        text.push_str(&format!(
            "\n[Input{input}]\nName='x{input}'\nRange=[0 20]\nNumMFs=20\n"
        ));
        for k in 0..20 {
            text.push_str(&format!(
                "MF{}='s{k}':'trimf',[{} {k} {}]\n",
                k + 1,
                k as f64 - 1.0,
                k + 1
            ));
        }
    }
    text.push_str("\n[Output1]\nName='y'\nRange=[0 1]\nNumMFs=1\nMF1='c':'constant',[0.5]\n");
    text.push_str("\n[Rules]\n1 1 1 1, 1 (1) : 1\n");
    let file = dir.join("wide.fis");
    std::fs::write(&file, text).unwrap();
    let line = refused(&hrm(&["fis", "check", path(&file)]));
    assert!(
        line.contains(
            "the completeness grid of this system needs 2825761 points (41 x 41 x 41 x 41"
        ) && line.contains(
            "more than the 1000000 `hrm fis check` evaluates: check a system with fewer \
                 inputs or sets"
        ) && !line.contains("raise"),
        "{line}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn fis_check_options_are_named_as_given() {
    let dir = scratch("errors-fis-options");
    let file = dir.join("small.fis");
    std::fs::write(&file, grid_fis(2)).unwrap();
    let line = refused(&hrm(&["fis", "check", path(&file), "--max-jump", "nan"]));
    assert!(
        line.contains("--max-jump") && line.contains("NaN"),
        "{line}"
    );
    let output = hrm(&["fis", "check", path(&file), "--coverage", "2"]);
    let line = refused(&output);
    assert!(
        line.contains("--coverage") && line.contains("got 2"),
        "{line}"
    );
    // Refused before any of the report is printed.
    assert!(output.stdout.is_empty(), "{output:?}");
    let line = refused(&hrm(&["fis", "check", path(&file), "--max-jump", "inf"]));
    assert!(
        line.ends_with("--max-jump must be positive and finite, got inf"),
        "{line}"
    );
    // A coverage whose threshold (coverage^2 under the product) underflows: every point passed.
    let line = refused(&hrm(&["fis", "check", path(&file), "--coverage", "1e-200"]));
    assert!(
        line.ends_with(
            "--coverage must give a threshold (coverage, raised to the number of inputs under \
             the product) of at least 2.2e-308, got 1e-200"
        ),
        "{line}"
    );
    // Extreme values are echoed compactly (1e-320 was 324 digits, 1e300 301).
    for (option, value, shown) in [
        ("--max-jump", "1e-320", "must stay below 1e-320)"),
        ("--max-jump", "1e300", "must stay below 1e300)"),
    ] {
        let output = hrm(&["fis", "check", path(&file), option, value]);
        let text = stdout(&output);
        assert!(text.contains(shown), "{option} {value}: {text}");
        let digits = text
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max();
        assert!(digits < Some(40), "{text}");
    }
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

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Every file under `dir` with its contents, sorted by path.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut files = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                files.push((path.clone(), std::fs::read(&path).unwrap()));
            }
        }
    }
    files.sort();
    files
}

#[test]
fn an_output_folder_holding_the_commands_input_is_refused_before_it_is_replaced() {
    // The scenario (and a FIS file) saved in an earlier output folder, then run into it: the
    // replaced folder would take its inputs with it.
    let dir = scratch("errors-input-inside-out");
    let out = dir.join("out");
    let first = hrm(&[
        "simulate",
        "--scenario",
        path(&short_scenario(&dir)),
        "--out",
        path(&out),
    ]);
    assert!(first.status.success(), "{first:?}");
    let inside = short_scenario(&out);
    let before = snapshot(&out);
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&inside),
        "--out",
        path(&out),
    ]));
    assert!(
        line.ends_with(&format!(
            "out: holds the scenario file {}, which replacing the folder would delete; choose \
             another --out or move the file out of it",
            inside.display()
        )),
        "{line}"
    );
    let line = refused(&hrm(&[
        "sweep",
        "--scenario",
        path(&inside),
        "--seeds",
        "1",
        "--out",
        path(&out),
    ]));
    assert!(line.contains("holds the scenario file"), "{line}");
    let fis = out.join("mine.fis");
    std::fs::write(&fis, include_str!("../../../fuzzy-sugeno/data/paper.fis")).unwrap();
    let line = refused(&hrm(&["fis", "surface", path(&fis), "--out", path(&out)]));
    assert!(line.contains("holds the FIS file"), "{line}");
    let with_fis = dir.join("with-fis.toml");
    let text = std::fs::read_to_string(&inside).unwrap();
    let text = text.replace(
        "kind = \"fuzzy\"",
        &format!("kind = \"fuzzy\"\nfis = {:?}", path(&fis)),
    );
    std::fs::write(&with_fis, text).unwrap();
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&with_fis),
        "--out",
        path(&out),
    ]));
    assert!(line.contains("holds the controller.fis file"), "{line}");
    let mut after = before.clone();
    after.push((fis.clone(), std::fs::read(&fis).unwrap()));
    after.sort();
    assert_eq!(snapshot(&out), after, "the output folder changed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failing_simulate_leaves_the_earlier_output_and_a_success_replaces_it() {
    let dir = scratch("errors-simulate-replace");
    let (scenario, out) = (short_scenario(&dir), dir.join("out"));
    let run = |scenario: &Path| {
        hrm(&[
            "simulate",
            "--scenario",
            path(scenario),
            "--out",
            path(&out),
        ])
    };
    let first = run(&scenario);
    assert!(first.status.success(), "{first:?}");
    assert!(stdout(&first).contains("wrote"));
    let before = snapshot(&out);
    // A scenario that fails validation (not a whole number of periods): refused, nothing
    // touched, no "wrote".
    let bad = dir.join("bad.toml");
    let text = std::fs::read_to_string(&scenario).unwrap();
    std::fs::write(&bad, text.replace("duration = 0.01", "duration = 0.0105")).unwrap();
    let output = run(&bad);
    let line = refused(&output);
    assert!(line.contains("duration must be a whole number"), "{line}");
    assert!(!stdout(&output).contains("wrote"), "{output:?}");
    assert_eq!(snapshot(&out), before, "the earlier output changed");
    // A file the user saved into the output: named, kept, nothing touched.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let before = snapshot(&out);
    let line = refused(&run(&scenario));
    assert!(
        line.contains("holds notes.txt, which hrm did not write"),
        "{line}"
    );
    assert_eq!(snapshot(&out), before, "the earlier output changed");
    // Without it, a success replaces the folder whole: a file of the earlier output that the
    // new one does not write is gone.
    std::fs::remove_file(out.join("notes.txt")).unwrap();
    std::fs::remove_file(out.join("timeseries.csv")).unwrap();
    let marker = std::fs::read_to_string(out.join(".hrm-output")).unwrap();
    std::fs::write(out.join("stale.csv"), "from an earlier run").unwrap();
    std::fs::write(out.join(".hrm-output"), marker + "stale.csv\n").unwrap();
    assert!(run(&scenario).status.success());
    assert!(!out.join("stale.csv").exists());
    assert!(out.join("timeseries.csv").is_file() && out.join(".hrm-output").is_file());
    // A folder that hrm did not write is never replaced.
    let mine = dir.join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&scenario),
        "--out",
        path(&mine),
    ]));
    assert!(line.contains("hrm did not write"), "{line}");
    assert!(mine.join("notes.txt").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_diverging_simulate_writes_its_data_up_to_the_stop() {
    let dir = scratch("errors-simulate-diverge");
    let scenario = dir.join("runaway.toml");
    // The step comes at 5 ms; a 0.05 rad runaway bound stops the run right after it.
    let text = std::fs::read_to_string(short_scenario(&dir)).unwrap();
    let text = text.replace("time = 0.0", "time = 0.005") + "\n[limits]\nmax_modal_error = 0.05\n";
    std::fs::write(&scenario, text).unwrap();
    let out = dir.join("out");
    let output = hrm(&[
        "simulate",
        "--scenario",
        path(&scenario),
        "--out",
        path(&out),
    ]);
    let line = refused(&output);
    assert!(line.contains("runaway tracking error"), "{line}");
    assert!(stdout(&output).contains("wrote"), "{output:?}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let stopped = summary["stopped_at_s"].as_f64().unwrap();
    assert!((0.005..0.01).contains(&stopped), "{summary}");
    assert!(summary["error"].as_str().unwrap().contains("runaway"));
    assert!(summary["tip_error_rms_m"].as_f64().unwrap().is_finite());
    let csv = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let last_t: f64 = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        csv.lines().count() > 5 && (last_t - stopped).abs() < 1e-12,
        "{csv}"
    );
    // A run that stops before its first recorded sample (links of 1e-100 m, whose C* overflows
    // at the first step) writes nothing: the earlier output stays as it was.
    let before = snapshot(&out);
    let tiny = dir.join("tiny.toml");
    let text = std::fs::read_to_string(short_scenario(&dir)).unwrap();
    std::fs::write(&tiny, text + "\n[arm]\nlink_length = 1e-100\n").unwrap();
    let output = hrm(&["simulate", "--scenario", path(&tiny), "--out", path(&out)]);
    let line = refused(&output);
    assert!(line.contains("C* is not finite"), "{line}");
    assert!(!stdout(&output).contains("wrote"), "{output:?}");
    assert_eq!(snapshot(&out), before, "the earlier output changed");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn counts_are_bounded_before_use_with_the_option_named() {
    let dir = scratch("errors-counts");
    let out = dir.join("out");
    let fis = PAPER_FIS;
    let noise: Vec<String> = (0..1001).map(|k| format!("{}", k as f64 * 1e-4)).collect();
    let noise = noise.join(",");
    // 10,000 rules of 4 inputs: 6 surfaces of 600 x 600 points are 2.16e10 rule evaluations.
    let mut text = String::from(
        "[System]\nName='many'\nType='sugeno'\nNumInputs=4\nNumOutputs=1\nNumRules=10000\n\
         AndMethod='prod'\nOrMethod='max'\nImpMethod='prod'\nAggMethod='sum'\n\
         DefuzzMethod='wtaver'\n\n",
    );
    for i in 1..=4 {
        text += &format!(
            "[Input{i}]\nName='x{i}'\nRange=[-1 1]\nNumMFs=3\nMF1='n':'gaussmf',[0.5 -1]\n\
             MF2='z':'gaussmf',[0.5 0]\nMF3='p':'gaussmf',[0.5 1]\n\n"
        );
    }
    text += "[Output1]\nName='y'\nRange=[-1 1]\nNumMFs=1\nMF1='a':'constant',[1]\n\n[Rules]\n";
    for r in 0..10_000 {
        text += &format!(
            "{} {} {} {}, 1 (1) : 1\n",
            r % 3 + 1,
            r / 3 % 3 + 1,
            r / 9 % 3 + 1,
            2
        );
    }
    let many = dir.join("many.fis");
    std::fs::write(&many, text).unwrap();
    for (args, expected) in [
        (
            vec![
                "fis",
                "surface",
                path(&many),
                "--out",
                path(&out),
                "--resolution",
                "600",
            ],
            "--resolution 600 would evaluate the system's 10000 rules at 6 surfaces of 600 x 600 \
             points, 2.16e10 rule evaluations, more than the 1e10 fis surface may take",
        ),
        (
            vec!["fis", "check", "--samples", "1000000000000", fis],
            "--samples must be at least 2 and at most 1000000, got 1000000000000",
        ),
        (
            vec!["fis", "check", "--samples", "-1", fis],
            "--samples must be at least 2",
        ),
        (
            vec![
                "fis",
                "surface",
                fis,
                "--out",
                path(&out),
                "--resolution",
                "100000",
            ],
            "--resolution must be at least 2 and at most 600",
        ),
        (
            vec![
                "fis",
                "surface",
                fis,
                "--out",
                path(&out),
                "--resolution",
                "-5",
            ],
            "got -5",
        ),
        (
            vec!["sweep", "--seeds", "-1", "--out", path(&out)],
            "--seeds must be at least 1 and at most 1000000, got -1",
        ),
        (
            vec![
                "sweep",
                "--seeds",
                "100000000000000000",
                "--shard",
                "1/2",
                "--out",
                path(&out),
            ],
            "--seeds must be at least 1",
        ),
        (
            vec!["sweep", "--noise", &noise, "--out", path(&out)],
            "--noise lists 1001 levels",
        ),
        (
            vec!["sweep", "--controllers", "pd,fuzzy,pd", "--out", path(&out)],
            "--controllers lists pd twice",
        ),
        (
            vec![
                "sweep",
                "--seeds",
                "1000000",
                "--controllers",
                "fuzzy,pd,computed-torque,fuzzy-gc",
                "--out",
                path(&out),
            ],
            "24000000 runs",
        ),
    ] {
        let line = refused(&hrm(&args));
        assert!(line.contains(expected), "{args:?}: {line}");
    }
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn input_files_are_read_with_a_size_limit() {
    let dir = scratch("errors-file-size");
    // Sparse files: refused by their size before a byte is read.
    let huge = |name: &str, len: u64| {
        let path = dir.join(name);
        std::fs::File::create(&path).unwrap().set_len(len).unwrap();
        path
    };
    let fis = huge("huge.fis", (16 << 20) + 1);
    let line = refused(&hrm(&["fis", "check", path(&fis)]));
    assert!(
        line.contains("16777217 bytes, more than the 16777216 allowed"),
        "{line}"
    );
    let toml = huge("huge.toml", 1 << 40);
    let line = refused(&hrm(&[
        "simulate",
        "--scenario",
        path(&toml),
        "--out",
        path(&dir.join("o")),
    ]));
    assert!(
        line.contains("huge.toml") && line.contains("more than the 16777216"),
        "{line}"
    );
    // Shard files are read a line at a time, each line up to 64 MiB.
    let shard = huge("shard-1-of-1.json", 1 << 40);
    let merge = |shard: &str| {
        refused(&hrm(&[
            "sweep",
            "merge",
            "--out",
            path(&dir.join("o")),
            shard,
        ]))
    };
    let line = merge(path(&shard));
    assert!(
        line.contains("line 1 is longer than the 67108864 bytes a shard file's line may have"),
        "{line}"
    );
    // A device, like a FIFO, is refused before it is opened (issue 32).
    if Path::new("/dev/zero").exists() {
        let line = refused(&hrm(&["fis", "eval", "/dev/zero", "0"]));
        assert!(line.contains("is not a regular file"), "{line}");
        let line = merge("/dev/zero");
        assert!(line.contains("is not a regular file"), "{line}");
    }
    let fifo = dir.join("controller.fis");
    if Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let line = refused(&hrm(&["fis", "check", path(&fifo)]));
        assert!(line.contains("is not a regular file"), "{line}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn control_bytes_from_a_file_are_escaped_in_the_message() {
    let dir = scratch("errors-control-bytes");
    let paper = include_str!("../../../fuzzy-sugeno/data/paper.fis");
    let fis = dir.join("evil.fis");
    std::fs::write(
        &fis,
        paper.replacen("NumMFs=2", "NumMFs=\u{1b}[2J\u{7}\r", 1),
    )
    .unwrap();
    let output = hrm(&["fis", "check", path(&fis)]);
    let line = refused(&output);
    assert!(
        !output.stderr.iter().any(|&b| b < 0x20 && b != b'\n'),
        "{line:?}"
    );
    assert!(line.contains("\\u{1b}[2J\\u{7}"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs `hrm args` with `stdin` as input and its standard output closed as soon as it starts,
/// as `hrm ... | head -0` would.
fn with_reader_gone(args: &[&str], stdin: &[u8]) -> Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let mut input = child.stdin.take().unwrap();
    // The write fails once hrm has stopped reading; that is fine.
    let _ = input.write_all(stdin);
    drop(input);
    child.wait_with_output().unwrap()
}

#[test]
fn output_ends_quietly_when_the_reader_goes_away() {
    let requests = "{\"op\":\"fk\",\"a\":[0.3,-0.2],\"alpha0\":1.2}\n".repeat(2000);
    let dir = scratch("reader-gone");
    let fis = PAPER_FIS;
    let csv = dir.join("train.csv");
    let rows: String = (0..20)
        .map(|i| {
            let (x1, x2) = (f64::from(i) / 19.0, f64::from(i * 7 % 20) / 19.0);
            format!("{x1},{x2},{}\n", x1 * x2)
        })
        .collect();
    std::fs::write(&csv, rows).unwrap();
    let (trained, exported) = (dir.join("t.fis"), dir.join("c"));
    for (args, stdin) in [
        (vec!["eval"], requests.as_bytes()),
        (vec!["fis", "eval", fis, "0.1", "0", "0", "0"], &b""[..]),
        (vec!["fis", "check", fis], &b""[..]),
        (
            vec![
                "fis",
                "train",
                "--data",
                path(&csv),
                "--epochs",
                "30",
                "--out",
                path(&trained),
            ],
            &b""[..],
        ),
        (
            vec![
                "fis",
                "export",
                fis,
                "--format",
                "c",
                "--out",
                path(&exported),
            ],
            &b""[..],
        ),
    ] {
        let output = with_reader_gone(&args, stdin);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
    // The commands went on to the end.
    assert!(trained.is_file() && exported.join("hrm_fis.c").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_merge_into_the_folder_of_its_shards_is_refused() {
    let dir = scratch("errors-merge-into-shards");
    let (scenario, shards) = (short_scenario(&dir), dir.join("shards"));
    let output = hrm(&[
        "sweep",
        "--scenario",
        path(&scenario),
        "--noise",
        "0",
        "--seeds",
        "1",
        "--controllers",
        "pd",
        "--shard",
        "1/1",
        "--out",
        path(&shards),
    ]);
    assert!(output.status.success(), "{output:?}");
    let before = snapshot(&shards);
    let line = refused(&hrm(&[
        "sweep",
        "merge",
        "--out",
        path(&shards),
        path(&shards),
    ]));
    // Refused as a folder of another kind (issue 32), before the merge's own check.
    assert!(
        line.contains("holds the output of `hrm sweep --shard`"),
        "{line}"
    );
    assert_eq!(snapshot(&shards), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 32: SIGINT or SIGTERM mid-run removes the staging folder at once and leaves the earlier
/// output as it was; the exit status is the signal's.
#[test]
fn an_interrupted_command_removes_its_staging_folder() {
    let dir = scratch("errors-signals");
    let out = dir.join("out");
    let scenario = short_scenario(&dir);
    let first = hrm(&[
        "simulate",
        "--scenario",
        path(&scenario),
        "--out",
        path(&out),
    ]);
    assert!(first.status.success(), "{first:?}");
    let before = snapshot(&out);
    for signal in ["INT", "TERM"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_hrm"))
            .args([
                "simulate",
                "--scenario",
                "paper-tracking",
                "--out",
                path(&out),
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Wait for the staging folder, then interrupt the run.
        let staging = dir.join(format!(".out.hrm-staging-{}", child.id()));
        let start = std::time::Instant::now();
        while !staging.exists() && start.elapsed() < std::time::Duration::from_secs(30) {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        assert!(staging.exists(), "no staging folder appeared");
        let sent = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let status = child.wait().unwrap();
        let expected = if signal == "INT" { 130 } else { 143 };
        assert_eq!(status.code(), Some(expected), "{signal}: {status:?}");
        assert!(!staging.exists(), "{signal}: the staging folder is left");
        assert_eq!(snapshot(&out), before, "{signal}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hrm_view_writes_a_page_and_a_gif_and_replaces_only_its_own_files() {
    let dir = scratch("errors-view");
    let run = dir.join("run");
    assert!(
        hrm(&[
            "simulate",
            "--scenario",
            path(&short_scenario(&dir)),
            "--out",
            path(&run)
        ])
        .status
        .success()
    );
    // A folder that is not there, and a file given for one.
    let missing = dir.join("missing");
    let line = refused(&hrm(&["view", path(&missing)]));
    assert_eq!(line, format!("hrm: {}: no such folder", missing.display()));
    let line = refused(&hrm(&["view", path(&run.join("summary.json"))]));
    assert!(line.ends_with("summary.json: not a folder"), "{line}");
    // A GIF's size, rate or speed without --gif is refused by clap, not ignored.
    for option in ["--width", "--height", "--fps", "--speed"] {
        let output = hrm(&["view", path(&run), option, "2"]);
        assert_eq!(output.status.code(), Some(2), "{option}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("required arguments were not provided"),
            "{stderr}"
        );
        assert!(stderr.contains("--gif <GIF>"), "{stderr}");
    }
    assert!(!run.join("view.html").exists());
    // --run chooses among a main job's runs: on one run's folder it is refused, not ignored.
    let line = refused(&hrm(&["view", path(&run), "--run", "paper-tracking/pd"]));
    assert!(
        line.ends_with(&format!(
            "--run paper-tracking/pd: takes a main job's output folder (hrm run); {} is one \
             run's",
            run.display()
        )),
        "{line}"
    );
    let gif = dir.join("run.gif");
    let output = hrm(&[
        "view",
        path(&run),
        "--gif",
        path(&gif),
        "--width",
        "120",
        "--height",
        "90",
    ]);
    assert!(output.status.success(), "{output:?}");
    let page = std::fs::read_to_string(run.join("view.html")).unwrap();
    assert!(page.contains("class=\"hrm-view\"") && page.contains("\"label\":\"fuzzy\""));
    assert_eq!(&std::fs::read(&gif).unwrap()[..6], b"GIF89a");
    // Again: hrm's own files are replaced.
    assert!(
        hrm(&["view", path(&run), "--gif", path(&gif)])
            .status
            .success()
    );
    // A file hrm did not write is never replaced, and then nothing is written.
    let mine = dir.join("mine.html");
    std::fs::write(&mine, "<p>my notes</p>").unwrap();
    std::fs::remove_file(&gif).unwrap();
    let line = refused(&hrm(&[
        "view",
        path(&run),
        "--out",
        path(&mine),
        "--gif",
        path(&gif),
    ]));
    assert!(
        line.contains("mine.html: exists and hrm did not write it"),
        "{line}"
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "<p>my notes</p>");
    assert!(!gif.exists());
    // The GIF aimed at the page (by another path to it, or at a new file): refused, the page
    // kept, nothing new written.
    let page_before = std::fs::read(run.join("view.html")).unwrap();
    let same = run.join(".").join("view.html");
    let line = refused(&hrm(&["view", path(&run), "--gif", path(&same)]));
    assert!(
        line.contains("view.html is the --out file") && line.contains("choose another --gif"),
        "{line}"
    );
    assert_eq!(std::fs::read(run.join("view.html")).unwrap(), page_before);
    let new = dir.join("new.html");
    refused(&hrm(&[
        "view",
        path(&run),
        "--out",
        path(&new),
        "--gif",
        path(
            &dir.join("..")
                .join(dir.file_name().unwrap())
                .join("new.html"),
        ),
    ]));
    assert!(!new.exists());
    // Runs in joint space (a deployment, a URDF arm) are named, not misread as modal runs.
    let joint_space = dir.join("joint-space");
    std::fs::create_dir_all(&joint_space).unwrap();
    std::fs::copy(
        run.join("timeseries.csv"),
        joint_space.join("timeseries.csv"),
    )
    .unwrap();
    let examples = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/urdf-arm");
    std::fs::copy(
        format!("{examples}/arm7.urdf"),
        joint_space.join("arm7.urdf"),
    )
    .unwrap();
    for (scenario, expected) in [
        (
            sim_study::Scenario::builtin("pipe-deploy")
                .unwrap()
                .to_toml(),
            "joint-space: a deployment on an insertion axis ([deploy])",
        ),
        (
            std::fs::read_to_string(format!("{examples}/step.toml")).unwrap(),
            "joint-space: a URDF arm's run in joint space (arm.urdf)",
        ),
    ] {
        std::fs::write(joint_space.join("scenario.toml"), scenario).unwrap();
        let line = refused(&hrm(&["view", path(&joint_space)]));
        assert!(
            line.contains(expected) && line.contains("`hrm view` animates"),
            "{line}"
        );
    }
    // Not a run; a broken time series; bad GIF options.
    let line = refused(&hrm(&["view", path(&dir)]));
    assert!(line.contains("neither an `hrm simulate` output"), "{line}");
    let csv = run.join("timeseries.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    std::fs::write(&csv, text.replacen("\n0,", "\nzero,", 1)).unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(
        line.contains("timeseries.csv: line 2: column t: \"zero\" is not a number"),
        "{line}"
    );
    // A value no run writes (the drawing would overflow), a line longer than the header.
    std::fs::write(&csv, text.replacen("\n0,", "\n1e300,", 1)).unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(
        line.contains("line 2: column t: 1e300 is beyond the 1e15 a run writes"),
        "{line}"
    );
    std::fs::write(
        &csv,
        text.replacen("\n0,", &format!("\n0,{}", "1,".repeat(10_000)), 1),
    )
    .unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(line.contains("line 2: more values than the"), "{line}");
    std::fs::write(&csv, text.replacen("\n0,", "\nNaN,", 1)).unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(
        line.contains("line 2: column t: NaN is not a value a run writes"),
        "{line}"
    );
    // An editor's byte-order mark before the header is no part of the column `t`.
    std::fs::write(&csv, format!("\u{feff}{text}")).unwrap();
    assert!(hrm(&["view", path(&run)]).status.success());
    // A time series that is not a regular file is named as such, not as missing.
    std::fs::remove_file(&csv).unwrap();
    std::fs::create_dir(&csv).unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(
        line.ends_with("timeseries.csv: not a regular file"),
        "{line}"
    );
    std::fs::remove_dir(&csv).unwrap();
    std::fs::write(&csv, text).unwrap();
    // An arm the scenario file cannot have is that file's fault, not the time series'.
    let toml = run.join("scenario.toml");
    let scenario = std::fs::read_to_string(&toml).unwrap();
    let links = scenario.replacen("[arm]\n", "[arm]\nlinks = 100000000\n", 1);
    assert_ne!(links, scenario);
    std::fs::write(&toml, links).unwrap();
    let line = refused(&hrm(&["view", path(&run)]));
    assert!(
        line.contains("scenario.toml: arm.links must be at most"),
        "{line}"
    );
    // A scenario.toml of another arm than the time series' torque columns.
    for links in [3, 11] {
        let other = scenario.replacen("[arm]\n", &format!("[arm]\nlinks = {links}\n"), 1);
        std::fs::write(&toml, other).unwrap();
        let line = refused(&hrm(&["view", path(&run)]));
        assert!(
            line.contains(&format!(
                "10 joint torque columns (joint_tau1, ...) but the arm of scenario.toml has \
                 {links} joints"
            )),
            "{line}"
        );
    }
    std::fs::write(&toml, scenario).unwrap();
    let line = refused(&hrm(&[
        "view",
        path(&run),
        "--gif",
        path(&gif),
        "--fps",
        "0",
    ]));
    assert!(line.contains("gif fps: 0"), "{line}");
    let line = refused(&hrm(&[
        "view",
        path(&run),
        "--gif",
        path(&gif),
        "--speed",
        "nan",
    ]));
    assert!(line.contains("gif speed: NaN"), "{line}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hrm_view_of_a_sweep_runs_the_chosen_runs_again() {
    let dir = scratch("errors-view-sweep");
    // The short step response with its own copy of the paper's fuzzy system.
    let fis = dir.join("mine.fis");
    std::fs::copy(PAPER_FIS, &fis).unwrap();
    let scenario = short_scenario(&dir);
    let text = std::fs::read_to_string(&scenario).unwrap();
    std::fs::write(
        &scenario,
        text.replace(
            "kind = \"fuzzy\"\n",
            "kind = \"fuzzy\"\nfis = \"mine.fis\"\n",
        ),
    )
    .unwrap();
    let sweep = dir.join("sweep");
    let output = hrm(&[
        "sweep",
        "--scenario",
        path(&scenario),
        "--noise",
        "0,0.05",
        "--seeds",
        "2",
        "--controllers",
        "fuzzy,pd",
        "--out",
        path(&sweep),
    ]);
    assert!(output.status.success(), "{output:?}");
    // The list: every run, numbered as in runs.json.
    let output = hrm(&["view", path(&sweep), "--list"]);
    assert!(output.status.success(), "{output:?}");
    let list = String::from_utf8(output.stdout).unwrap();
    let rows: Vec<&str> = list.lines().skip(2).collect();
    assert_eq!(rows.len(), 8, "{list}");
    let words: Vec<&str> = rows[6].split_whitespace().collect();
    assert_eq!(
        words[..7],
        ["6", "0.05", "pd", "1", "tip", "error", "RMS"],
        "{list}"
    );
    assert!(!sweep.join("view.html").exists(), "--list writes nothing");
    // And so it refuses the options of what it would not write.
    let gif = sweep.join("want.gif");
    let output = hrm(&["view", path(&sweep), "--list", "--gif", path(&gif)]);
    assert!(!output.status.success() && !gif.exists(), "{output:?}");
    let said = String::from_utf8_lossy(&output.stderr);
    assert!(
        said.contains("'--list' cannot be used with '--gif"),
        "{said}"
    );
    // By default the first seed of both controllers at both noise levels, run again: their
    // metrics are those the sweep stored, bit for bit (no warning).
    let output = hrm(&["view", path(&sweep)]);
    assert!(output.status.success(), "{output:?}");
    assert!(output.stderr.is_empty(), "{output:?}");
    let page = std::fs::read_to_string(sweep.join("view.html")).unwrap();
    assert_eq!(page.matches("<section class=\"hrm-scene\"").count(), 2);
    assert!(page.contains("at noise level L = 0.05 rad, seed 1"));
    assert!(page.contains("Runs 4 (fuzzy), 6 (pd) of the sweep"));
    // Chosen runs, one scene per noise level and seed.
    let page_b = dir.join("b.html");
    let output = hrm(&[
        "view",
        path(&sweep),
        "--runs",
        "5,1",
        "--out",
        path(&page_b),
    ]);
    assert!(output.status.success(), "{output:?}");
    let page = std::fs::read_to_string(&page_b).unwrap();
    assert_eq!(page.matches("<section class=\"hrm-scene\"").count(), 2);
    assert!(page.contains("L = 0 rad, seed 2") && page.contains("L = 0.05 rad, seed 2"));
    // A stored metric the re-run does not give is reported, and the page still written.
    let runs = sweep.join("runs.json");
    let stored = std::fs::read_to_string(&runs).unwrap();
    let mut lines: Vec<String> = stored.lines().map(String::from).collect();
    let mut run: serde_json::Value = serde_json::from_str(&lines[1]).unwrap();
    let rms = &mut run["outcome"]["completed"]["tip_error_rms_m"];
    *rms = serde_json::json!(rms.as_f64().unwrap() * 0.999);
    lines[1] = run.to_string();
    std::fs::write(&runs, lines.join("\n") + "\n").unwrap();
    let output = hrm(&["view", path(&sweep), "--runs", "0"]);
    assert!(output.status.success(), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.starts_with("warning: run 0 (fuzzy) of ")
            && stderr.contains("did not give the metrics the sweep stored"),
        "{stderr}"
    );
    std::fs::write(&runs, &stored).unwrap();
    // Bounded, checked selections.
    let line = refused(&hrm(&["view", path(&sweep), "--runs", "8"]));
    assert!(
        line.ends_with(
            "--runs 8: the sweep has 8 runs, numbered 0 to 7 (`hrm view DIR --list` lists them)"
        ),
        "{line}"
    );
    let line = refused(&hrm(&["view", path(&sweep), "--runs", "3,3"]));
    assert!(line.ends_with("--runs lists run 3 twice"), "{line}");
    let many = (0..13).map(|i| i.to_string()).collect::<Vec<_>>().join(",");
    let line = refused(&hrm(&["view", path(&sweep), "--runs", &many]));
    assert!(line.contains("more than the 12"), "{line}");
    let line = refused(&hrm(&["view", path(&dir), "--list"]));
    assert!(
        line.contains("--list and --runs take a sweep's output folder"),
        "{line}"
    );
    // The fuzzy system changed since the sweep ran: its runs cannot be run again.
    std::fs::write(&fis, std::fs::read_to_string(&fis).unwrap() + "\n").unwrap();
    let before = std::fs::read(sweep.join("view.html")).unwrap();
    let line = refused(&hrm(&["view", path(&sweep)]));
    assert!(
        line.contains("mine.fis") && line.contains("changed since the sweep ran"),
        "{line}"
    );
    assert_eq!(std::fs::read(sweep.join("view.html")).unwrap(), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A standard error that cannot be written (full, or its reader gone) drops hrm's warnings and
/// error lines: the command ends with its own status, and `hrm eval` answers every request
/// (a warning to a closed pipe made it panic with "failed printing to stderr", exit 101).
#[test]
fn an_unwritable_standard_error_is_no_crash() {
    let paper = PAPER_FIS;
    let full = || std::fs::File::create("/dev/full").unwrap();
    for (args, status) in [
        (vec!["fis", "eval", paper, "0", "0", "0"], 1),
        (vec!["fis", "eval", paper, "9", "0", "0", "0"], 0),
    ] {
        let output = Command::new(env!("CARGO_BIN_EXE_hrm"))
            .args(&args)
            .stderr(full())
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(status), "{args:?}");
    }
    let (reader, writer) = std::io::pipe().unwrap();
    let mut server = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .arg("eval")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(writer)
        .spawn()
        .unwrap();
    drop(reader);
    let requests = "{\"id\":1,\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":[5,0,0,0]}\n\
                    {\"id\":2,\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":[0,0,0,0]}\n";
    std::io::Write::write_all(&mut server.stdin.take().unwrap(), requests.as_bytes()).unwrap();
    let output = server.wait_with_output().unwrap();
    assert!(output.status.success(), "{:?}", output.status);
    let answers = String::from_utf8(output.stdout).unwrap();
    assert_eq!(answers.lines().count(), 2, "{answers}");
}

/// A negative `hrm run --duration` reaches hrm's own check (clap took `-1` for an option).
#[test]
fn a_negative_main_job_duration_is_named() {
    let dir = scratch("errors-run-duration");
    let out = dir.join("out");
    let line = refused(&hrm(&["run", "--duration", "-1", "--out", path(&out)]));
    assert_eq!(
        line,
        "hrm: --duration: -1, expected a finite positive number of seconds"
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Where no rule fires, `hrm fis eval` gives the middle of the output's range and says so on
/// standard error, as MATLAB's evalfis warns; where one fires, nothing is said.
#[test]
fn fis_eval_warns_where_no_rule_fires() {
    let dir = scratch("errors-fis-unfired");
    let file = dir.join("grid.fis");
    // Triangles [-1 0 1] and [0 1 2] on [0, 2]: at 2 neither fires.
    std::fs::write(&file, grid_fis(2)).unwrap();
    let unfired = hrm(&["fis", "eval", path(&file), "2", "2"]);
    assert!(unfired.status.success(), "{unfired:?}");
    assert_eq!(String::from_utf8_lossy(&unfired.stdout), "y = 0.5\n");
    assert_eq!(
        String::from_utf8_lossy(&unfired.stderr),
        "hrm: warning: no rule fired for output 1 ('y') at these inputs: its value is the middle \
         of its range, as MATLAB's evalfis gives\n"
    );
    let fired = hrm(&["fis", "eval", path(&file), "0.5", "0.5"]);
    assert!(
        fired.status.success() && fired.stderr.is_empty(),
        "{fired:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
