//! Fuzzing the `.fis` reader: arbitrary text and mutations of the shipped `data/paper.fis`
//! (lines deleted, duplicated, swapped or replaced, numbers turned into `nan`, `inf`, huge or
//! negative values, wrong counts, out-of-range rule indices, unknown function types).
//!
//! Whatever the text, `from_fis` must not panic; it either refuses with a message that names a
//! line, or returns a system that writes and reads back to an equal system and that evaluates
//! over its input ranges to finite outputs (or, when parameters near `f64::MAX` overflow, to
//! the evaluator's clear "came out non-finite" error, never to a NaN).

use fuzzy_sugeno::{Evaluator, FuzzySystem};
use proptest::prelude::*;

const PAPER_FIS: &str = include_str!("../../data/paper.fis");

/// Numbers a mutation may put in place of any number of the file.
const NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "Inf",
    "1e308",
    "-1e308",
    "1e400",
    "-1e400",
    "1e-320",
    "0",
    "-0",
    "-1",
    "-5",
    "0.5",
    "2",
    "3",
    "17",
    "1000000000000",
    "99999999999999999999",
    "18446744073709551616",
    "9223372036854775808",
    "-9223372036854775808",
    "x",
    "",
    "1.000",
    "2.5",
];

/// Whole lines a mutation may insert or put in place of another.
const LINES: &[&str] = &[
    "",
    "%comment",
    "[",
    "]",
    "[]",
    "=",
    "garbage=",
    "[System]",
    "[Rules]",
    "[Input0]",
    "[Input3]",
    "[Input9]",
    "[Output0]",
    "[Output3]",
    "[Input18446744073709551616]",
    "NumInputs=1000000000000",
    "NumInputs=18446744073709551615",
    "NumOutputs=1000000000000",
    "NumRules=0",
    "NumRules=1000000000000",
    "NumMFs=1000000000000",
    "NumMFs=18446744073709551615",
    "NumMFs=0",
    "Type='mamdani'",
    "Type='sugeno",
    "Name=''",
    "Name='a'b'",
    "Name='da1'",
    "Range=[1 -1]",
    "Range=[nan 1]",
    "Range=[0 1e308]",
    "Range=[-1e308 1e308]",
    "Range=[0]",
    "Range=[]",
    "MF1='X':'unknownmf',[1 2 3]",
    "# comment",
    "Enabled=1",
    "LockRange = 0",
    "AndMethod=''",
    "OrMethod=''",
    "ImpMethod='min'",
    "AggMethod=''",
    "MF1='X':'pimf',[1 2 3 4]",
    "MF2='X':'smf',[2 1]",
    "MF1 = 'X' : 'gbellmf', [1 2 3 4]",
    "1.000 1.000 0 0, 1.000 0 (1.000) : 2.000",
    "MF3='Z':'trimf',[0 0 0]",
    "MF1='N':'gbellmf',[0 2 -0.3]",
    "MF1='N':'gbellmf',[1e308 1e308 1e308]",
    "MF2='P':'gbellmf',[1e-320 0.5 0]",
    "MF1='N':'gaussmf',[0 0]",
    "MF1='N':'gaussmf',[1e308 -1e308]",
    "MF1='N':'sigmf',[1e308 0]",
    "MF1='N':'trapmf',[1 0 0 1]",
    "MF2='P':'trimf',[-1e308 0 1e308]",
    "MF1='VN':'constant',[1e308]",
    "MF4='VP':'linear',[1e308 1e308 1e308 1e308 1e308]",
    "MF1='VN':'constant',[]",
    "MF1='VN':'constant'",
    "MF1=",
    "MF0='A':'constant',[1]",
    "MF18446744073709551616='A':'constant',[1]",
    "1 1 1 1, 9 9 (1) : 1",
    "-1 -2 0 0, 1 1 (nan) : 2",
    "1, 1 ) (1 : 1",
    "1 1 1 1, 1 1 ) (1 : 1",
    "1 1 1 1, 1 1 ) : 1 (1)",
    "1 1 1 1, 1 1 (1) : 3",
    "1 1 1 1, -1 1 (1) : 1",
    "0 0 0 0, 1 1 (0) : 1",
    "0 0 0 0, 0 0 (1) : 1",
    "1 1 1 1, 1 1 (inf) : 1",
    "1 1 1 1, 1 1 (-1) : 1",
    "-9223372036854775808 1 1 1, 1 1 (1) : 1",
    "9223372036854775807 1 1 1, 1 1 (1) : 1",
    "1 1 1 1, 1 1 (1)",
    "1 1 1 1 1 1 (1) : 1",
];

