//! Lock-step groups (`Lockstep`, formed by `Prepared::lockstep`) against the same runs one at a
//! time, each built alone by `Simulation::new`: every run of a group, completed or stopped,
//! gives the same record, summary and error, bit for bit, whatever the group's size (smaller
//! than a SIMD group, a whole number of them, with a remainder), however its runs differ (seed,
//! noise level, the state of their controllers) and wherever some of them stop (a controller
//! error, a non-finite torque, dynamics that overflow inside an RK4 stage, a runaway error);
//! the same for the loop stepped by hand, for Dormand-Prince groups and for a sweep's groups,
//! whose runs share their reference samples.

use backbone_kin::ModalMap;
use manip_dyn::ChainModel;
use modal_reduce::{ReducedModel, batch_lanes};
use proptest::prelude::*;
use sim_core::controller::{ControlContext, Controller, ControllerError, PdController};
use sim_core::ode::Tolerances;
use sim_core::reference::Sinusoid;
use sim_core::{
    ControllerFactory, Integrator, Lockstep, LoopSettings, Prepared, RunNoise, Simulation,
};
use sim_study::study::{self, Shard, SweepConfig, SweepSettings};
use sim_study::{NoiseSpec, Scenario};
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use test_support::config::check_scaled;

/// How a scripted run stops.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stop {
    /// It runs to the end (unless its noise throws it past the runaway bound).
    Never,
    /// Its controller fails at `t`.
    ControllerError(f64),
    /// Its controller returns a NaN torque at `t`.
    NanTorque(f64),
    /// Its controller returns `1e300` from `t`: the dynamics overflow inside the RK4 stages.
    HugeTorque(f64),
}

/// A PD law that stops as told.
#[derive(Clone)]
struct Scripted {
    pd: PdController,
    stop: Stop,
}

impl Controller for Scripted {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau: &mut [f64],
    ) -> Result<(), ControllerError> {
        self.pd.control(ctx, tau)?;
        match self.stop {
            Stop::ControllerError(t) if ctx.t >= t => return Err("scripted failure".into()),
            Stop::NanTorque(t) if ctx.t >= t => tau[0] = f64::NAN,
            Stop::HugeTorque(t) if ctx.t >= t => tau.fill(1e300),
            _ => {}
        }
        Ok(())
    }
}

/// One run of a group: its seed, sensor noise (rad) and how it stops.
#[derive(Debug, Clone, Copy)]
struct Spec {
    seed: u64,
    noise: f64,
    stop: Stop,
}

fn paper_model() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

fn sinusoid() -> Sinusoid {
    Sinusoid::new(&[0.3, -0.2], &[0.1, 0.05], &[2.0, 3.0], &[0.0, 1.0]).unwrap()
}

fn scripted(stop: Stop) -> Scripted {
    let pd = PdController::new(&[0.0; 2], &[8.0, 6.0], &[1.0, 0.8]).unwrap();
    Scripted { pd, stop }
}

/// Two RK4 steps per controller period over 0.3 s, recording every other sample, a runaway
/// bound of 0.5 rad, no noise.
fn settings(integrator: Integrator) -> LoopSettings {
    let mut settings = LoopSettings::new(integrator, 2e-3, 0.3);
    settings.record_period = 4e-3;
    settings.max_modal_error = 0.5;
    settings
}

/// A run's seed and sensor noise.
fn noise(spec: Spec) -> RunNoise {
    let n = spec.noise;
    RunNoise {
        seed: spec.seed,
        reference_std: Vec::new(),
        sensor_std: vec![n, n, 10.0 * n, 10.0 * n],
    }
}

/// The paper's arm tracking a sinusoid for 0.3 s under a PD law that stops as `spec` says,
/// built alone.
fn simulation(spec: Spec, integrator: Integrator) -> Simulation {
    Simulation::new(
        paper_model(),
        Box::new(sinusoid()),
        Box::new(scripted(spec.stop)),
        settings(integrator).with_noise(&noise(spec)),
        None,
    )
    .unwrap()
}

/// The runs of `specs` as one group of a prepared simulation whose controller factory hands
/// run `k` the PD law that stops as `specs[k]` says.
fn group(specs: &[Spec], integrator: Integrator) -> Lockstep {
    let stops: Vec<Stop> = specs.iter().map(|s| s.stop).collect();
    let next = AtomicUsize::new(0);
    let controllers: ControllerFactory = Arc::new(move || {
        let k = next.fetch_add(1, Ordering::Relaxed);
        Ok(Box::new(scripted(stops[k])))
    });
    let prepared = Prepared::new(
        paper_model(),
        Prepared::reference_clones(sinusoid()),
        controllers,
        settings(integrator),
        None,
    )
    .unwrap();
    let noises: Vec<RunNoise> = specs.iter().map(|&s| noise(s)).collect();
    prepared.lockstep(&noises).unwrap()
}

const RK4: Integrator = Integrator::Rk4 { dt: 1e-3 };

