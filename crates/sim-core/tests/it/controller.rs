//! Controllers against independent facts: the hand-computed slope of the paper's fuzzy system,
//! the fuzzy system evaluated directly, and the reduced forward dynamics for computed torque and
//! gravity compensation, for every modal family of `m = 2, 3, 4, 5` coordinates.

use backbone_kin::{BaseAngle, ModalMap};
use fuzzy_sugeno::{Evaluator, paper_controller};
use manip_dyn::ChainModel;
use modal_reduce::{ReducedData, ReducedModel, forward_dynamics};
use optimal_ctl::Linearisation;
use proptest::prelude::*;
use sim_core::SimError;
use sim_core::controller::{
    ComputedTorque, ControlContext, Controller, FuzzyController, LqrController, ModalState,
    PdController,
};
use sim_core::reference::{ReferenceSample, Step};
use sim_core::{Integrator, LoopSettings, Simulation};

/// The paper's arm with `m` coordinates: `K = m / 2` harmonics, `alpha0` free when `m` is odd.
fn model(m: usize) -> ReducedModel {
    let base = if m.is_multiple_of(2) {
        BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)
    } else {
        BaseAngle::Free
    };
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::uniform(10, m / 2, base).unwrap(),
    )
    .unwrap()
}

/// `controller`'s torque for `model` at `measured` and `reference`.
fn control(
    controller: &mut dyn Controller,
    model: &ReducedModel,
    measured: &ModalState,
    reference: &ReferenceSample,
) -> Result<Vec<f64>, SimError> {
    let mut tau = vec![0.0; model.n_coords()];
    let ctx = ControlContext {
        t: 0.0,
        measured,
        reference,
        model: model.into(),
        tau_star_limits: None,
    };
    controller
        .control(&ctx, &mut tau)
        .map_err(|e| SimError::from_controller(0.0, e))?;
    Ok(tau)
}

fn accelerations(model: &ReducedModel, state: &ModalState, tau: &[f64]) -> Vec<f64> {
    let mut data = ReducedData::new(model);
    let mut a_ddot = vec![0.0; tau.len()];
    forward_dynamics(model, &mut data, &state.a, &state.a_dot, tau, &mut a_ddot).unwrap();
    a_ddot
}

#[test]
fn pd_gains_are_the_paper_fuzzy_slope() {
    // By hand: at the origin each bell is 1/2 with slope -+1/r, so d tau1/d da1 =
    // (1/2r)(-(VP + P) + (N + VN)) = -180/0.3 and d tau1/d a1_dot = (1/2)(-(VP + N) + (P + VN)).
    // Per pair for more coordinates; a free alpha0 (last of an odd m) takes a1's rules.
    let expected: [(&[f64], &[f64]); 4] = [
        (&[600.0, 300.0], &[20.0, 10.0]),
        (&[600.0, 300.0, 600.0], &[20.0, 10.0, 20.0]),
        (&[600.0, 300.0, 600.0, 300.0], &[20.0, 10.0, 20.0, 10.0]),
        (
            &[600.0, 300.0, 600.0, 300.0, 600.0],
            &[20.0, 10.0, 20.0, 10.0, 20.0],
        ),
    ];
    for (m, (kp, kd)) in (2..=5).zip(expected) {
        let pd = PdController::from_fuzzy_slope(&paper_controller(), m).unwrap();
        for (got, want) in pd.kp().iter().zip(kp).chain(pd.kd().iter().zip(kd)) {
            assert!((got - want).abs() < 1e-6, "m = {m}: {pd:?}");
        }
        assert_eq!(pd.offset(), vec![0.0; m]);
    }
}

