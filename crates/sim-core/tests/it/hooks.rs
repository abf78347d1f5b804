//! Hooks in the loop (`LoopHooks`): a disturbance torque acts as the same torque added to the
//! plant by another path, at rest without gravity it accelerates the arm by `M*^-1 f` (eq 15,
//! `M*` from the kinetic energy) and does the work `f . (a - a0)` (work-energy theorem); an
//! observer sees every controller sample, in order; hooks that do nothing change nothing; a
//! lock-step group with hooks gives each run with its hooks alone, for planar and spatial arms;
//! forces beyond double precision (a disturbance's, an effort's squares) stop the run, named.

use backbone_kin::ModalMap;
use lane_math::Classify;
use manip_dyn::ChainModel;
use modal_reduce::{ReducedData, ReducedModel};
use sim_core::controller::{ControlContext, Controller, ControllerError, ModalState, PdController};
use sim_core::reference::Step;
use sim_core::{
    ControlSample, Integrator, LoopHooks, LoopSettings, Prepared, RunNoise, SimError, Simulation,
};
use std::f64::consts::FRAC_PI_2;

fn model(gravity: f64) -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, gravity).unwrap(),
        ModalMap::paper_fixed_alpha0(10, FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

fn pd() -> PdController {
    PdController::new(&[0.0; 2], &[20.0, 15.0], &[2.0, 1.5]).unwrap()
}

fn simulation(model: ReducedModel, controller: Box<dyn Controller>) -> Simulation {
    let reference = Step::new(&[0.1, -0.05], &[0.3, -0.2], 0.05).unwrap();
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 5e-4 }, 1e-3, 0.2);
    Simulation::new(model, Box::new(reference), controller, settings, None).unwrap()
}

/// A constant joint torque `tau_d`, from `from` seconds on.
struct Push {
    tau: Vec<f64>,
    from: f64,
}

impl LoopHooks for Push {
    fn disturbance(&mut self, t: f64, _state: &ModalState, tau: &mut [f64]) -> bool {
        if t < self.from {
            return false;
        }
        tau.copy_from_slice(&self.tau);
        true
    }
}

/// `J^T tau` by the map's entries, each sum in joint order from zero.
fn project(map: &ModalMap, tau: &[f64]) -> Vec<f64> {
    let mut f = vec![0.0; map.n_coords()];
    for (i, &t) in tau.iter().enumerate() {
        for (j, f) in f.iter_mut().enumerate() {
            *f += map.entry(i, j) * t;
        }
    }
    f
}

/// A controller plus a constant modal force `f`: the disturbance added to the plant by the
/// controller's path.
struct PlusForce<C> {
    inner: C,
    f: Vec<f64>,
    from: f64,
}

impl<C: Controller> Controller for PlusForce<C> {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau: &mut [f64],
    ) -> Result<(), ControllerError> {
        self.inner.control(ctx, tau)?;
        if ctx.t >= self.from {
            for (tau, f) in tau.iter_mut().zip(&self.f) {
                *tau += f;
            }
        }
        Ok(())
    }
}

#[test]
fn a_disturbance_is_the_same_torque_added_to_the_plant() {
    let tau_d: Vec<f64> = (0..10).map(|i| 0.02 * (i as f64 - 3.5)).collect();
    let from = 0.08;
    let f = project(model(9.81).map(), &tau_d);
    let mut pushed = simulation(model(9.81), Box::new(pd()));
    let hooked = pushed
        .run_with(&mut Push {
            tau: tau_d.clone(),
            from,
        })
        .unwrap();
    let plus = PlusForce {
        inner: pd(),
        f: f.clone(),
        from,
    };
    let added = simulation(model(9.81), Box::new(plus)).run().unwrap();
    let (a, b) = (&hooked.record, &added.record);
    assert_eq!(a.t, b.t);
    assert_eq!(a.a, b.a, "the same plant, bit for bit");
    assert_eq!(a.a_dot, b.a_dot);
    assert_ne!(
        a.a,
        simulation(model(9.81), Box::new(pd()))
            .run()
            .unwrap()
            .record
            .a
    );
    // The recorded joint torques are the actuators': eq 13's less the push.
    let n = tau_d.len();
    for (k, &t) in a.t.iter().enumerate() {
        for (i, &d) in tau_d.iter().enumerate() {
            let (actuator, total) = (a.joint_torques[k * n + i], b.joint_torques[k * n + i]);
            let push = if t >= from { d } else { 0.0 };
            assert!(
                (actuator + push - total).abs() <= 1e-12 * (1.0 + total.abs()),
                "sample {k}, joint {i}: {actuator} + {push} vs {total}"
            );
        }
    }
    // The recorded tau* is the controller's alone: the hooked run's plus f is the other's.
    let m = f.len();
    let last = a.t.len() - 1;
    for (j, f) in f.iter().enumerate() {
        assert_eq!(a.tau_star[last * m + j] + f, b.tau_star[last * m + j]);
    }
}

