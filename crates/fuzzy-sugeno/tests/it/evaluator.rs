//! The evaluator against an independent reference, by-hand values, the hull property and every
//! error path and policy.

use crate::common::{self, Rng, random_point, random_system, reference_eval};
use fuzzy_sugeno::{
    AndMethod, Connective, Defuzzification, EvalOptions, Evaluator, FuzzyError, FuzzySystem,
    MembershipFn, NoRuleFired, OrMethod, OutOfRange, OutputFn,
};
use proptest::prelude::*;

proptest! {
    #[test]
    fn evaluator_matches_the_reference_on_random_systems(seed in any::<u64>()) {
        let system = random_system(seed, false);
        let mut evaluator = Evaluator::new(system.clone());
        let mut rng = Rng::new(seed ^ 0xA5A5);
        let mut out = vec![0.0; system.outputs().len()];
        for _ in 0..8 {
            let x = random_point(&system, &mut rng);
            evaluator.eval(&x, &mut out).unwrap();
            let (strengths, expected) = reference_eval(&system, &x);
            for (w, w_ref) in evaluator.fire(&x).unwrap().iter().zip(&strengths) {
                prop_assert!((w - w_ref).abs() <= 1e-9, "strength {w} vs {w_ref}");
            }
            for (o, (y, y_ref)) in out.iter().zip(&expected).enumerate() {
                let scale = 1.0 + system.outputs()[o].range.iter().map(|v| v.abs()).fold(0.0, f64::max) * 10.0;
                match y_ref {
                    Some(y_ref) => prop_assert!((y - y_ref).abs() <= 1e-6 * scale, "output {o}: {y} vs {y_ref}"),
                    // No rule fired: the default policy gives the middle of the range.
                    None => prop_assert_eq!(*y, 0.5 * (system.outputs()[o].range[0] + system.outputs()[o].range[1])),
                }
            }
        }
    }

    #[test]
    fn zero_order_outputs_lie_in_the_hull_of_the_fired_constants(seed in any::<u64>()) {
        let system = random_system(seed, true);
        let mut evaluator = Evaluator::new(system.clone());
        let mut rng = Rng::new(!seed);
        let mut out = vec![0.0; system.outputs().len()];
        for _ in 0..8 {
            let x = random_point(&system, &mut rng);
            evaluator.eval(&x, &mut out).unwrap();
            let strengths = evaluator.fire(&x).unwrap().to_vec();
            for (o, output) in system.outputs().iter().enumerate() {
                let fired: Vec<f64> = system
                    .rules()
                    .iter()
                    .zip(&strengths)
                    .filter(|(_, w)| **w > 0.0)
                    .filter_map(|(rule, _)| rule.consequents[o])
                    .map(|t| match output.terms[t].function {
                        OutputFn::Constant(c) => c,
                        OutputFn::Linear { .. } => unreachable!("zero-order system"),
                    })
                    .collect();
                if fired.is_empty() {
                    continue;
                }
                let lo = fired.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = fired.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let slack = 1e-12 * lo.abs().max(hi.abs());
                prop_assert!(out[o] >= lo - slack && out[o] <= hi + slack, "{} outside [{lo}, {hi}]", out[o]);
            }
        }
    }
}

/// One input on [0, 1] with two triangles that leave (0.4, 0.6) uncovered, one output on [0, 10].
fn gapped() -> FuzzySystem {
    FuzzySystem::builder("gapped")
        .input(
            "x",
            [0.0, 1.0],
            [
                ("lo", MembershipFn::triangle(-1.0, 0.0, 0.4)),
                ("hi", MembershipFn::triangle(0.6, 1.0, 2.0)),
            ],
        )
        .output(
            "y",
            [0.0, 10.0],
            [
                ("a", OutputFn::Constant(2.0)),
                ("b", OutputFn::Constant(8.0)),
            ],
        )
        .rule(["lo"], ["a"])
        .rule(["hi"], ["b"])
        .build()
        .unwrap()
}

