//! Process-level fuzzing of every `hrm` subcommand: random and hostile option values, mutated
//! `.fis`, scenario, CSV and shard files (their counts, indices and seeds too), random bytes on
//! standard input, stray arguments; and output folders in every state (files of other kinds,
//! FIFOs, read-only outputs, symbolic links) written by commands interrupted by signals.
//!
//! Properties of every invocation: it ends within [`DEADLINE`]; its exit status is 0, 1 or 2
//! (success, a refusal, a usage error); nothing it prints contains `panicked`; a refusal is
//! exactly one line on standard error, starting with `hrm: `, without raw control bytes or
//! numbers of more than 39 digits.
//!
//! Every generated command is cheap by construction (runs of at most a few hundredths of a
//! second, small grids), so the whole test takes seconds in the dev profile.

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The longest any generated command may take.
const DEADLINE: Duration = Duration::from_secs(60);

/// Values for numeric (and other) options and for numbers inside files.
const HOSTILE: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "-1",
    "-0",
    "0.5",
    "1e12",
    "1000000000000",
    "18446744073709551616",
    "-9223372036854775809",
    "nan",
    "inf",
    "-inf",
    "1e308",
    "-1.7e308",
    "1e-300",
    "",
    "x",
    "\u{1b}[31m",
    "0,0",
    "1/0",
];

/// Stray arguments inserted anywhere in a command line.
const STRAY: &[&str] = &[
    "--seeds",
    "--out",
    "--help",
    "-1",
    "merge",
    "--resolution=3",
    "--frobnicate",
    "\u{7}",
    "--",
];

/// Files shared by every case: the paper's `.fis`, a 10 ms scenario, the shard files of a tiny
/// sweep (whole, and split in two), a small training CSV.
struct Fixture {
    dir: PathBuf,
    fis: String,
    scenario: String,
    shards: [String; 3],
    csv: String,
}

/// The shard files of the fixture's sweep: `(shard, file name)`.
const SHARD_FILES: [(&str, &str); 3] = [
    ("1/1", "shard-1-of-1.json"),
    ("1/2", "shard-1-of-2.json"),
    ("2/2", "shard-2-of-2.json"),
];

const SHORT_SCENARIO: &str = r#"name = "short"
duration = 0.01
alpha0 = 1.5707963267948966
record_period = 0.001

[reference]
kind = "step"
initial = [0.0, 0.0]
target = [0.2, -0.2]
time = 0.002

[controller]
kind = "fuzzy"
period = 0.001

[integrator]
method = "rk4"
dt = 0.0001

[limits]
max_modal_error = 3.0
"#;

fn fixture() -> &'static Fixture {
    static FIXTURE: OnceLock<Fixture> = OnceLock::new();
    FIXTURE.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("hrm-cli-fuzz-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let scenario = dir.join("short.toml");
        std::fs::write(&scenario, SHORT_SCENARIO).unwrap();
        let shards = dir.join("shards");
        for (shard, _) in SHARD_FILES {
            let output = hrm(
                &[
                    "sweep",
                    "--scenario",
                    scenario.to_str().unwrap(),
                    "--noise",
                    "0,0.01",
                    "--seeds",
                    "2",
                    "--controllers",
                    "pd,fuzzy",
                    "--shard",
                    shard,
                    "--out",
                    shards.to_str().unwrap(),
                ],
                b"",
            );
            assert!(output.status.success(), "{output:?}");
        }
        let csv: String = (0..12)
            .map(|i| {
                let (x1, x2) = (i as f64 / 11.0, (i * 7 % 12) as f64 / 11.0);
                format!("{x1},{x2},{}\n", x1 * x2 + 0.5 * x1)
            })
            .collect();
        Fixture {
            fis: std::fs::read_to_string(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../fuzzy-sugeno/data/paper.fis"
            ))
            .unwrap(),
            scenario: SHORT_SCENARIO.to_string(),
            shards: SHARD_FILES
                .map(|(_, name)| std::fs::read_to_string(shards.join(name)).unwrap()),
            csv,
            dir,
        }
    })
}

