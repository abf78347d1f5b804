//! FCL against the real fuzzylite 6 program (Debian's `fuzzylite`): every FCL this crate writes
//! is read by fuzzylite and evaluates as this crate does to 1e-9 (fuzzylite's `-decimals 12`
//! output), for the paper's controller, random zero- and first-order systems and a system
//! learned by ANFIS; and the FCL fuzzylite writes from the MATLAB examples this crate reads
//! loads back as the same system. Skipped when `fuzzylite` is missing, unless
//! `HRM_REQUIRE_ENGINES=1`.

use crate::common::{Rng, random_point, random_system, reference_eval};
use crate::fcl::{has_step, with_identifiers};
use fuzzy_sugeno::learn::{AnfisOptions, GridPartition, TrainingData, anfis, genfis_grid};
use fuzzy_sugeno::{EvalOptions, Evaluator, FuzzySystem, OutOfRange, paper_controller};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A scratch directory of its own (tests run in parallel), removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let k = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("hrm-fuzzylite-{}-{name}-{k}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs fuzzylite with `args`; panics with its output when it reports an error (fuzzylite
/// exits 0 after `[syntax error]` and `[import error]`, so standard error is what tells).
fn run(fuzzylite: &Path, args: &[&str]) {
    let out = Command::new(fuzzylite).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && !stderr.contains("error") && !stdout.contains("error"),
        "fuzzylite {args:?} failed:\n{stdout}\n{stderr}"
    );
}