proptest! {
    #[test]
    fn pd_agrees_with_fuzzy_to_second_order_near_the_origin(
        m in 2usize..=5,
        direction in prop::collection::vec(-1.0f64..1.0, 10),
        scale in 1e-4f64..1e-2,
    ) {
        let model = model(m);
        let mut fuzzy = FuzzyController::new(paper_controller(), m).unwrap();
        let mut pd = PdController::from_fuzzy_slope(&paper_controller(), m).unwrap();
        let mut reference = ReferenceSample::zeros(m);
        for (i, a) in reference.a.iter_mut().enumerate() {
            *a = 0.3 - 0.1 * i as f64;
        }
        let a: Vec<f64> = (0..m).map(|i| reference.a[i] + scale * direction[i]).collect();
        let a_dot: Vec<f64> = (0..m).map(|i| scale * direction[m + i]).collect();
        let measured = ModalState::new(&a, &a_dot).unwrap();
        let f = control(&mut fuzzy, &model, &measured, &reference).unwrap();
        let p = control(&mut pd, &model, &measured, &reference).unwrap();
        // The paper's surface is odd, so the remainder is cubic; 1e6 bounds its coefficient
        // (third derivative of the bells ~ 1/r^3 with r = 0.3, times 100 N m).
        for i in 0..m {
            prop_assert!((f[i] - p[i]).abs() < 1e6 * scale.powi(3) + 1e-9, "{f:?} vs {p:?}");
        }
    }

    #[test]
    fn computed_torque_imposes_the_error_dynamics(
        m in 2usize..=5,
        values in prop::collection::vec(-1.0f64..1.0, 25),
    ) {
        let model = model(m);
        let kp: Vec<f64> = (0..m).map(|i| 400.0 + 100.0 * i as f64).collect();
        let kd: Vec<f64> = (0..m).map(|i| 40.0 + 5.0 * i as f64).collect();
        let mut controller = ComputedTorque::new(&model, &kp, &kd).unwrap();
        let v = |k: usize, i: usize, scale: f64| scale * values[k * 5 + i];
        let a: Vec<f64> = (0..m).map(|i| v(0, i, 1.0)).collect();
        let a_dot: Vec<f64> = (0..m).map(|i| v(1, i, 2.0)).collect();
        let measured = ModalState::new(&a, &a_dot).unwrap();
        let reference = ReferenceSample {
            a: (0..m).map(|i| v(2, i, 1.0)).collect(),
            a_dot: (0..m).map(|i| v(3, i, 2.0)).collect(),
            a_ddot: (0..m).map(|i| v(4, i, 2.0)).collect(),
        };
        let tau = control(&mut controller, &model, &measured, &reference).unwrap();
        let a_ddot = accelerations(&model, &measured, &tau);
        for i in 0..m {
            let expected = reference.a_ddot[i] - kp[i] * (a[i] - reference.a[i])
                - kd[i] * (a_dot[i] - reference.a_dot[i]);
            prop_assert!((a_ddot[i] - expected).abs() < 1e-8 * (1.0 + expected.abs()), "{a_ddot:?}");
        }
    }

    #[test]
    fn gravity_compensation_adds_exactly_g_star(
        m in 2usize..=5,
        a in prop::collection::vec(-1.0f64..1.0, 5),
        da in prop::collection::vec(-0.5f64..0.5, 5),
    ) {
        let model = model(m);
        let mut fuzzy = FuzzyController::new(paper_controller(), m).unwrap();
        let mut fuzzy_gc = FuzzyController::new(paper_controller(), m).unwrap()
            .with_gravity_compensation(&model).unwrap();
        let measured = ModalState::new(&a[..m], &vec![0.0; m]).unwrap();
        let mut reference = ReferenceSample::zeros(m);
        for i in 0..m {
            reference.a[i] = a[i] + da[i];
        }
        let plain = control(&mut fuzzy, &model, &measured, &reference).unwrap();
        let compensated = control(&mut fuzzy_gc, &model, &measured, &reference).unwrap();
        // At rest, the difference G* alone holds the arm still.
        let difference: Vec<f64> = compensated.iter().zip(&plain).map(|(c, p)| c - p).collect();
        let a_ddot = accelerations(&model, &measured, &difference);
        prop_assert!(a_ddot.iter().all(|x| x.abs() < 1e-8), "{a_ddot:?}");
    }
}

