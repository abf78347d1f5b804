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

/// A margin the arm cannot keep (20 cm, 100 m, 1000 m about `narrow-gap`'s planned motion
/// between circles 3 cm from its path): the plans diverge, and the run stops saying so and pointing at the margin
/// rather than at the non-finite dynamics alone.
#[test]
fn a_margin_no_motion_keeps_stops_the_run_naming_the_plan() {
    let mut scenario = Scenario::builtin("narrow-gap").unwrap();
    scenario.duration = 0.5;
    scenario.controller.kind = ControllerKind::Mpc;
    scenario.controller.clearance_m = Some(0.2);
    let failure = scenario.build().unwrap().run().unwrap_err();
    let message = failure.error.to_string();
    assert!(
        message.contains("the plan from the measured state diverged (reduced dynamics: ")
            && message.ends_with(
                "the limits and the clearance margin it keeps may admit no motion from this state"
            ),
        "{message}"
    );
    // Margins up to the largest accepted (1000 m) overflow the penalties of the backward pass
    // itself: the same stop (it read "box QP gradient g must be finite, got NaN").
    for margin in [100.0, 1000.0] {
        scenario.controller.clearance_m = Some(margin);
        let failure = scenario.build().unwrap().run().unwrap_err();
        let message = failure.error.to_string();
        assert!(
            message.contains(
                "the plan from the measured state diverged (the backward pass's gradient Q_u is \
                 not finite"
            ) && message.ends_with("may admit no motion from this state"),
            "{margin}: {message}"
        );
    }
}

/// The paper's arm (`K = 2`) tracking a sinusoid from rest (its rates start 1-3 rad/s off the
/// reference's) with a circle of `radius` at `center` out of its way, by MPC without a `tau*`
/// box within a 1 cm margin, or in free space.
fn sinusoid_beside_a_circle(
    (center, radius): ([f64; 2], f64),
    [amplitude, frequency_hz]: [[f64; 4]; 2],
    with_circle: bool,
) -> Scenario {
    let circle =
        format!("[[obstacles]]\nkind = \"circle\"\ncenter = {center:?}\nradius = {radius}\n");
    let text = format!(
        r#"name = "sinusoid-beside-a-circle"
description = "MPC from rest onto a sinusoid, a circle out of the arm's way"
duration = 0.5
alpha0 = 1.5707963267948966
record_period = 0.001

[modal]
harmonics = 2

[arm]
links = 10
link_length = 0.1
link_mass = 0.1
gravity = 9.81
radius = 0.01

{circles}
[reference]
kind = "sinusoid"
amplitude = {amplitude:?}
frequency_hz = {frequency_hz:?}

[controller]
kind = "mpc"
period = 0.001
{margin}

[integrator]
method = "rk4"
dt = 0.001
"#,
        circles = if with_circle { circle.as_str() } else { "" },
        margin = if with_circle {
            "clearance_m = 0.01"
        } else {
            ""
        },
    );
    Scenario::from_toml(&text).unwrap()
}

/// Plans whose predicted motion (not the arm's) swings near an obstacle in the transient: the
/// warm start moved within the clearance rows diverged (the rows could ask for any torque, and
/// a trajectory thrown far asks for ever more), and the run stopped at its first plan. The
/// barrier's rows now act through the next rate as well as the next position, and a solve whose
/// warm start within the rows diverges or makes no step starts again from it rolled out without
/// them (needed by the second arm, whose runs stopped at t = 0.02 s with the barrier alone). The
/// runs complete and keep the margin; their tracking is within a few times MPC's without the
/// circle (plans near the circle are slower than plans in free space).
#[test]
fn mpc_completes_and_keeps_the_margin_where_its_predicted_transient_nears_an_obstacle() {
    for (circle, reference) in [
        (
            ([0.608, 0.33], 0.052),
            [[-0.171, 0.483, 0.459, 0.418], [1.29, 1.375, 0.5, 1.127]],
        ),
        (
            ([0.319, 0.398], 0.04),
            [[0.081, 0.039, 0.394, 0.483], [1.275, 0.916, 1.035, 1.31]],
        ),
    ] {
        let scenario = sinusoid_beside_a_circle(circle, reference, true);
        let run = run_one(&scenario, ControllerKind::Mpc)
            .result
            .unwrap_or_else(|f| panic!("{circle:?}: {}", f.error));
        let clearance = run.summary.min_clearance_m.unwrap();
        assert!(clearance > 0.01 - 1e-3, "{circle:?}: {clearance} m");
        let free = sinusoid_beside_a_circle(circle, reference, false);
        let free = run_one(&free, ControllerKind::Mpc)
            .result
            .unwrap_or_else(|f| panic!("{circle:?} without the circle: {}", f.error));
        let (tip, free_tip) = (run.summary.tip_error_rms_m, free.summary.tip_error_rms_m);
        assert!(
            tip < 3.0 * free_tip,
            "{circle:?}: {tip} m against {free_tip} m"
        );
    }
}
