//! MPC in the loop plans within the clearance margin (`[controller] clearance_m`, the `[task]`'s
//! clearance by default): where MPC within the `tau*` box alone drives a link into an obstacle,
//! MPC within the clearance rows keeps the margin; and the margin's key is refused out of its
//! domain by name.

use backbone_kin::{Branch, chain_inverse_kinematics};
use optimal_ctl::MpcSettings;
use sim_core::controller::MpcController;
use sim_core::reference::Sinusoid;
use sim_study::study::run_one;
use sim_study::{ControllerKind, ReferenceSpec, Scenario, TaskSpec};

/// The time of the unplanned motion (s).
const TRAVEL: f64 = 1.5;

/// The unplanned motion's reference, `a(t) = goal (1 - cos(pi t / T)) / 2`, arriving at `t = T`
/// (the run ends then): offsets, amplitudes, frequencies and phases of a [`Sinusoid`].
fn half_cosine(goal: &[f64]) -> [Vec<f64>; 4] {
    let half: Vec<f64> = goal.iter().map(|g| g / 2.0).collect();
    let m = goal.len();
    [
        half.clone(),
        half.iter().map(|h| -h).collect(),
        vec![0.5 / TRAVEL; m],
        vec![std::f64::consts::FRAC_PI_2; m],
    ]
}

/// `narrow-gap` without its plan: a smooth motion from the straight arm to the closed-form
/// `K = 1` goal (in the scenario's `K = 2` coordinates), a shape with a joint inside an obstacle
/// (`task.rs`), over 1.5 s.
fn unplanned_motion() -> (Scenario, Vec<f64>) {
    let mut scenario = Scenario::builtin("narrow-gap").unwrap();
    let Some(TaskSpec::Reach { target, .. }) = &scenario.task else {
        panic!("narrow-gap has a reach task")
    };
    let target = [target[0], target[1]];
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let a = chain_inverse_kinematics(&[0.1; 10], target, alpha0, Branch::Positive).unwrap();
    let goal = vec![a[0], a[1], 0.0, 0.0];
    scenario.task = None;
    let [offset, amplitude, frequency_hz, phase] = half_cosine(&goal);
    scenario.reference = ReferenceSpec::Sinusoid {
        offset: Some(offset),
        amplitude,
        frequency_hz,
        phase: Some(phase),
    };
    scenario.duration = TRAVEL;
    // The arm held off its goal by the obstacle is far from the reference: no runaway stop.
    scenario.limits.max_modal_error = 100.0;
    (scenario, goal)
}

#[test]
fn mpc_within_the_clearance_rows_keeps_the_margin_where_mpc_within_the_box_collides() {
    let (mut scenario, goal) = unplanned_motion();
    let margin = 0.01;
    scenario.controller.clearance_m = Some(margin);
    // MPC within the tau* box alone (no limits: the controller built by hand).
    let model = scenario.model().unwrap();
    let [offset, amplitude, frequency_hz, phase] = half_cosine(&goal);
    let reference = Sinusoid::new(&offset, &amplitude, &frequency_hz, &phase).unwrap();
    let free = MpcController::new(&model, &MpcSettings::uniform(4), Box::new(reference)).unwrap();
    let run = scenario
        .build_with_controller(Box::new(free))
        .unwrap()
        .run()
        .unwrap_or_else(|f| panic!("{}", f.error));
    let free_clearance = run.summary.min_clearance_m.unwrap();
    assert!(free_clearance < 0.0, "{free_clearance} m");
    // The scenario's MPC plans within the margin.
    let run = run_one(&scenario, ControllerKind::Mpc)
        .result
        .unwrap_or_else(|f| panic!("{}", f.error));
    let clearance = run.summary.min_clearance_m.unwrap();
    // Within 1 mm: the rows are the clearance linearised about each node's predicted
    // coordinates, and between plans the loop applies the plan's feedback unprojected.
    assert!(clearance > margin - 1e-3, "{clearance} m");
    // It is pressed against the margin, not kept away by chance.
    assert!(clearance < margin + 2e-3, "{clearance} m");
}

#[test]
fn the_mpc_clearance_margin_is_refused_out_of_its_domain_by_name() {
    let (scenario, _) = unplanned_motion();
    for (margin, problem) in [
        (-0.01, "must be non-negative and at most 1e3 m, got -0.01"),
        (f64::NAN, "must be non-negative and at most 1e3 m, got NaN"),
        (1e4, "must be non-negative and at most 1e3 m, got 10000"),
    ] {
        let mut s = scenario.clone();
        s.controller.clearance_m = Some(margin);
        let e = s.build().err().unwrap().to_string();
        assert_eq!(e, format!("controller.clearance_m {problem}"));
    }
    let mut free = Scenario::builtin("paper-tracking").unwrap();
    free.controller.clearance_m = Some(0.01);
    let e = free.build().err().unwrap().to_string();
    assert!(
        e.starts_with("controller.clearance_m is a margin to [[obstacles]]"),
        "{e}"
    );
    // Through the file format too.
    let mut text = scenario.to_toml();
    text = text.replace("[controller]\n", "[controller]\nclearance_m = -1.0\n");
    let e = Scenario::from_toml(&text).unwrap().build().err().unwrap();
    assert!(e.to_string().starts_with("controller.clearance_m"), "{e}");
}