/// A fresh path in the fixture's folder.
fn fresh(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let k = COUNTER.fetch_add(1, Ordering::Relaxed);
    fixture().dir.join(format!("{k}-{name}"))
}

/// Runs `hrm args` with `stdin`, killing it after [`DEADLINE`].
fn hrm(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hrm starts");
    let mut input = child.stdin.take().unwrap();
    let stdin = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&stdin);
    });
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            panic!("hrm {args:?} ran for more than {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let output = child.wait_with_output().unwrap();
    writer.join().unwrap();
    output
}

/// A mutation of a text file.
#[derive(Debug, Clone)]
enum Mutation {
    /// Replace the `k`-th number (mod their count) by a hostile value.
    Number(usize, &'static str),
    /// Cut the text at a fraction of its length.
    Truncate(f64),
    /// Insert bytes at a fraction of its length.
    Insert(f64, Vec<u8>),
    /// Remove line `k` (mod the line count).
    DropLine(usize),
    /// Repeat line `k` (mod the line count).
    RepeatLine(usize),
    /// Replace the value of the `k`-th occurrence (mod their count) of a JSON key: a shard's
    /// counts, indices and seeds.
    Key(&'static str, usize, &'static str),
}

/// The keys of a shard file whose values a [`Mutation::Key`] replaces.
const SHARD_KEYS: &[&str] = &[
    "index",
    "count",
    "seeds",
    "seed",
    "seed_index",
    "base_seed",
    "noise_level",
    "harmonics",
    "sha256",
    "format",
];

/// Values a [`Mutation::Key`] writes.
const KEY_VALUES: &[&str] = &[
    "0",
    "1",
    "2",
    "3",
    "-1",
    "4294967296",
    "10000000",
    "10000001",
    "18446744073709551615",
    "18446744073709551616",
    "1e300",
    "0.5",
    "null",
    "\"x\"",
    "[]",
    "{}",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => (any::<usize>(), prop::sample::select(HOSTILE)).prop_map(|(k, v)| Mutation::Number(k, v)),
        1 => (0.0..1.0f64).prop_map(Mutation::Truncate),
        1 => ((0.0..1.0f64), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(at, b)| Mutation::Insert(at, b)),
        1 => any::<usize>().prop_map(Mutation::DropLine),
        1 => any::<usize>().prop_map(Mutation::RepeatLine),
        4 => (prop::sample::select(SHARD_KEYS), any::<usize>(), prop::sample::select(KEY_VALUES))
            .prop_map(|(key, k, v)| Mutation::Key(key, k, v)),
    ]
}

/// `text` with `mutations` applied.
fn mutate(text: &str, mutations: &[Mutation]) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    for m in mutations {
        match m {
            Mutation::Number(k, value) => {
                let spans = number_spans(&bytes);
                if !spans.is_empty() {
                    let (start, end) = spans[k % spans.len()];
                    bytes.splice(start..end, value.bytes());
                }
            }
            Mutation::Truncate(at) => bytes.truncate((bytes.len() as f64 * at) as usize),
            Mutation::Insert(at, b) => {
                let at = (bytes.len() as f64 * at) as usize;
                bytes.splice(at..at, b.iter().copied());
            }
            Mutation::DropLine(k) => {
                let mut lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
                let k = k % lines.len();
                lines.remove(k);
                bytes = lines.join(&b'\n');
            }
            Mutation::RepeatLine(k) => {
                let mut lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
                let k = k % lines.len();
                lines.insert(k, lines[k]);
                bytes = lines.join(&b'\n');
            }
            Mutation::Key(key, k, value) => {
                let spans = value_spans(&bytes, key);
                if !spans.is_empty() {
                    let (start, end) = spans[k % spans.len()];
                    bytes.splice(start..end, value.bytes());
                }
            }
        }
    }
    bytes
}

/// The byte ranges of the numbers in `text`.
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit()
            && (i == 0 || !(text[i - 1].is_ascii_alphanumeric() || text[i - 1] == b'_'));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        while i < text.len() && (text[i].is_ascii_digit() || b".eE+-".contains(&text[i])) {
            i += 1;
        }
        spans.push((start, i));
    }
    spans
}

