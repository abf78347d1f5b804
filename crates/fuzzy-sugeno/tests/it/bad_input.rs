//! One test per fuzzy-sugeno row of `docs/bad-input.md` (the `.fis` parser has its own fuzz
//! tests): each bad input is refused with the named [`FuzzyError`] variant and nothing is written
//! to the output.

use fuzzy_sugeno::{
    AnalysisOptions, EvalOptions, Evaluator, FuzzyError, FuzzySystem, MembershipFn, NoRuleFired,
    OutOfRange, OutputFn, SystemProblem, paper_controller,
};

/// A value no evaluation writes: an output still holding it was left untouched.
const SENTINEL: f64 = -12345.0;

/// The reason an `InvalidMembership` error gives.
fn membership_reason(mf: MembershipFn) -> String {
    match mf.validate() {
        Err(FuzzyError::InvalidMembership { reason, .. }) => reason,
        other => panic!("{mf:?}: expected InvalidMembership, got {other:?}"),
    }
}

/// One input on `[0, 1]` whose only set covers `[0, 0.5]`, and one output: no rule fires on
/// `(0.5, 1]`, where the centre average would be 0/0.
fn half_covered() -> FuzzySystem {
    FuzzySystem::builder("half covered")
        .input(
            "x",
            [0.0, 1.0],
            [("low", MembershipFn::triangle(0.0, 0.0, 0.5))],
        )
        .output("y", [-1.0, 3.0], [("one", OutputFn::Constant(1.0))])
        .rule(["low"], ["one"])
        .build()
        .unwrap()
}

#[test]
fn membership_zero_width() {
    assert!(
        membership_reason(MembershipFn::bell(0.0, 2.0, 0.0)).contains("width a must be positive")
    );
    assert!(membership_reason(MembershipFn::gaussian(0.0, 0.0)).contains("sigma must be positive"));
    let reason = membership_reason(MembershipFn::triangle(0.3, 0.3, 0.3));
    assert!(reason.contains("zero width"), "{reason}");
    let reason = membership_reason(MembershipFn::trapezoid(0.3, 0.3, 0.3, 0.3));
    assert!(reason.contains("zero width"), "{reason}");
    // A shoulder (a == b) still has width, and is allowed.
    assert!(MembershipFn::triangle(0.0, 0.0, 0.5).validate().is_ok());
    let err = MembershipFn::triangle(0.3, 0.3, 0.3)
        .degree(0.3)
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "trimf: zero width: the feet must satisfy a < c, got [0.3 0.3 0.3]"
    );
}

/// A Gaussian whose `1 / (2 sigma^2)` leaves double precision gave NaN degrees (read as rules
/// that did not fire: a wrong answer, no error); refused, while the ends of the range evaluate.
#[test]
fn membership_gaussian_scale_beyond_double_precision() {
    for sigma in [1e308, 1e154, 1e-160, 1e-300] {
        let reason = membership_reason(MembershipFn::gaussian(sigma, 0.0));
        assert!(
            reason.starts_with("sigma must be within [1e-154, 1e153]"),
            "{reason}"
        );
    }
    let two = MembershipFn::Gaussian2 {
        sigma1: 1.0,
        center1: 0.0,
        sigma2: 1e-300,
        center2: 1.0,
    };
    assert!(membership_reason(two).contains("sigma2 must be within"));
    for (sigma, x) in [(1e153, 1e153), (1e-154, 1e-154), (1e153, 1.7e308)] {
        let degree = MembershipFn::gaussian(sigma, 0.0).degree(x).unwrap();
        let expected = (-0.5 * (x / sigma) * (x / sigma)).exp();
        assert!((degree - expected).abs() < 1e-12, "{sigma} {x}: {degree}");
    }
}

#[test]
fn membership_non_positive_slope() {
    assert!(
        membership_reason(MembershipFn::bell(0.3, -2.0, 0.0)).contains("slope b must be positive")
    );
}

#[test]
fn membership_unordered_corners() {
    let reason = membership_reason(MembershipFn::triangle(0.5, 0.0, 1.0));
    assert_eq!(reason, "corners must satisfy a <= b <= c, got [0.5 0 1]");
    let reason = membership_reason(MembershipFn::trapezoid(0.0, 2.0, 1.0, 3.0));
    assert!(reason.contains("a <= b <= c <= d"), "{reason}");
}

