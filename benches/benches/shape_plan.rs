//! Shape planning (issue 30): the `narrow-gap` plan of the paper's arm with two harmonics between
//! circles that block both closed-form `K = 1` shapes, and one generated narrow passage.

use backbone_kin::BaseAngle;
use clearance::{ClearanceModel, Obstacle};
use criterion::{Criterion, criterion_group, criterion_main};
use shape_plan::{PassageSpec, PlanOptions, PlanarArm, Planner, narrow_passage};
use std::hint::black_box;

fn plans(c: &mut Criterion) {
    let mut group = c.benchmark_group("shape_plan");
    // The obstacles of crates/sim-study/scenarios/narrow-gap.toml.
    let arm = PlanarArm::new(&[0.1; 10], 2, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)).unwrap();
    let obstacles = vec![
        Obstacle::circle([-0.14, 0.36], 0.03).unwrap(),
        Obstacle::circle([0.32, 0.11], 0.03).unwrap(),
    ];
    let model = ClearanceModel::new(10, 0.01, obstacles).unwrap();
    let options = PlanOptions {
        clearance: 0.01,
        ..PlanOptions::default()
    };
    let mut planner = Planner::new(arm, model, options).unwrap();
    group.bench_function("narrow_gap", |b| {
        b.iter(|| {
            planner
                .plan(black_box(&[0.0; 4]), black_box(&[0.35, 0.55]))
                .unwrap()
        })
    });
    let problem = narrow_passage(&PassageSpec {
        link_lengths: vec![0.1; 10],
        harmonics: 2,
        alpha0: std::f64::consts::FRAC_PI_2,
        radius: 0.01,
        clearance: 0.01,
        gap: 0.005,
        obstacles: 6,
        obstacle_radius: 0.03,
        amplitude: 1.5,
        seed: 1,
    })
    .unwrap();
    let options = PlanOptions {
        clearance: 0.01,
        check_slack: 0.002,
        ..PlanOptions::default()
    };
    let mut planner = Planner::new(problem.arm, problem.clearance_model, options).unwrap();
    group.bench_function("passage_6", |b| {
        b.iter(|| {
            planner
                .plan(black_box(&problem.initial), black_box(&problem.target))
                .unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, plans);
criterion_main!(benches);
