//! Files in the styles of MATLAB's older examples, Octave's fuzzy-logic-toolkit and fuzzylite's
//! FIS exporter (`data/interop/*.fis`, written for these tests): each loads, reports what it
//! accepted but ignored, evaluates as MATLAB's formulas say (checked against direct
//! evaluations written out below, independently of the crate's evaluator and of
//! `common::reference_eval`), and survives `read -> write -> read` with every value.

use crate::common::{random_system, reference_eval};
use fuzzy_sugeno::{EvalOptions, Evaluator, FuzzyError, FuzzySystem, NoRuleFired};
use proptest::prelude::*;
use std::f64::consts::PI;

const LEGACY: &str = include_str!("../../data/interop/matlab_legacy.fis");
const OCTAVE: &str = include_str!("../../data/interop/octave_style.fis");
const FUZZYLITE: &str = include_str!("../../data/interop/fuzzylite_export.fis");

/// The 1-based number of the first line of `text` that starts with `needle` (indentation
/// aside).
fn line_of(text: &str, needle: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.trim_start().starts_with(needle))
        .unwrap_or_else(|| panic!("no line contains {needle:?}"))
}

/// `n` evenly spaced points of `[lo, hi]`, both ends included.
fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// Within 1e-12 relative of `expected` (absolute below magnitude 1).
fn assert_close(got: f64, expected: f64, at: &[f64]) {
    assert!(
        (got - expected).abs() <= 1e-12 * expected.abs().max(1.0),
        "at {at:?}: got {got}, expected {expected}"
    );
}

// MATLAB's membership functions, written out from their documented definitions.
fn smf(x: f64, a: f64, b: f64) -> f64 {
    let m = (a + b) / 2.0;
    match x {
        x if x <= a => 0.0,
        x if x <= m => 2.0 * ((x - a) / (b - a)).powi(2),
        x if x <= b => 1.0 - 2.0 * ((b - x) / (b - a)).powi(2),
        _ => 1.0,
    }
}
fn zmf(x: f64, a: f64, b: f64) -> f64 {
    let m = (a + b) / 2.0;
    match x {
        x if x <= a => 1.0,
        x if x <= m => 1.0 - 2.0 * ((x - a) / (b - a)).powi(2),
        x if x <= b => 2.0 * ((b - x) / (b - a)).powi(2),
        _ => 0.0,
    }
}
fn gbellmf(x: f64, a: f64, b: f64, c: f64) -> f64 {
    1.0 / (1.0 + ((x - c) / a).abs().powf(2.0 * b))
}
fn gaussmf(x: f64, sigma: f64, c: f64) -> f64 {
    (-(x - c).powi(2) / (2.0 * sigma * sigma)).exp()
}
fn sigmf(x: f64, a: f64, c: f64) -> f64 {
    1.0 / (1.0 + (-a * (x - c)).exp())
}
fn trimf(x: f64, a: f64, b: f64, c: f64) -> f64 {
    ((x - a) / (b - a)).min((c - x) / (c - b)).max(0.0)
}
fn trapmf(x: f64, a: f64, b: f64, c: f64, d: f64) -> f64 {
    ((x - a) / (b - a)).min(1.0).min((d - x) / (d - c)).max(0.0)
}

/// `matlab_legacy.fis` by hand: min AND, max OR, weighted average; ImpMethod/AggMethod play
/// no part; only the leading parameters of `zmf [-0.8 0.6 0 0]` and `gbellmf [1 2 -2 7]`.
fn legacy_by_hand(angle: f64, rate: f64, load: f64) -> f64 {
    let neg = zmf(angle, -0.8, 0.6);
    let pos = smf(angle, -0.6, 0.8);
    let slow = gbellmf(rate, 1.0, 2.0, -2.0);
    let mid = gaussmf(rate, 0.7, 0.0);
    let fast = gbellmf(rate, 1.0, 2.5, 2.0);
    let push = 2.0 * angle - rate + 0.5 * load - 3.0;
    let pull = -2.0 * angle + rate - 0.25 * load + 3.0;
    let rules = [
        (neg.min(slow), push),
        (0.5 * neg.max(fast), 0.0),
        (pos, pull),
        (0.8 * (1.0 - neg).min(mid), 0.0),
    ];
    let total: f64 = rules.iter().map(|(w, _)| w).sum();
    rules.iter().map(|(w, z)| w * z).sum::<f64>() / total
}

