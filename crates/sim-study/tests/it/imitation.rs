//! A fuzzy controller learned by imitation of computed torque (`sim_study::imitation`): its input
//! layout against the quantities it documents, the training pairs reproduced, the `.fis` file
//! reloaded equal, and the closed loop on the paper's tracking path, which the training never
//! saw, pinned.

use fuzzy_sugeno::{FuzzySystem, MembershipFn, OutputFn, Rule};
use sim_core::controller::{ControlContext, Controller, FuzzyController, ModalState};
use sim_core::reference::ReferenceSample;
use sim_study::imitation::{
    self, ImitationOptions, PAPER_TRAINING_SCENARIOS, input_names, output_names,
};
use sim_study::{Alpha0, ControllerKind, Scenario};
use std::sync::OnceLock;

/// The paper's tracking figure of its own fuzzy controller (m): 4.83 mm RMS.
const PAPER_FUZZY_TIP_RMS_M: f64 = 0.004_831_339_946_999_177_5;

fn paper_training() -> Vec<Scenario> {
    PAPER_TRAINING_SCENARIOS
        .iter()
        .map(|name| Scenario::builtin(name).unwrap())
        .collect()
}

/// The controller the main job learns (default options, the paper's step and sine responses
/// about the paper grid of operating points), trained once for every test that needs it.
fn learned() -> &'static imitation::Imitation {
    static LEARNED: OnceLock<imitation::Imitation> = OnceLock::new();
    LEARNED.get_or_init(|| {
        let demonstrations = imitation::paper_demonstrations().unwrap();
        imitation::imitate(&demonstrations, &ImitationOptions::default(), |_, _| {}).unwrap()
    })
}

/// A scratch file name for this process and `test`.
fn scratch(test: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!(
        "sim-core-imitation-{}-{test}.fis",
        std::process::id()
    ))
}

#[test]
fn the_scheduled_layout_feeds_the_documented_quantities() {
    // A system with 4m inputs and no sets: one rule that always fires, and output i equal to
    // input j(i), so each output reads one input back.
    let m = 2;
    let names = input_names(&["a1".into(), "a2".into()]);
    assert_eq!(
        names,
        [
            "da1",
            "da2",
            "da1_dot",
            "da2_dot",
            "a1",
            "a2",
            "a1_ref_ddot",
            "a2_ref_ddot"
        ]
    );
    let picks = [[0, 1], [2, 3], [4, 5], [6, 7]];
    let measured = ModalState::new(&[0.3, -0.1], &[1.5, -2.0]).unwrap();
    let reference = ReferenceSample {
        a: vec![0.25, 0.05],
        a_dot: vec![0.5, 1.0],
        a_ddot: vec![-3.0, 7.0],
    };
    let expected = [[0.05, -0.15], [1.0, -3.0], [0.3, -0.1], [-3.0, 7.0]];
    let model = Scenario::builtin("paper-tracking")
        .unwrap()
        .model()
        .unwrap();
    for (pick, want) in picks.iter().zip(expected) {
        let mut builder = FuzzySystem::builder("probe");
        for (k, name) in names.iter().enumerate() {
            let sets = if k == 0 {
                vec![("one", MembershipFn::Constant { value: 1.0 })]
            } else {
                Vec::new()
            };
            builder = builder.input(name.clone(), [-10.0, 10.0], sets);
        }
        for (o, &j) in pick.iter().enumerate() {
            let mut coefficients = vec![0.0; 4 * m];
            coefficients[j] = 1.0;
            builder = builder.output(
                format!("tau{}", o + 1),
                [-10.0, 10.0],
                [(
                    "x",
                    OutputFn::Linear {
                        coefficients,
                        constant: 0.0,
                    },
                )],
            );
        }
        let system = builder
            .indexed_rule(Rule {
                antecedents: std::iter::once(fuzzy_sugeno::Antecedent::Is(0))
                    .chain(vec![fuzzy_sugeno::Antecedent::Any; 4 * m - 1])
                    .collect(),
                consequents: vec![Some(0), Some(0)],
                weight: 1.0,
                connective: fuzzy_sugeno::Connective::And,
            })
            .build()
            .unwrap();
        let mut controller = FuzzyController::new(system, m).unwrap();
        let ctx = ControlContext {
            t: 0.0,
            measured: &measured,
            reference: &reference,
            model: (&model).into(),
            tau_star_limits: None,
        };
        let mut tau = [0.0; 2];
        controller.control(&ctx, &mut tau).unwrap();
        for (got, want) in tau.iter().zip(want) {
            assert!((got - want).abs() < 1e-12, "{pick:?}: {tau:?} vs {want:?}");
        }
    }
}