/// The byte ranges of the scalar values (up to the next `,`, `}` or `]`) of the JSON key `key`
/// in `text`.
fn value_spans(text: &[u8], key: &str) -> Vec<(usize, usize)> {
    let pattern = format!("\"{key}\":");
    let pattern = pattern.as_bytes();
    let mut spans = Vec::new();
    for start in 0..text.len().saturating_sub(pattern.len()) {
        if text[start..].starts_with(pattern) {
            let from = start + pattern.len();
            let to = text[from..]
                .iter()
                .position(|b| b",}]\n".contains(b))
                .map_or(text.len(), |p| from + p);
            spans.push((from, to));
        }
    }
    spans
}

/// Writes `bytes` to a fresh file named `name`; returns its path.
fn file(name: &str, bytes: &[u8]) -> String {
    let path = fresh(name);
    std::fs::write(&path, bytes).unwrap();
    path.to_str().unwrap().to_string()
}

/// A file argument: a mutated copy of `text`, or a hostile path.
fn file_arg(name: &'static str, text: &'static str) -> impl Strategy<Value = FileArg> {
    prop_oneof![
        4 => Just(FileArg::Mutated(name, text, Vec::new())),
        6 => prop::collection::vec(mutation(), 1..3).prop_map(move |m| FileArg::Mutated(name, text, m)),
        1 => prop::sample::select(vec!["/dev/zero", "/nonexistent/x", "/", ""]).prop_map(FileArg::Path),
    ]
}

#[derive(Debug, Clone)]
enum FileArg {
    Mutated(&'static str, &'static str, Vec<Mutation>),
    Path(&'static str),
}

impl FileArg {
    fn realise(&self) -> String {
        match self {
            FileArg::Path(p) => p.to_string(),
            FileArg::Mutated(name, which, mutations) => {
                let f = fixture();
                let text = match *which {
                    "fis" => &f.fis,
                    "scenario" => &f.scenario,
                    "csv" => &f.csv,
                    "shard-1-of-2" => &f.shards[1],
                    "shard-2-of-2" => &f.shards[2],
                    _ => &f.shards[0],
                };
                file(name, &mutate(text, mutations))
            }
        }
    }
}

/// An optional `--option value`: mostly one of `values`, sometimes any hostile value.
fn option(
    name: &'static str,
    values: &'static [&'static str],
) -> impl Strategy<Value = Vec<String>> {
    prop::option::of(value(values))
        .prop_map(move |v| v.map_or(Vec::new(), |v| vec![name.to_string(), v.to_string()]))
}

/// One of `values`, or rarely any hostile value.
fn value(values: &'static [&'static str]) -> impl Strategy<Value = &'static str> {
    prop_oneof![
        6 => prop::sample::select(values),
        1 => prop::sample::select(HOSTILE),
    ]
}

/// Where `--out` points: a fresh path, one under a regular file, a regular file, a folder of
/// the user's.
fn outs() -> impl Strategy<Value = &'static str> {
    prop_oneof![
        5 => Just("fresh"),
        1 => Just("blocked"),
        1 => Just("file"),
        1 => Just("foreign"),
    ]
}

