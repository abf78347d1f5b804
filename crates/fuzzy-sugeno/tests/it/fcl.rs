//! FCL (IEC 61131-7): round trips with `.fis` over random systems, a file as fuzzylite's FCL
//! exporter writes it, and malformed files named by line.

use crate::common;

use crate::common::{Rng, random_point, random_system};
use fuzzy_sugeno::{
    Antecedent, Connective, Evaluator, FuzzyError, FuzzySystem, MembershipFn, paper_controller,
};
use proptest::prelude::*;

const FUZZYLITE_FCL: &str = include_str!("../../data/paper.fuzzylite.fcl");

/// The same system with FCL identifiers for names (random names hold spaces, dots and dashes),
/// and its one-premise OR rules as AND rules (FCL writes no connective for one premise; both
/// evaluate to the premise's degree).
pub fn with_identifiers(system: &FuzzySystem) -> FuzzySystem {
    let methods = system.methods();
    let mut builder = FuzzySystem::builder("random")
        .and_method(methods.and)
        .or_method(methods.or)
        .defuzzification(methods.defuzzification);
    for (i, input) in system.inputs().iter().enumerate() {
        let sets = input
            .sets
            .iter()
            .enumerate()
            .map(|(k, s)| (format!("s{k}"), s.membership));
        builder = builder.input(format!("in{i}"), input.range, sets);
    }
    for (o, output) in system.outputs().iter().enumerate() {
        let terms = output
            .terms
            .iter()
            .enumerate()
            .map(|(k, t)| (format!("t{k}"), t.function.clone()));
        builder = builder.output(format!("out{o}"), output.range, terms);
    }
    for rule in system.rules() {
        let mut rule = rule.clone();
        let premises = rule
            .antecedents
            .iter()
            .filter(|a| **a != Antecedent::Any)
            .count();
        if premises == 1 {
            rule.connective = Connective::And;
        }
        builder = builder.indexed_rule(rule);
    }
    builder.build().unwrap()
}

/// Whether a set of the system is one of MATLAB's steps (`smf`, `zmf` or `pimf` with a foot at
/// or past its shoulder).
pub fn has_step(system: &FuzzySystem) -> bool {
    system
        .inputs()
        .iter()
        .flat_map(|i| &i.sets)
        .any(|set| match set.membership {
            MembershipFn::SShape { start, end } | MembershipFn::ZShape { start, end } => {
                start >= end
            }
            MembershipFn::PiShape {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            } => left_foot >= left_shoulder || right_shoulder >= right_foot,
            _ => false,
        })
}

proptest! {
    #[test]
    fn fis_to_fcl_and_back_is_the_identical_system(seed in any::<u64>(), zero_order in any::<bool>()) {
        let system = with_identifiers(&random_system(seed, zero_order));
        let fcl = match system.to_fcl() {
            Ok(fcl) => fcl,
            // MATLAB's steps, which FCL cannot carry, are refused by name.
            Err(FuzzyError::FclStep { .. }) => {
                prop_assert!(has_step(&system));
                return Ok(());
            }
            Err(e) => return Err(TestCaseError::fail(e.to_string())),
        };
        let read = FuzzySystem::from_fcl(&fcl).map_err(|e| TestCaseError::fail(format!("{e}\n{fcl}")))?;
        prop_assert_eq!(&read, &system);
        // And through .fis: fis -> system -> fcl -> system -> fis gives the same text.
        let fis = system.to_fis();
        prop_assert_eq!(FuzzySystem::from_fcl(&FuzzySystem::from_fis(&fis).unwrap().to_fcl().unwrap()).unwrap().to_fis(), fis);
        prop_assert!(!has_step(&system));
    }
}

#[test]
fn the_paper_controller_round_trips() {
    let fcl = paper_controller().to_fcl().unwrap();
    assert_eq!(FuzzySystem::from_fcl(&fcl).unwrap(), paper_controller());
    assert!(fcl.contains("    RULE 1 : if da1 is N and da2 is N and a1_dot is N and a2_dot is N then tau1 is VP and tau2 is VP;"));
    // fuzzylite stops at a `(*` comment; the standard has no `//`: no comment at all.
    assert!(fcl.starts_with("FUNCTION_BLOCK paper\n"));
}