#[test]
fn the_learned_system_reproduces_the_teacher_on_its_training_pairs() {
    let learned = learned();
    let data = &learned.data;
    // 2 s and 4 s at 0.1 ms, one pair per 5 ms, about 15 operating points.
    assert_eq!(data.rows(), 15 * (400 + 800));
    // The operating points cover |a1| <= 1.8, |a2| <= 0.75 (a1 and a2 are inputs 5 and 6).
    // (Up to the teacher's overshoot, below 1e-3 rad.)
    let [lo, hi] = data.column_range(4);
    assert!(
        (lo + 1.8).abs() < 1e-3 && (hi - 1.8).abs() < 1e-3,
        "{lo} {hi}"
    );
    assert!((data.column_range(5)[1] - 0.75).abs() < 1e-3);
    assert_eq!((data.n_inputs(), data.n_outputs()), (8, 2));
    assert_eq!(learned.system.rules().len(), 2 * 9);
    assert_eq!(
        learned
            .system
            .outputs()
            .iter()
            .map(|o| o.name.clone())
            .collect::<Vec<_>>(),
        output_names(&["a1".into(), "a2".into()])
    );
    // The RMSE recomputed here, independently of the trainer's bookkeeping, and against the
    // spread of the teacher's torques.
    let rmse = imitation::rmse(&learned.system, data).unwrap();
    assert_eq!(rmse, learned.training_rmse);
    for (o, &e) in rmse.iter().enumerate() {
        let rows = data.rows() as f64;
        let mean = (0..data.rows()).map(|r| data.target(r, o)).sum::<f64>() / rows;
        let std = ((0..data.rows())
            .map(|r| (data.target(r, o) - mean).powi(2))
            .sum::<f64>()
            / rows)
            .sqrt();
        eprintln!("tau{}: RMSE {e:.4e} N m, teacher std {std:.4e} N m", o + 1);
        // Measured: 0.114 and 0.125 N m, 5 % and 3 % of the spread of the teacher's torques.
        assert!(
            e < 0.13 && e < 0.1 * std,
            "tau{}: RMSE {e} vs teacher std {std}",
            o + 1
        );
        // The kept epoch's error is the smallest of the history.
        let best = learned.history[o][learned.best_epoch[o] - 1].training_rmse;
        assert!(learned.history[o].iter().all(|r| r.training_rmse >= best));
    }
}

#[test]
fn the_learned_fis_reloads_equal_and_is_a_scenario_controller() {
    let learned = learned();
    let text = learned.system.to_fis();
    assert!(text.contains("Type='sugeno'") && text.contains("NumInputs=8"));
    let reloaded = FuzzySystem::from_fis(&text).unwrap();
    assert_eq!(reloaded, learned.system);
    // Any scenario of the same coordinates takes it; one of other coordinates refuses it.
    let file = scratch("reload");
    std::fs::write(&file, &text).unwrap();
    let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
    scenario.controller.fis = Some(file.clone());
    scenario.duration = 0.05;
    let from_file = scenario.build().unwrap().run().unwrap();
    // The system kept in memory (the main job's learned row) runs as read from its file, bit for
    // bit, and needs no file.
    let in_memory = |scenario: &Scenario| {
        let prepared = scenario.prepare_with_system(&learned.system).unwrap();
        let noise = prepared.settings().noise();
        prepared.simulation(&noise).unwrap().run().unwrap()
    };
    assert_eq!(in_memory(&scenario), from_file);
    let mut no_file = scenario.clone();
    no_file.controller.fis = Some(file.with_extension("missing"));
    assert_eq!(in_memory(&no_file), from_file);
    scenario.alpha0 = Some(Alpha0::Free);
    scenario.reference = sim_study::ReferenceSpec::Constant {
        a: vec![0.0, 0.0, 1.5],
    };
    let err = scenario.build().err().unwrap().to_string();
    assert!(
        err.contains("must have 6 inputs") && err.contains("has 8 inputs and 2 outputs"),
        "{err}"
    );
    std::fs::remove_file(&file).unwrap();
}