/// A command line (and standard input) of one subcommand, before files are written.
#[derive(Debug, Clone)]
struct Case {
    head: Vec<String>,
    files: Vec<(String, FileArg)>,
    tail: Vec<String>,
    out: Option<&'static str>,
    stray: Option<(usize, &'static str)>,
    stdin: Vec<u8>,
}

fn case(
    head: &[&str],
    files: Vec<(&str, FileArg)>,
    tail: Vec<Vec<String>>,
    out: Option<&'static str>,
) -> Case {
    Case {
        head: head.iter().map(|s| s.to_string()).collect(),
        files: files.into_iter().map(|(f, a)| (f.to_string(), a)).collect(),
        tail: tail.concat(),
        out,
        stray: None,
        stdin: Vec::new(),
    }
}

/// A request of every `hrm eval` operation (docs/eval-protocol.md).
const REQUESTS: &str = concat!(
    r#"{"id":1,"op":"fk","a":[0.3,-0.2],"alpha0":1.2}"#,
    "\n",
    r#"{"id":2,"op":"ik","target":[0.3,0.5],"alpha0":1.5707963267948966}"#,
    "\n",
    r#"{"id":3,"op":"joints","arm":{"links":5},"a":[0.1,0.2,0.3]}"#,
    "\n",
    r#"{"id":4,"op":"dynamics","arm":{"links":3,"gravity":9.81},"theta":[0.1,0.2,0.3],"theta_dot":[1,-1,0.5]}"#,
    "\n",
    r#"{"id":5,"op":"reduced","a":[0.4,-0.3],"alpha0":1.2,"a_dot":[0.5,1],"tau_star":[0.3,-0.1]}"#,
    "\n",
);

const DURATIONS: &[&str] = &["0.01", "0.005", "-1", "0", "1e308", "1e-300", "0.0105"];
const SMALL_COUNTS: &[&str] = &["-1", "0", "1", "2", "3", "1000001", "18446744073709551616"];
const RESOLUTIONS: &[&str] = &["-1", "0", "1", "2", "3", "5", "601", "1000000000000"];
const NOISE: &[&str] = &["0", "0,0.01", "0.01,0", "-0.1", "nan", "1e308", "0,0,0"];
const CONTROLLERS: &[&str] = &["pd", "fuzzy,computed-torque", "fuzzy-gc", "pd,pd"];
const SHARDS: &[&str] = &[
    "1/1",
    "1/2",
    "2/2",
    "0/1",
    "2/1",
    "3/3",
    "10000000/10000000",
    "1/10000001",
    "18446744073709551615/18446744073709551615",
    "1/18446744073709551616",
];
const EPOCHS: &[&str] = &["0", "1", "2", "-1", "100001", "18446744073709551616"];
const FRACTIONS: &[&str] = &["0.5", "0.9", "1", "10", "0", "-1", "nan", "1e-300"];
const INPUTS: &[&str] = &[
    "0", "0.1", "-0.3", "1e308", "-1e308", "nan", "inf", "1e-300",
];

fn cases() -> impl Strategy<Value = Case> {
    // The main job always fails at its output folder: a whole run takes minutes.
    let run = prop::sample::select(vec!["blocked", "file", "foreign"])
        .prop_map(|out| case(&["run"], vec![], vec![], Some(out)));
    let simulate = (
        file_arg("scenario.toml", "scenario"),
        option(
            "--controller",
            &["fuzzy", "pd", "computed-torque", "fuzzy-gc"],
        ),
        outs(),
    )
        .prop_map(|(scenario, controller, out)| {
            case(
                &["simulate"],
                vec![("--scenario", scenario)],
                vec![controller],
                Some(out),
            )
        });
    let eval = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..200),
        prop::collection::vec(mutation(), 0..3).prop_map(|m| mutate(REQUESTS, &m)),
    ]
    .prop_map(|bytes| {
        let mut c = case(&["eval"], vec![], vec![], None);
        c.stdin = bytes;
        c
    });
    let fis_check = (
        file_arg("check.fis", "fis"),
        option("--samples", SMALL_COUNTS),
        option("--coverage", FRACTIONS),
        option("--max-jump", FRACTIONS),
    )
        .prop_map(|(fis, samples, coverage, jump)| {
            case(
                &["fis", "check"],
                vec![("", fis)],
                vec![samples, coverage, jump],
                None,
            )
        });
    let fis_eval = (
        file_arg("eval.fis", "fis"),
        prop::collection::vec(value(INPUTS), 3..6),
        option("--out-of-range", &["clamp", "as-given", "error"]),
    )
        .prop_map(|(fis, inputs, policy)| {
            let inputs = inputs.iter().map(|s| s.to_string()).collect();
            case(
                &["fis", "eval"],
                vec![("", fis)],
                vec![inputs, policy],
                None,
            )
        });
    let fis_surface = (
        file_arg("surface.fis", "fis"),
        option("--resolution", RESOLUTIONS),
        option(
            "--reference",
            &["0,0,0,0", "0", "nan,0,0,0", "1e308,-1e308,0,0"],
        ),
        outs(),
    )
        .prop_map(|(fis, resolution, reference, out)| {
            case(
                &["fis", "surface"],
                vec![("", fis)],
                vec![resolution, reference],
                Some(out),
            )
        });
    let sweep = (
        file_arg("sweep.toml", "scenario"),
        value(DURATIONS),
        option("--seeds", SMALL_COUNTS),
        value(NOISE),
        value(CONTROLLERS),
        option("--base-seed", SMALL_COUNTS),
        option("--shard", SHARDS),
        (
            option("--rate-noise-ratio", FRACTIONS),
            option("--reference-noise-ratio", FRACTIONS),
        ),
        outs(),
    )
        .prop_map(
            |(scenario, duration, seeds, noise, controllers, base, shard, ratios, out)| {
                let fixed = vec![
                    "--duration".to_string(),
                    duration.to_string(),
                    "--noise".to_string(),
                    noise.to_string(),
                    "--controllers".to_string(),
                    controllers.to_string(),
                ];
                case(
                    &["sweep"],
                    vec![("--scenario", scenario)],
                    vec![fixed, seeds, base, shard, ratios.0, ratios.1],
                    Some(out),
                )
            },
        );
    let shard_file = prop_oneof![
        file_arg("shard-1-of-1.json", "shard-1-of-1"),
        file_arg("shard-1-of-2.json", "shard-1-of-2"),
        file_arg("shard-2-of-2.json", "shard-2-of-2"),
    ];
    let merge = (prop::collection::vec(shard_file, 1..4), outs()).prop_map(|(shards, out)| {
        let files = shards.into_iter().map(|s| ("", s)).collect();
        case(&["sweep", "merge"], files, vec![], Some(out))
    });
    let fis_train = (
        file_arg("train.csv", "csv"),
        prop::option::of(file_arg("check.csv", "csv")),
        option("--mfs", SMALL_COUNTS),
        option("--mf-type", &["gbellmf", "trimf", "gaussmf", "x"]),
        option("--order", &["0", "1", "2", "-1", "256"]),
        option("--epochs", EPOCHS),
        (
            option("--step", FRACTIONS),
            option("--ridge", FRACTIONS),
            prop::option::weighted(0.2, value(FRACTIONS)),
        ),
    )
        .prop_map(|(data, check, mfs, mf_type, order, epochs, rest)| {
            let (step, ridge, radius) = rest;
            let radius = radius.map_or(Vec::new(), |r| {
                vec!["--cluster-radius".to_string(), r.to_string()]
            });
            let out = vec![
                "--out".to_string(),
                fresh("trained.fis").to_str().unwrap().to_string(),
            ];
            let mut files = vec![("--data", data)];
            files.extend(check.map(|c| ("--check", c)));
            case(
                &["fis", "train"],
                files,
                vec![mfs, mf_type, order, epochs, step, ridge, radius, out],
                None,
            )
        });
    let fis_export = (
        file_arg("export.fis", "fis"),
        value(&["c", "fcl", "x"]),
        option("--prefix", &["hrm_fis", "a-b", "", "9x", "\u{1b}"]),
        option("--out-of-range", &["clamp", "as-given", "error"]),
        option("--no-rule-fired", &["middle", "error"]),
        outs(),
    )
        .prop_map(|(fis, format, prefix, range, no_rule, out)| {
            let format = vec!["--format".to_string(), format.to_string()];
            case(
                &["fis", "export"],
                vec![("", fis)],
                vec![format, prefix, range, no_rule],
                Some(out),
            )
        });
    let stray = prop::option::weighted(0.1, (any::<usize>(), prop::sample::select(STRAY)));
    (
        prop_oneof![
            run,
            simulate,
            eval,
            fis_check,
            fis_eval,
            fis_surface,
            fis_train,
            fis_export,
            sweep,
            merge
        ],
        stray,
    )
        .prop_map(|(mut c, stray)| {
            c.stray = stray;
            c
        })
}

