//! Spatial-chain dynamics (`manip_dyn::spatial`) per call: forward dynamics by the
//! articulated-body algorithm one state at a time (`spatial_aba`) and in a batch of 1024 states
//! (`spatial_aba_batch`, SIMD across states, throughput in states so that the figure is per
//! state), the analytic ABA derivatives (`spatial_aba_derivatives`: `qdd`, `d qdd / d q`,
//! `d qdd / d v`, `M^-1`) and the analytic RNEA derivatives (`spatial_rnea_derivatives`:
//! `d tau / d q`, `d tau / d v`, `M`, at the state's `tau` taken as `qdd`).
//!
//! And the spatial modal arm of `modal_reduce::spatial` (`reduced_fd_spatial/<n>`: reduced
//! forward dynamics of `n` universal-joint links of 0.1 m and 0.1 kg as slender rods, `K = 1`
//! harmonic per plane so `m = 4`, gravity along `-z`, at a moving state; Pinocchio's
//! `pinocchio/reduced_fd_spatial/<n>` times CRBA + NLE + `J^T M J` + Cholesky on the same arm's
//! URDF export), one state at a time and in a batch of 1024 states (`reduced_fd_spatial_batch`,
//! per state).
//!
//! Two chains, read from the URDF files Pinocchio's harness reads (`benches/pinocchio/`, the
//! anchors `pinocchio/spatial_*/<name>` of `docs/performance.md`): the 10-link universal-joint
//! snake (`snake20`: 20 revolute joints alternating `z` and `y`, each yaw joint moving a massless
//! cross, each pitch joint a 0.1 m, 0.1 kg link) and a 7-joint chain of fixed pseudo-random axes,
//! origins and inertias, one joint prismatic (`random7`), under gravity `[0, 0, -9.81]`, at a
//! moving state.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use manip_dyn::spatial::{
    SpatialBatchData, SpatialData, SpatialDerivativeData, SpatialModel, aba, aba_batch,
    aba_derivatives, rnea_derivatives,
};
use modal_reduce::spatial::{
    SpatialReducedBatchData, SpatialReducedData, SpatialReducedModel, spatial_forward_dynamics,
    spatial_forward_dynamics_batch,
};
use std::hint::black_box;

/// The spatial chain of a URDF file of `benches/pinocchio/`.
fn from_urdf(text: &str) -> SpatialModel {
    let robot = robot_desc::read_urdf(text).unwrap().robot;
    robot_desc::to_spatial(&robot, [0.0, 0.0, -9.81]).unwrap()
}

/// A chain at a moving state, with small efforts.
struct Case {
    name: &'static str,
    model: SpatialModel,
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
}

fn cases() -> [Case; 2] {
    [
        ("snake20", include_str!("../pinocchio/snake20.urdf")),
        ("random7", include_str!("../pinocchio/random7.urdf")),
    ]
    .map(|(name, urdf)| {
        let model = from_urdf(urdf);
        let n = model.n_links();
        let s = |i: usize, k: f64| (k * i as f64 / n as f64 + 0.3).sin();
        Case {
            name,
            q: (0..n).map(|i| 0.3 * s(i, 6.0)).collect(),
            v: (0..n).map(|i| 0.5 * s(i, 3.0)).collect(),
            tau: (0..n).map(|i| 0.01 * s(i, 2.0)).collect(),
            model,
        }
    })
}

fn spatial_aba(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial_aba");
    for case in cases() {
        let mut data = SpatialData::new(&case.model);
        let mut out = vec![0.0; case.model.n_links()];
        group.bench_function(BenchmarkId::from_parameter(case.name), |b| {
            b.iter(|| {
                let (q, v, tau) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                aba(&case.model, &mut data, q, v, tau, &mut out).unwrap();
                black_box(out[0])
            })
        });
    }
    group.finish();
}

/// States in `spatial_aba_batch`.
const BATCH: usize = 1024;