#[test]
fn the_learned_controller_tracks_the_unseen_path_within_half_the_paper_error() {
    let file = scratch("tracking");
    std::fs::write(&file, learned().system.to_fis()).unwrap();
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.controller.fis = Some(file.clone());
    let run = scenario.build().unwrap().run().unwrap();
    std::fs::remove_file(&file).unwrap();
    let (rms, max) = (run.summary.tip_error_rms_m, run.summary.tip_error_max_m);
    eprintln!("learned on paper-tracking: tip RMS {rms:e} m, max {max:e} m");
    assert!(rms <= 0.5 * PAPER_FUZZY_TIP_RMS_M, "{rms}");
    // Pinned to 0.2 %, far above rounding (the computation is deterministic): every variant
    // tried while choosing the defaults (grid, stride, sets, epochs) moved it by 0.7 % to 170 %.
    let (pinned_rms, pinned_max) = (2.554_949_637_479_256e-4, 9.823_831_202_493_01e-4);
    assert!(
        (rms - pinned_rms).abs() <= 0.002 * pinned_rms,
        "tip RMS {rms:e} m, pinned {pinned_rms:e}"
    );
    assert!(
        (max - pinned_max).abs() <= 0.002 * pinned_max,
        "tip max {max:e} m, pinned {pinned_max:e}"
    );
}

#[test]
fn recording_and_training_are_deterministic() {
    let mut scenarios = paper_training();
    for s in &mut scenarios {
        s.duration = 0.3;
    }
    let options = ImitationOptions {
        epochs: 3,
        stride: 5,
        ..ImitationOptions::default()
    };
    let first = imitation::imitate(&scenarios, &options, |_, _| {}).unwrap();
    let second = imitation::imitate(&scenarios, &options, |_, _| {}).unwrap();
    assert_eq!(first, second);
    assert_eq!(first.data.rows(), 2 * 3000 / 5);
    // The inputs are what the teacher measured, the outputs what it applied: the first row of
    // the step response is at rest on the reference, where computed torque is G*(a = 0).
    let row = first.data.row(0);
    assert!(row[..8].iter().all(|&x| x == 0.0), "{row:?}");
    let model = scenarios[0].model().unwrap();
    let mut data = modal_reduce::ReducedData::new(&model);
    modal_reduce::reduced_terms(&model, &mut data, &[0.0; 2], &[0.0; 2]).unwrap();
    assert_eq!(&row[8..], data.gravity());
}

#[test]
fn operating_points_shift_the_reference_and_nothing_else() {
    let step = Scenario::builtin("paper-responses-step").unwrap();
    let sine = Scenario::builtin("paper-responses-sine").unwrap();
    let grid = [vec![-1.0, 0.5], vec![0.25, 0.0, -0.25]];
    let shifted = imitation::shifted_grid(&[step.clone(), sine.clone()], &grid).unwrap();
    assert_eq!(shifted.len(), 12);
    // The fifth of the step's six: a1 offset 0.5, a2 offset 0.0 (the last coordinate fastest).
    let fifth = &shifted[4];
    assert_eq!(
        fifth.reference,
        sim_study::ReferenceSpec::Step {
            initial: Some(vec![0.5, 0.0]),
            target: vec![0.7, -0.2],
            time: 0.1
        }
    );
    assert_eq!(
        (fifth.duration, &fifth.controller),
        (step.duration, &step.controller)
    );
    // The whole response moves by the offset: the teacher's errors are those of the original.
    let mut original = step.clone();
    original.controller.kind = ControllerKind::ComputedTorque;
    let mut moved = fifth.clone();
    moved.controller.kind = ControllerKind::ComputedTorque;
    let (a, b) = (
        original.build().unwrap().run().unwrap(),
        moved.build().unwrap().run().unwrap(),
    );
    let (ea, eb) = (a.summary.modal_error_rms_rad, b.summary.modal_error_rms_rad);
    assert!((ea[0] - eb[0]).abs() < 0.05 * ea[0], "{ea:?} vs {eb:?}");
    let path = Scenario::builtin("paper-tracking").unwrap();
    assert_eq!(
        imitation::shifted_grid(&[path], &grid)
            .unwrap_err()
            .to_string(),
        "imitation.offsets cannot shift the path reference of 'paper-tracking': a tip path fixes its configurations"
    );
    assert_eq!(
        imitation::shifted_grid(std::slice::from_ref(&sine), &grid[..1])
            .unwrap_err()
            .to_string(),
        "imitation.offsets has 1 lists, 'paper-responses-sine' has 2 modal coordinates (one list each)"
    );
    assert_eq!(
        imitation::shifted_grid(std::slice::from_ref(&sine), &[vec![0.0], vec![]])
            .unwrap_err()
            .to_string(),
        "imitation.offsets must give at least one offset per coordinate, got an empty list"
    );
    let huge = vec![vec![0.0; 1000], vec![0.0; 1000]];
    assert_eq!(
        imitation::shifted_grid(std::slice::from_ref(&sine), &huge)
            .unwrap_err()
            .to_string(),
        "imitation.offsets must make at most 10000 scenarios, got a grid of 1000 x 1000 offsets for 1 scenarios (1000000 in all)"
    );
    assert_eq!(
        imitation::shifted_grid(&[sine], &[vec![f64::NAN], vec![0.0]])
            .unwrap_err()
            .to_string(),
        "imitation.offsets must be finite, got NaN"
    );
}

