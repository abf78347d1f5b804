//! The closed loop allocates per run, never per step: the number of allocations of a run does
//! not depend on how many steps it takes.

use sim_study::{Alpha0, ControllerKind, NoiseSpec, ReferenceSpec, Scenario};
use test_support::alloc::{allocations_during, is_counting};

/// Allocations made by one run of `scenario` cut to `duration` seconds (building excluded).
fn allocations(scenario: &Scenario, duration: f64) -> usize {
    let mut scenario = scenario.clone();
    scenario.duration = duration;
    let mut simulation = scenario.build().unwrap();
    let mut steps = 0;
    let count = allocations_during(|| steps = simulation.run().unwrap().summary.steps);
    assert!(steps > 0);
    count
}

#[test]
fn allocations_do_not_grow_with_the_number_of_steps() {
    assert!(is_counting());
    for kind in ControllerKind::ALL {
        for name in ["paper-tracking", "paper-responses-noise"] {
            let mut scenario = Scenario::builtin(name).unwrap();
            scenario.controller.kind = kind;
            scenario.noise.sensor_a_std = Some(vec![1e-3, 1e-3]);
            let (short, long) = (allocations(&scenario, 0.05), allocations(&scenario, 0.5));
            assert_eq!(
                short, long,
                "{name} with {kind}: {short} vs {long} allocations"
            );
        }
    }
    // Actuator limits that clamp part of the time: the clamp and its flags reuse their buffers.
    for kind in ControllerKind::ALL {
        let mut limited = Scenario::builtin("paper-tracking").unwrap();
        limited.controller.kind = kind;
        limited.limits.tau_star = Some(sim_study::ModalTorqueLimit::PerCoordinate(vec![3.0, 2.0]));
        assert_eq!(
            allocations(&limited, 0.05),
            allocations(&limited, 0.5),
            "{kind} with limits"
        );
    }
    let mut adaptive = Scenario::builtin("paper-responses-step").unwrap();
    adaptive.integrator = sim_study::IntegratorSpec::Dopri5 {
        rtol: 1e-9,
        atol: 1e-12,
        h_max: None,
        max_steps: None,
    };
    assert_eq!(allocations(&adaptive, 0.05), allocations(&adaptive, 0.5));
    // A 100-link arm: the per-step work is O(n) and still allocation-free.
    let mut large = Scenario::builtin("paper-responses-sine").unwrap();
    large.arm.links = Some(100);
    large.arm.link_length = Some(0.01);
    large.arm.link_mass = Some(0.01);
    assert_eq!(allocations(&large, 0.05), allocations(&large, 0.5));
    // Every modal family of m = 2, 3, 4, 5 coordinates, on a constant reference with noise and on
    // the paper's path (through the numerical continuation for m > 2).
    for m in 2..=5 {
        for kind in ControllerKind::ALL {
            for name in ["paper-responses-sine", "paper-tracking"] {
                let mut scenario = Scenario::builtin(name).unwrap();
                scenario.modal.harmonics = m / 2;
                if m % 2 == 1 {
                    scenario.alpha0 = Some(Alpha0::Free);
                }
                scenario.controller.kind = kind;
                scenario.noise = NoiseSpec::uniform(m, 1e-3, 1e-2, 1e-3);
                if name == "paper-responses-sine" {
                    let mut a = vec![0.1; m];
                    a[m - 1] = if m % 2 == 1 { 1.5 } else { -0.1 };
                    scenario.reference = ReferenceSpec::Constant { a };
                }
                let (short, long) = (allocations(&scenario, 0.05), allocations(&scenario, 0.5));
                assert_eq!(short, long, "{name}, m = {m}, {kind}: {short} vs {long}");
            }
        }
    }
}

/// A constant push on the last joint and a running sum of `a1`: hooks that allocate nothing.
struct PushAndSum {
    sum: f64,
}