/// A result as text: `{:?}` writes every `f64` exactly (and a NaN as `NaN`, which `==` would not
/// equal).
fn exact<T: std::fmt::Debug>(value: &T) -> String {
    format!("{value:?}")
}

/// Runs `specs` as one group and one at a time and checks that every result is the same.
/// Returns the errors of the runs that stopped.
fn check_group(specs: &[Spec], integrator: Integrator) -> Vec<String> {
    let mut group = group(specs, integrator);
    assert_eq!(
        group.is_lockstep(),
        matches!(integrator, Integrator::Rk4 { .. }) && batch_lanes(&paper_model()) > 1
    );
    let together = group.run();
    assert_eq!(together.len(), specs.len());
    let mut errors = Vec::new();
    for (k, (spec, result)) in specs.iter().zip(&together).enumerate() {
        let alone = simulation(*spec, integrator).run();
        assert_eq!(exact(result), exact(&alone), "run {k} of {specs:?}");
        if let Err(failure) = result {
            errors.push(failure.error.to_string());
        }
    }
    errors
}

fn stop_strategy() -> impl Strategy<Value = Stop> {
    let at = 0.0..0.3f64;
    prop_oneof![
        4 => Just(Stop::Never),
        1 => at.clone().prop_map(Stop::ControllerError),
        1 => at.clone().prop_map(Stop::NanTorque),
        2 => at.prop_map(Stop::HugeTorque),
    ]
}

fn spec_strategy() -> impl Strategy<Value = Spec> {
    // Noise of 0.05 rad or more may throw a run past its runaway bound.
    let noise = prop_oneof![Just(0.0), 0.0..0.01f64, 0.05..0.3f64];
    (any::<u64>(), noise, stop_strategy()).prop_map(|(seed, noise, stop)| Spec {
        seed,
        noise,
        stop,
    })
}

#[test]
fn groups_of_any_size_give_the_runs_alone_bit_for_bit() {
    check_scaled(16, prop::collection::vec(spec_strategy(), 1..20), |specs| {
        check_group(&specs, RK4);
        Ok(())
    });
}

#[test]
fn runs_that_stop_mid_way_leave_the_others_running() {
    let quiet = |seed| Spec {
        seed,
        noise: 1e-3,
        stop: Stop::Never,
    };
    let lanes = batch_lanes(&paper_model());
    // One of each way to stop, in a group of two SIMD groups and three more.
    let mut specs: Vec<Spec> = (0..2 * lanes as u64 + 3).map(quiet).collect();
    specs[1].stop = Stop::HugeTorque(0.05);
    specs[2].stop = Stop::ControllerError(0.1);
    specs[3].stop = Stop::NanTorque(0.15);
    specs[4].noise = 50.0;
    let last = specs.len() - 1;
    specs[last].stop = Stop::HugeTorque(0.2);
    let errors = check_group(&specs, RK4);
    assert_eq!(errors.len(), 5, "{errors:?}");
    // The torque of 1e300 overflows the dynamics inside an RK4 stage: the batch fails and the
    // group evaluates that stage run by run.
    assert!(
        errors[0].contains("the right-hand side failed"),
        "{}",
        errors[0]
    );
    assert!(errors[1].contains("scripted failure"), "{}", errors[1]);
    assert!(
        errors[2].contains("non-finite modal torque"),
        "{}",
        errors[2]
    );
    assert!(
        errors[3].contains("runaway tracking error"),
        "{}",
        errors[3]
    );
    // Every run stopped but one SIMD group and a remainder of three.
    let mut all: Vec<Spec> = specs.clone();
    for (k, spec) in all.iter_mut().enumerate() {
        spec.stop = Stop::HugeTorque(0.01 * k as f64);
    }
    let errors = check_group(&all, RK4);
    assert_eq!(errors.len(), all.len());
}

#[test]
fn a_group_stepped_by_hand_is_each_run_stepped_alone() {
    let specs: Vec<Spec> = (0..11)
        .map(|k| Spec {
            seed: 100 + k,
            noise: 0.002 * k as f64,
            stop: match k {
                3 => Stop::HugeTorque(0.02),
                7 => Stop::ControllerError(0.04),
                _ => Stop::Never,
            },
        })
        .collect();
    let mut group = group(&specs, RK4);
    let mut alone: Vec<Simulation> = specs.iter().map(|&s| simulation(s, RK4)).collect();
    let mut errors: Vec<Option<String>> = vec![None; specs.len()];
    for _ in 0..50 {
        let running = group.step();
        for (k, run) in alone.iter_mut().enumerate() {
            if errors[k].is_none() {
                errors[k] = run.step().err().map(|e| e.to_string());
            }
            let grouped = group.simulation(k);
            assert_eq!(exact(grouped.state()), exact(run.state()), "run {k}");
            assert_eq!(
                exact(grouped.last_sample()),
                exact(run.last_sample()),
                "run {k}"
            );
            assert_eq!(grouped.samples_taken(), run.samples_taken(), "run {k}");
            assert_eq!(
                group.stopped(k).map(|e| e.to_string()),
                errors[k],
                "run {k}"
            );
            if errors[k].is_none() {
                assert_eq!(
                    exact(&group.observe(k).unwrap()),
                    exact(&run.observe().unwrap())
                );
            }
        }
        assert_eq!(running, errors.iter().filter(|e| e.is_none()).count());
    }
    assert_eq!(group.running(), specs.len() - 2);
    group.reset();
    assert_eq!(group.running(), specs.len());
    assert_eq!(group.simulation(3).samples_taken(), 0);
}