/// The command line of `case`, its files written.
fn realise(case: &Case) -> Vec<String> {
    let mut args = case.head.clone();
    for (flag, file) in &case.files {
        if !flag.is_empty() {
            args.push(flag.clone());
        }
        args.push(file.realise());
    }
    args.extend(case.tail.iter().cloned());
    if let Some(out) = case.out {
        let path = match out {
            "blocked" => PathBuf::from(file("blocker", b"a file")).join("out"),
            "file" => PathBuf::from(file("a-file", b"a file")),
            "foreign" => {
                let dir = fresh("foreign");
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join("keep.txt"), "mine").unwrap();
                dir
            }
            _ => fresh("out"),
        };
        args.push("--out".into());
        args.push(path.to_str().unwrap().into());
    }
    if let Some((at, token)) = case.stray {
        // Never before the subcommand: `hrm <stray>` alone could start the main job.
        let at = case.head.len() + at % (args.len() - case.head.len() + 1);
        args.insert(at, token.to_string());
    }
    args
}

fn check(args: &[String], output: &Output) -> Result<(), TestCaseError> {
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    let code = output.status.code();
    prop_assert!(
        matches!(code, Some(0..=2)),
        "hrm {args:?} exited with {:?}: {stderr}",
        output.status
    );
    prop_assert!(
        !stdout.contains("panicked") && !stderr.contains("panicked"),
        "hrm {args:?} panicked: {stderr}"
    );
    if code == Some(1) {
        let lines: Vec<&str> = stderr.lines().collect();
        prop_assert!(
            lines.len() == 1 && lines[0].starts_with("hrm: "),
            "hrm {args:?}: a refusal is one `hrm: ` line, got {stderr:?}"
        );
        prop_assert!(
            !output.stderr.iter().any(|&b| b < 0x20 && b != b'\n'),
            "hrm {args:?}: raw control bytes in {stderr:?}"
        );
        let longest_number = stderr
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0);
        prop_assert!(
            longest_number <= 39,
            "hrm {args:?}: an unreadable number in {stderr:?}"
        );
    }
    Ok(())
}

