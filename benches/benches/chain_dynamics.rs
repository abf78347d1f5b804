//! Full planar-chain dynamics (`manip-dyn`) per step: forward dynamics by the articulated-body
//! algorithm (`full_fd`, O(n); `full_fd_batch/10`, a batch of 1024 states of the 10-link arm,
//! SIMD across states, with Criterion's throughput in states so that `cargo xtask bench`
//! records nanoseconds per state) and through a Cholesky solve of `M` (`fd_cholesky`, O(n^3)), the
//! mass matrix by CRBA (`crba`, O(n^2)), and inverse dynamics by RNEA (`rnea`, O(n)).
//!
//! Chains of `n` uniform links of 0.1 m and 0.1 kg (the paper's links) at a curled, moving
//! state; every call reuses one `ChainData`, as a simulation step does.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use manip_dyn::faer::Mat;
use manip_dyn::{
    AbaBatchData, ChainData, ChainModel, aba, aba_batch, forward_dynamics, mass_matrix, rnea,
};
use std::hint::black_box;

/// An arm of `n` links at a smooth, curled pose, moving, with small torques.
struct Case {
    arm: ChainModel,
    data: ChainData,
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    out: Vec<f64>,
}

impl Case {
    fn new(n: usize) -> Self {
        let arm = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap();
        let data = ChainData::new(&arm);
        let s = |i: usize, k: f64| (k * i as f64 / n as f64).sin();
        Case {
            q: (0..n).map(|i| 0.3 * s(i, 6.0)).collect(),
            v: (0..n).map(|i| 0.5 * s(i, 3.0)).collect(),
            tau: (0..n).map(|i| 0.01 * s(i, 2.0)).collect(),
            out: vec![0.0; n],
            arm,
            data,
        }
    }
}

fn full_fd(c: &mut Criterion) {
    let mut group = c.benchmark_group("full_fd");
    for n in [10, 100, 1000] {
        let mut case = Case::new(n);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                let (q, v, tau) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                aba(&case.arm, &mut case.data, q, v, tau, &mut case.out).unwrap();
                black_box(case.out[n - 1])
            })
        });
    }
    group.finish();
}

/// States in `full_fd_batch/10`.
const BATCH: usize = 1024;

/// A batch of [`BATCH`] different states of the 10-link arm (the state of `full_fd/10` scaled
/// differently in each), per state.
fn full_fd_batch(c: &mut Criterion) {
    let case = Case::new(10);
    let mut data = AbaBatchData::new(&case.arm);
    let batch = |base: &[f64]| {
        (0..BATCH)
            .flat_map(|i| base.iter().map(move |x| x * (1.0 + 0.1 * (i as f64).sin())))
            .collect::<Vec<f64>>()
    };
    let (q, v, tau) = (batch(&case.q), batch(&case.v), batch(&case.tau));
    let mut qdd = vec![0.0; q.len()];
    let mut group = c.benchmark_group("full_fd_batch");
    group.throughput(Throughput::Elements(BATCH as u64));
    group.bench_function("10", |b| {
        b.iter(|| {
            let (q, v, tau) = (black_box(&q), black_box(&v), black_box(&tau));
            aba_batch(&case.arm, &mut data, q, v, tau, &mut qdd).unwrap();
            black_box(&qdd);
        })
    });
    group.finish();
}

fn fd_cholesky(c: &mut Criterion) {
    let mut group = c.benchmark_group("fd_cholesky");
    for n in [10, 100] {
        let mut case = Case::new(n);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                let (q, v, tau) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                forward_dynamics(&case.arm, &mut case.data, q, v, tau, &mut case.out).unwrap();
                black_box(case.out[n - 1])
            })
        });
    }
    group.finish();
}

fn crba(c: &mut Criterion) {
    let mut group = c.benchmark_group("crba");
    for n in [10, 100, 1000] {
        let mut case = Case::new(n);
        let mut m = Mat::<f64>::zeros(n, n);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                mass_matrix(&case.arm, &mut case.data, black_box(&case.q), m.as_mut()).unwrap();
                black_box(m[(0, 0)])
            })
        });
    }
    group.finish();
}

fn rnea_bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("rnea");
    for n in [10, 100, 1000] {
        let mut case = Case::new(n);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                // The torque profile doubles as a smooth acceleration.
                let (q, v, a) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                rnea(&case.arm, &mut case.data, q, v, a, &mut case.out).unwrap();
                black_box(case.out[0])
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    full_fd,
    full_fd_batch,
    fd_cholesky,
    crba,
    rnea_bench
);
criterion_main!(benches);