/// `octave_style.fis` by hand: product AND, probabilistic-sum OR, weighted sums per output
/// over the rules that conclude on it (`None` where none of them fires).
fn octave_by_hand(t: f64, h: f64) -> [Option<f64>; 2] {
    let extreme_low = trapmf(t, -1.0, 0.0, 20.0, 40.0);
    let mild = smf(t, 10.0, 40.0) * zmf(t, 60.0, 90.0);
    let left = if t <= 90.0 {
        gaussmf(t, 10.0, 90.0)
    } else {
        1.0
    };
    let right = if t >= 100.0 {
        gaussmf(t, 5.0, 100.0)
    } else {
        1.0
    };
    let extreme_high = left * right;
    let dry = sigmf(h, -12.0, 0.3);
    let ok = (sigmf(h, 15.0, 0.2) - sigmf(h, 15.0, 0.7)).abs();
    let middle = trimf(h, 0.2, 0.5, 0.8);
    let w1 = extreme_low * dry;
    let w2 = mild;
    let w3 = 0.5 * (extreme_high + ok - extreme_high * ok);
    let w4 = (1.0 - mild) * middle;
    let level = 0.2 * t + 30.0 * h + 5.0;
    let heater = w1 * 1.0 + w2 * 0.0 + w3 * 0.0;
    let fan = w1 * level + w2 * 50.0 + w4 * level;
    [
        (w1 + w2 + w3 > 0.0).then_some(heater),
        (w1 + w2 + w4 > 0.0).then_some(fan),
    ]
}

/// `fuzzylite_export.fis` by hand: neighbouring triangles sum to 1 inside (0.25, 0.75), so
/// the output is their convex combination; only DARK fires below 0.25 and only BRIGHT above
/// 0.75; nothing fires at 0 and 1.
fn dimmer_by_hand(x: f64) -> Option<f64> {
    match x {
        x if x <= 0.0 || x >= 1.0 => None,
        x if x <= 0.25 => Some(0.75),
        x if x <= 0.5 => {
            let medium = (x - 0.25) / 0.25;
            Some(0.75 * (1.0 - medium) + 0.5 * medium)
        }
        x if x < 0.75 => {
            let bright = (x - 0.5) / 0.25;
            Some(0.5 * (1.0 - bright) + 0.25 * bright)
        }
        _ => Some(0.25),
    }
}

