//! The paper's runs must not move: every figure of the `paper-*` scenario summaries, with every
//! controller, pinned to 1e-9 relative against the numbers measured before the loop was
//! generalised to any number of modal coordinates (issue 10), stored in
//! `tests/it/data/paper_summaries.json`.

use serde_json::Value;
use sim_study::{ControllerKind, Scenario};

/// Relative tolerance of every pinned number.
const TOLERANCE: f64 = 1e-9;

/// Checks that every field of `expected` is in `actual` with the same value (numbers to
/// [`TOLERANCE`] relative, integers exactly); `path` names the field in failures.
fn assert_matches(expected: &Value, actual: &Value, path: &str) {
    match (expected, actual) {
        (Value::Object(e), Value::Object(a)) => {
            for (key, value) in e {
                let Some(other) = a.get(key) else {
                    panic!("{path}.{key} is missing from {actual}");
                };
                assert_matches(value, other, &format!("{path}.{key}"));
            }
        }
        (Value::Array(e), Value::Array(a)) => {
            assert_eq!(e.len(), a.len(), "{path}: {expected} vs {actual}");
            for (k, (x, y)) in e.iter().zip(a).enumerate() {
                assert_matches(x, y, &format!("{path}[{k}]"));
            }
        }
        (Value::Number(e), Value::Number(a)) if e.is_f64() || a.is_f64() => {
            let (e, a) = (e.as_f64().unwrap(), a.as_f64().unwrap());
            assert!(
                (e - a).abs() <= TOLERANCE * e.abs().max(a.abs()),
                "{path}: pinned {e:e}, now {a:e}"
            );
        }
        _ => assert_eq!(expected, actual, "{path}"),
    }
}

#[test]
fn every_paper_summary_is_unchanged() {
    let pinned: Value =
        serde_json::from_str(include_str!("data/paper_summaries.json")).expect("pinned JSON");
    let pinned = pinned.as_array().expect("a list of runs");
    // The paper's four experiments with the four controllers of the paper's comparison; the
    // controllers and scenarios added since (LQR, MPC, `paper-tracking-fast`) are not pinned.
    let names = [
        "paper-tracking",
        "paper-responses-step",
        "paper-responses-sine",
        "paper-responses-noise",
    ];
    let kinds = [
        ControllerKind::Fuzzy,
        ControllerKind::Pd,
        ControllerKind::ComputedTorque,
        ControllerKind::FuzzyGc,
    ];
    assert_eq!(pinned.len(), names.len() * kinds.len());
    let mut k = 0;
    for name in names {
        for kind in kinds {
            let entry = &pinned[k];
            k += 1;
            assert_eq!(entry["scenario"], name);
            assert_eq!(entry["controller"], kind.name());
            let mut scenario = Scenario::builtin(name).unwrap();
            scenario.controller.kind = kind;
            let run = scenario.build().unwrap().run().unwrap();
            let summary = serde_json::to_value(&run.summary).unwrap();
            assert_matches(&entry["summary"], &summary, &format!("{name}/{kind}"));
        }
    }
}