fn eval_with(system: FuzzySystem, options: EvalOptions, x: &[f64]) -> Result<Vec<f64>, FuzzyError> {
    let mut evaluator = Evaluator::with_options(system, options)?;
    let mut out = vec![0.0; evaluator.system().outputs().len()];
    evaluator.eval(x, &mut out).map(|()| out)
}

#[test]
fn the_no_rule_fired_policy_is_applied() {
    let options = |no_rule_fired| EvalOptions {
        no_rule_fired,
        ..EvalOptions::default()
    };
    assert_eq!(
        eval_with(gapped(), EvalOptions::default(), &[0.5]).unwrap(),
        [5.0]
    );
    assert_eq!(
        eval_with(gapped(), options(NoRuleFired::Values(vec![-1.0])), &[0.5]).unwrap(),
        [-1.0]
    );
    let error = eval_with(gapped(), options(NoRuleFired::Error), &[0.5]).unwrap_err();
    assert_eq!(error.to_string(), "no rule fired for output 1 ('y')");
    // Where a rule fires the policy does not matter: at x = 0.2, lo = 1/2 alone gives 2.
    assert_eq!(
        eval_with(gapped(), options(NoRuleFired::Error), &[0.2]).unwrap(),
        [2.0]
    );
    let wrong = Evaluator::with_options(gapped(), options(NoRuleFired::Values(vec![1.0, 2.0])))
        .unwrap_err();
    assert_eq!(
        wrong.to_string(),
        "evaluation options: no-rule-fired values have 2 entries for 1 outputs"
    );
    let nan = Evaluator::with_options(gapped(), options(NoRuleFired::Values(vec![f64::NAN])))
        .unwrap_err();
    assert!(matches!(nan, FuzzyError::NonFiniteFallback { value } if value.is_nan()));
}

/// A system without rules (a `.fis` file may declare `NumRules=0`) builds, and no rule fires:
/// one point and a batch both give the no-rule-fired policy's value.
#[test]
fn a_system_without_rules_fires_none() {
    let empty = common::without_rules();
    let mut evaluator = Evaluator::new(empty.clone());
    let mut out = [0.0];
    evaluator.eval(&[0.2], &mut out).unwrap();
    assert_eq!(out, [5.0]);
    assert!(evaluator.firing_strengths().is_empty());
    let mut outs = [0.0; 11];
    let points: Vec<f64> = (0..11).map(|k| k as f64 / 10.0).collect();
    evaluator.eval_batch(&points, &mut outs).unwrap();
    assert_eq!(outs, [5.0; 11]);
    let options = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    let error = eval_with(empty, options, &[0.2]).unwrap_err();
    assert_eq!(error.to_string(), "no rule fired for output 1 ('y')");
}

#[test]
fn the_out_of_range_policy_is_applied() {
    let options = |out_of_range| EvalOptions {
        out_of_range,
        ..EvalOptions::default()
    };
    // Clamped to 1: hi = 1 fires alone.
    assert_eq!(
        eval_with(gapped(), options(OutOfRange::Clamp), &[7.0]).unwrap(),
        [8.0]
    );
    // As given: hi(1.5) = 0.5 alone still gives 8; at 2.5 nothing fires.
    assert_eq!(
        eval_with(gapped(), options(OutOfRange::AsGiven), &[1.5]).unwrap(),
        [8.0]
    );
    assert_eq!(
        eval_with(gapped(), options(OutOfRange::AsGiven), &[2.5]).unwrap(),
        [5.0]
    );
    let error = eval_with(gapped(), options(OutOfRange::Error), &[1.5]).unwrap_err();
    assert_eq!(
        error.to_string(),
        "input 1 ('x') = 1.5 lies outside its range [0, 1]"
    );
    assert_eq!(
        eval_with(gapped(), options(OutOfRange::Error), &[1.0]).unwrap(),
        [8.0]
    );
}