/// Solves the small dense system `A x = b` by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        let (above, below) = a.split_at_mut(c + 1);
        let pivot = &above[c];
        for (r, row) in below.iter_mut().enumerate() {
            let factor = row[c] / pivot[c];
            for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                *x -= factor * p;
            }
            b[c + 1 + r] -= factor * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let sum: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - sum) / a[r][r];
    }
    x
}

/// No torque at all.
struct Zero;

impl Controller for Zero {
    fn control(
        &mut self,
        _ctx: &ControlContext<'_>,
        tau: &mut [f64],
    ) -> Result<(), ControllerError> {
        tau.fill(0.0);
        Ok(())
    }
}

/// Keeps every sample it is shown.
#[derive(Default)]
struct Tape {
    samples: Vec<ControlSample>,
}

impl LoopHooks for Tape {
    fn observe(&mut self, sample: &ControlSample) {
        self.samples.push(sample.clone());
    }
}

/// A push and a tape.
struct PushAndTape {
    push: Push,
    tape: Tape,
}

impl LoopHooks for PushAndTape {
    fn disturbance(&mut self, t: f64, state: &ModalState, tau: &mut [f64]) -> bool {
        self.push.disturbance(t, state, tau)
    }

    fn observe(&mut self, sample: &ControlSample) {
        self.tape.observe(sample);
    }
}

/// At rest without gravity (`C* = G* = 0`) and without control, a push whose modal force is `f`
/// accelerates the arm by `a_dd = M*^-1 f` (eq 15), `M*` taken from the kinetic energy
/// `T = 1/2 a_dot^T M* a_dot` by polarisation (not from the reduced terms the loop uses), and
/// the constant push does the work `tau_d . (theta - theta0) = f . (a - a0)`, all of which is
/// kinetic energy.
#[test]
fn a_push_at_rest_without_gravity_accelerates_by_the_inverse_mass_matrix() {
    let model = model(0.0);
    let (n, m) = (model.n_links(), model.n_coords());
    let map = model.map().clone();
    // tau_d = J y with J^T J y = f: a joint torque whose modal force is the chosen f.
    let f = vec![0.3, -0.2];
    let jtj: Vec<Vec<f64>> = (0..m)
        .map(|r| {
            (0..m)
                .map(|c| (0..n).map(|i| map.entry(i, r) * map.entry(i, c)).sum())
                .collect()
        })
        .collect();
    let y = solve(jtj, f.clone());
    let tau_d: Vec<f64> = (0..n)
        .map(|i| (0..m).map(|j| map.entry(i, j) * y[j]).sum())
        .collect();
    let mut data = ReducedData::new(&model);
    let reference = Step::constant(&[0.4, -0.1]).unwrap();
    let a0 = vec![0.4, -0.1];
    let mut kinetic = |a: &[f64], a_dot: &[f64]| {
        modal_reduce::kinetic_energy(&model, &mut data, a, a_dot).unwrap()
    };
    let unit = |j: usize| -> Vec<f64> { (0..m).map(|k| f64::from(u8::from(k == j))).collect() };
    let mass: Vec<Vec<f64>> = (0..m)
        .map(|r| {
            (0..m)
                .map(|c| {
                    let both: Vec<f64> = (0..m).map(|k| unit(r)[k] + unit(c)[k]).collect();
                    if r == c {
                        2.0 * kinetic(&a0, &unit(r))
                    } else {
                        kinetic(&a0, &both) - kinetic(&a0, &unit(r)) - kinetic(&a0, &unit(c))
                    }
                })
                .collect()
        })
        .collect();
    let expected = solve(mass, f.clone());
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-3, 0.1);
    let mut sim = Simulation::new(
        model.clone(),
        Box::new(reference),
        Box::new(Zero),
        settings,
        None,
    )
    .unwrap();
    let mut hooks = PushAndTape {
        push: Push {
            tau: tau_d.clone(),
            from: 0.0,
        },
        tape: Tape::default(),
    };
    let run = sim.run_with(&mut hooks).unwrap();
    let first = &hooks.tape.samples[0];
    assert_eq!(first.state.a, a0);
    for j in 0..m {
        assert!(
            (first.disturbance[j] - f[j]).abs() < 1e-12,
            "{:?}",
            first.disturbance
        );
        let scale = expected[j].abs().max(1e-3);
        assert!(
            (first.a_ddot[j] - expected[j]).abs() < 1e-9 * scale,
            "a_dd = {:?}, M*^-1 f = {expected:?}",
            first.a_ddot
        );
    }
    // Work-energy: T(t) = f . (a(t) - a0), to the integrator's accuracy.
    let last = run.record.t.len() - 1;
    let a = &run.record.a[last * m..(last + 1) * m];
    let a_dot = &run.record.a_dot[last * m..(last + 1) * m];
    let mut data = ReducedData::new(&model);
    let energy = modal_reduce::kinetic_energy(&model, &mut data, a, a_dot).unwrap();
    let work: f64 = (0..m).map(|j| first.disturbance[j] * (a[j] - a0[j])).sum();
    assert!(energy > 1e-4, "the push moved the arm: T = {energy}");
    assert!(
        (energy - work).abs() < 1e-8 * energy,
        "T = {energy}, work = {work}"
    );
}