/// fuzzylite's outputs at `points` for the FCL `text`, read from its `-of fld` table.
fn fuzzylite_eval(fuzzylite: &Path, text: &str, points: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let dir = Scratch::new("eval");
    let (fcl, input, output) = (
        dir.0.join("system.fcl"),
        dir.0.join("in.fld"),
        dir.0.join("out.fld"),
    );
    std::fs::write(&fcl, text).unwrap();
    let rows: Vec<String> = points
        .iter()
        .map(|x| {
            x.iter()
                .map(|v| format!("{v:?}"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect();
    std::fs::write(&input, rows.join("\n") + "\n").unwrap();
    let path = |p: &PathBuf| p.to_str().unwrap().to_string();
    run(
        fuzzylite,
        &[
            "-i",
            &path(&fcl),
            "-if",
            "fcl",
            "-of",
            "fld",
            "-d",
            &path(&input),
            "-decimals",
            "12",
            "-dheader",
            "false",
            "-dinputs",
            "false",
            "-o",
            &path(&output),
        ],
    );
    std::fs::read_to_string(&output)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Writes `system` as FCL, has fuzzylite evaluate it at `points` and compares with this
/// crate's evaluation of the inputs as given (fuzzylite, like MATLAB, does not clamp them).
fn agrees_with_fuzzylite(fuzzylite: &Path, system: &FuzzySystem, points: &[Vec<f64>]) {
    let text = system.to_fcl().unwrap();
    let theirs = fuzzylite_eval(fuzzylite, &text, points);
    assert_eq!(theirs.len(), points.len(), "{text}");
    let options = EvalOptions {
        out_of_range: OutOfRange::AsGiven,
        ..EvalOptions::default()
    };
    let mut evaluator = Evaluator::with_options(system.clone(), options).unwrap();
    let mut ours = vec![0.0; system.outputs().len()];
    for (x, theirs) in points.iter().zip(&theirs) {
        evaluator.eval(x, &mut ours).unwrap();
        assert_eq!(theirs.len(), ours.len());
        for (a, b) in ours.iter().zip(theirs) {
            assert!(
                (a - b).abs() <= 1e-9 * (1.0 + a.abs()),
                "at {x:?}: hrm {ours:?}, fuzzylite {theirs:?}\n{text}"
            );
        }
    }
}

fn points(system: &FuzzySystem, seed: u64, n: usize) -> Vec<Vec<f64>> {
    let mut rng = Rng::new(seed);
    (0..n).map(|_| random_point(system, &mut rng)).collect()
}

#[test]
fn fuzzylite_evaluates_the_paper_controller_as_hrm_does() {
    let Some(fuzzylite) = test_support::engine::program("fuzzylite", "fuzzylite") else {
        return;
    };
    let system = paper_controller();
    let mut at = points(&system, 1, 200);
    // The point and MATLAB's out-of-range point.
    at.push(vec![0.1, 0.05, -0.2, 0.3]);
    at.push(vec![-0.414, -0.263, 0.904, 0.246]);
    agrees_with_fuzzylite(&fuzzylite, &system, &at);
}

#[test]
fn fuzzylite_evaluates_random_systems_as_hrm_does() {
    let Some(fuzzylite) = test_support::engine::program("fuzzylite", "fuzzylite") else {
        return;
    };
    let mut tested = 0;
    for seed in 0..40 {
        let system = with_identifiers(&random_system(seed, seed % 2 == 0));
        // MATLAB's steps are refused by the writer (tests/it/fcl.rs).
        if has_step(&system) {
            continue;
        }
        // fuzzylite skips a rule whose strength is within its tolerance (1e-6) of zero,
        // which moves the output by up to that much: points where a rule fires that weakly
        // are left out.
        let at: Vec<Vec<f64>> = points(&system, seed, 60)
            .into_iter()
            .map(|x| {
                x.iter()
                    .zip(system.inputs())
                    .map(|(v, input)| v.clamp(input.range[0], input.range[1]))
                    .collect::<Vec<f64>>()
            })
            .filter(|x| {
                reference_eval(&system, x)
                    .0
                    .iter()
                    .all(|&w| w == 0.0 || w > 1e-5)
            })
            .collect();
        if at.len() < 10 {
            continue;
        }
        agrees_with_fuzzylite(&fuzzylite, &system, &at);
        tested += 1;
    }
    assert!(tested >= 20, "{tested} systems without steps");
}

#[test]
fn fuzzylite_evaluates_a_learned_system_as_hrm_does() {
    let Some(fuzzylite) = test_support::engine::program("fuzzylite", "fuzzylite") else {
        return;
    };
    // y = sin(x1) cos(x2) on a 9 x 9 grid, a first-order system of 3 x 3 bell rules trained
    // by ANFIS.
    let mut values = Vec::new();
    for i in 0..9 {
        for j in 0..9 {
            let (x1, x2) = (-1.5 + 0.375 * i as f64, -1.5 + 0.375 * j as f64);
            values.extend([x1, x2, x1.sin() * x2.cos()]);
        }
    }
    let data = TrainingData::new(2, 1, values).unwrap();
    let grid = GridPartition {
        sets_per_input: 3,
        ..GridPartition::default()
    };
    let initial = genfis_grid(&data, 0, &grid).unwrap();
    let options = AnfisOptions {
        epochs: 10,
        ..AnfisOptions::default()
    };
    let trained = anfis(initial.clone(), &data, None, 0, &options)
        .unwrap()
        .system;
    assert_ne!(trained, initial);
    agrees_with_fuzzylite(&fuzzylite, &trained, &points(&trained, 5, 200));
}

/// The system with each set and term named by its variable and position where two of a
/// variable's share a name (a `.fis` file allows it; FCL rules name terms, so neither hrm's nor
/// fuzzylite's FCL can carry it, and hrm's writer refuses it).
fn distinct_names(system: &FuzzySystem) -> FuzzySystem {
    let rename = |names: Vec<String>| {
        let shared = names
            .iter()
            .enumerate()
            .any(|(k, n)| names[..k].contains(n));
        names
            .into_iter()
            .enumerate()
            .map(|(k, n)| if shared { format!("{n}{k}") } else { n })
            .collect::<Vec<_>>()
    };
    let methods = system.methods();
    let mut builder = FuzzySystem::builder(system.name())
        .and_method(methods.and)
        .or_method(methods.or)
        .defuzzification(methods.defuzzification);
    for input in system.inputs() {
        let names = rename(input.sets.iter().map(|s| s.name.clone()).collect());
        let sets = names
            .into_iter()
            .zip(input.sets.iter().map(|s| s.membership));
        builder = builder.input(input.name.clone(), input.range, sets);
    }
    for output in system.outputs() {
        let names = rename(output.terms.iter().map(|t| t.name.clone()).collect());
        let terms = names
            .into_iter()
            .zip(output.terms.iter().map(|t| t.function.clone()));
        builder = builder.output(output.name.clone(), output.range, terms);
    }
    for rule in system.rules() {
        builder = builder.indexed_rule(rule.clone());
    }
    builder.build().unwrap()
}

#[test]
fn fcl_fuzzylite_writes_from_the_matlab_examples_loads_back() {
    let Some(fuzzylite) = test_support::engine::program("fuzzylite", "fuzzylite") else {
        return;
    };
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let mut files = vec![data.join("paper.fis")];
    let mut interop: Vec<PathBuf> = std::fs::read_dir(data.join("interop"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fis"))
        .collect();
    interop.sort();
    files.extend(interop);
    let dir = Scratch::new("examples");
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let system = distinct_names(&FuzzySystem::from_fis(&text).unwrap());
        // The file as MATLAB writes it (the interop examples hold habits of other writers that
        // fuzzylite's reader does not take: `-pi/4`, `[ -1 , 110 ]`, `LockRange`).
        let fis = dir.0.join("example.fis");
        std::fs::write(&fis, system.to_fis()).unwrap();
        let fcl = dir.0.join("example.fcl");
        let path = |p: &PathBuf| p.to_str().unwrap().to_string();
        run(
            &fuzzylite,
            &[
                "-i",
                &path(&fis),
                "-if",
                "fis",
                "-of",
                "fcl",
                "-decimals",
                "17",
                "-o",
                &path(&fcl),
            ],
        );
        let written = std::fs::read_to_string(&fcl).unwrap();
        let read = FuzzySystem::from_fcl(&written)
            .unwrap_or_else(|e| panic!("{}: {e}\n{written}", file.display()));
        // Names and structure exactly; numbers to fuzzylite's 17 decimals.
        let mut a = Evaluator::new(system.clone());
        let mut b = Evaluator::new(read.clone());
        assert_eq!(read.rules(), system.rules(), "{}", file.display());
        assert_eq!(read.inputs().len(), system.inputs().len());
        let (mut ya, mut yb) = (
            vec![0.0; system.outputs().len()],
            vec![0.0; system.outputs().len()],
        );
        for x in points(&system, 9, 100) {
            a.eval(&x, &mut ya).unwrap();
            b.eval(&x, &mut yb).unwrap();
            for (p, q) in ya.iter().zip(&yb) {
                assert!(
                    (p - q).abs() <= 1e-9 * (1.0 + p.abs()),
                    "{}: {x:?}",
                    file.display()
                );
            }
        }
    }
}