#[test]
fn a_file_written_by_fuzzylite_loads() {
    // data/paper.fuzzylite.fcl follows fuzzylite 6's FclExporter: a `//` header, two-space
    // indents, `name: REAL;`, a RANGE in FUZZIFY, `Bell center width slope` with three decimals,
    // bare singleton values, `METHOD : COGS;`, `DEFAULT := nan;`, an unnamed RULEBLOCK and
    // lower-case rules without a final `;`.
    let system = FuzzySystem::from_fcl(FUZZYLITE_FCL).unwrap();
    assert_eq!(system, paper_controller());
    let mut rng = Rng::new(3);
    let (mut a, mut b) = (Evaluator::new(system), Evaluator::new(paper_controller()));
    let (mut ya, mut yb) = ([0.0; 2], [0.0; 2]);
    for _ in 0..100 {
        let x = random_point(a.system(), &mut rng);
        a.eval(&x, &mut ya).unwrap();
        b.eval(&x, &mut yb).unwrap();
        assert_eq!(ya, yb);
    }
}

#[test]
fn iec_point_lists_comments_and_weights() {
    let text = "(* a standard file *)\nFUNCTION_BLOCK tank\nVAR_INPUT level : REAL; END_VAR\n\
                VAR_OUTPUT valve : REAL; END_VAR\nFUZZIFY level\n  RANGE := (0 .. 10);\n  \
                TERM low := (0, 0) (2, 1) (6, 0);\n  TERM high := (3, 0) (5, 1) (8, 1) (10, 0); // shoulder\nEND_FUZZIFY\n\
                DEFUZZIFY valve\n  RANGE := (-1 .. 1);\n  TERM close := -1;\n  TERM open := 1;\n  METHOD : COGS;\n  DEFAULT := 0;\nEND_DEFUZZIFY\n\
                RULEBLOCK r\n  AND : MIN;\n  OR : MAX;\n  ACT : MIN;\n  RULE 1 : IF level IS low THEN valve IS open;\n  \
                RULE 2 : IF level IS NOT low THEN valve IS close WITH 0.5;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK\n";
    let system = FuzzySystem::from_fcl(text).unwrap();
    assert_eq!(
        system.inputs()[0].sets[1].membership,
        MembershipFn::trapezoid(3.0, 5.0, 8.0, 10.0)
    );
    assert_eq!(system.rules()[1].weight, 0.5);
    let mut evaluator = Evaluator::new(system);
    let mut y = [0.0];
    // At 2: low = 1, not low = 0: the valve opens fully.
    evaluator.eval(&[2.0], &mut y).unwrap();
    assert_eq!(y, [1.0]);
}

/// fuzzylite's `SShape start end`, `ZShape start end` and
/// `PiShape bottomLeft topLeft topRight bottomRight` read as MATLAB's smf, zmf and pimf with the
/// parameters in the same order, the step `start >= end` included.
#[test]
fn fuzzylite_s_z_and_pi_shapes_keep_their_parameter_order() {
    use fuzzy_sugeno::MembershipFn;
    let term = |text: &str| {
        let fcl = FUZZYLITE_FCL.replacen("Bell -0.300 0.300 2.000", text, 1);
        FuzzySystem::from_fcl(&fcl).unwrap().inputs()[0].sets[0].membership
    };
    assert_eq!(
        term("SShape -0.5 0.25"),
        MembershipFn::SShape {
            start: -0.5,
            end: 0.25
        }
    );
    assert_eq!(
        term("ZShape 0.25 -0.5"),
        MembershipFn::ZShape {
            start: 0.25,
            end: -0.5
        }
    );
    assert_eq!(
        term("PiShape -0.5 -0.25 0.25 0.5"),
        MembershipFn::PiShape {
            left_foot: -0.5,
            left_shoulder: -0.25,
            right_shoulder: 0.25,
            right_foot: 0.5
        }
    );
}