#[test]
fn an_observer_sees_every_controller_sample_in_order() {
    let mut sim = simulation(model(9.81), Box::new(pd()));
    let mut tape = Tape::default();
    let run = sim.run_with(&mut tape).unwrap();
    let samples = &tape.samples;
    assert_eq!(samples.len(), run.summary.controller_samples);
    // The settings say so before the run (a progress bar's length).
    assert_eq!(samples.len(), sim.settings().controller_samples());
    assert_eq!(
        samples.len(),
        run.record.t.len(),
        "every sample is recorded"
    );
    let m = 2;
    for (k, sample) in samples.iter().enumerate() {
        assert_eq!(sample.t, run.record.t[k], "sample {k}");
        assert_eq!(sample.state.a, run.record.a[k * m..(k + 1) * m]);
        assert_eq!(sample.tau_star, run.record.tau_star[k * m..(k + 1) * m]);
        assert_eq!(sample.disturbance, [0.0; 2]);
    }
    let integrated = &samples[..samples.len() - 1];
    assert!(integrated.iter().all(|s| s.steps == (2, 0)));
    assert_eq!(samples.last().unwrap().steps, (0, 0));
    // Stepped by hand: the observer sees what each step returns.
    sim.reset();
    let mut tape = Tape::default();
    for (k, expected) in samples.iter().take(20).enumerate() {
        let sample = sim.step_with(&mut tape).unwrap().clone();
        assert_eq!(tape.samples[k], sample);
        assert_eq!(&sample, expected);
    }
}

#[test]
fn hooks_that_do_nothing_change_nothing() {
    let mut sim = simulation(model(9.81), Box::new(pd()));
    let plain = sim.run().unwrap();
    let watched = sim.run_with(&mut Tape::default()).unwrap();
    assert_eq!(plain, watched);
    let late = Push {
        tau: vec![1.0; 10],
        from: 10.0,
    };
    let mut late = late;
    assert_eq!(sim.run_with(&mut late).unwrap(), plain);
}

#[test]
fn a_non_finite_disturbance_stops_the_run() {
    let mut sim = simulation(model(9.81), Box::new(pd()));
    let mut push = Push {
        tau: vec![f64::NAN; 10],
        from: 0.05,
    };
    let failure = sim.run_with(&mut push).unwrap_err();
    assert!(
        matches!(failure.error, SimError::NonFiniteDisturbance { t, .. } if t == 0.05),
        "{}",
        failure.error
    );
    assert!(failure.error.is_numerical());
    assert_eq!(failure.summary.simulated_s, 0.049);
}

#[test]
fn a_finite_disturbance_whose_modal_force_overflows_is_named() {
    let mut sim = simulation(model(9.81), Box::new(pd()));
    let mut push = Push {
        tau: vec![1e308; 10],
        from: 0.05,
    };
    let failure = sim.run_with(&mut push).unwrap_err();
    assert!(
        matches!(failure.error, SimError::DisturbanceOverflow { t, .. } if t == 0.05),
        "{}",
        failure.error
    );
    let message = failure.error.to_string();
    assert!(
        message
            .starts_with("the disturbance hook's joint torques at t = 0.05 s give a modal force")
            && message.contains("inf"),
        "{message}"
    );
    assert!(failure.error.is_numerical());
}