#[test]
fn bad_requests_are_refused_by_name() {
    let message = |scenarios: &[Scenario], options: ImitationOptions| {
        imitation::record(scenarios, &options)
            .unwrap_err()
            .to_string()
    };
    let d = ImitationOptions::default();
    assert_eq!(
        message(&[], d),
        "imitation.scenarios must name at least one training scenario"
    );
    let step = Scenario::builtin("paper-responses-step").unwrap();
    let free = Scenario::builtin("free-base-tracking").unwrap();
    assert_eq!(
        message(&[step.clone(), free], d),
        "imitation.scenarios must share their modal coordinates: 'paper-responses-step' has 2 (a1, a2), 'free-base-tracking' has 3 (a1, a2, alpha0)"
    );
    for (options, text) in [
        (
            ImitationOptions { stride: 0, ..d },
            "imitation.stride must be at least 1 and at most 1000000, got 0",
        ),
        (
            ImitationOptions { sets: 10, ..d },
            "imitation.sets must be at least 1 and at most 9, got 10",
        ),
        (
            ImitationOptions { epochs: 0, ..d },
            "imitation.epochs must be at least 1 and at most 10000, got 0",
        ),
        (
            ImitationOptions {
                step: f64::NAN,
                ..d
            },
            "imitation.step must be finite and at least 0, got NaN",
        ),
        (
            ImitationOptions { margin: -1.0, ..d },
            "imitation.margin must lie in [0, 100], got -1",
        ),
    ] {
        assert_eq!(message(std::slice::from_ref(&step), options), text);
    }
    // A step alone never moves the reference's accelerations: the constant input is named.
    let mut short = step.clone();
    short.duration = 0.5;
    let options = ImitationOptions { epochs: 1, ..d };
    let data = imitation::record(std::slice::from_ref(&short), &options).unwrap();
    let constant = imitation::train(&data, &options, |_, _| {})
        .unwrap_err()
        .to_string();
    assert!(
        constant.starts_with(
            "imitation data input 'a1_ref_ddot' is constant (0) over the demonstrations"
        ),
        "{constant}"
    );
    // Too many rows for the learner, refused before anything runs.
    let mut long = step.clone();
    long.duration = 200.0;
    assert_eq!(
        message(&[long], ImitationOptions { stride: 1, ..d }),
        "imitation.stride = 1 records 2000000 rows from these scenarios, more than 1000000; use a larger stride"
    );
    // Runs each within a run's bound whose sum is not: refused at the build that passes it,
    // before any runs (a 2,000-link step of 2 s is an estimated 1.09e10 operations, 1.9 s).
    let text = Scenario::builtin_text("paper-responses-step")
        .unwrap()
        .to_owned()
        + "\n[arm]\nlinks = 2000\nlink_length = 0.0005\nlink_mass = 0.0005\n";
    let many = imitation::shifted_grid(
        &[Scenario::from_toml(&text).unwrap()],
        &[(0..100).map(|i| 1e-3 * f64::from(i)).collect(), vec![0.0]],
    )
    .unwrap();
    assert_eq!(
        message(&many, d),
        "imitation.scenarios make 100 teacher runs, whose first 92 already take an estimated \
         1.00e12 operations, more than the 1e12 the runs of one imitation may take (about ten \
         minutes): fewer or shorter scenarios, or fewer offsets"
    );
    // A teacher that does not hold the step: the runaway bound stops the recording.
    let mut tight = step;
    tight.limits.max_modal_error = 0.01;
    let err = message(
        &[tight],
        ImitationOptions {
            teacher: ControllerKind::Pd,
            ..d
        },
    );
    assert!(
        err.starts_with("runaway tracking error at t = 0.1 s"),
        "{err}"
    );
}