/// Cases run by default; `PROPTEST_CASES` overrides it for a longer hunt.
const CASES: u32 = 200;

#[test]
fn no_command_line_crashes_hrm() {
    fixture_is_sound();
    let count = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(CASES);
    let mut runner = TestRunner::new(Config {
        cases: count,
        ..Config::default()
    });
    let result = runner.run(&cases(), |case| {
        let args = realise(&case);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let output = hrm(&refs, &case.stdin);
        check(&args, &output)
    });
    match result {
        // The files of a failing case are kept for a look.
        Ok(()) => std::fs::remove_dir_all(&fixture().dir).unwrap(),
        Err(e) => panic!("{e}"),
    }
}

/// The unmutated files are accepted: the fuzzing starts from working inputs.
fn fixture_is_sound() {
    let f = fixture();
    let fis = file("sound.fis", f.fis.as_bytes());
    let output = hrm(&["fis", "eval", &fis, "0.1", "0", "0", "0"], b"");
    assert!(output.status.success(), "{output:?}");
    let scenario = file("sound.toml", f.scenario.as_bytes());
    let out = fresh("sound-out");
    let output = hrm(
        &[
            "simulate",
            "--scenario",
            &scenario,
            "--out",
            out.to_str().unwrap(),
        ],
        b"",
    );
    assert!(output.status.success(), "{output:?}");
    let whole = file("shard-1-of-1.json", f.shards[0].as_bytes());
    let halves = [1, 2].map(|k| file(SHARD_FILES[k].1, f.shards[k].as_bytes()));
    for shards in [vec![whole], halves.to_vec()] {
        let out = fresh("sound-merge");
        let mut args = vec!["sweep", "merge", "--out", out.to_str().unwrap()];
        args.extend(shards.iter().map(String::as_str));
        let output = hrm(&args, b"");
        assert!(output.status.success(), "{output:?}");
    }
    for key in SHARD_KEYS {
        assert!(
            !value_spans(f.shards[1].as_bytes(), key).is_empty(),
            "{key}"
        );
    }
    assert!(!number_spans(f.shards[0].as_bytes()).is_empty());
    let csv = file("sound.csv", f.csv.as_bytes());
    let trained = fresh("sound.fis");
    let output = hrm(
        &[
            "fis",
            "train",
            "--data",
            &csv,
            "--epochs",
            "2",
            "--out",
            trained.to_str().unwrap(),
        ],
        b"",
    );
    assert!(output.status.success(), "{output:?}");
    assert!(Path::new(&fixture().dir).is_dir());
}