#[test]
fn fuzzy_controller_is_the_fuzzy_system_per_pair() {
    let mut evaluator = Evaluator::new(paper_controller());
    let a = [0.25, -0.1, 0.05, 0.2, 1.0];
    let a_dot = [0.3, -0.7, 0.2, 0.1, -0.4];
    let a_ref = [0.1, 0.05, -0.05, 0.0, 1.2];
    for m in 2..=5 {
        let model = model(m);
        let mut controller = FuzzyController::new(paper_controller(), m).unwrap();
        let measured = ModalState::new(&a[..m], &a_dot[..m]).unwrap();
        let mut reference = ReferenceSample::zeros(m);
        reference.a.copy_from_slice(&a_ref[..m]);
        let tau = control(&mut controller, &model, &measured, &reference).unwrap();
        // Pairs (a1, a2), (a3, a4); a lone last coordinate takes the first slot.
        let mut expected = vec![0.0; m];
        for p in 0..m.div_ceil(2) {
            let (i, j) = (2 * p, 2 * p + 1);
            let pick = |v: &[f64], w: &[f64], k: usize| if k < m { v[k] - w[k] } else { 0.0 };
            let x = [
                pick(&a, &a_ref, i),
                pick(&a, &a_ref, j),
                a_dot[i],
                pick(&a_dot, &[0.0; 5], j),
            ];
            let mut out = [0.0; 2];
            evaluator.eval(&x, &mut out).unwrap();
            expected[i] = out[0];
            if j < m {
                expected[j] = out[1];
            }
        }
        assert_eq!(tau, expected, "m = {m}");
    }
}

#[test]
fn controllers_refuse_wrong_shapes_and_gains() {
    let (two, three) = (model(2), model(3));
    assert!(matches!(
        ComputedTorque::new(&three, &[1.0; 2], &[1.0; 2]),
        Err(SimError::InvalidSetting { .. })
    ));
    let fuzzy = FuzzyController::new(paper_controller(), 2).unwrap();
    assert!(fuzzy.clone().with_gravity_compensation(&three).is_err());
    assert!(ComputedTorque::new(&two, &[-1.0, 1.0], &[1.0; 2]).is_err());
    assert!(ComputedTorque::new(&two, &[1.0, 1.0], &[f64::NAN, 1.0]).is_err());
    assert!(PdController::new(&[0.0, f64::INFINITY], &[1.0; 2], &[1.0; 2]).is_err());
    assert!(PdController::new(&[0.0; 2], &[1.0; 3], &[1.0; 2]).is_err());
    // A controller built for 2 coordinates, called with 3, fails with a message.
    let mut fuzzy = fuzzy;
    let err = control(
        &mut fuzzy,
        &three,
        &ModalState::zeros(3),
        &ReferenceSample::zeros(3),
    )
    .unwrap_err();
    assert!(err.to_string().contains("built for 2"), "{err}");
    let two_inputs = fuzzy_sugeno::FuzzySystem::builder("small")
        .input(
            "e",
            [-1.0, 1.0],
            [("N", fuzzy_sugeno::MembershipFn::bell(1.0, 2.0, -1.0))],
        )
        .input(
            "v",
            [-1.0, 1.0],
            [("N", fuzzy_sugeno::MembershipFn::bell(1.0, 2.0, -1.0))],
        )
        .output(
            "u",
            [-1.0, 1.0],
            [("A", fuzzy_sugeno::OutputFn::Constant(1.0))],
        )
        .rule(["N", "N"], ["A"])
        .build()
        .unwrap();
    let err = FuzzyController::new(two_inputs.clone(), 2).unwrap_err();
    assert!(err.to_string().contains("must have 4 inputs"), "{err}");
    assert!(PdController::from_fuzzy_slope(&two_inputs, 3).is_err());
    // Two inputs and one output is the shape of one coordinate.
    assert!(FuzzyController::new(two_inputs, 1).is_ok());
}

/// The paper's arm with `m` coordinates without gravity: at rest at `a = 0` eq 15 is the double
/// integrator `M*(0) a_ddot = tau*` to first order.
fn weightless(m: usize) -> ReducedModel {
    let base = if m.is_multiple_of(2) {
        BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)
    } else {
        BaseAngle::Free
    };
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 0.0).unwrap(),
        ModalMap::uniform(10, m / 2, base).unwrap(),
    )
    .unwrap()
}