#[test]
fn a_control_effort_that_overflows_stops_the_run() {
    // Links of 1e300 kg take finite torques of 1e160 N m in their stride, whose squares are not:
    // the effort the summary reports would be infinite, so the run stops naming it.
    let heavy = |push: f64| {
        let model = ReducedModel::new(
            ChainModel::uniform(10, 0.1, 1e300, 9.81).unwrap(),
            ModalMap::paper_fixed_alpha0(10, FRAC_PI_2).unwrap(),
        )
        .unwrap();
        let controller = PlusForce {
            inner: pd(),
            f: vec![push, 0.0],
            from: 0.1,
        };
        simulation(model, Box::new(controller))
    };
    let mut sim = heavy(1e160);
    let failure = sim.run().unwrap_err();
    assert!(
        matches!(failure.error, SimError::EffortOverflow { t, .. } if t == 0.1),
        "{}",
        failure.error
    );
    let message = failure.error.to_string();
    assert!(
        message
            .starts_with("the control effort (the integral of |tau*|^2) overflowed at t = 0.1 s")
            && message.contains("1e160"),
        "{message}"
    );
    assert!(failure.error.is_numerical());
    assert!(failure.summary.control_effort_n2m2s.is_finite());
    // 1e150 N m squares to a finite effort.
    let summary = heavy(1e150).run().unwrap().summary;
    assert!(summary.control_effort_n2m2s.is_finite() && summary.control_effort_n2m2s > 1e297);
}

#[test]
fn a_divergence_shows_the_modal_force_held_over_the_period() {
    // A finite push far beyond the arm's scale: the state leaves double precision within the
    // period, and the message shows the force that drove it there (it named only C*).
    let mut sim = simulation(model(9.81), Box::new(pd()));
    let mut push = Push {
        tau: vec![1e100; 10],
        from: 0.05,
    };
    let failure = sim.run_with(&mut push).unwrap_err();
    let SimError::Integration { tau_star, .. } = &failure.error else {
        panic!("{}", failure.error);
    };
    // The held force is the controller's plus J^T tau_d: of the push's scale.
    assert!(tau_star.iter().any(|f| f.abs() > 1e99), "{tau_star:?}");
    let message = failure.error.to_string();
    assert!(
        message.starts_with("integration diverged under the held modal force tau* = [")
            && message.contains(&format!("{:?}", tau_star[0]))
            && message.contains("N m: the right-hand side failed at t = 0.05"),
        "{message}"
    );
    assert!(failure.error.is_numerical());
}

/// The PD controller on a step of the arm under gravity, prepared for runs of `duration`.
fn prepared_step(duration: f64) -> Prepared {
    let reference = Step::new(&[0.1, -0.05], &[0.3, -0.2], 0.05).unwrap();
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 5e-4 }, 1e-3, duration);
    Prepared::new(
        model(9.81),
        Prepared::reference_clones(reference),
        Prepared::controller_clones(pd()),
        settings,
        None,
    )
    .unwrap()
}

#[test]
fn a_group_with_hooks_gives_each_run_with_its_hooks_alone() {
    let prepared = prepared_step(0.1);
    let noises: Vec<RunNoise> = (0..5)
        .map(|seed| RunNoise {
            seed,
            reference_std: vec![],
            sensor_std: vec![1e-3; 4],
        })
        .collect();
    let hooks = |k: usize| PushAndTape {
        push: Push {
            tau: vec![0.01 * k as f64; 10],
            from: 0.02 * k as f64,
        },
        tape: Tape::default(),
    };
    let mut together: Vec<PushAndTape> = (0..5).map(hooks).collect();
    let results = prepared
        .lockstep(&noises)
        .unwrap()
        .run_with(&mut together)
        .unwrap();
    for (k, noise) in noises.iter().enumerate() {
        let mut alone = hooks(k);
        let run = prepared.simulation(noise).unwrap().run_with(&mut alone);
        assert_eq!(results[k], run, "run {k}");
        assert_eq!(together[k].tape.samples, alone.tape.samples, "run {k}");
    }
}