#[test]
fn dormand_prince_groups_integrate_each_run_alone() {
    let adaptive = Integrator::DormandPrince(Tolerances {
        rtol: 1e-8,
        atol: 1e-10,
        ..Tolerances::default()
    });
    let specs: Vec<Spec> = (0..5)
        .map(|k| Spec {
            seed: k,
            noise: 0.003 * k as f64,
            stop: if k == 2 {
                Stop::NanTorque(0.1)
            } else {
                Stop::Never
            },
        })
        .collect();
    assert_eq!(check_group(&specs, adaptive).len(), 1);
}

#[test]
fn a_group_of_no_run_or_of_bad_noise_is_refused() {
    let prepared = Prepared::new(
        paper_model(),
        Prepared::reference_clones(sinusoid()),
        Prepared::controller_clones(scripted(Stop::Never)),
        settings(RK4),
        None,
    )
    .unwrap();
    let refused = |noises: &[RunNoise]| match prepared.lockstep(noises) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a group was built"),
    };
    let err = refused(&[]);
    assert!(err.contains("at least one simulation"), "{err}");
    let spec = Spec {
        seed: 1,
        noise: 0.01,
        stop: Stop::Never,
    };
    let mut short = noise(spec);
    short.sensor_std.pop();
    let err = refused(&[noise(spec), short]);
    assert!(
        err.contains("noise.sensor_std") && err.contains("has 3 entries"),
        "{err}"
    );
    let mut negative = noise(spec);
    negative.reference_std = vec![-1.0, 0.0];
    let err = refused(&[negative]);
    assert!(err.contains("noise.reference_std"), "{err}");
}

/// A sweep's lock-step groups (`study::for_each_run`) give every run as `study::execute` runs
/// it alone: every controller, two noise levels of which one throws runs past their runaway
/// bound mid-way, groups smaller than a SIMD group and larger.
#[test]
fn a_sweep_in_lock_step_gives_every_run_as_run_alone() {
    let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
    scenario.duration = 0.2;
    scenario.limits.max_modal_error = 0.25;
    let lanes = batch_lanes(&scenario.model().unwrap());
    let settings = SweepSettings {
        noise_levels: vec![0.0, 0.02, 2.0],
        seeds: lanes + 3,
        base_seed: 5,
        ..SweepSettings::default()
    };
    let config = SweepConfig::new(scenario, settings).unwrap();
    assert_eq!(study::lockstep_size(&config), lanes);
    for shard in [Shard::WHOLE, Shard { index: 2, count: 3 }] {
        let whole = study::run_shard(&config, shard, || {}).unwrap();
        let indices: Vec<usize> = shard.indices(config.runs().unwrap()).collect();
        assert_eq!(whole.runs.len(), indices.len());
        let mut failed = 0;
        for (run, i) in whole.runs.iter().zip(indices) {
            let alone = study::execute(&config, &config.run_at(i));
            assert_eq!(exact(run), exact(&alone), "run {i}");
            failed += usize::from(matches!(run.outcome, study::StoredOutcome::Failed { .. }));
        }
        assert!(failed > 0, "some runs must stop mid-way");
    }
    // A configuration another version made is not run under this version's name.
    let mut other = config.clone();
    other.hrm_version = "9.9.9".into();
    let error = study::run_shard(&other, Shard::WHOLE, || {}).unwrap_err();
    assert!(
        error
            .to_string()
            .starts_with("hrm_version: the sweep was configured by hrm 9.9.9, this is hrm "),
        "{error}"
    );
}

/// The runs of one prepared scenario that differ in noise and seed share their reference
/// samples (here a path followed by inverse kinematics, with reference noise too) and still give
/// each run alone, built from its own scenario.
#[test]
fn runs_of_one_reference_share_its_samples_and_give_each_run_alone() {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = 0.05;
    let m = scenario.n_coords();
    let scenarios: Vec<Scenario> = (0..5)
        .map(|k| {
            let mut run = scenario.clone();
            run.seed = k + 1;
            run.noise = NoiseSpec::uniform(m, 1e-3 * k as f64, 1e-2, 0.5);
            run
        })
        .collect();
    let noises: Vec<RunNoise> = scenarios.iter().map(|s| s.run_noise().unwrap()).collect();
    let mut group = scenario.prepare().unwrap().lockstep(&noises).unwrap();
    for (k, (together, scenario)) in group.run().iter().zip(&scenarios).enumerate() {
        let alone = scenario.build().unwrap().run();
        assert_eq!(exact(together), exact(&alone), "run {k}");
    }
}