impl sim_core::LoopHooks for PushAndSum {
    fn disturbance(
        &mut self,
        _t: f64,
        _state: &sim_core::controller::ModalState,
        tau: &mut [f64],
    ) -> bool {
        tau.fill(0.0);
        tau[tau.len() - 1] = 0.01;
        true
    }

    fn observe(&mut self, sample: &sim_core::ControlSample) {
        self.sum += sample.state.a[0];
    }
}

/// The loop with hooks allocates per run, never per step, as without.
#[test]
fn hooks_allocate_nothing_per_step() {
    assert!(is_counting());
    let count = |duration: f64| {
        let mut scenario = Scenario::builtin("paper-tracking").unwrap();
        scenario.duration = duration;
        let mut simulation = scenario.build().unwrap();
        let mut hooks = PushAndSum { sum: 0.0 };
        let count = allocations_during(|| {
            simulation.run_with(&mut hooks).unwrap();
        });
        assert!(hooks.sum != 0.0);
        count
    };
    assert_eq!(count(0.05), count(0.5));
}

/// A lock-step group allocates per run, never per step: stepping it by hand allocates nothing,
/// and a whole run of the group as much for 0.05 s as for 0.5 s.
#[test]
fn lock_step_groups_allocate_nothing_per_step() {
    assert!(is_counting());
    let group = |duration: f64| {
        let mut scenario = Scenario::builtin("paper-tracking").unwrap();
        scenario.duration = duration;
        scenario.noise.sensor_a_std = Some(vec![1e-3, 1e-3]);
        let noise = scenario.run_noise().unwrap();
        let noises: Vec<_> = (0..11)
            .map(|seed| sim_core::RunNoise {
                seed,
                ..noise.clone()
            })
            .collect();
        scenario.prepare().unwrap().lockstep(&noises).unwrap()
    };
    let mut stepped = group(0.5);
    stepped.step();
    let count = allocations_during(|| {
        for _ in 0..100 {
            assert_eq!(stepped.step(), 11);
        }
    });
    assert_eq!(count, 0);
    let (mut short, mut long) = (group(0.05), group(0.5));
    let runs = |g: &mut sim_core::Lockstep| {
        allocations_during(|| assert!(g.run().iter().all(Result::is_ok)))
    };
    assert_eq!(runs(&mut short), runs(&mut long));
}

/// MPC planning within joint torque and angle limits and the clearance margin (`narrow-gap`,
/// its plan made when the scenario is built) allocates per run, never per step.
#[test]
fn mpc_within_limits_and_clearance_allocates_nothing_per_step() {
    assert!(is_counting());
    let mut scenario = Scenario::builtin("narrow-gap").unwrap();
    scenario.controller.kind = ControllerKind::Mpc;
    scenario.limits.joint_torque_nm = Some(sim_study::TorqueLimit::All(10.0));
    scenario.limits.joint_angle_rad = Some(sim_study::AngleLimit::All(3.0));
    assert_eq!(allocations(&scenario, 0.05), allocations(&scenario, 0.5));
}

/// The deployment's joint-space loop (`pipe-deploy`, `run_chain_loop_mpc` with
/// `controller.kind = "mpc"` and `run_chain_loop` with computed torque) and its metrics
/// allocate per run, never per step.
#[test]
fn deployment_mpc_allocates_nothing_per_step() {
    assert!(is_counting());
    let deploy_allocations = |scenario: &Scenario, duration: f64| {
        let mut scenario = scenario.clone();
        scenario.duration = duration;
        let mut samples = 0;
        let count = allocations_during(|| {
            samples = scenario
                .run_deploy()
                .unwrap()
                .run
                .summary
                .controller_samples;
        });
        assert!(samples > 1);
        count
    };
    for kind in [ControllerKind::Mpc, ControllerKind::ComputedTorque] {
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.controller.kind = kind;
        let (short, long) = (
            deploy_allocations(&scenario, 0.02),
            deploy_allocations(&scenario, 0.2),
        );
        assert_eq!(short, long, "{kind}: {short} vs {long} allocations");
    }
}
