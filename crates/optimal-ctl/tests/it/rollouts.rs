//! iLQR's rollouts that linearise on their way (`Ilqr::solve` without constraints): the
//! Jacobians they leave are those a separate linearisation of the trajectory computes, so a
//! solve whose rollouts cannot linearise (and fall back to stepping) ends on the same bits, and
//! a warm-started solve evaluates each node's dynamics once. The reduced model's Euler map gives
//! the same next state whether stepped or linearised, which the sharing relies on. A planar map
//! with a batch workspace linearises whole trajectories SIMD across nodes instead, to the same
//! bits, so its solves end on the bits of those that linearise on their way.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;
use modal_reduce::spatial::SpatialReducedModel;
use modal_reduce::{Plant, PlantData, PlantDerivatives, ReducedDerivativesBatch, ReducedModel};
use optimal_ctl::{
    DiscreteDynamics, Ilqr, IlqrReport, Mpc, MpcSettings, OptimalError, ReducedEuler,
};

/// `inner`, counting its evaluations (steps and linearisations), with the `linearise` calls whose index (from 0) is in
/// `refused` failing (and evaluating nothing).
struct Counted<'a> {
    inner: ReducedEuler<'a>,
    refused: &'static [usize],
    steps: usize,
    linearisations: usize,
}

impl<'a> Counted<'a> {
    fn new(inner: ReducedEuler<'a>, refused: &'static [usize]) -> Self {
        Self {
            inner,
            refused,
            steps: 0,
            linearisations: 0,
        }
    }
}

impl DiscreteDynamics for Counted<'_> {
    fn state_dim(&self) -> usize {
        self.inner.state_dim()
    }

    fn control_dim(&self) -> usize {
        self.inner.control_dim()
    }

    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError> {
        self.steps += 1;
        self.inner.step(x, u, next)
    }

    fn linearise(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<(), OptimalError> {
        let call = self.linearisations;
        self.linearisations += 1;
        if self.refused.contains(&call) {
            return Err(OptimalError::InvalidSetting {
                name: "test linearisation",
                requirement: "not refused",
                value: call as f64,
            });
        }
        self.inner.linearise(x, u, next, a, b)
    }
}

/// The 10-link arm of 1 m and 1 kg with `alpha0 = pi/2` fixed (`m = 2`).
fn arm() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

/// A sinusoidal reference about `(1, 0)` from `t` over the horizon of `mpc`.
fn set_references(mpc: &mut Mpc, model: &ReducedModel, t: f64) {
    let w = 2.0 * std::f64::consts::PI;
    for k in 0..=mpc.horizon() {
        let s = t + k as f64 * mpc.step();
        let a = [1.0 + 0.3 * (w * s).sin(), 0.1 * (w * s + 0.5).sin()];
        let a_dot = [0.3 * w * (w * s).cos(), 0.1 * w * (w * s + 0.5).cos()];
        let a_ddot = [-w * w * (a[0] - 1.0), -w * w * a[1]];
        mpc.set_reference(model, k, &a, &a_dot, &a_ddot).unwrap();
    }
}

/// A planned MPC of `model` (limits that bind), shifted by one step with the references of the
/// next horizon set, and the state it is next solved from (off the plan's prediction): the warm
/// start of `benches/benches/mpc.rs`.
fn warm_start(model: &ReducedModel) -> (Mpc, [f64; 4]) {
    let mut settings = MpcSettings::uniform(2);
    settings.tau_star_limits = Some(vec![1.5, 0.6]);
    let mut mpc = Mpc::new(model, &settings).unwrap();
    set_references(&mut mpc, model, 0.0);
    // From rest at the reference's start.
    for _ in 0..5 {
        mpc.solve(model, &[1.0, 0.1 * 0.5f64.sin()], &[0.0; 2])
            .unwrap();
    }
    let x = &mpc.ilqr().states()[4..8];
    let x0 = [x[0] + 2e-3, x[1] - 1e-3, x[2] + 1e-2, x[3]];
    mpc.shift(1);
    let h = mpc.step();
    set_references(&mut mpc, model, h);
    (mpc, x0)
}

