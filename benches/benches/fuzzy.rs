//! Fuzzy inference: one evaluation of the paper's controller (4 inputs, 8 bell sets, 16 rules,
//! 2 outputs), and of a first-order system with 2 inputs, 7 bell sets each and 49 rules; and
//! the same systems evaluated at 1024 points by one `eval_batch` (SIMD across points), timed per
//! point (Criterion's throughput).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fuzzy_sugeno::{
    Antecedent, Connective, Evaluator, FuzzySystem, MembershipFn, OutputFn, Rule, paper_controller,
};
use std::hint::black_box;

/// 7 bells (b = 2) evenly spread over [-1, 1]; neighbours cross at degree 1/2.
fn seven_bells() -> Vec<(String, MembershipFn)> {
    (0..7)
        .map(|k| {
            (
                format!("S{k}"),
                MembershipFn::bell(1.0 / 6.0, 2.0, -1.0 + k as f64 / 3.0),
            )
        })
        .collect()
}

/// The 7 x 7 grid of first-order rules `z = p x + q y + r` with distinct coefficients.
fn forty_nine_rules() -> FuzzySystem {
    let terms: Vec<(String, OutputFn)> = (0..49)
        .map(|k| {
            let (i, j) = ((k / 7) as f64, (k % 7) as f64);
            (
                format!("z{k}"),
                OutputFn::Linear {
                    coefficients: vec![1.0 + 0.1 * i, -0.5 + 0.2 * j],
                    constant: i - j,
                },
            )
        })
        .collect();
    let mut builder = FuzzySystem::builder("49rules")
        .input("x", [-1.0, 1.0], seven_bells())
        .input("y", [-1.0, 1.0], seven_bells())
        .output("z", [-10.0, 10.0], terms);
    for k in 0..49 {
        let rule = Rule {
            antecedents: vec![Antecedent::Is(k / 7), Antecedent::Is(k % 7)],
            consequents: vec![Some(k)],
            weight: 1.0,
            connective: Connective::And,
        };
        builder = builder.indexed_rule(rule);
    }
    builder.build().expect("valid by construction")
}

fn fuzzy(c: &mut Criterion) {
    let mut group = c.benchmark_group("fuzzy");
    let mut paper = Evaluator::new(paper_controller());
    let x = [0.12, -0.07, 0.4, -0.25];
    let mut tau = [0.0; 2];
    group.bench_function("paper", |b| {
        b.iter(|| {
            paper.eval(black_box(&x), &mut tau).expect("in range");
            black_box(tau)
        })
    });
    let mut grid = Evaluator::new(forty_nine_rules());
    let xy = [0.31, -0.58];
    let mut z = [0.0];
    group.bench_function("49rules", |b| {
        b.iter(|| {
            grid.eval(black_box(&xy), &mut z).expect("in range");
            black_box(z)
        })
    });
    group.finish();
}

/// Points of a batch.
const BATCH_POINTS: usize = 1024;

/// `BATCH_POINTS` points spread over `[-1.2, 1.2]` times each input's half-range `scale`
/// (some outside the ranges, so clamped).
fn points(scale: &[f64]) -> Vec<f64> {
    (0..BATCH_POINTS * scale.len())
        .map(|k| 1.2 * scale[k % scale.len()] * (0.37 * k as f64).sin())
        .collect()
}

fn fuzzy_batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("fuzzy_batch");
    group.throughput(Throughput::Elements(BATCH_POINTS as u64));
    let mut paper = Evaluator::new(paper_controller());
    let x = points(&[0.3, 0.3, 1.0, 1.0]);
    let mut tau = vec![0.0; 2 * BATCH_POINTS];
    group.bench_function("paper", |b| {
        b.iter(|| {
            paper.eval_batch(black_box(&x), &mut tau).expect("in range");
            black_box(tau[0])
        })
    });
    let mut grid = Evaluator::new(forty_nine_rules());
    let xy = points(&[1.0, 1.0]);
    let mut z = vec![0.0; BATCH_POINTS];
    group.bench_function("49rules", |b| {
        b.iter(|| {
            grid.eval_batch(black_box(&xy), &mut z).expect("in range");
            black_box(z[0])
        })
    });
    group.finish();
}

criterion_group!(benches, fuzzy, fuzzy_batch);
criterion_main!(benches);
