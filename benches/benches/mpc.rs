//! Model-predictive control (issue 13): `mpc/solve_10` is one warm-started MPC solve for the
//! paper's 10-link arm (`alpha0 = pi/2` fixed, m = 2) over the default horizon (60 steps of 5 ms), with
//! `tau*` limits that bind: the previous plan shifted by one step, the references of the new
//! horizon set, and control-limited iLQR run from a state slightly off the previous plan's
//! prediction (at most the default 5 iterations). Preparing the warm start (a clone of the
//! planned workspace) is not timed. `mpc/solve_30` is the same arm (1 m, 1 kg) split into 30
//! links, beside Crocoddyl's solve of the full joint space (benches/crocoddyl/mpc.py, issue 34).
//! `mpc/solve_constrained_10` is the 10-link solve within the joint-torque polytope as well
//! (issue 30: `JointTorqueRows` at every node, each joint's limit 10% below its peak over the
//! free plan, `Mpc::solve_constrained`). `mpc/solve_clearance_10` is the 10-link solve within a
//! clearance margin of 1 cm (links 1 cm thick) to two circles set 5 mm inside that margin of the
//! free plan's links 6 and 10 at its middle node (`sim_core::controller::MpcConstraints`: the
//! linearised clearance rows of the pairs near the margin, active at many nodes).

use backbone_kin::ModalMap;
use clearance::{ClearanceModel, Obstacle};
use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use manip_dyn::ChainModel;
use modal_reduce::ReducedData;
use modal_reduce::ReducedModel;
use optimal_ctl::{JointTorqueRows, Mpc, MpcSettings, StepConstraints};
use sim_core::controller::{MpcConstraints, MpcLimits};
use sim_core::reference::{Reference, ReferenceSample, Sinusoid};
use std::hint::black_box;

/// Sets the references of the horizon starting at `t`.
fn set_references(mpc: &mut Mpc, model: &ReducedModel, reference: &mut Sinusoid, t: f64) {
    let mut sample = ReferenceSample::zeros(2);
    for k in 0..=mpc.horizon() {
        reference
            .sample(t + k as f64 * mpc.step(), &mut sample)
            .unwrap();
        mpc.set_reference(model, k, &sample.a, &sample.a_dot, &sample.a_ddot)
            .unwrap();
    }
}

fn solve(c: &mut Criterion) {
    let mut group = c.benchmark_group("mpc");
    for n in [10, 30] {
        solve_n(&mut group, n);
    }
    group.finish();
}

