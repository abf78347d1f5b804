//! Reduced forward dynamics with the paper's three coordinates `(a1, a2, alpha0)`: `M*`, `C*`,
//! `G*` and the Cholesky solve of eq 15, by the default `O(n m^2)` modal recursion
//! (`reduced_fd/n`) and by projecting the full chain's `M`, `C`, `G` with faer
//! (`reduced_fd_projection/n`, `O(n^2 m)`). Arms of `n` equal links with total length 1 m, mass 1 kg.
//! `reduced_fd/10_k2`: the 10-link arm with two harmonics and `alpha0` fixed (`m = 4`).
//! `reduced_fd/10000` and `/1000000`: the default path far beyond the faer path's limit of 4096
//! links. `reduced_fd_batch/10`: a batch of 1024 states of the 10-link arm, SIMD across states;
//! Criterion's throughput is set to the states, so `cargo xtask bench` records nanoseconds per
//! state.

use backbone_kin::{BaseAngle, ModalMap};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use manip_dyn::ChainModel;
use modal_reduce::{
    ReducedBatchData, ReducedData, ReducedModel, forward_dynamics, forward_dynamics_batch,
    forward_dynamics_by_projection,
};
use std::hint::black_box;

/// Sizes of both paths.
const SIZES: [usize; 3] = [10, 100, 1000];
/// Sizes of the default path only, with Criterion's fewest samples (a call takes milliseconds).
const LARGE_SIZES: [usize; 2] = [10_000, 1_000_000];
/// States in `reduced_fd_batch/10`.
const BATCH: usize = 1024;
const A: [f64; 3] = [0.4, -0.3, 1.2];
const A_DOT: [f64; 3] = [0.5, 0.2, -0.1];
const TAU_STAR: [f64; 3] = [1.0, -0.5, 0.2];

/// The paper's arm scaled to `n` links.
fn model(n: usize) -> ReducedModel {
    let link = 1.0 / n as f64;
    ReducedModel::new(
        ChainModel::uniform(n, link, link, 9.81).unwrap(),
        ModalMap::paper(n).unwrap(),
    )
    .unwrap()
}

type ForwardDynamics = fn(
    &ReducedModel,
    &mut ReducedData,
    &[f64],
    &[f64],
    &[f64],
    &mut [f64],
) -> Result<(), modal_reduce::ReduceError>;

fn bench_group(c: &mut Criterion, name: &str, solve: ForwardDynamics, sizes: &[(usize, usize)]) {
    let mut group = c.benchmark_group(name);
    for &(n, sample_size) in sizes {
        group.sample_size(sample_size);
        let model = model(n);
        let mut data = ReducedData::new(&model);
        let mut a_ddot = [0.0; 3];
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                solve(
                    &model,
                    &mut data,
                    black_box(&A),
                    black_box(&A_DOT),
                    black_box(&TAU_STAR),
                    &mut a_ddot,
                )
                .unwrap();
                black_box(a_ddot)
            })
        });
    }
    group.finish();
}

fn reduced_fd(c: &mut Criterion) {
    let sizes: Vec<(usize, usize)> = SIZES
        .iter()
        .map(|&n| (n, 100))
        .chain(LARGE_SIZES.iter().map(|&n| (n, 10)))
        .collect();
    bench_group(c, "reduced_fd", forward_dynamics, &sizes);
}

/// A batch of [`BATCH`] different states of the 10-link arm, per state.
fn reduced_fd_batch(c: &mut Criterion) {
    let model = model(10);
    let mut data = ReducedBatchData::new(&model);
    let spread = |base: [f64; 3], i: usize| base.map(|x| x * (1.0 + 0.1 * (i as f64).sin()));
    let batch = |base| {
        (0..BATCH)
            .flat_map(|i| spread(base, i))
            .collect::<Vec<f64>>()
    };
    let (a, a_dot, tau_star) = (batch(A), batch(A_DOT), batch(TAU_STAR));
    let mut a_ddot = vec![0.0; 3 * BATCH];
    let mut group = c.benchmark_group("reduced_fd_batch");
    group.throughput(Throughput::Elements(BATCH as u64));
    group.bench_function("10", |b| {
        b.iter(|| {
            forward_dynamics_batch(
                &model,
                &mut data,
                black_box(&a),
                black_box(&a_dot),
                black_box(&tau_star),
                &mut a_ddot,
            )
            .unwrap();
            black_box(&a_ddot);
        })
    });
    group.finish();
}

/// The 10-link arm with the two-harmonic family, `alpha0 = pi/2` fixed: `m = 4`.
fn reduced_fd_k2(c: &mut Criterion) {
    let map = ModalMap::uniform(10, 2, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)).unwrap();
    let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(), map).unwrap();
    let mut data = ReducedData::new(&model);
    let (a, a_dot, tau_star) = (
        [0.4, -0.3, 0.1, -0.05],
        [0.5, 0.2, -0.1, 0.05],
        [1.0, -0.5, 0.2, 0.1],
    );
    let mut a_ddot = [0.0; 4];
    let mut group = c.benchmark_group("reduced_fd");
    group.bench_function("10_k2", |b| {
        b.iter(|| {
            forward_dynamics(
                &model,
                &mut data,
                black_box(&a),
                black_box(&a_dot),
                black_box(&tau_star),
                &mut a_ddot,
            )
            .unwrap();
            black_box(a_ddot)
        })
    });
    group.finish();
}

fn reduced_fd_projection(c: &mut Criterion) {
    // Milliseconds per call at n = 1000: fewer samples keep the run short.
    let sizes: Vec<(usize, usize)> = SIZES.iter().map(|&n| (n, 20)).collect();
    bench_group(
        c,
        "reduced_fd_projection",
        forward_dynamics_by_projection,
        &sizes,
    );
}

criterion_group!(
    benches,
    reduced_fd,
    reduced_fd_batch,
    reduced_fd_k2,
    reduced_fd_projection
);
criterion_main!(benches);