#[test]
fn bad_arguments_are_errors_never_nan() {
    let mut evaluator = Evaluator::new(gapped());
    let mut out = [0.0];
    for bad in [f64::NAN, f64::INFINITY] {
        let error = evaluator.eval(&[bad], &mut out).unwrap_err();
        assert!(
            matches!(error, FuzzyError::NonFiniteInput { index: 0, .. }),
            "{error}"
        );
    }
    assert_eq!(
        evaluator
            .eval(&[0.1, 0.2], &mut out)
            .unwrap_err()
            .to_string(),
        "expected 1 inputs, got 2"
    );
    assert_eq!(
        evaluator
            .eval(&[0.1], &mut [0.0, 0.0])
            .unwrap_err()
            .to_string(),
        "the output buffer has 2 slots but the system has 1 outputs"
    );
    let error = evaluator
        .eval_batch(&[0.1, f64::NAN, 0.3], &mut [0.0; 3])
        .unwrap_err();
    assert_eq!(
        error.to_string(),
        "batch row 2: input 1 ('x') is not finite: NaN"
    );
    let paper = Evaluator::new(fuzzy_sugeno::paper_controller())
        .eval_batch(&[0.0; 6], &mut [0.0; 2])
        .unwrap_err();
    assert_eq!(
        paper.to_string(),
        "a batch of inputs has 6 values, not a multiple of the 4 inputs"
    );
}

#[test]
fn an_overflowing_first_order_consequent_is_an_error() {
    let system = FuzzySystem::builder("big")
        .input(
            "x",
            [0.0, 10.0],
            [("any", MembershipFn::Constant { value: 1.0 })],
        )
        .output(
            "y",
            [0.0, 1.0],
            [(
                "huge",
                OutputFn::Linear {
                    coefficients: vec![1e308],
                    constant: 0.0,
                },
            )],
        )
        .rule(["any"], ["huge"])
        .build()
        .unwrap();
    let mut evaluator = Evaluator::new(system);
    let mut out = [0.0];
    evaluator.eval(&[1.0], &mut out).unwrap();
    assert_eq!(out, [1e308]);
    let error = evaluator.eval(&[10.0], &mut out).unwrap_err();
    assert_eq!(
        error.to_string(),
        "output 1 ('y') came out non-finite (inf)"
    );
}

/// Two Gaussian sets on x in [-1, 1] (sigma = 1, centres -1 and 1), one output.
fn two_sets(
    and: AndMethod,
    or: OrMethod,
    defuzzification: Defuzzification,
) -> fuzzy_sugeno::SystemBuilder {
    FuzzySystem::builder("two")
        .and_method(and)
        .or_method(or)
        .defuzzification(defuzzification)
        .input(
            "x",
            [-1.0, 1.0],
            [
                ("L", MembershipFn::gaussian(1.0, -1.0)),
                ("R", MembershipFn::gaussian(1.0, 1.0)),
            ],
        )
        .input(
            "y",
            [-1.0, 1.0],
            [
                ("L", MembershipFn::gaussian(1.0, -1.0)),
                ("R", MembershipFn::gaussian(1.0, 1.0)),
            ],
        )
}

#[test]
fn first_order_weighted_average_by_hand() {
    // At x = 0, y = 0.5: L(0) = R(0) = e^-1/2; rules "x is L -> z = 2x + y + 1" and
    // "x is R -> z = -x + 3" fire equally, so z = ((0 + 0.5 + 1) + 3) / 2 = 2.25.
    let system = two_sets(
        AndMethod::Product,
        OrMethod::Maximum,
        Defuzzification::WeightedAverage,
    )
    .output(
        "z",
        [-10.0, 10.0],
        [
            (
                "a",
                OutputFn::Linear {
                    coefficients: vec![2.0, 1.0],
                    constant: 1.0,
                },
            ),
            (
                "b",
                OutputFn::Linear {
                    coefficients: vec![-1.0, 0.0],
                    constant: 3.0,
                },
            ),
        ],
    )
    .rule(["L", "-"], ["a"])
    .rule(["R", "-"], ["b"])
    .build()
    .unwrap();
    assert_eq!(
        eval_with(system, EvalOptions::default(), &[0.0, 0.5]).unwrap(),
        [2.25]
    );
}