/// One edit of the file's lines; indices are reduced modulo the current line count.
#[derive(Debug, Clone)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    Replace(usize, &'static str),
    Insert(usize, &'static str),
    /// Replaces the `k`-th number of a line (modulo the count of numbers in it).
    Number(usize, usize, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let index = any::<usize>();
    prop_oneof![
        index.prop_map(Mutation::Delete),
        index.prop_map(Mutation::Duplicate),
        (index, index).prop_map(|(i, j)| Mutation::Swap(i, j)),
        (index, prop::sample::select(LINES)).prop_map(|(i, l)| Mutation::Replace(i, l)),
        (index, prop::sample::select(LINES)).prop_map(|(i, l)| Mutation::Insert(i, l)),
        (index, index, prop::sample::select(NUMBERS))
            .prop_map(|(i, k, n)| Mutation::Number(i, k, n)),
        (index, index, prop::sample::select(NUMBERS))
            .prop_map(|(i, k, n)| Mutation::Number(i, k, n)),
        (index, index, prop::sample::select(NUMBERS))
            .prop_map(|(i, k, n)| Mutation::Number(i, k, n)),
    ]
}

/// The byte ranges of the numbers (digits with sign, point and exponent) in `line`.
fn number_spans(line: &str) -> Vec<(usize, usize)> {
    let bytes = line.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let mut start = i;
            if start > 0 && matches!(bytes[start - 1], b'-' | b'.') {
                start -= 1;
            }
            let mut end = i;
            while end < bytes.len()
                && (bytes[end].is_ascii_digit()
                    || matches!(bytes[end], b'.' | b'e' | b'E')
                    || (matches!(bytes[end], b'-' | b'+') && matches!(bytes[end - 1], b'e' | b'E')))
            {
                end += 1;
            }
            spans.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

fn mutate(text: &str, mutations: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for m in mutations {
        let n = lines.len().max(1);
        match *m {
            Mutation::Delete(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Mutation::Duplicate(i) if !lines.is_empty() => {
                let line = lines[i % n].clone();
                lines.insert(i % n, line);
            }
            Mutation::Swap(i, j) if !lines.is_empty() => lines.swap(i % n, j % n),
            Mutation::Replace(i, line) if !lines.is_empty() => lines[i % n] = line.to_string(),
            Mutation::Insert(i, line) => lines.insert(i % (lines.len() + 1), line.to_string()),
            Mutation::Number(i, k, number) if !lines.is_empty() => {
                let line = &mut lines[i % n];
                let spans = number_spans(line);
                if !spans.is_empty() {
                    let (start, end) = spans[k % spans.len()];
                    line.replace_range(start..end, number);
                }
            }
            _ => {}
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// The property: refused with a message naming a line, or a sound, round-tripping system.
fn check(text: &str) -> Result<(), TestCaseError> {
    let system = match FuzzySystem::from_fis(text) {
        Err(error) => {
            let message = error.to_string();
            prop_assert!(
                message.starts_with("line ") && message.len() > 10,
                "unhelpful error `{}` for\n{}",
                message,
                text
            );
            return Ok(());
        }
        Ok(system) => system,
    };
    let written = system.to_fis();
    let read = FuzzySystem::from_fis(&written).map_err(|e| {
        TestCaseError::fail(format!("written system does not read back: {e}\n{written}"))
    })?;
    prop_assert_eq!(&read, &system, "round trip changed the system\n{}", written);
    let ranges: Vec<[f64; 2]> = system.inputs().iter().map(|v| v.range).collect();
    let mut evaluator = Evaluator::new(system);
    let mut outputs = vec![0.0; evaluator.system().outputs().len()];
    // The corners and centre of the input box, and points along its diagonals.
    let corners = 1usize << ranges.len().min(6);
    let fractions = [0.0, 1.0, 0.5, 0.25, 0.9, 1e-9, 1.0 - 1e-9];
    for corner in 0..corners {
        for f in fractions {
            let x: Vec<f64> = ranges
                .iter()
                .enumerate()
                .map(|(i, &[lo, hi])| {
                    let t = if corner >> (i % 6) & 1 == 1 {
                        1.0 - f
                    } else {
                        f
                    };
                    (lo * (1.0 - t) + hi * t).clamp(lo, hi)
                })
                .collect();
            // Parameters near f64::MAX may overflow inside the ranges (1e308 * x): the
            // evaluator then refuses with a clear error instead of answering NaN or infinity.
            if let Err(e) = evaluator.eval(&x, &mut outputs) {
                prop_assert!(
                    e.to_string().contains("came out non-finite"),
                    "eval at {:?} failed: {}\n{}",
                    x,
                    e,
                    text
                );
                continue;
            }
            prop_assert!(
                outputs.iter().all(|y| y.is_finite()),
                "non-finite outputs {:?} at {:?}\n{}",
                outputs,
                x,
                text
            );
        }
    }
    Ok(())
}

fn fuzz_config() -> ProptestConfig {
    ProptestConfig::default()
}

proptest! {
    #![proptest_config(fuzz_config())]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        check(&text)?;
    }

    #[test]
    fn fis_like_text_never_panics(text in "[\\[\\]A-Za-z0-9=',:() .%\n-]{0,300}") {
        check(&text)?;
    }

    #[test]
    fn mutated_paper_file_is_refused_or_sound(mutations in prop::collection::vec(mutation(), 1..5)) {
        check(&mutate(PAPER_FIS, &mutations))?;
    }

    #[test]
    fn mutated_written_systems_are_refused_or_sound(
        seed in any::<u64>(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        // A written system with other membership functions, linear outputs, OR rules.
        let text = small_system(seed).to_fis();
        check(&mutate(&text, &mutations))?;
    }
}

/// A small system of one or two inputs with every membership type and linear outputs.
fn small_system(seed: u64) -> FuzzySystem {
    let kinds = [
        "'trimf',[-1 0 1]",
        "'trapmf',[-1 -0.5 0.5 1]",
        "'gaussmf',[0.5 0]",
        "'gbellmf',[0.5 2 0]",
        "'sigmf',[4 0]",
    ];
    let pick = |k: u64| kinds[(seed >> (3 * k)) as usize % kinds.len()];
    let text = format!(
        "[System]\nName='s'\nType='sugeno'\nVersion=2.0\nNumInputs=2\nNumOutputs=1\nNumRules=3\n\
         AndMethod='min'\nOrMethod='max'\nImpMethod='prod'\nAggMethod='sum'\nDefuzzMethod='wtsum'\n\
         [Input1]\nName='x'\nRange=[-1 1]\nNumMFs=2\nMF1='a':{}\nMF2='b':{}\n\
         [Input2]\nName='y'\nRange=[-2 3]\nNumMFs=1\nMF1='c':{}\n\
         [Output1]\nName='z'\nRange=[-5 5]\nNumMFs=2\nMF1='l':'linear',[1 -2 0.5]\nMF2='k':'constant',[3]\n\
         [Rules]\n1 1, 1 (1) : 1\n-2 0, 2 (0.5) : 2\n0 -1, 1 (1) : 1\n",
        pick(0),
        pick(1),
        pick(2)
    );
    FuzzySystem::from_fis(&text).expect("the template is valid")
}

/// Regressions found by the fuzzer, each a minimal reproducer.
mod regressions {
    use super::*;

    fn refused(text: &str) -> String {
        match FuzzySystem::from_fis(text) {
            Err(e) => e.to_string(),
            Ok(system) => panic!("accepted {system:?}"),
        }
    }

    #[test]
    fn the_templates_are_sound() {
        check(PAPER_FIS).unwrap();
        for seed in 0..64 {
            check(&small_system(seed).to_fis()).unwrap();
        }
    }

    #[test]
    fn a_huge_input_count_is_refused_without_allocating() {
        let text = PAPER_FIS.replace("NumInputs=4", "NumInputs=18446744073709551615");
        assert_eq!(
            refused(&text),
            "line 1: missing section [Input5] (NumInputs=18446744073709551615)"
        );
        let text = PAPER_FIS.replace("NumOutputs=2", "NumOutputs=1000000000000");
        assert_eq!(
            refused(&text),
            "line 1: missing section [Output3] (NumOutputs=1000000000000)"
        );
    }

    #[test]
    fn a_huge_function_count_is_refused_without_allocating() {
        let text = PAPER_FIS.replacen("NumMFs=2", "NumMFs=18446744073709551615", 1);
        assert_eq!(
            refused(&text),
            "line 17: NumMFs=18446744073709551615 but [Input1] has 2 MF lines"
        );
    }

    #[test]
    fn a_closing_parenthesis_before_the_weight_is_refused() {
        // The `)` before the `(` once sliced the weight out of order and panicked.
        let text = PAPER_FIS.replacen("1 1 1 1, 4 4 (1) : 1", "1 1 1 1, 4 4 ) : 1 (1)", 1);
        assert_eq!(
            refused(&text),
            "line 61: expected a rule `i1 ... in, o1 ... om (weight) : connective`, \
             found `1 1 1 1, 4 4 ) : 1 (1)` (no `:` after the weight)"
        );
    }
}
