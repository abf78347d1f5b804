//! The whole `paper-tracking` closed loop (`sim-core`): the paper's 10-link arm tracking
//! `y = 0.4 sin(5x) + 0.2` for 5.5 s with the fuzzy controller, RK4 at `dt = 1e-4` s and the
//! controller sampled every step: 55,000 steps, 220,000 reduced forward-dynamics evaluations,
//! 55,001 reference and controller samples, 5,501 recorded samples. No file is written.
//!
//! The simulation is built once (scenario parsing, path checks); each iteration is one
//! complete run from the initial state, recording included. Target: at most 100 ms.
//!
//! `scenario/harmonic_tracking`: the same task with the two-harmonic family (`m = 4`), whose
//! reference comes from the numerical inverse kinematics at every controller sample.
//!
//! `scenario/spatial_tracking_ct`: the shipped `spatial-tracking` (10 universal-joint links,
//! `m = 4`, the tip on a circle out of the arm's plane for 4.5 s) with computed torque, RK4 at
//! `dt = 1e-3` s and the controller sampled every step: 4,500 steps, 18,000 spatial reduced
//! forward-dynamics evaluations and 4,501 computed-torque samples (each evaluates the spatial
//! reduced terms), the reference by continuation. Target: under 0.5 s (issue 29).
//!
//! `scenario_group/alone` and `scenario_group/lockstep`: one SIMD group's worth of
//! `paper-tracking` runs (8 with AVX-512), each with its own seed of sensor noise
//! (`L = 0.01` rad, as a sweep runs them), run one after the other and as one `Lockstep` group
//! whose RK4 stages are evaluated together and whose reference is sampled once for all runs;
//! Criterion's throughput is in runs, so both read as time per run.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sim_core::{RunNoise, Simulation};
use sim_study::{ControllerKind, NoiseSpec, Scenario};
use std::hint::black_box;
use std::time::Duration;

fn paper_tracking(c: &mut Criterion) {
    let scenario = Scenario::builtin("paper-tracking").expect("the shipped scenario parses");
    assert_eq!(scenario.controller.kind, ControllerKind::Fuzzy);
    let mut simulation = scenario.build().expect("the shipped scenario builds");
    let mut group = c.benchmark_group("scenario");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    group.bench_function("paper_tracking", |b| {
        b.iter(|| {
            let run = simulation.run().expect("the paper's scenario runs");
            black_box(run.summary.tip_error_rms_m)
        })
    });
    let harmonic = Scenario::builtin("harmonic-tracking").expect("the shipped scenario parses");
    let mut simulation = harmonic.build().expect("the shipped scenario builds");
    group.bench_function("harmonic_tracking", |b| {
        b.iter(|| {
            let run = simulation.run().expect("the shipped scenario runs");
            black_box(run.summary.tip_error_rms_m)
        })
    });
    let mut spatial = Scenario::builtin("spatial-tracking").expect("the shipped scenario parses");
    spatial.controller.kind = ControllerKind::ComputedTorque;
    let mut simulation = spatial.build().expect("the shipped scenario builds");
    group.bench_function("spatial_tracking_ct", |b| {
        b.iter(|| {
            let run = simulation.run().expect("the shipped scenario runs");
            black_box(run.summary.tip_error_rms_m)
        })
    });
    group.finish();
}

fn paper_tracking_group(c: &mut Criterion) {
    let mut scenario = Scenario::builtin("paper-tracking").expect("the shipped scenario parses");
    let model = scenario.model().expect("the shipped scenario builds");
    let lanes = modal_reduce::batch_lanes(&model);
    scenario.noise = NoiseSpec::uniform(scenario.n_coords(), 0.01, 0.1, 0.0);
    let prepared = scenario.prepare().expect("the shipped scenario builds");
    let noise = scenario.run_noise().expect("the shipped scenario builds");
    let noises: Vec<RunNoise> = (1..=lanes as u64)
        .map(|seed| RunNoise {
            seed,
            ..noise.clone()
        })
        .collect();
    let mut alone: Vec<Simulation> = noises
        .iter()
        .map(|noise| {
            prepared
                .simulation(noise)
                .expect("the shipped scenario builds")
        })
        .collect();
    let mut together = prepared
        .lockstep(&noises)
        .expect("runs of one scenario make a group");
    let mut group = c.benchmark_group("scenario_group");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    group.throughput(Throughput::Elements(lanes as u64));
    group.bench_function("alone", |b| {
        b.iter(|| {
            for simulation in &mut alone {
                let run = simulation.run().expect("the paper's scenario runs");
                black_box(run.summary.tip_error_rms_m);
            }
        })
    });
    group.bench_function("lockstep", |b| {
        b.iter(|| {
            for run in together.run() {
                black_box(
                    run.expect("the paper's scenario runs")
                        .summary
                        .tip_error_rms_m,
                );
            }
        })
    });
    group.finish();
}

criterion_group!(benches, paper_tracking, paper_tracking_group);
criterion_main!(benches);