#[test]
fn membership_non_finite_parameter() {
    for mf in [
        MembershipFn::bell(f64::NAN, 2.0, 0.0),
        MembershipFn::gaussian(0.1, f64::INFINITY),
        MembershipFn::triangle(f64::NEG_INFINITY, 0.0, 1.0),
    ] {
        assert!(membership_reason(mf).contains("parameters must be finite"));
    }
}

#[test]
fn membership_from_matlab_of_wrong_arity() {
    assert!(matches!(
        MembershipFn::from_matlab("gbellmf", &[0.3, 2.0]),
        Err(FuzzyError::InvalidMembership { .. })
    ));
    assert!(MembershipFn::from_matlab("nosuchmf", &[1.0]).is_err());
}

#[test]
fn system_with_an_invalid_set() {
    let err = FuzzySystem::builder("bad set")
        .input(
            "x",
            [0.0, 1.0],
            [("flat", MembershipFn::triangle(0.5, 0.5, 0.5))],
        )
        .output("y", [0.0, 1.0], [("one", OutputFn::Constant(1.0))])
        .rule(["flat"], ["one"])
        .build()
        .unwrap_err();
    assert!(
        matches!(&err, FuzzyError::InvalidSystem { context, problem: SystemProblem::Membership(_) }
            if context == "input 'x' set 'flat'"),
        "{err:?}"
    );
    assert!(err.to_string().contains("zero width"), "{err}");
}

#[test]
fn system_with_an_empty_or_non_finite_range() {
    for range in [[1.0, 1.0], [2.0, 1.0], [0.0, f64::INFINITY]] {
        let err = FuzzySystem::builder("bad range")
            .input("x", range, [("a", MembershipFn::gaussian(0.3, 0.0))])
            .output("y", [0.0, 1.0], [("one", OutputFn::Constant(1.0))])
            .rule(["a"], ["one"])
            .build()
            .unwrap_err();
        assert!(
            matches!(&err, FuzzyError::InvalidSystem { context, problem: SystemProblem::Range { .. } }
                if context == "input 'x'"),
            "{err:?}"
        );
        assert!(
            err.to_string()
                .contains("range must be finite with min < max")
        );
    }
    // An output's range may be a point (MATLAB's juggler example has [0 0]), not reversed.
    let output = |range| {
        FuzzySystem::builder("output range")
            .input("x", [0.0, 1.0], [("a", MembershipFn::gaussian(0.3, 0.0))])
            .output("y", range, [("one", OutputFn::Constant(1.0))])
            .rule(["a"], ["one"])
            .build()
    };
    assert!(output([0.0, 0.0]).is_ok());
    assert_eq!(
        output([2.0, 1.0]).unwrap_err().to_string(),
        "output 'y': range must be finite with min <= max, got [2, 1]"
    );
}

#[test]
fn rule_naming_an_unknown_set() {
    let err = FuzzySystem::builder("typo")
        .input("x", [0.0, 1.0], [("low", MembershipFn::gaussian(0.3, 0.0))])
        .output("y", [0.0, 1.0], [("one", OutputFn::Constant(1.0))])
        .rule(["lwo"], ["one"])
        .build()
        .unwrap_err();
    assert!(matches!(err, FuzzyError::InvalidSystem { .. }), "{err:?}");
    assert!(err.to_string().contains("lwo"), "{err}");
}

#[test]
fn wrong_number_of_inputs() {
    let mut controller = Evaluator::new(paper_controller());
    let mut out = [SENTINEL; 2];
    let err = controller.eval(&[0.1; 3], &mut out).unwrap_err();
    assert_eq!(
        err,
        FuzzyError::InputCount {
            expected: 4,
            found: 3
        }
    );
    assert_eq!(err.to_string(), "expected 4 inputs, got 3");
    assert_eq!(out, [SENTINEL; 2]);
}

