//! The C export compiled by the system C compiler (`cc`) and run against the Rust evaluator:
//! the paper's controller and random systems covering every membership type, AND/OR method,
//! defuzzifier, negation, "don't care", rule weight and evaluation policy, 10^4 points each
//! group, agreeing to 1e-12 (relative, or absolute below 1), with the same refusals.

use crate::common;

use crate::common::{Rng, random_point, random_system};
use fuzzy_sugeno::{
    EvalOptions, Evaluator, FuzzyError, FuzzySystem, NoRuleFired, OutOfRange, paper_controller,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fuzzy-export-c-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A C literal `scanf("%lf")` reads back exactly.
fn c_number(v: f64) -> String {
    if v.is_nan() {
        "nan".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{v:e}")
    }
}

/// The return code the C function must give for a Rust result.
fn expected_code(result: &Result<(), FuzzyError>) -> i32 {
    match result {
        Ok(()) => 0,
        Err(FuzzyError::NonFiniteInput { .. }) => 1,
        Err(FuzzyError::InputOutOfRange { .. }) => 2,
        Err(FuzzyError::NoRuleFired { .. }) => 3,
        Err(FuzzyError::NonFiniteOutput { .. }) => 4,
        Err(other) => panic!("unexpected evaluator error {other}"),
    }
}

/// Exports every system under prefix `sysK`, compiles them with a harness that evaluates the
/// rows of `points` (system index, then inputs) and returns each row's code and outputs.
fn run_in_c(
    dir: &Path,
    systems: &[(FuzzySystem, EvalOptions)],
    points: &[(usize, Vec<f64>)],
) -> Vec<(i32, Vec<f64>)> {
    let mut harness = String::from("#include <stdio.h>\n");
    let mut sources = Vec::new();
    for (k, (system, options)) in systems.iter().enumerate() {
        let c = system.to_c(&format!("sys{k}"), options).unwrap();
        std::fs::write(dir.join(&c.header_name), &c.header).unwrap();
        std::fs::write(dir.join(&c.source_name), &c.source).unwrap();
        sources.push(dir.join(&c.source_name));
        let _ = writeln!(harness, "#include \"{}\"", c.header_name);
    }
    harness.push_str(
        "int main(int argc, char **argv)\n{\n    FILE *f;\n    int sys, rc, i, n_in, n_out;\n    double in[16], out[16];\n    \
         if (argc != 2 || !(f = fopen(argv[1], \"r\"))) {\n        return 99;\n    }\n    \
         while (fscanf(f, \"%d\", &sys) == 1) {\n        switch (sys) {\n",
    );
    for (k, _) in systems.iter().enumerate() {
        let upper = format!("SYS{k}");
        let _ = writeln!(
            harness,
            "        case {k}: n_in = {upper}_N_INPUTS; n_out = {upper}_N_OUTPUTS; break;"
        );
    }
    harness.push_str(
        "        default: return 98;\n        }\n        for (i = 0; i < n_in; ++i) {\n            \
         if (fscanf(f, \"%lf\", &in[i]) != 1) {\n                return 97;\n            }\n        }\n        \
         for (i = 0; i < n_out; ++i) {\n            out[i] = -12345.0;\n        }\n        switch (sys) {\n",
    );
    for (k, _) in systems.iter().enumerate() {
        let _ = writeln!(
            harness,
            "        case {k}: rc = sys{k}_eval(in, out); break;"
        );
    }
    harness.push_str(
        "        default: return 98;\n        }\n        printf(\"%d\", rc);\n        \
         for (i = 0; i < n_out; ++i) {\n            printf(\" %.17g\", out[i]);\n        }\n        \
         printf(\"\\n\");\n    }\n    fclose(f);\n    return 0;\n}\n",
    );
    std::fs::write(dir.join("harness.c"), harness).unwrap();
    let binary = dir.join("harness");
    let compiled = Command::new("cc")
        .args([
            "-std=c99",
            "-pedantic",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-O2",
            "-o",
        ])
        .arg(&binary)
        .arg(dir.join("harness.c"))
        .args(&sources)
        .arg("-lm")
        .output()
        .expect("the system C compiler `cc` runs");
    assert!(
        compiled.status.success(),
        "cc failed:\n{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let mut input = String::new();
    for (k, x) in points {
        let _ = write!(input, "{k}");
        for v in x {
            let _ = write!(input, " {}", c_number(*v));
        }
        input.push('\n');
    }
    std::fs::write(dir.join("points.txt"), input).unwrap();
    let run = Command::new(&binary)
        .arg(dir.join("points.txt"))
        .output()
        .unwrap();
    assert!(run.status.success(), "harness exit {:?}", run.status);
    String::from_utf8(run.stdout)
        .unwrap()
        .lines()
        .map(|line| {
            let mut fields = line.split(' ');
            let code = fields.next().unwrap().parse().unwrap();
            (code, fields.map(|v| v.parse().unwrap()).collect())
        })
        .collect()
}

fn compare(systems: Vec<(FuzzySystem, EvalOptions)>, points: Vec<(usize, Vec<f64>)>, test: &str) {
    let dir = scratch(test);
    let results = run_in_c(&dir, &systems, &points);
    assert_eq!(results.len(), points.len());
    let mut evaluators: Vec<Evaluator> = systems
        .into_iter()
        .map(|(s, o)| Evaluator::with_options(s, o).unwrap())
        .collect();
    let mut refused = 0;
    for ((k, x), (code, c_out)) in points.iter().zip(&results) {
        let evaluator = &mut evaluators[*k];
        let mut out = vec![-12345.0; evaluator.system().outputs().len()];
        let result = evaluator.eval(x, &mut out);
        assert_eq!(
            *code,
            expected_code(&result),
            "system {k} at {x:?}: {result:?}"
        );
        refused += usize::from(result.is_err());
        for (rust, c) in out.iter().zip(c_out) {
            assert!(
                (rust - c).abs() <= 1e-12 * rust.abs().max(1.0),
                "system {k} at {x:?}: Rust {rust}, C {c}"
            );
        }
    }
    println!("{test}: {} points, {refused} refused by both", points.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_paper_controller_in_c_matches_rust() {
    let mut rng = Rng::new(7);
    let system = paper_controller();
    let points = (0..10_000)
        .map(|_| (0, random_point(&system, &mut rng)))
        .collect();
    compare(vec![(system, EvalOptions::default())], points, "paper");
}

#[test]
fn random_systems_and_policies_in_c_match_rust() {
    let mut rng = Rng::new(11);
    let mut systems = Vec::new();
    for seed in 0..40u64 {
        let out_of_range =
            [OutOfRange::Clamp, OutOfRange::AsGiven, OutOfRange::Error][seed as usize % 3];
        let system = random_system(1000 + seed, seed % 4 == 0);
        let no_rule_fired = match seed % 3 {
            0 => NoRuleFired::MiddleOfRange,
            1 => NoRuleFired::Error,
            _ => NoRuleFired::Values(
                (0..system.outputs().len())
                    .map(|o| o as f64 - 0.5)
                    .collect(),
            ),
        };
        systems.push((
            system,
            EvalOptions {
                out_of_range,
                no_rule_fired,
            },
        ));
    }
    let mut points = Vec::new();
    for _ in 0..10_000 {
        let k = rng.below(systems.len());
        let mut x = random_point(&systems[k].0, &mut rng);
        if rng.chance(0.01) {
            x[0] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][rng.below(3)];
        }
        points.push((k, x));
    }
    compare(systems, points, "random");
}

#[test]
fn the_source_is_self_contained() {
    let c = paper_controller()
        .to_c("hrm_fis", &EvalOptions::default())
        .unwrap();
    assert_eq!(c.header_name, "hrm_fis.h");
    assert!(
        c.header
            .contains("int hrm_fis_eval(const double *in, double *out);")
    );
    let includes: Vec<&str> = c
        .source
        .lines()
        .filter(|l| l.starts_with("#include"))
        .collect();
    assert_eq!(includes, ["#include <math.h>", "#include \"hrm_fis.h\""]);
    for forbidden in ["malloc", "pow(", "static double mu", "static double w"] {
        assert!(!c.source.contains(forbidden), "{forbidden}");
    }
    // No file-scope object: every unindented line is a preprocessor line, a comment, a
    // function signature or a brace.
    for line in c
        .source
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with(' '))
    {
        assert!(
            line.starts_with('#')
                || line.starts_with("/*")
                || line.starts_with(" *")
                || line.ends_with(')')
                || line == "{"
                || line == "}",
            "file-scope line {line:?}"
        );
    }
    // A leading digit, and a leading underscore (`_` would write `__eval`, `_H` `__H`: names C
    // reserves), are refused.
    for prefix in ["9lives", "_", "_x", "__x"] {
        let bad = paper_controller()
            .to_c(prefix, &EvalOptions::default())
            .unwrap_err();
        assert!(
            bad.to_string()
                .starts_with("export: the prefix must be a C identifier"),
            "{prefix}: {bad}"
        );
    }
}

/// An input with no sets and a point output range (both allowed by validation) export and
/// evaluate as in Rust, including where no rule fires (the fallback is the point).
#[test]
fn empty_inputs_and_point_output_ranges_in_c_match_rust() {
    let system = common::relaxed_system();
    let mut rng = Rng::new(5);
    let points = (0..5_000)
        .map(|_| (rng.below(2), random_point(&system, &mut rng)))
        .collect();
    let strict = EvalOptions {
        out_of_range: OutOfRange::Error,
        no_rule_fired: NoRuleFired::Error,
    };
    compare(
        vec![(system.clone(), EvalOptions::default()), (system, strict)],
        points,
        "relaxed",
    );
}

/// A system without rules exports, and in C as in Rust no rule fires: the fallback everywhere.
#[test]
fn a_system_without_rules_in_c_matches_rust() {
    let system = common::without_rules();
    let points = (0..=10).map(|k| (0, vec![k as f64 / 10.0])).collect();
    let strict = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    compare(
        vec![(system.clone(), EvalOptions::default()), (system, strict)],
        points,
        "no-rules",
    );
}

/// A system whose degrees are all constants reads no input: its C still compiles under
/// `-Werror` (the inputs array was set and unused) and matches Rust.
#[test]
fn a_system_that_reads_no_input_in_c_matches_rust() {
    let text = "[System]\nName='u'\nType='sugeno'\nNumInputs=1\nNumOutputs=1\nNumRules=1\n\
                AndMethod='prod'\nOrMethod='probor'\nDefuzzMethod='wtaver'\n\n[Input1]\n\
                Name='x'\nRange=[-1 1]\nNumMFs=1\nMF1='always':'constant',[0.5]\n\n\
                [Output1]\nName='y'\nRange=[-5 5]\nNumMFs=1\nMF1='k':'constant',[2]\n\n\
                [Rules]\n1, 1 (1) : 1\n";
    let system = FuzzySystem::from_fis(text).unwrap();
    let points = (0..=4).map(|k| (0, vec![k as f64 / 2.0 - 1.0])).collect();
    compare(
        vec![(system, EvalOptions::default())],
        points,
        "constant-degrees",
    );
}

/// Names with zero-width and bidirectional formatting characters (a right-to-left override
/// would make the source read otherwise than it compiles) are written escaped in the export's
/// comments, so that the compiler, warning on such characters under `-Werror`, takes it; a
/// prefix naming a C standard header, in any case, is refused.
#[test]
fn hostile_names_are_escaped_and_standard_header_prefixes_refused() {
    let text = include_str!("../../data/paper.fis")
        .replacen("Name='da1'", "Name='da1 \u{202e}ltr'", 1)
        .replacen("[System]\nName='", "[System]\nName='\u{200f}*/ /*", 1);
    let system = FuzzySystem::from_fis(&text).unwrap();
    let c = system.to_c("hostile", &EvalOptions::default()).unwrap();
    for text in [&c.header, &c.source] {
        assert!(!text.contains(['\u{202e}', '\u{200f}']));
    }
    assert!(c.header.contains("da1 \\u{202e}ltr"), "{}", c.header);
    assert!(c.source.contains("'\\u{200f}* / / *"), "{}", c.source);
    let mut rng = Rng::new(3);
    let points = (0..100)
        .map(|_| (0, random_point(&system, &mut rng)))
        .collect();
    compare(vec![(system, EvalOptions::default())], points, "hostile");
    for prefix in ["math", "Math", "stdio", "STDINT", "string"] {
        let err = paper_controller()
            .to_c(prefix, &EvalOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&format!(
                "export: the prefix {prefix:?} would write {prefix}.h"
            )),
            "{err}"
        );
    }
    paper_controller()
        .to_c("mathematics", &EvalOptions::default())
        .unwrap();
}