/// Reads, writes and reads again: the same system, bit-identical outputs at `points`, and a
/// written file with nothing left to note.
fn assert_round_trip(system: &FuzzySystem, points: &[Vec<f64>]) {
    let written = system.to_fis();
    let (read, notes) = FuzzySystem::from_fis_with_notes(&written).unwrap();
    assert_eq!(&read, system, "{written}");
    assert_eq!(read.to_fis(), written);
    assert!(notes.is_empty(), "{notes:?}");
    let n_out = system.outputs().len();
    let (mut a, mut b) = (Evaluator::new(system.clone()), Evaluator::new(read));
    let (mut ya, mut yb) = (vec![0.0; n_out], vec![0.0; n_out]);
    for x in points {
        a.eval(x, &mut ya).unwrap();
        b.eval(x, &mut yb).unwrap();
        assert_eq!(
            ya.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            yb.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn a_legacy_matlab_sugeno_file_evaluates_by_matlabs_formulas() {
    let (system, notes) = FuzzySystem::from_fis_with_notes(LEGACY).unwrap();
    let noted: Vec<usize> = notes.iter().map(|n| n.line).collect();
    assert_eq!(
        noted,
        [
            line_of(LEGACY, "Version=1.0"),
            line_of(LEGACY, "ImpMethod="),
            line_of(LEGACY, "AggMethod="),
            line_of(LEGACY, "MF1='neg'"),
            line_of(LEGACY, "MF1='slow'"),
        ],
        "{notes:#?}"
    );
    assert!(notes[1].message.starts_with("ImpMethod='min' is not used"));
    assert!(notes[3].message.contains("the extra [0 0] ignored"));
    assert!(system.inputs()[2].sets.is_empty());
    let mut evaluator = Evaluator::new(system.clone());
    let mut y = [0.0];
    let mut points = Vec::new();
    assert_eq!(system.inputs()[0].range, [-PI / 4.0, PI / 4.0]);
    assert_eq!(system.outputs()[0].range, [0.0, 0.0]);
    for angle in grid(-PI / 4.0, PI / 4.0, 41) {
        for rate in grid(-2.0, 2.0, 41) {
            for load in [0.0, 3.7, 10.0] {
                let x = [angle, rate, load];
                evaluator.eval(&x, &mut y).unwrap();
                assert_close(y[0], legacy_by_hand(angle, rate, load), &x);
                assert_close(y[0], reference_eval(&system, &x).1[0].unwrap(), &x);
                points.push(x.to_vec());
            }
        }
    }
    assert_round_trip(&system, &points);
}

#[test]
fn an_octave_style_file_evaluates_by_matlabs_formulas() {
    let (system, notes) = FuzzySystem::from_fis_with_notes(OCTAVE).unwrap();
    assert_eq!(notes.len(), 1, "{notes:#?}");
    assert_eq!(notes[0].line, line_of(OCTAVE, "MF2 = 'on'"));
    // Shared names are kept; rules use the indices.
    let temperature = &system.inputs()[0];
    assert_eq!(temperature.sets[0].name, temperature.sets[2].name);
    let mut evaluator = Evaluator::new(system.clone());
    let mut y = [0.0; 2];
    let mut points = Vec::new();
    for t in grid(-1.0, 110.0, 112) {
        for h in grid(0.0, 1.0, 51) {
            let x = [t, h];
            evaluator.eval(&x, &mut y).unwrap();
            let expected = octave_by_hand(t, h);
            let reference = reference_eval(&system, &x).1;
            for (o, output) in system.outputs().iter().enumerate() {
                // MATLAB's default where no rule fires: the middle of the output's range.
                let middle = 0.5 * (output.range[0] + output.range[1]);
                assert_eq!(expected[o].is_none(), reference[o].is_none(), "at {x:?}");
                assert_close(y[o], expected[o].unwrap_or(middle), &x);
                assert_close(y[o], reference[o].unwrap_or(middle), &x);
            }
            points.push(x.to_vec());
        }
    }
    assert_round_trip(&system, &points);
}

#[test]
fn a_fuzzylite_export_loads_and_returns_matlabs_default_where_no_rule_fires() {
    let (system, notes) = FuzzySystem::from_fis_with_notes(FUZZYLITE).unwrap();
    let messages: Vec<String> = notes.iter().map(ToString::to_string).collect();
    // Version, the four empty methods, and six extension keys.
    assert_eq!(messages.len(), 11, "{messages:#?}");
    assert!(messages[1].starts_with("line 8: AndMethod='' is not used by any rule"));
    assert!(messages[5].starts_with("line 16: `Enabled=1` in [Input1] is not a MATLAB key"));
    assert!(
        messages
            .iter()
            .any(|m| m.contains("`Default=nan` in [Output1]"))
    );
    let mut evaluator = Evaluator::new(system.clone());
    let mut y = [0.0];
    let xs = grid(0.0, 1.0, 401);
    for &x in &xs {
        evaluator.eval(&[x], &mut y).unwrap();
        // Where no rule fires, MATLAB's evalfis returns the middle of the output range.
        let expected = dimmer_by_hand(x).unwrap_or(0.5);
        assert_close(y[0], expected, &[x]);
    }
    assert_eq!(reference_eval(&system, &[0.0]).1[0], None);
    // The other policies stay available.
    let refuse = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    let mut strict = Evaluator::with_options(system.clone(), refuse).unwrap();
    assert!(matches!(
        strict.eval(&[1.0], &mut y),
        Err(FuzzyError::NoRuleFired { index: 0, .. })
    ));
    let points: Vec<Vec<f64>> = xs.iter().map(|&x| vec![x]).collect();
    assert_round_trip(&system, &points);
}

#[test]
fn what_is_really_wrong_is_still_refused_with_its_line() {
    let two_inputs = FUZZYLITE
        .replace("NumInputs=1", "NumInputs=2")
        .replace(
            "[Output1]",
            "[Input2]\nName='Motion'\nRange=[0 1]\nNumMFs=1\nMF1='ANY':'trimf',[0 0.5 1]\n\n[Output1]",
        )
        .replace("1.000 , 3.000", "1.000 1.000 , 3.000")
        .replace("2.000 , 2.000", "2.000 0 , 2.000")
        .replace("3.000 , 1.000", "3.000 0 , 1.000");
    // The first rule now combines two inputs with AND, which AndMethod='' cannot do.
    let cases = [
        (
            two_inputs.clone(),
            "line 8: expected AndMethod='prod' or 'min', found AndMethod='' (the rule at line 43 needs it)",
        ),
        (
            FUZZYLITE.replace("2.000 , 2.000", "2.200 , 2.000"),
            "line 38: expected an integer input index, found `2.200` (fuzzylite writes hedges",
        ),
        (
            FUZZYLITE.replace("'trimf',[0.000 0.250 0.500]", "'rampmf',[0 1]"),
            "line 20: rampmf: unknown membership function type",
        ),
        (
            FUZZYLITE.replace("'trimf',[0.000 0.250 0.500]", "'trimf',[0.000 0.250]"),
            "line 20: trimf: expected 3 parameters, got 2",
        ),
        (
            FUZZYLITE.replace("NumMFs=3\nMF1='LOW'", "NumMFs=0\nMF1='LOW'"),
            "line 31: expected NumMFs=<integer >= 1>, found NumMFs=0",
        ),
        (
            LEGACY.replace("2 0 0, 3 (1) : 1", "2 0 1, 3 (1) : 1"),
            "line 50: rule input 'load' has 0 sets, there is no set 1",
        ),
        (
            OCTAVE.replace("Type = 'sugeno'", "Type = 'mamdani'"),
            "line 6: Mamdani systems are not supported",
        ),
        (
            OCTAVE.replace("[-12 0.3]", "[-12 nan]"),
            "line 29: sigmf: parameters must be finite",
        ),
    ];
    for (text, expected) in cases {
        let message = FuzzySystem::from_fis(&text).unwrap_err().to_string();
        assert!(
            message.starts_with(expected),
            "got    {message}\nwanted {expected}"
        );
    }
    // With OrMethod set, the same file is fine once AndMethod is too.
    let fixed = two_inputs.replace("AndMethod=''", "AndMethod='min'");
    assert!(FuzzySystem::from_fis(&fixed).is_ok());
}

#[test]
fn other_spellings_of_the_same_file_give_the_same_system() {
    let legacy = FuzzySystem::from_fis(LEGACY).unwrap();
    let variants = [
        // No Version line, no NumRules line (the [Rules] section has them all).
        LEGACY
            .replace("Version=1.0\n", "")
            .replace("NumRules=4\n", ""),
        // Windows line ends, a byte-order mark, tabs, `#` comments between sections.
        format!(
            "\u{feff}{}",
            LEGACY
                .replace("\n[", "\n# next section\n\t[")
                .replace('\n', "\r\n")
        ),
        // Integer-valued decimals where MATLAB's readfis reads integers.
        LEGACY
            .replace("NumInputs=3", "NumInputs=3.0")
            .replace("NumMFs=2", "NumMFs=2.000")
            .replace(
                "-1 2 0, 2 (0.8) : 1",
                "-1.000 2.000 0.000 , 2.000 (0.800) : 1.000",
            ),
        // Spaces around every separator, commas between numbers.
        LEGACY
            .replace(
                "MF1='push':'linear',[2 -1 0.5 -3]",
                "MF1 = 'push' : 'linear' , [ 2, -1, 0.5, -3 ]",
            )
            .replace("Range=[-2 2]", "Range = [ -2 , 2 ]"),
    ];
    for text in variants {
        assert_eq!(FuzzySystem::from_fis(&text).unwrap(), legacy, "{text}");
    }
}

/// Rewrites a file written by `to_fis` with the habits of real files: comment lines of both
/// kinds, indentation, spaces around `=`, `:` and `,`, no `Version`, `ImpMethod='min'` and
/// `AggMethod='max'`, fuzzylite's extension keys and `1.000` indices, one extra parameter on
/// every function, trailing spaces. Returns the text and the number of notes it must give.
fn with_habits(text: &str) -> (String, usize) {
    let mut out = String::new();
    let mut notes = 2; // ImpMethod and AggMethod
    let (mut in_rules, mut in_system) = (false, false);
    for line in text.lines() {
        if line.starts_with('[') {
            out.push_str("# a comment\n% another\n");
            in_rules = line == "[Rules]";
            in_system = line == "[System]";
            out.push_str(line);
            out.push('\n');
            continue;
        }
        if line.starts_with("Version=") {
            continue;
        }
        let rewritten = if in_rules {
            let spaced = line.replace(',', " , ");
            let tokens: Vec<String> = spaced
                .split_whitespace()
                .map(|t| match t.parse::<i64>() {
                    Ok(k) => format!("{k}.000"),
                    Err(_) => t.to_string(),
                })
                .collect();
            format!("{}   ", tokens.join(" "))
        } else if line.starts_with("MF") {
            notes += 1;
            line.replacen('=', " = ", 1)
                .replace("':'", "' : '")
                .replace("',[", "', [")
                .replace(']', " 0.5]")
        } else {
            line.replacen('=', " = ", 1)
                .replace("ImpMethod = 'prod'", "ImpMethod = 'min'")
                .replace("AggMethod = 'sum'", "AggMethod = 'max'")
        };
        out.push('\t');
        out.push_str(&rewritten);
        out.push('\n');
        if line.starts_with("Name=") && !in_system {
            out.push_str("\tEnabled=1\n  LockRange = 0\n");
            notes += 2;
        }
    }
    (out, notes)
}

proptest! {
    #[test]
    fn the_habits_of_real_files_change_nothing(seed in any::<u64>(), zero_order in any::<bool>()) {
        let system = random_system(seed, zero_order);
        let (text, expected_notes) = with_habits(&system.to_fis());
        let (read, notes) = FuzzySystem::from_fis_with_notes(&text)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&read, &system, "{}", text);
        prop_assert_eq!(notes.len(), expected_notes, "{:#?}\n{}", notes, text);
    }
}