/// What `--out` is before a command writes it.
#[derive(Debug, Clone, Copy)]
enum OutState {
    Missing,
    RegularFile,
    Fifo,
    UserFolder,
    SymlinkToUserFolder,
    ShardFolder,
    ReadOnlyOutput,
    SymlinkToOutput,
    DanglingSymlink,
}

const OUT_STATES: [OutState; 9] = [
    OutState::Missing,
    OutState::RegularFile,
    OutState::Fifo,
    OutState::UserFolder,
    OutState::SymlinkToUserFolder,
    OutState::ShardFolder,
    OutState::ReadOnlyOutput,
    OutState::SymlinkToOutput,
    OutState::DanglingSymlink,
];

/// Puts `out` (in its own parent folder) in `state`; returns the user's paths whose contents
/// no command may change.
fn prepare_out(out: &Path, state: OutState) -> Vec<PathBuf> {
    use std::os::unix::fs::{PermissionsExt, symlink};
    let parent = out.parent().unwrap();
    std::fs::create_dir_all(parent).unwrap();
    let user = parent.join("user");
    let user_folder = || {
        std::fs::create_dir_all(&user).unwrap();
        std::fs::write(user.join("thesis.tex"), "mine").unwrap();
        vec![user.join("thesis.tex")]
    };
    let marked = |dir: &Path, command: &str| {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(
            dir.join(".hrm-output"),
            format!("written by `hrm {command}`\n"),
        )
        .unwrap();
    };
    match state {
        OutState::Missing => Vec::new(),
        OutState::RegularFile => {
            std::fs::write(out, "notes").unwrap();
            vec![out.to_path_buf()]
        }
        OutState::Fifo => {
            let made = Command::new("mkfifo").arg(out).status();
            assert!(made.is_ok_and(|s| s.success()), "mkfifo");
            Vec::new()
        }
        OutState::UserFolder => {
            std::fs::create_dir_all(out).unwrap();
            std::fs::write(out.join("thesis.tex"), "mine").unwrap();
            vec![out.join("thesis.tex")]
        }
        OutState::SymlinkToUserFolder => {
            let kept = user_folder();
            symlink(&user, out).unwrap();
            kept
        }
        OutState::ShardFolder => {
            marked(out, "sweep --shard");
            let shard = out.join("shard-1-of-2.json");
            std::fs::write(&shard, &fixture().shards[1]).unwrap();
            vec![shard]
        }
        OutState::ReadOnlyOutput => {
            marked(out, "simulate");
            std::fs::create_dir_all(out.join("data")).unwrap();
            for dir in [out.join("data"), out.to_path_buf()] {
                std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o555)).unwrap();
            }
            Vec::new()
        }
        OutState::SymlinkToOutput => {
            let target = parent.join("real-output");
            marked(&target, "simulate");
            symlink(&target, out).unwrap();
            Vec::new()
        }
        OutState::DanglingSymlink => {
            symlink(parent.join("nowhere"), out).unwrap();
            Vec::new()
        }
    }
}

/// The contents of `paths` (a FIFO or folder as a marker), to compare before and after.
fn contents(paths: &[PathBuf]) -> Vec<Option<Vec<u8>>> {
    paths.iter().map(|p| std::fs::read(p).ok()).collect()
}