#[test]
fn malformed_files_name_the_line_and_the_problem() {
    let message = |text: &str| FuzzySystem::from_fcl(text).unwrap_err().to_string();
    let swap = |from: &str, to: &str| message(&FUZZYLITE_FCL.replacen(from, to, 1));
    assert_eq!(
        swap("METHOD : COGS;", "METHOD : COG;"),
        "FCL line 47: METHOD COG is a Mamdani defuzzifier; this crate reads Sugeno systems (COGS, or fuzzylite's COGSS)"
    );
    assert_eq!(
        swap("TERM N := Bell -0.300 0.300 2.000;", "TERM N := Ramp 0 1;"),
        "FCL line 19: input term class 'Ramp' is not supported; expected a point list or one of Triangle, Trapezoid, Bell, Gaussian, GaussianProduct, Sigmoid, SigmoidDifference, SigmoidProduct, SShape, ZShape, PiShape, Constant"
    );
    assert_eq!(
        swap(
            "TERM N := Bell -0.300 0.300 2.000;",
            "TERM N := Bell -0.300 0.300 2.000 0.5;"
        ),
        "FCL line 19: Bell with height 0.5: only height 1 is supported"
    );
    // Two terms of one variable under one name: rules could not tell them apart.
    assert_eq!(
        swap(
            "TERM P := Bell 0.300 0.300 2.000;",
            "TERM P := Bell 0.300 0.300 2.000;\n    TERM N := Bell 0.300 0.010 2.000;"
        ),
        "FCL line 21: variable 'da1' already has a term named 'N'; rules name terms, so rename one"
    );
    assert_eq!(
        swap("if da1 is N and", "if da1 is very N and"),
        "FCL line 64: input 'da1' has no term 'very' (hedges other than NOT are not supported)"
    );
    assert_eq!(
        swap("if da1 is N and", "if da1 is N or"),
        "FCL line 64: the rule mixes AND and OR; a .fis rule has one connective"
    );
    assert_eq!(
        swap("  RANGE := (-0.300 .. 0.300);\n", ""),
        "FCL line 6: input 'da1' has no RANGE (this crate needs every variable's range)"
    );
    assert_eq!(
        message("FUNCTION_BLOCK x\nVAR_INPUT\n a : REAL;\nEND_VAR\n"),
        "FCL line 4: expected END_FUNCTION_BLOCK before the end of the text"
    );
    // Refusals of the whole system point at the RANGE, TERM or RULE they name.
    assert_eq!(
        swap("RANGE := (-1.000 .. 1.000);", "RANGE := (1.000 .. -1.000);"),
        "FCL line 30: input 'a1_dot': range must be finite with min < max, got [1, -1]"
    );
    assert_eq!(
        swap("tau2 is P\n", "tau2 is P with 2.0\n"),
        "FCL line 65: rule 2: weight must lie in [0, 1], got 2"
    );
    assert_eq!(
        swap(
            "TERM P := Bell 0.300 0.300 2.000;",
            "TERM P := Bell 0.300 0 2.000;"
        ),
        "FCL line 20: gbellmf: width a must be positive, got 0"
    );
    assert_eq!(message("(* open"), "FCL line 1: unterminated (* comment");
    assert_eq!(
        message("VAR_INPUT\n"),
        "FCL line 1: expected FUNCTION_BLOCK, found `VAR_INPUT`"
    );
    let bad_name = FuzzySystem::builder("my system")
        .input("x", [0.0, 1.0], [("a", MembershipFn::gaussian(1.0, 0.0))])
        .output(
            "y",
            [0.0, 1.0],
            [("c", fuzzy_sugeno::OutputFn::Constant(0.0))],
        )
        .rule(["a"], ["c"])
        .build()
        .unwrap();
    assert!(
        bad_name
            .to_fcl()
            .unwrap_err()
            .to_string()
            .starts_with("export: the system name 'my system' cannot be written in FCL")
    );
    // Keywords of the standard or of fuzzylite's rules, in any case, are refused by name
    // rather than written into a file that reads as something else.
    for (input, set, kind, name) in [
        ("END_VAR", "a", "input", "END_VAR"),
        ("x", "any", "set", "any"),
        ("range", "a", "input", "range"),
        ("x", "Then", "set", "Then"),
        ("x", "very", "set", "very"),
    ] {
        let system = FuzzySystem::builder("s")
            .input(input, [0.0, 1.0], [(set, MembershipFn::gaussian(1.0, 0.0))])
            .output(
                "y",
                [0.0, 1.0],
                [("c", fuzzy_sugeno::OutputFn::Constant(0.0))],
            )
            .rule([set], ["c"])
            .build()
            .unwrap();
        let message = system.to_fcl().unwrap_err().to_string();
        assert!(
            message.starts_with(&format!(
                "export: the {kind} name '{name}' cannot be written"
            )),
            "{message}"
        );
    }
    // A .fis file may give two sets of an input the same name; FCL rules could not tell them
    // apart.
    let shared =
        FuzzySystem::from_fis(include_str!("../../data/interop/octave_style.fis")).unwrap();
    assert_eq!(
        shared.to_fcl().unwrap_err().to_string(),
        "export: input 'temperature' has two terms named 'extreme'; FCL rules name terms, so \
         rename one"
    );
}

