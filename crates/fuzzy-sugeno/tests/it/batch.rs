//! `Evaluator::eval_batch` (SIMD across points) against `Evaluator::eval` one point at a time:
//! bit for bit on random systems of every membership kind and method, for batches of every length
//! (whole SIMD groups and leftovers), under every policy, and with a refused row anywhere.

use crate::common::{Rng, random_point, random_system};
use fuzzy_sugeno::{EvalOptions, Evaluator, FuzzyError, NoRuleFired, OutOfRange, paper_controller};
use proptest::prelude::*;

/// Random options: the range policies that accept every finite input, and the no-rule policies
/// that never fail.
fn options(rng: &mut Rng, n_out: usize) -> EvalOptions {
    EvalOptions {
        out_of_range: if rng.chance(0.5) {
            OutOfRange::Clamp
        } else {
            OutOfRange::AsGiven
        },
        no_rule_fired: if rng.chance(0.5) {
            NoRuleFired::MiddleOfRange
        } else {
            NoRuleFired::Values((0..n_out).map(|_| rng.range(-3.0, 3.0)).collect())
        },
    }
}

/// Output rows that are never a result, to see which rows a failed batch wrote.
const SENTINEL: f64 = -7.25e300;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn a_batch_equals_row_by_row_evaluation(seed in any::<u64>(), rows in 0usize..45) {
        let system = random_system(seed, seed % 3 == 0);
        let (n_in, n_out) = (system.inputs().len(), system.outputs().len());
        let mut rng = Rng::new(seed.rotate_left(7));
        let options = options(&mut rng, n_out);
        let inputs: Vec<f64> = (0..rows).flat_map(|_| random_point(&system, &mut rng)).collect();
        let mut batch = vec![SENTINEL; rows * n_out];
        let mut evaluator = Evaluator::with_options(system, options).unwrap();
        evaluator.eval_batch(&inputs, &mut batch).unwrap();
        let mut row = vec![0.0; n_out];
        for (x, y) in inputs.chunks(n_in).zip(batch.chunks(n_out)) {
            evaluator.eval(x, &mut row).unwrap();
            let (bits, batch_bits): (Vec<u64>, Vec<u64>) =
                (row.iter().map(|v| v.to_bits()).collect(), y.iter().map(|v| v.to_bits()).collect());
            prop_assert_eq!(bits, batch_bits, "{:?} against {:?} at {:?}", row, y, x);
        }
    }

    #[test]
    fn a_refused_row_is_named_and_the_rows_before_it_are_written(
        seed in any::<u64>(),
        rows in 1usize..40,
        bad in any::<prop::sample::Index>(),
        error_policy in any::<bool>(),
    ) {
        let system = random_system(seed, false);
        let (n_in, n_out) = (system.inputs().len(), system.outputs().len());
        let mut rng = Rng::new(seed ^ 0x5EED);
        let mut inputs: Vec<f64> = (0..rows).flat_map(|_| random_point(&system, &mut rng)).collect();
        let bad = bad.index(rows);
        let column = rng.below(n_in);
        let range = system.inputs()[column].range;
        // A NaN, or a value out of range under `OutOfRange::Error`.
        let options = EvalOptions {
            out_of_range: if error_policy { OutOfRange::Error } else { OutOfRange::Clamp },
            ..EvalOptions::default()
        };
        if error_policy {
            // Every other row within range, the bad one beyond it.
            for (k, x) in inputs.iter_mut().enumerate() {
                let r = system.inputs()[k % n_in].range;
                *x = x.clamp(r[0], r[1]);
            }
            inputs[bad * n_in + column] = range[1] + 1.0;
        } else {
            inputs[bad * n_in + column] = f64::NAN;
        }
        let mut evaluator = Evaluator::with_options(system, options).unwrap();
        let mut batch = vec![SENTINEL; rows * n_out];
        let err = evaluator.eval_batch(&inputs, &mut batch).unwrap_err();
        let FuzzyError::Batch { row, source } = &err else {
            panic!("not a batch error: {err:?}");
        };
        prop_assert_eq!(*row, bad);
        let named = match **source {
            FuzzyError::NonFiniteInput { index, .. } => !error_policy && index == column,
            FuzzyError::InputOutOfRange { index, .. } => error_policy && index == column,
            _ => false,
        };
        prop_assert!(named, "{err:?}");
        let mut one = vec![0.0; n_out];
        for (k, (x, y)) in inputs.chunks(n_in).zip(batch.chunks(n_out)).enumerate() {
            if k < bad {
                evaluator.eval(x, &mut one).unwrap();
                prop_assert_eq!(&one[..], y);
            } else {
                prop_assert!(y.iter().all(|&v| v == SENTINEL), "row {k} written");
            }
        }
    }
}

/// The paper's controller over a grid of 9^4 points spanning and exceeding its ranges (clamped):
/// every point as one evaluation gives.
#[test]
fn the_paper_controller_over_a_grid() {
    let mut evaluator = Evaluator::new(paper_controller());
    let axis = |half: f64| (0..9).map(move |k| half * (-1.2 + 0.3 * k as f64));
    let mut inputs = Vec::new();
    for a in axis(0.3) {
        for b in axis(0.3) {
            for c in axis(1.0) {
                for d in axis(1.0) {
                    inputs.extend([a, b, c, d]);
                }
            }
        }
    }
    let mut batch = vec![0.0; inputs.len() / 2];
    evaluator.eval_batch(&inputs, &mut batch).unwrap();
    let mut one = [0.0; 2];
    for (x, y) in inputs.chunks(4).zip(batch.chunks(2)) {
        evaluator.eval(x, &mut one).unwrap();
        assert_eq!(&one[..], y, "at {x:?}");
    }
}

/// A policy that refuses an output (no rule fired) in the middle of a SIMD group.
#[test]
fn no_rule_fired_in_a_group_names_its_row() {
    let options = EvalOptions {
        no_rule_fired: NoRuleFired::Error,
        ..EvalOptions::default()
    };
    // Two triangles on [0, 1] leaving (0.4, 0.6) uncovered.
    let system = fuzzy_sugeno::FuzzySystem::builder("gapped")
        .input(
            "x",
            [0.0, 1.0],
            [
                ("low", fuzzy_sugeno::MembershipFn::triangle(0.0, 0.0, 0.4)),
                ("high", fuzzy_sugeno::MembershipFn::triangle(0.6, 1.0, 1.0)),
            ],
        )
        .output(
            "y",
            [0.0, 10.0],
            [
                ("a", fuzzy_sugeno::OutputFn::Constant(1.0)),
                ("b", fuzzy_sugeno::OutputFn::Constant(9.0)),
            ],
        )
        .rule(["low"], ["a"])
        .rule(["high"], ["b"])
        .build()
        .unwrap();
    let mut evaluator = Evaluator::with_options(system, options).unwrap();
    let mut inputs: Vec<f64> = (0..20)
        .map(|k| if k % 2 == 0 { 0.1 } else { 0.9 })
        .collect();
    inputs[11] = 0.5;
    let mut out = vec![SENTINEL; 20];
    let err = evaluator.eval_batch(&inputs, &mut out).unwrap_err();
    assert!(
        matches!(&err, FuzzyError::Batch { row: 11, source } if matches!(**source, FuzzyError::NoRuleFired { index: 0, .. })),
        "{err:?}"
    );
    assert!(out[..11].iter().all(|&v| v == 1.0 || v == 9.0));
    assert!(out[11..].iter().all(|&v| v == SENTINEL));
}