#[test]
fn a_group_refuses_hooks_that_are_not_one_per_run() {
    let prepared = prepared_step(0.05);
    let noises: Vec<RunNoise> = (0..3)
        .map(|seed| RunNoise {
            seed,
            reference_std: vec![],
            sensor_std: vec![],
        })
        .collect();
    let mut group = prepared.lockstep(&noises).unwrap();
    let mut two: Vec<Tape> = (0..2).map(|_| Tape::default()).collect();
    let error = group.run_with(&mut two).unwrap_err();
    assert!(error.to_string().contains("hooks"), "{error}");
    assert!(error.to_string().contains("3 runs"), "{error}");
    let error = group.step_with(&mut two).unwrap_err();
    assert!(error.to_string().contains("got 2"), "{error}");
    // A refusal leaves the group as it was: with no hooks it runs.
    assert!(group.run().iter().all(Result::is_ok));
}

/// A lock-step group of a spatial arm (`m = 4`, 20 joints, under gravity along `-z`) with
/// computed torque on a step in all four coordinates, sensor noise and a push per run: its
/// stages go through the spatial SIMD batch (on a processor with SIMD) and each run, its record
/// and its hooks' tapes are those of the run alone, bit for bit. Eleven runs: whole SIMD groups,
/// a padded one and, with 8 lanes, a remainder.
#[test]
fn a_spatial_group_gives_each_run_alone() {
    use modal_reduce::Plant;
    use modal_reduce::spatial::SpatialReducedModel;
    use sim_core::controller::ComputedTorque;
    let spatial = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    let lanes = Plant::from(&spatial).batch_lanes();
    let controller = ComputedTorque::new(&spatial, &[400.0; 4], &[40.0; 4]).unwrap();
    let reference = Step::new(&[0.1, -0.05, 0.05, 0.0], &[0.3, -0.2, -0.1, 0.15], 0.02).unwrap();
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 5e-4 }, 1e-3, 0.08);
    let prepared = Prepared::new(
        spatial,
        Prepared::reference_clones(reference),
        Prepared::controller_clones(controller),
        settings,
        None,
    )
    .unwrap();
    let noises: Vec<RunNoise> = (0..11)
        .map(|seed| RunNoise {
            seed,
            reference_std: vec![],
            sensor_std: vec![1e-3; 8],
        })
        .collect();
    let hooks = |k: usize| PushAndTape {
        push: Push {
            tau: (0..20).map(|j| 1e-3 * (k + j % 3) as f64).collect(),
            from: 0.005 * k as f64,
        },
        tape: Tape::default(),
    };
    let mut group = prepared.lockstep(&noises).unwrap();
    assert_eq!(group.is_lockstep(), lanes > 1, "{lanes} lanes");
    let mut together: Vec<PushAndTape> = (0..11).map(hooks).collect();
    let results = group.run_with(&mut together).unwrap();
    for (k, noise) in noises.iter().enumerate() {
        let mut alone = hooks(k);
        let run = prepared.simulation(noise).unwrap().run_with(&mut alone);
        assert!(run.is_ok(), "run {k}: {run:?}");
        assert_eq!(results[k], run, "run {k}");
        assert_eq!(together[k].tape.samples, alone.tape.samples, "run {k}");
    }
}

/// A step whose rate turns NaN from `from` seconds on (a user's reference gone bad).
struct SpoiledStep {
    step: Step,
    from: f64,
}

impl sim_core::reference::Reference for SpoiledStep {
    fn n_coords(&self) -> usize {
        self.step.n_coords()
    }

    fn sample(
        &mut self,
        t: f64,
        s: &mut sim_core::reference::ReferenceSample,
    ) -> Result<(), SimError> {
        self.step.sample(t, s)?;
        if t >= self.from {
            s.a_dot[1] = f64::NAN;
        }
        Ok(())
    }
}

#[test]
fn a_non_finite_reference_stops_the_run_before_the_controller_sees_it() {
    let reference = SpoiledStep {
        step: Step::new(&[0.1, -0.05], &[0.3, -0.2], 0.05).unwrap(),
        from: 0.1,
    };
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 5e-4 }, 1e-3, 0.2);
    let mut sim = Simulation::new(
        model(9.81),
        Box::new(reference),
        Box::new(pd()),
        settings,
        None,
    )
    .unwrap();
    let failure = sim.run().unwrap_err();
    assert_eq!(
        failure.error.to_string(),
        "the reference's a_dot[1] came out NaN at t = 0.1 s: its parameters are beyond double \
         precision"
    );
    assert_eq!(failure.summary.simulated_s, 0.099);
}