proptest! {
    /// Hostile edits of a valid file give a system or an error, never a panic.
    #[test]
    fn mangled_files_never_panic(edits in prop::collection::vec((0usize..4000, 0usize..12, any::<bool>()), 1..6)) {
        const PIECES: [&str; 12] = ["(*", "*)", ";", ":=", "IS", "(", ")", ",", "..", "-1e999", "\n", "WITH"];
        let mut text = FUZZYLITE_FCL.to_string();
        for (at, piece, delete) in edits {
            let mut at = at % text.len();
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            if delete {
                let end = (at + PIECES[piece].len()).min(text.len());
                if text.is_char_boundary(end) {
                    text.replace_range(at..end, "");
                }
            } else {
                text.insert_str(at, PIECES[piece]);
            }
        }
        let _ = FuzzySystem::from_fcl(&text);
    }
}

/// An input with no sets and a point output range (both allowed by validation) survive the
/// round trip through FCL exactly.
#[test]
fn empty_inputs_and_point_output_ranges_round_trip() {
    // Its set 'high' is MATLAB's step, which FCL cannot carry: refused by name, and the same
    // system with that set a proper spline round-trips.
    let relaxed = common::relaxed_system();
    assert_eq!(
        relaxed.to_fcl().unwrap_err().to_string(),
        "export: the set 'high' of input 'a' is MATLAB's step (smf with its foot at or past its \
         shoulder), which fuzzylite evaluates otherwise; FCL cannot carry it"
    );
    let mut inputs = relaxed.inputs().to_vec();
    for input in &mut inputs {
        for set in &mut input.sets {
            if let MembershipFn::SShape { start, end } = set.membership {
                set.membership = MembershipFn::SShape {
                    start: end,
                    end: start,
                };
            }
        }
    }
    let methods = relaxed.methods();
    let mut builder = FuzzySystem::builder("relaxed")
        .and_method(methods.and)
        .or_method(methods.or)
        .defuzzification(methods.defuzzification);
    for input in inputs {
        let sets = input.sets.into_iter().map(|s| (s.name, s.membership));
        builder = builder.input(input.name, input.range, sets);
    }
    for output in relaxed.outputs() {
        let terms = output
            .terms
            .iter()
            .map(|t| (t.name.clone(), t.function.clone()));
        builder = builder.output(output.name.clone(), output.range, terms);
    }
    for rule in relaxed.rules() {
        builder = builder.indexed_rule(rule.clone());
    }
    let system = builder.build().unwrap();
    let fcl = system.to_fcl().unwrap();
    assert!(fcl.contains("RANGE := (2.0 .. 2.0);"), "{fcl}");
    assert_eq!(FuzzySystem::from_fcl(&fcl).unwrap(), system);
}