#[test]
fn weights_negation_or_min_max_and_weighted_sum_by_hand() {
    // x = 1, y = -1: L(x) = e^-2, R(x) = 1, L(y) = 1, R(y) = e^-2.
    let e2 = (-2.0f64).exp();
    let build = |and, or, defuzzification| {
        two_sets(and, or, defuzzification)
            .output(
                "z",
                [0.0, 10.0],
                [
                    ("one", OutputFn::Constant(1.0)),
                    ("nine", OutputFn::Constant(9.0)),
                ],
            )
            // rule 1: x is R and y is not L, weight 0.5 -> 1
            .weighted_rule(["R", "not L"], ["one"], 0.5, Connective::And)
            // rule 2: x is L or y is L -> 9
            .weighted_rule(["L", "L"], ["nine"], 1.0, Connective::Or)
            // rule 3: x is not L and y is R -> 9
            .rule(["not L", "R"], ["nine"])
            .build()
            .unwrap()
    };
    let strengths = |and, or| {
        let mut evaluator = Evaluator::new(build(and, or, Defuzzification::WeightedAverage));
        evaluator.fire(&[1.0, -1.0]).unwrap().to_vec()
    };
    // Product / probabilistic sum: 0.5 * 1 * (1 - 1) = 0; e^-2 + 1 - e^-2 = 1; (1 - e^-2) e^-2.
    let w = strengths(AndMethod::Product, OrMethod::ProbabilisticSum);
    assert_eq!(w[0], 0.0);
    assert!((w[1] - 1.0).abs() < 1e-15);
    assert!((w[2] - (1.0 - e2) * e2).abs() < 1e-15);
    // Minimum / maximum: min(1, 0) = 0; max(e^-2, 1) = 1; min(1 - e^-2, e^-2) = e^-2.
    let w = strengths(AndMethod::Minimum, OrMethod::Maximum);
    assert_eq!(w, [0.0, 1.0, e2]);
    // Weighted sum: 9 * 1 + 9 * e^-2 (rule 1 does not fire).
    let sum = eval_with(
        build(
            AndMethod::Minimum,
            OrMethod::Maximum,
            Defuzzification::WeightedSum,
        ),
        EvalOptions::default(),
        &[1.0, -1.0],
    );
    assert!((sum.unwrap()[0] - 9.0 * (1.0 + e2)).abs() < 1e-13);
    // The rule weight scales the strength: at x = 1, y = 1 rule 1 fires 0.5 * 1 * (1 - e^-2).
    let mut evaluator = Evaluator::new(build(
        AndMethod::Product,
        OrMethod::Maximum,
        Defuzzification::WeightedAverage,
    ));
    let w = evaluator.fire(&[1.0, 1.0]).unwrap();
    assert!((w[0] - 0.5 * (1.0 - e2)).abs() < 1e-15);
}

#[test]
fn an_output_ignores_rules_that_say_nothing_about_it() {
    let system = two_sets(
        AndMethod::Product,
        OrMethod::Maximum,
        Defuzzification::WeightedAverage,
    )
    .output("u", [0.0, 10.0], [("c", OutputFn::Constant(4.0))])
    .output("v", [0.0, 10.0], [("c", OutputFn::Constant(6.0))])
    .rule(["L", "-"], ["c", "-"])
    .rule(["R", "-"], ["-", "c"])
    .build()
    .unwrap();
    assert_eq!(
        eval_with(system, EvalOptions::default(), &[0.3, 0.0]).unwrap(),
        [4.0, 6.0]
    );
}