#[test]
fn wrong_number_of_output_slots() {
    let mut controller = Evaluator::new(paper_controller());
    let mut out = [SENTINEL; 3];
    let err = controller.eval(&[0.1; 4], &mut out).unwrap_err();
    assert!(matches!(
        err,
        FuzzyError::OutputCount {
            expected: 2,
            found: 3
        }
    ));
    assert_eq!(out, [SENTINEL; 3]);
}

#[test]
fn non_finite_input() {
    let mut controller = Evaluator::new(paper_controller());
    let mut out = [SENTINEL; 2];
    let err = controller
        .eval(&[0.1, f64::NAN, 0.0, 0.0], &mut out)
        .unwrap_err();
    assert!(matches!(&err, FuzzyError::NonFiniteInput { index: 1, name, .. } if name == "da2"));
    assert_eq!(out, [SENTINEL; 2]);
    // The evaluator is still usable and gives what a fresh one gives.
    controller.eval(&[0.3, 0.0, 0.0, 0.0], &mut out).unwrap();
    let mut fresh = [0.0; 2];
    Evaluator::new(paper_controller())
        .eval(&[0.3, 0.0, 0.0, 0.0], &mut fresh)
        .unwrap();
    assert_eq!(out, fresh);
}

#[test]
fn input_out_of_range_under_the_error_policy() {
    let options = EvalOptions {
        out_of_range: OutOfRange::Error,
        ..EvalOptions::default()
    };
    let mut controller = Evaluator::with_options(paper_controller(), options).unwrap();
    let mut out = [SENTINEL; 2];
    let err = controller
        .eval(&[1e9, 0.0, 0.0, 0.0], &mut out)
        .unwrap_err();
    assert!(
        matches!(err, FuzzyError::InputOutOfRange { index: 0, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("lies outside its range"));
    assert_eq!(out, [SENTINEL; 2]);
}

#[test]
fn no_rule_fires_gives_the_middle_of_the_range_by_default() {
    let mut evaluator = Evaluator::new(half_covered());
    let mut out = [SENTINEL];
    evaluator.eval(&[0.8], &mut out).unwrap();
    assert_eq!(out, [1.0]); // (-1 + 3) / 2, not 0/0
    let options = EvalOptions {
        no_rule_fired: NoRuleFired::Values(vec![-0.5]),
        ..EvalOptions::default()
    };
    let mut evaluator = Evaluator::with_options(half_covered(), options).unwrap();
    evaluator.eval(&[0.8], &mut out).unwrap();
    assert_eq!(out, [-0.5]);
}

#[test]
fn no_rule_fires_under_the_error_policy() {
    let options = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    let mut evaluator = Evaluator::with_options(half_covered(), options).unwrap();
    let mut out = [SENTINEL];
    let err = evaluator.eval(&[0.8], &mut out).unwrap_err();
    assert!(matches!(&err, FuzzyError::NoRuleFired { index: 0, name } if name == "y"));
    assert_eq!(err.to_string(), "no rule fired for output 1 ('y')");
    assert_eq!(out, [SENTINEL]);
    evaluator.eval(&[0.2], &mut out).unwrap();
    assert_eq!(out, [1.0]);
}

#[test]
fn no_rule_fires_on_one_output_of_two() {
    // Output 0 always has a rule; output 1 has none on (0.5, 1]: nothing may be written.
    let system = FuzzySystem::builder("partial")
        .input(
            "x",
            [0.0, 1.0],
            [
                ("low", MembershipFn::triangle(0.0, 0.0, 0.5)),
                ("any", MembershipFn::trapezoid(-1.0, 0.0, 1.0, 2.0)),
            ],
        )
        .output("y0", [0.0, 4.0], [("two", OutputFn::Constant(2.0))])
        .output("y1", [0.0, 4.0], [("three", OutputFn::Constant(3.0))])
        .rule(["any"], ["two", "-"])
        .rule(["low"], ["-", "three"])
        .build();
    let system = match system {
        Ok(system) => system,
        Err(e) => panic!("{e}"),
    };
    let options = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    let mut evaluator = Evaluator::with_options(system, options).unwrap();
    let mut out = [SENTINEL; 2];
    let err = evaluator.eval(&[0.8], &mut out).unwrap_err();
    assert!(
        matches!(err, FuzzyError::NoRuleFired { index: 1, .. }),
        "{err:?}"
    );
    assert_eq!(out, [SENTINEL; 2]);
}

#[test]
fn no_rule_fired_values_of_wrong_length_or_non_finite() {
    for values in [vec![0.0, 0.0], vec![f64::NAN]] {
        let options = EvalOptions {
            no_rule_fired: NoRuleFired::Values(values),
            ..EvalOptions::default()
        };
        let err = Evaluator::with_options(half_covered(), options.clone()).unwrap_err();
        assert!(
            matches!(
                err,
                FuzzyError::FallbackCount {
                    expected: 1,
                    found: 2
                } | FuzzyError::NonFiniteFallback { .. }
            ),
            "{err:?}"
        );
        // The C export checks the options the same way.
        let exported = half_covered().to_c("x", &options).unwrap_err();
        assert_eq!(exported.to_string(), err.to_string());
    }
}

#[test]
fn overflowing_linear_consequent() {
    let system = FuzzySystem::builder("overflow")
        .input(
            "x",
            [0.0, 1e300],
            [("all", MembershipFn::trapezoid(-1.0, 0.0, 1e300, 2e300))],
        )
        .output(
            "y",
            [0.0, 1.0],
            [(
                "huge",
                OutputFn::Linear {
                    coefficients: vec![1e300],
                    constant: 0.0,
                },
            )],
        )
        .rule(["all"], ["huge"])
        .build()
        .unwrap();
    let mut evaluator = Evaluator::new(system);
    let mut out = [SENTINEL];
    let err = evaluator.eval(&[1e300], &mut out).unwrap_err();
    assert!(
        matches!(err, FuzzyError::NonFiniteOutput { index: 0, .. }),
        "{err:?}"
    );
    assert_eq!(out, [SENTINEL]);
}

#[test]
fn linear_consequent_at_inputs_of_wrong_length() {
    let f = OutputFn::Linear {
        coefficients: vec![1.0, 2.0],
        constant: 0.5,
    };
    assert_eq!(f.value(&[1.0, 1.0]), Ok(3.5));
    assert_eq!(
        f.value(&[1.0]),
        Err(FuzzyError::InputCount {
            expected: 2,
            found: 1
        })
    );
}

#[test]
fn batch_not_a_whole_number_of_rows() {
    let mut controller = Evaluator::new(paper_controller());
    let mut out = [SENTINEL; 4];
    let err = controller.eval_batch(&[0.0; 7], &mut out).unwrap_err();
    assert_eq!(err, FuzzyError::BatchLength { len: 7, inputs: 4 });
    assert_eq!(out, [SENTINEL; 4]);
}

#[test]
fn batch_with_a_bad_row() {
    let mut controller = Evaluator::new(paper_controller());
    let mut inputs = [0.1; 12];
    inputs[5] = f64::NAN; // row 1
    let mut out = [SENTINEL; 6];
    let err = controller.eval_batch(&inputs, &mut out).unwrap_err();
    assert!(
        matches!(&err, FuzzyError::Batch { row: 1, source } if matches!(**source, FuzzyError::NonFiniteInput { index: 1, .. })),
        "{err:?}"
    );
    assert!(err.to_string().starts_with("batch row 2: input 2"));
    // Row 0 holds its result, rows 1 and 2 are untouched.
    assert!(out[..2].iter().all(|v| v.is_finite() && *v != SENTINEL));
    assert_eq!(out[2..], [SENTINEL; 4]);
}

#[test]
fn analysis_options_out_of_domain() {
    let system = paper_controller();
    for options in [
        AnalysisOptions {
            coverage: 0.0,
            ..AnalysisOptions::default()
        },
        AnalysisOptions {
            coverage: f64::NAN,
            ..AnalysisOptions::default()
        },
        AnalysisOptions {
            max_relative_jump: -1.0,
            ..AnalysisOptions::default()
        },
    ] {
        assert!(
            matches!(
                system.analyze(&options),
                Err(FuzzyError::AnalysisOption { .. })
            ),
            "{options:?}"
        );
    }
}