/// The solve of `ilqr` from `x0` with MPC's settings through [`Counted`] refusing `refused`:
/// the solved workspace, its report, and the counted dynamics' evaluations.
fn solve(
    model: &ReducedModel,
    ilqr: &Ilqr,
    x0: &[f64],
    refused: &'static [usize],
) -> (Ilqr, IlqrReport, usize, usize) {
    let mut ilqr = ilqr.clone();
    let mut data = PlantData::new(model.into());
    let mut derivatives = PlantDerivatives::new(model.into());
    let euler = ReducedEuler::new(model, &mut data, &mut derivatives, 0.005).unwrap();
    let mut dynamics = Counted::new(euler, refused);
    let report = ilqr
        .solve(&mut dynamics, x0, &MpcSettings::uniform(2).solver)
        .unwrap();
    (ilqr, report, dynamics.steps, dynamics.linearisations)
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn rollouts_that_cannot_linearise_end_on_the_same_bits() {
    let model = arm();
    let (mpc, x0) = warm_start(&model);
    let (shared, report, ..) = solve(&model, mpc.ilqr(), &x0, &[]);
    // Call 0 is the warm start's first node (its rollout then steps every node and the solve
    // linearises the 60 nodes: calls 1-60); call 70 is node 9 of the first line search's first
    // trial, which then steps its other nodes.
    let (separate, separate_report, steps, ..) = solve(&model, mpc.ilqr(), &x0, &[0, 70]);
    assert!(
        steps >= 2 * 60 - 10,
        "{steps} steps: the fallbacks did not step"
    );
    assert_eq!(report, separate_report);
    assert!(report.iterations >= 2, "{report:?}");
    assert_eq!(bits(shared.controls()), bits(separate.controls()));
    assert_eq!(bits(shared.states()), bits(separate.states()));
    assert_eq!(bits(shared.gains()), bits(separate.gains()));
}

#[test]
fn a_warm_started_solve_evaluates_each_node_once() {
    let model = arm();
    let (mpc, x0) = warm_start(&model);
    let (_, report, steps, linearisations) = solve(&model, mpc.ilqr(), &x0, &[]);
    let horizon = mpc.horizon();
    // Every line search of this warm start takes its first trial: six rollouts (the warm
    // start's and five line searches'), each node evaluated once a rollout, linearised but in
    // the last (a separate linearisation would evaluate 5 more times 60 nodes).
    assert_eq!(report.iterations, 5, "{report:?}");
    assert_eq!(linearisations, 5 * horizon);
    assert_eq!(steps, horizon);
}

#[test]
fn the_euler_map_linearised_steps_to_the_bits_of_its_step() {
    // m = 2, 3 and 5 (planar), 4 (spatial).
    let spatial = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    let planar = [
        (1, BaseAngle::Fixed(0.3)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Free),
    ]
    .map(|(harmonics, base)| {
        ReducedModel::new(
            ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
            ModalMap::new(&[0.1; 10], harmonics, base).unwrap(),
        )
        .unwrap()
    });
    let plants = planar
        .iter()
        .map(Plant::from)
        .chain([Plant::from(&spatial)]);
    for model in plants {
        let m = model.n_coords();
        let mut data = PlantData::new(model);
        let mut derivatives = PlantDerivatives::new(model);
        let mut euler = ReducedEuler::new(model, &mut data, &mut derivatives, 0.005).unwrap();
        let (n, mut a, mut b) = (2 * m, vec![0.0; 4 * m * m], vec![0.0; 2 * m * m]);
        for sample in 0..20 {
            let s = sample as f64;
            let x: Vec<f64> = (0..n).map(|i| (0.7 * s + 1.3 * i as f64).sin()).collect();
            let u: Vec<f64> = (0..m).map(|i| 0.5 * (0.3 * s - i as f64).cos()).collect();
            let (mut stepped, mut linearised) = (vec![0.0; n], vec![0.0; n]);
            euler.step(&x, &u, &mut stepped).unwrap();
            euler
                .linearise(&x, &u, &mut linearised, &mut a, &mut b)
                .unwrap();
            assert_eq!(
                bits(&stepped),
                bits(&linearised),
                "{} at {x:?}",
                model.family()
            );
        }
    }
}

#[test]
fn trajectories_linearised_in_batches_get_the_bits_of_each_node() {
    // m = 2, 3, 5 and one beyond the batch's kernels (7), over 13 nodes: a last group of fewer
    // nodes than a SIMD register holds.
    for (harmonics, base) in [
        (1, BaseAngle::Fixed(0.3)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Free),
        (3, BaseAngle::Free),
    ] {
        let model = ReducedModel::new(
            ChainModel::uniform(12, 0.1, 0.1, 9.81).unwrap(),
            ModalMap::new(&[0.1; 12], harmonics, base).unwrap(),
        )
        .unwrap();
        let (m, nodes) = (model.n_coords(), 13);
        let (nx, nu) = (2 * m, m);
        let x: Vec<f64> = (0..nodes * nx)
            .map(|i| 0.8 * (0.37 * i as f64).sin())
            .collect();
        let u: Vec<f64> = (0..nodes * nu)
            .map(|i| 0.5 * (0.21 * i as f64).cos())
            .collect();
        let mut data = PlantData::new((&model).into());
        let mut derivatives = PlantDerivatives::new((&model).into());
        let mut work = ReducedDerivativesBatch::new(&model);
        let mut batched = ReducedEuler::new(&model, &mut data, &mut derivatives, 0.005)
            .unwrap()
            .with_batch(&mut work);
        assert_eq!(
            batched.linearises_trajectories(),
            m <= 5 && Plant::from(&model).batch_lanes() > 1
        );
        let (mut a, mut b) = (vec![0.0; nodes * nx * nx], vec![0.0; nodes * nx * nu]);
        let mut next = vec![0.0; nx];
        batched
            .linearise_trajectory(&x, &u, &mut next, &mut a, &mut b)
            .unwrap();
        let (mut a_node, mut b_node) = (vec![0.0; nx * nx], vec![0.0; nx * nu]);
        for k in 0..nodes {
            let (state, control) = (&x[k * nx..(k + 1) * nx], &u[k * nu..(k + 1) * nu]);
            batched
                .linearise(state, control, &mut next, &mut a_node, &mut b_node)
                .unwrap();
            assert_eq!(
                bits(&a[k * nx * nx..(k + 1) * nx * nx]),
                bits(&a_node),
                "m = {m}, node {k}"
            );
            assert_eq!(
                bits(&b[k * nx * nu..(k + 1) * nx * nu]),
                bits(&b_node),
                "m = {m}, node {k}"
            );
        }
        // A node the model refuses is an error, not a silent result.
        let mut bad = x.clone();
        bad[11 * nx + 1] = f64::NAN;
        assert!(
            batched
                .linearise_trajectory(&bad, &u, &mut next, &mut a, &mut b)
                .is_err()
        );
        // Slices of other sizes are refused, the one at fault named.
        let short = &x[..x.len() - 1];
        let error = batched
            .linearise_trajectory(short, &u, &mut next, &mut a, &mut b)
            .unwrap_err();
        assert!(error.to_string().contains("states"), "{error}");
        let error = batched
            .linearise_trajectory(&x, &u, &mut next, &mut a[1..], &mut b)
            .unwrap_err();
        assert!(error.to_string().contains("state Jacobians"), "{error}");
    }
}

#[test]
fn solves_that_linearise_in_batches_end_on_the_bits_of_those_that_linearise_on_their_way() {
    let model = arm();
    let (mpc, x0) = warm_start(&model);
    // `Counted` keeps the trait's node-by-node linearisation: it linearises on its way.
    let (on_the_way, report, ..) = solve(&model, mpc.ilqr(), &x0, &[]);
    let mut batched = mpc.ilqr().clone();
    let mut data = PlantData::new((&model).into());
    let mut derivatives = PlantDerivatives::new((&model).into());
    let mut work = ReducedDerivativesBatch::new(&model);
    let mut dynamics = ReducedEuler::new(&model, &mut data, &mut derivatives, 0.005)
        .unwrap()
        .with_batch(&mut work);
    let batched_report = batched
        .solve(&mut dynamics, &x0, &MpcSettings::uniform(2).solver)
        .unwrap();
    assert_eq!(report, batched_report);
    assert_eq!(bits(on_the_way.controls()), bits(batched.controls()));
    assert_eq!(bits(on_the_way.states()), bits(batched.states()));
    assert_eq!(bits(on_the_way.gains()), bits(batched.gains()));
}