/// Runs `hrm args`, sending `signal` (`INT` or `TERM`) after `delay` if it is still running.
fn hrm_signalled(args: &[&str], signal: Option<(&str, Duration)>) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hrm starts");
    if let Some((name, delay)) = signal {
        std::thread::sleep(delay);
        let _ = Command::new("kill")
            .args([format!("-{name}"), child.id().to_string()])
            .status();
    }
    let pid = child.id();
    let waiter = std::thread::spawn(move || child.wait_with_output().unwrap());
    let start = Instant::now();
    while !waiter.is_finished() {
        if start.elapsed() > DEADLINE {
            let _ = Command::new("kill")
                .args(["-KILL", &pid.to_string()])
                .status();
            panic!("hrm {args:?} ran for more than {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    waiter.join().unwrap()
}

/// Output folders in every state a user or an earlier command leaves them (files of other
/// kinds, FIFOs, read-only outputs, symbolic links), written by `simulate` and `sweep`,
/// sometimes interrupted by SIGINT or SIGTERM mid-run: the user's files never change, no
/// staging folder or temporary file is left, and the command succeeds, refuses in one line or
/// ends with the signal's status.
#[test]
fn output_folders_of_every_kind_and_signals_lose_nothing() {
    // A folder of its own: the other fuzz test removes the fixture's folder when it ends.
    let root = std::env::temp_dir().join(format!("hrm-cli-out-states-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    let scenario_path = root.join("signals.toml");
    std::fs::write(&scenario_path, &fixture().scenario).unwrap();
    let scenario = scenario_path.to_str().unwrap().to_string();
    let counter = AtomicUsize::new(0);
    let strategy = (
        0..OUT_STATES.len(),
        0..2usize,
        prop::option::of((prop::bool::ANY, 0..150u64)),
    );
    let mut runner = TestRunner::new(Config {
        cases: 48,
        ..Config::default()
    });
    let result = runner.run(&strategy, |(state, command, signal)| {
        let state = OUT_STATES[state];
        let parent = root.join(counter.fetch_add(1, Ordering::Relaxed).to_string());
        let out = parent.join("out");
        let kept = prepare_out(&out, state);
        let before = contents(&kept);
        let out_arg = out.to_str().unwrap();
        let args: Vec<&str> = match command {
            0 => vec!["simulate", "--scenario", &scenario, "--out", out_arg],
            _ => vec![
                "sweep",
                "--scenario",
                &scenario,
                "--noise",
                "0,0.01",
                "--seeds",
                "2",
                "--controllers",
                "pd",
                "--out",
                out_arg,
            ],
        };
        let signal =
            signal.map(|(int, ms)| (if int { "INT" } else { "TERM" }, Duration::from_millis(ms)));
        let output = hrm_signalled(&args, signal);
        let code = output.status.code();
        let stderr = String::from_utf8_lossy(&output.stderr);
        let expected: &[i32] = if signal.is_some() {
            &[0, 1, 130, 143]
        } else {
            &[0, 1]
        };
        // A signal that arrives before hrm installs its handler (at once, before anything is
        // written) ends the process by the signal itself.
        let killed_before_handler = {
            use std::os::unix::process::ExitStatusExt;
            signal.is_some() && matches!(output.status.signal(), Some(2 | 15))
        };
        prop_assert!(
            killed_before_handler || code.is_some_and(|c| expected.contains(&c)),
            "{state:?} {args:?} {signal:?}: exit {:?}: {stderr}",
            output.status
        );
        prop_assert!(!stderr.contains("panicked"), "{stderr}");
        if code == Some(1) {
            prop_assert!(
                stderr.lines().count() == 1 && stderr.starts_with("hrm: "),
                "{state:?} {args:?}: {stderr:?}"
            );
        }
        prop_assert_eq!(
            contents(&kept),
            before,
            "{:?} {:?}: user files changed",
            state,
            args
        );
        let leftovers: Vec<String> = std::fs::read_dir(&parent)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".hrm-staging-") || n.contains(".hrm-partial-"))
            .collect();
        prop_assert!(
            leftovers.is_empty(),
            "{state:?} {args:?} {signal:?}: left {leftovers:?}"
        );
        Ok(())
    });
    match result {
        // The folders of a failing case are kept for a look.
        Ok(()) => std::fs::remove_dir_all(&root).unwrap(),
        Err(e) => panic!("{e}"),
    }
}
