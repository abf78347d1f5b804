//! Analytic derivatives of the dynamics (issue 13): `rnea_derivatives/n` (`d tau / d q`,
//! `d tau / d v` in closed form and `M`), `aba_derivatives/n` (`qdd`, `d qdd / d q`,
//! `d qdd / d v`, `M^-1`), and `reduced_derivatives/10/m<m>` (the reduced forward dynamics and
//! its three `m x m` Jacobians, for `m = 2, 3, 4` coordinates).
//!
//! The chains are the `chain_dynamics` benches' (uniform links of 0.1 m and 0.1 kg at a curled,
//! moving state), the same chain the Pinocchio harness in `benches/pinocchio/` times; the
//! reduced models the paper's arm with one harmonic (`alpha0` fixed: m = 2; free: m = 3) and two
//! harmonics with `alpha0` fixed (m = 4).

use backbone_kin::{BaseAngle, ModalMap};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use manip_dyn::{ChainData, ChainModel, DerivativeData, aba_derivatives, rnea_derivatives};
use modal_reduce::{ReducedData, ReducedDerivatives, ReducedModel, reduced_derivatives};
use std::hint::black_box;

/// An arm of `n` links at a smooth, curled pose, moving, with small torques (as in
/// `chain_dynamics`).
fn state(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let s = |i: usize, k: f64| (k * i as f64 / n as f64).sin();
    (
        (0..n).map(|i| 0.3 * s(i, 6.0)).collect(),
        (0..n).map(|i| 0.5 * s(i, 3.0)).collect(),
        (0..n).map(|i| 0.01 * s(i, 2.0)).collect(),
    )
}

type Derivatives = fn(
    &ChainModel,
    &mut ChainData,
    &mut DerivativeData,
    &[f64],
    &[f64],
    &[f64],
) -> Result<(), manip_dyn::DynError>;

fn chain_group(c: &mut Criterion, name: &str, algorithm: Derivatives) {
    let mut group = c.benchmark_group(name);
    for n in [10, 100] {
        let arm = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap();
        let mut data = ChainData::new(&arm);
        let mut derivatives = DerivativeData::new(&arm);
        let (q, v, u) = state(n);
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| {
                let (q, v, u) = (black_box(&q), black_box(&v), black_box(&u));
                algorithm(&arm, &mut data, &mut derivatives, q, v, u).unwrap();
                black_box(derivatives.d_q()[(n - 1, 0)])
            })
        });
    }
    group.finish();
}

fn rnea(c: &mut Criterion) {
    chain_group(c, "rnea_derivatives", rnea_derivatives);
}

fn aba(c: &mut Criterion) {
    chain_group(c, "aba_derivatives", aba_derivatives);
}

fn reduced(c: &mut Criterion) {
    let mut group = c.benchmark_group("reduced_derivatives");
    let n = 10;
    for (harmonics, base) in [
        (1, BaseAngle::Fixed(1.2)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Fixed(1.2)),
    ] {
        let map = ModalMap::new(&[0.1; 10], harmonics, base).unwrap();
        let model =
            ReducedModel::new(ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap(), map).unwrap();
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let mut derivatives = ReducedDerivatives::new(&model);
        let a: Vec<f64> = [0.4, -0.3, 1.2, 0.1][..m].to_vec();
        let a_dot: Vec<f64> = [0.5, 0.2, -0.1, 0.3][..m].to_vec();
        let tau_star: Vec<f64> = [1.0, -0.5, 0.2, 0.1][..m].to_vec();
        group.bench_function(BenchmarkId::new(n.to_string(), format!("m{m}")), |b| {
            b.iter(|| {
                reduced_derivatives(
                    &model,
                    &mut data,
                    &mut derivatives,
                    black_box(&a),
                    black_box(&a_dot),
                    black_box(&tau_star),
                )
                .unwrap();
                black_box(derivatives.d_a()[(0, 0)])
            })
        });
    }
    group.finish();
}

criterion_group!(benches, rnea, aba, reduced);
criterion_main!(benches);