/// `mpc/solve_<n>`: the arm of 1 m and 1 kg in `n` equal links.
fn solve_n(group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>, n: usize) {
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let size = 1.0 / n as f64;
    let model = ReducedModel::new(
        ChainModel::uniform(n, size, size, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(n, alpha0).unwrap(),
    )
    .unwrap();
    // A brisk motion about the paper's start (a1 ~ 1, a2 ~ 0): 0.3 rad and 0.1 rad at 1 Hz.
    let mut reference = Sinusoid::new(&[1.0, 0.0], &[0.3, 0.1], &[1.0, 1.0], &[0.0, 0.5]).unwrap();
    let mut settings = MpcSettings::uniform(2);
    settings.tau_star_limits = Some(vec![1.5, 0.6]);
    let mut mpc = Mpc::new(&model, &settings).unwrap();
    // The plan at t = 0 from rest at the reference, converged, then the warm start at t = h.
    set_references(&mut mpc, &model, &mut reference, 0.0);
    let mut start = ReferenceSample::zeros(2);
    reference.sample(0.0, &mut start).unwrap();
    for _ in 0..5 {
        mpc.solve(&model, &start.a, &[0.0; 2]).unwrap();
    }
    let predicted = mpc.ilqr().states()[4..8].to_vec();
    let a = [predicted[0] + 2e-3, predicted[1] - 1e-3];
    let a_dot = [predicted[2] + 1e-2, predicted[3]];
    mpc.shift(1);
    let h = mpc.step();
    set_references(&mut mpc, &model, &mut reference, h);
    group.bench_function(format!("solve_{n}"), |b| {
        b.iter_batched_ref(
            || mpc.clone(),
            |mpc| mpc.solve(&model, black_box(&a), black_box(&a_dot)).unwrap(),
            BatchSize::SmallInput,
        )
    });
    if n == 10 {
        solve_clearance_10(group, &mpc, &model, (&a, &a_dot));
        // The same warm start re-planned within joint-torque limits 10% below each joint's peak
        // over the free plan (binding), the constraint memory sized beforehand.
        let limits = plan_peaks(&mpc, &model).map(|peak| 0.9 * peak);
        let rows = JointTorqueRows::new(&model, &limits).unwrap();
        let mut warm = mpc.clone();
        warm.reserve_constraints(rows.max_rows()).unwrap();
        group.bench_function("solve_constrained_10", |b| {
            b.iter_batched_ref(
                || (warm.clone(), rows.clone()),
                |(mpc, rows)| {
                    mpc.solve_constrained(&model, black_box(&a), black_box(&a_dot), rows)
                        .unwrap()
                },
                BatchSize::SmallInput,
            )
        });
    }
}

/// `mpc/solve_clearance_10`: the warm start of `mpc/solve_10` re-planned within a clearance
/// margin that the free plan breaks.
fn solve_clearance_10(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    mpc: &Mpc,
    model: &ReducedModel,
    (a, a_dot): (&[f64; 2], &[f64; 2]),
) {
    let (link_radius, margin, radius) = (0.01, 0.01, 0.03);
    // The free plan's chain at its middle node.
    let ilqr = mpc.ilqr();
    let middle = &ilqr.states()[(ilqr.horizon() / 2) * 4..][..2];
    let mut theta = [0.0; 10];
    model.map().joint_angles(middle, &mut theta).unwrap();
    let mut points = [[0.0; 2]; 11];
    backbone_kin::joint_positions(&[0.1; 10], &theta, &mut points).unwrap();
    // A circle beside the middle of a link, its clearance 5 mm short of the margin.
    let beside = |link: usize, side: f64| {
        let (p, q) = (points[link], points[link + 1]);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let offset = side * (radius + link_radius + margin - 0.005) / dx.hypot(dy);
        Obstacle::circle(
            [
                0.5 * (p[0] + q[0]) - offset * dy,
                0.5 * (p[1] + q[1]) + offset * dx,
            ],
            radius,
        )
        .unwrap()
    };
    let obstacles = vec![beside(5, 1.0), beside(9, -1.0)];
    let limits = MpcLimits {
        clearance: Some(ClearanceModel::new(10, link_radius, obstacles).unwrap()),
        clearance_margin_m: margin,
        ..MpcLimits::default()
    };
    let constraints = MpcConstraints::new(model, &limits, mpc.step())
        .unwrap()
        .unwrap();
    let mut warm = mpc.clone();
    warm.reserve_constraints(constraints.max_rows()).unwrap();
    group.bench_function("solve_clearance_10", |b| {
        b.iter_batched_ref(
            || (warm.clone(), constraints.clone()),
            |(mpc, constraints)| {
                let mut rows = constraints.bind(model.into());
                mpc.solve_constrained(model, black_box(a), black_box(a_dot), &mut rows)
                    .unwrap()
            },
            BatchSize::SmallInput,
        )
    });
}

/// Each joint's largest torque over the nodes of `mpc`'s plan (eq 13 at the planned states).
fn plan_peaks(mpc: &Mpc, model: &ReducedModel) -> [f64; 10] {
    let ilqr = mpc.ilqr();
    let mut data = ReducedData::new(model);
    let (mut a_ddot, mut tau, mut peaks) = ([0.0; 2], [0.0; 10], [0.0f64; 10]);
    for k in 0..ilqr.horizon() {
        let x = &ilqr.states()[k * 4..(k + 1) * 4];
        let u = &ilqr.controls()[k * 2..(k + 1) * 2];
        modal_reduce::forward_dynamics(model, &mut data, &x[..2], &x[2..], u, &mut a_ddot).unwrap();
        modal_reduce::joint_torques(model, &mut data, &x[..2], &x[2..], &a_ddot, &mut tau).unwrap();
        for (p, t) in peaks.iter_mut().zip(tau) {
            *p = p.max(t.abs());
        }
    }
    peaks
}

criterion_group!(benches, solve);
criterion_main!(benches);