#[test]
fn lqr_gain_is_the_double_integrator_closed_form_without_gravity() {
    // For M0 a_ddot = tau* with Q = diag(omega^4 M0^2, 0) and R = I the continuous LQR gain is
    // K = M0 [omega^2 I, sqrt(2) omega I]; sampled every h it differs by O(omega h).
    let (omega, h) = (50.0, 1e-4);
    for m in 2..=4 {
        let model = weightless(m);
        let mut lqr = LqrController::new(&model, h, omega, 0.01).unwrap();
        control(
            &mut lqr,
            &model,
            &ModalState::zeros(m),
            &ReferenceSample::zeros(m),
        )
        .unwrap();
        let mut data = ReducedData::new(&model);
        modal_reduce::reduced_terms(&model, &mut data, &vec![0.0; m], &vec![0.0; m]).unwrap();
        let mass = data.mass_matrix();
        let gain = lqr.gain();
        let scale = (0..m).fold(0.0f64, |s, i| s.max(mass[(i, i)])) * omega * omega;
        for i in 0..m {
            for j in 0..m {
                let (kp, kd) = (
                    mass[(i, j)] * omega * omega,
                    mass[(i, j)] * std::f64::consts::SQRT_2 * omega,
                );
                assert!(
                    (gain[(i, j)] - kp).abs() < 0.01 * scale,
                    "m = {m}, K[{i}][{j}] = {} vs {kp}",
                    gain[(i, j)]
                );
                assert!(
                    (gain[(i, m + j)] - kd).abs() < 0.01 * scale / omega,
                    "m = {m}, K[{i}][{}] = {} vs {kd}",
                    m + j,
                    gain[(i, m + j)]
                );
            }
        }
    }
}

#[test]
fn lqr_loop_is_its_linearisation_near_an_equilibrium() {
    // Without gravity a = 0 is an equilibrium with u_ref = 0: from an offset of size eps the
    // nonlinear loop follows x_{k+1} = (A_d - B_d K) x_k up to O(eps^2).
    let (omega, h) = (50.0, 1e-3);
    for m in [2, 3] {
        let model = weightless(m);
        let settings = LoopSettings::new(Integrator::Rk4 { dt: h / 10.0 }, h, 0.1);
        let reference = Step::constant(&vec![0.0; m]).unwrap();
        let eps = 1e-6;
        let a0: Vec<f64> = (0..m).map(|i| eps * (1.0 + i as f64)).collect();
        let initial = ModalState::new(&a0, &vec![0.0; m]).unwrap();
        let controller = LqrController::new(&model, h, omega, 1.0).unwrap();
        let mut lin = Linearisation::new(&model);
        lin.linearise(&model, &vec![0.0; m], &vec![0.0; m], &vec![0.0; m], h)
            .unwrap();
        let mut sim = Simulation::new(
            model,
            Box::new(reference),
            Box::new(controller),
            settings,
            Some(initial),
        )
        .unwrap();
        let run = sim.run().unwrap();
        // The gain, from a controller of its own on the same model.
        let mut probe = LqrController::new(sim.model(), h, omega, 1.0).unwrap();
        control(
            &mut probe,
            sim.model(),
            &ModalState::zeros(m),
            &ReferenceSample::zeros(m),
        )
        .unwrap();
        let (a_d, b_d, k) = (lin.discrete_a(), lin.discrete_b(), probe.gain());
        let n = 2 * m;
        let mut x: Vec<f64> = [a0.clone(), vec![0.0; m]].concat();
        for step in 0..run.record.len() {
            let recorded = [run.record.a_at(step), run.record.a_dot_at(step)].concat();
            let worst = x
                .iter()
                .zip(&recorded)
                .fold(0.0f64, |w, (p, q)| w.max((p - q).abs()));
            assert!(worst < 1e-4 * eps, "m = {m}, step {step}: {worst:e}");
            let u: Vec<f64> = (0..m)
                .map(|i| -(0..n).map(|j| k[(i, j)] * x[j]).sum::<f64>())
                .collect();
            x = (0..n)
                .map(|i| {
                    (0..n).map(|j| a_d[(i, j)] * x[j]).sum::<f64>()
                        + (0..m).map(|j| b_d[(i, j)] * u[j]).sum::<f64>()
                })
                .collect();
        }
        // The loop is stable: the offset has decayed.
        let last = run.record.len() - 1;
        assert!(run.record.a_at(last).iter().all(|a| a.abs() < 0.2 * eps));
    }
}