fn spatial_aba_batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial_aba_batch");
    group.throughput(Throughput::Elements(BATCH as u64));
    for case in cases() {
        let n = case.model.n_links();
        let mut data = SpatialBatchData::new(&case.model);
        let spread = |x: &[f64]| -> Vec<f64> {
            (0..BATCH)
                .flat_map(|s| x.iter().map(move |x| x * (1.0 + 1e-3 * s as f64)))
                .collect()
        };
        let (q, v, tau) = (spread(&case.q), spread(&case.v), spread(&case.tau));
        let mut out = vec![0.0; n * BATCH];
        group.bench_function(BenchmarkId::from_parameter(case.name), |b| {
            b.iter(|| {
                aba_batch(&case.model, &mut data, black_box(&q), &v, &tau, &mut out).unwrap();
                black_box(out[0])
            })
        });
    }
    group.finish();
}

fn spatial_aba_derivatives(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial_aba_derivatives");
    for case in cases() {
        let mut data = SpatialData::new(&case.model);
        let mut derivatives = SpatialDerivativeData::new(&case.model);
        group.bench_function(BenchmarkId::from_parameter(case.name), |b| {
            b.iter(|| {
                let (q, v, tau) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                aba_derivatives(&case.model, &mut data, &mut derivatives, q, v, tau).unwrap();
                black_box(derivatives.value()[0])
            })
        });
    }
    group.finish();
}

fn spatial_rnea_derivatives(c: &mut Criterion) {
    let mut group = c.benchmark_group("spatial_rnea_derivatives");
    for case in cases() {
        let mut data = SpatialData::new(&case.model);
        let mut derivatives = SpatialDerivativeData::new(&case.model);
        group.bench_function(BenchmarkId::from_parameter(case.name), |b| {
            b.iter(|| {
                let (q, v, qdd) = (black_box(&case.q), black_box(&case.v), black_box(&case.tau));
                rnea_derivatives(&case.model, &mut data, &mut derivatives, q, v, qdd).unwrap();
                black_box(derivatives.d_q()[(0, 0)])
            })
        });
    }
    group.finish();
}

/// The spatial modal arm of `n` links (`m = 4`) and its moving state `(a, a_dot, tau*)`: those
/// whose URDF export and map `benches/pinocchio/spatial.cpp` times.
fn spatial_arm_state(n: usize) -> (SpatialReducedModel, [Vec<f64>; 3]) {
    (hrm_benches::spatial_arm(n), hrm_benches::spatial_state())
}

fn reduced_fd_spatial(c: &mut Criterion) {
    let mut group = c.benchmark_group("reduced_fd_spatial");
    for n in [10, 100] {
        let (model, [a, a_dot, tau_star]) = spatial_arm_state(n);
        let mut data = SpatialReducedData::new(&model);
        let mut a_ddot = [0.0; 4];
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                let (a, a_dot) = (black_box(&a), black_box(&a_dot));
                spatial_forward_dynamics(&model, &mut data, a, a_dot, &tau_star, &mut a_ddot)
                    .unwrap();
                black_box(a_ddot[0])
            })
        });
    }
    group.finish();
}

fn reduced_fd_spatial_batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("reduced_fd_spatial_batch");
    group.throughput(Throughput::Elements(BATCH as u64));
    for n in [10, 100] {
        let (model, state) = spatial_arm_state(n);
        let [a, a_dot, tau_star] = state.map(|x| {
            (0..BATCH)
                .flat_map(|s| {
                    x.iter()
                        .map(move |x| x * (1.0 + 1e-3 * s as f64))
                        .collect::<Vec<_>>()
                })
                .collect::<Vec<f64>>()
        });
        let mut data = SpatialReducedBatchData::new(&model);
        let mut out = vec![0.0; a.len()];
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                spatial_forward_dynamics_batch(
                    &model,
                    &mut data,
                    black_box(&a),
                    &a_dot,
                    &tau_star,
                    &mut out,
                )
                .unwrap();
                black_box(out[0])
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    reduced_fd_spatial,
    reduced_fd_spatial_batch,
    spatial_aba,
    spatial_aba_batch,
    spatial_aba_derivatives,
    spatial_rnea_derivatives
);
criterion_main!(benches);