/// Every model-based controller on a spatial arm (`m = 4`, a cantilever under gravity along
/// `-z`): computed torque realises its desired acceleration through the spatial forward
/// dynamics, the fuzzy controller plus `G*` adds the spatial `G*`, the LQR at rest on a resting
/// reference gives the holding torque `G*`, and MPC plans finite torques within its limits.
#[test]
fn model_based_controllers_run_on_a_spatial_arm() {
    use modal_reduce::spatial::SpatialReducedModel;
    use modal_reduce::{Plant, PlantData};
    use sim_core::controller::MpcController;
    let spatial = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    let plant = Plant::from(&spatial);
    let measured = ModalState::new(&[0.2, -0.1, 0.15, 0.05], &[0.3, 0.0, -0.2, 0.1]).unwrap();
    let mut reference = ReferenceSample::zeros(4);
    reference.a.copy_from_slice(&[0.25, -0.05, 0.1, 0.0]);
    reference.a_ddot.copy_from_slice(&[0.5, -0.2, 0.1, 0.3]);
    let context = |measured, reference| ControlContext {
        t: 0.0,
        measured,
        reference,
        model: plant,
        tau_star_limits: None,
    };
    let (kp, kd) = ([400.0; 4], [40.0; 4]);
    let mut ct = ComputedTorque::new(&spatial, &kp, &kd).unwrap();
    let mut tau = [0.0; 4];
    ct.control(&context(&measured, &reference), &mut tau)
        .unwrap();
    let mut data = PlantData::new(plant);
    let mut a_ddot = [0.0; 4];
    plant
        .forward_dynamics(&mut data, &measured.a, &measured.a_dot, &tau, &mut a_ddot)
        .unwrap();
    for i in 0..4 {
        let desired = reference.a_ddot[i]
            - kp[i] * (measured.a[i] - reference.a[i])
            - kd[i] * (measured.a_dot[i] - reference.a_dot[i]);
        assert!(
            (a_ddot[i] - desired).abs() < 1e-9,
            "{i}: {} vs {desired}",
            a_ddot[i]
        );
    }
    let gravity = data.gravity().to_vec();
    assert!(gravity.iter().any(|g| g.abs() > 0.1), "{gravity:?}");
    let (mut fuzzy, mut fuzzy_gc) = (
        FuzzyController::new(paper_controller(), 4).unwrap(),
        FuzzyController::new(paper_controller(), 4)
            .unwrap()
            .with_gravity_compensation(&spatial)
            .unwrap(),
    );
    let (mut plain, mut compensated) = ([0.0; 4], [0.0; 4]);
    fuzzy
        .control(&context(&measured, &reference), &mut plain)
        .unwrap();
    fuzzy_gc
        .control(&context(&measured, &reference), &mut compensated)
        .unwrap();
    for i in 0..4 {
        assert!((compensated[i] - plain[i] - gravity[i]).abs() < 1e-12);
    }
    // At rest on a resting reference the LQR's feedback vanishes: the feedforward G* holds.
    let mut lqr = LqrController::new(&spatial, 1e-3, 20.0, 0.05).unwrap();
    let rest = ModalState::new(&reference.a, &[0.0; 4]).unwrap();
    let mut resting = reference.clone();
    resting.a_ddot.fill(0.0);
    lqr.control(&context(&rest, &resting), &mut tau).unwrap();
    plant.terms(&mut data, &rest.a, &rest.a_dot).unwrap();
    for (t, g) in tau.iter().zip(data.gravity()) {
        assert!((t - g).abs() < 1e-9 * (1.0 + t.abs()), "{t} vs {g}");
    }
    let mut settings = optimal_ctl::MpcSettings::uniform(4);
    settings.horizon = 10;
    settings.tau_star_limits = Some(vec![5.0; 4]);
    let step = Step::new(&reference.a, &reference.a, 0.0).unwrap();
    let mut mpc = MpcController::new(&spatial, &settings, Box::new(step)).unwrap();
    mpc.control(&context(&measured, &reference), &mut tau)
        .unwrap();
    assert!(
        tau.iter().all(|t| t.is_finite() && t.abs() <= 5.0),
        "{tau:?}"
    );
}
