//! One test per sim-core row of `docs/bad-input.md` (the scenario loader has its own fuzz tests):
//! each bad setting is refused with the named [`SimError`] or [`OdeError`] variant when the
//! simulation is built, never half-way through a run, and a failing run keeps its data.

use backbone_kin::{BaseAngle, Branch, ModalMap};
use lane_math::Classify;
use manip_dyn::ChainModel;
use modal_reduce::ReducedModel;
use sim_core::controller::{ComputedTorque, FuzzyController, PdController};
use sim_core::ode::{DormandPrince, MIN_RTOL, OdeError, OdeSystem, Rk4, Tolerances};
use sim_core::reference::{CartesianPath, PathShape, Sinusoid, Step};
use sim_core::{
    Integrator, LoopSettings, MAX_CONTROLLER_SAMPLES, MAX_MODAL_MAGNITUDE, MAX_RECORDED_VALUES,
    MAX_RK4_STEPS, MAX_RUN_WORK, SimError, Simulation,
};
use sim_study::MAX_GRAVITY;
use std::f64::consts::FRAC_PI_2;

fn paper_model() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

fn settings() -> LoopSettings {
    LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 0.1)
}

/// Builds the paper's arm under `settings` with a PD law tracking a step.
fn build(settings: LoopSettings) -> Result<Simulation, SimError> {
    let reference = Step::new(&[0.0, 0.0], &[0.2, -0.1], 0.0).unwrap();
    let controller = PdController::new(&[0.0; 2], &[5.0, 5.0], &[1.0, 1.0]).unwrap();
    Simulation::new(
        paper_model(),
        Box::new(reference),
        Box::new(controller),
        settings,
        None,
    )
}

/// The setting an `InvalidSetting` error names, and its message.
fn invalid(result: Result<Simulation, SimError>) -> (String, String) {
    match result {
        Err(e @ SimError::InvalidSetting { .. }) => {
            let message = e.to_string();
            let SimError::InvalidSetting { name, .. } = e else {
                unreachable!()
            };
            (name, message)
        }
        Err(other) => panic!("expected InvalidSetting, got {other:?}"),
        Ok(_) => panic!("expected InvalidSetting, got a simulation"),
    }
}

#[test]
fn reference_and_controller_of_another_size_than_the_model() {
    let free = ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper(10).unwrap(),
    )
    .unwrap();
    let result = Simulation::new(
        free,
        Box::new(Step::constant(&[0.0; 2]).unwrap()),
        Box::new(PdController::new(&[0.0; 2], &[0.0; 2], &[0.0; 2]).unwrap()),
        settings(),
        None,
    );
    // The model with alpha0 free has 3 coordinates: the 2-coordinate reference is refused first.
    let (name, message) = invalid(result);
    assert_eq!(name, "reference");
    assert!(
        message.contains("sets 2 coordinates, the model has 3"),
        "{message}"
    );
}

#[test]
fn controller_period_not_positive() {
    for period in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let s = LoopSettings {
            controller_period: period,
            ..settings()
        };
        let (name, message) = invalid(build(s));
        assert_eq!(name, "controller.period", "{period}");
        assert!(message.contains("must be positive and finite"), "{message}");
    }
}

#[test]
fn duration_not_positive() {
    for duration in [0.0, -1.0, f64::NAN] {
        let s = LoopSettings {
            duration,
            ..settings()
        };
        assert_eq!(invalid(build(s)).0, "duration");
    }
}

#[test]
fn duration_not_a_whole_number_of_periods() {
    let s = LoopSettings {
        duration: 0.1005,
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "duration");
    assert!(message.contains("whole number of controller periods"));
}

#[test]
fn record_period_not_a_whole_number_of_periods() {
    for record_period in [0.0015, 0.0, -1.0] {
        let s = LoopSettings {
            record_period,
            ..settings()
        };
        assert_eq!(invalid(build(s)).0, "record_period", "{record_period}");
    }
}

#[test]
fn rk4_step_not_positive_or_not_dividing_the_period() {
    for dt in [0.0, -1e-4, f64::NAN] {
        let s = LoopSettings {
            integrator: Integrator::Rk4 { dt },
            ..settings()
        };
        assert_eq!(invalid(build(s)).0, "integrator.dt", "{dt}");
    }
    let s = LoopSettings {
        integrator: Integrator::Rk4 { dt: 3e-4 },
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "controller.period");
    assert!(message.contains("whole number of RK4 steps (integrator.dt = 0.0003 s)"));
    // A step too small to count the steps of is named, not the period it cannot divide.
    let s = LoopSettings {
        integrator: Integrator::Rk4 { dt: 5e-324 },
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "integrator.dt");
    assert!(
        message.starts_with("integrator.dt = 5e-324 s would take inf RK4 steps"),
        "{message}"
    );
}

/// A list of fixed length given longer (a quaternion for roll-pitch-yaw, a 3-D point in a planar
/// path) is refused by its line, not read as its first entries: TOML's reader of `[f64; N]`
/// dropped the rest without a word.
#[test]
fn fixed_length_lists_are_read_whole() {
    let spatial = sim_study::Scenario::builtin_text("spatial-tracking").unwrap();
    let planar = "name = \"p\"\nduration = 0.1\nalpha0 = 1.5707963267948966\n\
                  integrator = { method = \"rk4\", dt = 0.001 }\n\
                  [reference]\nkind = \"path\"\ntravel_time = 0.1\n\
                  points = [[0.3, 0.5], [0.3, 0.6]]\n";
    sim_study::Scenario::from_toml(planar).unwrap();
    for (base, from, to, expected) in [
        (
            spatial,
            "rpy = [0.0, 0.0, 0.0]",
            "rpy = [0.0, 0.0, 0.0, 1.0]",
            "(`rpy = [0.0, 0.0, 0.0, 1.0]`): invalid length 4, expected 3 numbers",
        ),
        (
            spatial,
            "rpy = [0.0, 0.0, 0.0]",
            "rpy = [0.0, 0.0]",
            "(`rpy = [0.0, 0.0]`): invalid length 2, expected 3 numbers",
        ),
        (
            spatial,
            "start = [0.8, 0.15, 0.0]",
            "start = [0.8, 0.15, 0.0, 99.0]",
            "(`start = [0.8, 0.15, 0.0, 99.0]`): invalid length 4, expected 3 numbers",
        ),
        (
            planar,
            "[0.3, 0.6]]",
            "[0.3, 0.6, 9.0]]",
            "(`points = [[0.3, 0.5], [0.3, 0.6, 9.0]]`): point 1 has 3 numbers, expected 2",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let message = sim_study::Scenario::from_toml(&base.replacen(from, to, 1))
            .unwrap_err()
            .to_string();
        assert!(message.ends_with(expected), "{to}: {message}");
    }
}

/// A TOML date or time where a number is expected is called one (serde saw "a map").
#[test]
fn a_date_where_a_number_is_expected_is_called_a_date() {
    let step = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    for value in ["1979-05-27T07:32:00Z", "1979-05-27", "07:32:00"] {
        let text = step.replacen("duration = 2.0", &format!("duration = {value}"), 1);
        let message = sim_study::Scenario::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(
            message.ends_with(&format!(
                "(`duration = {value}`): invalid type: date-time, expected f64"
            )),
            "{message}"
        );
    }
}

/// A wrongly typed key of a table tagged by `kind` or `method` is named by its own line (it was
/// named by the table's header), and a key of another kind is refused as serde refused it.
#[test]
fn keys_of_tagged_tables_are_named_by_their_line() {
    let gap = sim_study::Scenario::builtin_text("narrow-gap").unwrap();
    let step = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    for (base, from, to, expected) in [
        (
            &gap,
            "clearance = 0.01",
            "clearance = \"0.01\"",
            "(`clearance = \"0.01\"`): invalid type: string \"0.01\", expected f64",
        ),
        (
            &gap,
            "radius = 0.03",
            "radius = \"0.03\"",
            "(`radius = \"0.03\"`): invalid type: string \"0.03\", expected f64",
        ),
        (
            &gap,
            "travel_time = 3.0",
            "travel_time = [3.0]",
            "(`travel_time = [3.0]`): invalid type: sequence, expected f64",
        ),
        (
            &step,
            "dt = 0.0001",
            "dt = true",
            "(`dt = true`): invalid type: boolean `true`, expected f64",
        ),
        (
            &gap,
            "kind = \"reach\"",
            "kind = \"reach\"\nsamples = -3",
            "(`samples = -3`): invalid value: integer `-3`, expected usize",
        ),
        (
            &gap,
            "kind = \"circle\"",
            "kind = \"blob\"",
            "(`kind = \"blob\"`): unknown variant `blob`, expected one of `circle`, `sphere`, \
             `capsule`, `box`",
        ),
        (
            &gap,
            "radius = 0.03",
            "radius = 0.03\nhalf_extents = [0.1, 0.1]",
            "(`[[obstacles]]`): unknown field `half_extents`, expected `center` or `radius`",
        ),
        (
            &gap,
            "radius = 0.03",
            "colour = 3",
            "(`colour = 3`): unknown field `colour`, expected one of `kind`, `center`, `radius`, \
             `from`, `to`, `half_extents`, `rpy`",
        ),
        (
            &gap,
            "clearance = 0.01",
            "",
            "(`[task]`): missing field `clearance`",
        ),
        (
            &step,
            "dt = 0.0001",
            "rtol = 1e-6",
            "(`[integrator]`): unknown field `rtol`, expected `dt`",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let text = base.replacen(from, to, 1);
        let message = sim_study::Scenario::from_toml(&text)
            .unwrap_err()
            .to_string();
        assert!(message.ends_with(expected), "{from} -> {to}: {message}");
    }
    // The tables read back as they were written, their defaults filled in.
    for name in sim_study::Scenario::builtin_names() {
        let scenario = sim_study::Scenario::builtin(name).unwrap();
        assert_eq!(
            sim_study::Scenario::from_toml(&scenario.to_toml()).unwrap(),
            scenario
        );
    }
}

/// Each sensor noise entry out of its domain is named by its scenario key and index.
#[test]
fn sensor_noise_entries_are_named_by_their_key() {
    let base = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    for (line, expected) in [
        (
            "sensor_a_dot_std = [0.0, -1.0]",
            "noise.sensor_a_dot_std[1] must be non-negative and finite, got -1",
        ),
        (
            "sensor_a_std = [inf, 0.0]",
            "noise.sensor_a_std[0] must be non-negative and finite, got inf",
        ),
        (
            "reference_std = [0.0, 1e7]",
            "noise.reference_std[1] must be at most 1000000 (rad, rad/s), got 10000000",
        ),
    ] {
        let text = format!("{base}\n[noise]\n{line}\n");
        let scenario = sim_study::Scenario::from_toml(&text).unwrap();
        let message = scenario.build().err().unwrap().to_string();
        assert_eq!(message, expected);
    }
}

#[test]
fn dormand_prince_tolerances_out_of_domain() {
    let base = Tolerances::default();
    let bad = [
        ("rtol", Tolerances { rtol: 0.0, ..base }),
        // Below 100 machine epsilons the step size would fall to its minimum at t = 0.
        (
            "rtol",
            Tolerances {
                rtol: 1e-320,
                atol: 1e-320,
                ..base
            },
        ),
        (
            "rtol",
            Tolerances {
                rtol: 1e-15,
                ..base
            },
        ),
        (
            "atol",
            Tolerances {
                atol: f64::NAN,
                ..base
            },
        ),
        ("h_max", Tolerances { h_max: 0.0, ..base }),
        (
            "h_min",
            Tolerances {
                h_min: -1.0,
                ..base
            },
        ),
        (
            "h_init",
            Tolerances {
                h_init: Some(-1e-3),
                ..base
            },
        ),
        (
            "max_steps",
            Tolerances {
                max_steps: 0,
                ..base
            },
        ),
    ];
    for (field, tolerances) in bad {
        // Refused when the simulation is built, naming the field, not at the first step of a
        // run...
        let s = LoopSettings {
            integrator: Integrator::DormandPrince(tolerances),
            ..settings()
        };
        let (name, message) = invalid(build(s));
        assert_eq!(name, format!("integrator.{field}"), "{tolerances:?}");
        assert!(
            message.starts_with(&format!("integrator.{field} must ")) && message.contains(", got "),
            "{message}"
        );
        // ...and by the integrator itself.
        let mut y = [1.0];
        let err = DormandPrince::new(1, tolerances)
            .integrate(&mut Decay, 0.0, 1.0, &mut y)
            .unwrap_err();
        assert!(
            matches!(err, OdeError::InvalidTolerance { name, .. } if name == field),
            "{err:?}"
        );
        assert_eq!(y, [1.0]);
    }
    // Just below the floor, the floor is written in full and the value given echoed.
    let s = LoopSettings {
        integrator: Integrator::DormandPrince(Tolerances {
            rtol: 2.2e-14,
            ..base
        }),
        ..settings()
    };
    let (_, message) = invalid(build(s));
    assert_eq!(
        message,
        "integrator.rtol must be finite and at least 2.220446049250313e-14 (100 machine \
         epsilons), got 2.2e-14"
    );
    // The tightest relative tolerance runs.
    let s = LoopSettings {
        integrator: Integrator::DormandPrince(Tolerances {
            rtol: MIN_RTOL,
            ..base
        }),
        ..settings()
    };
    assert!(build(s).is_ok());
}

/// A scenario's controller keys are checked whichever controller runs (a sweep may run any on
/// it): a computed-torque run refuses an LQR frequency out of its domain and a `fis` file that
/// cannot be read, as the per-coordinate gains were.
#[test]
fn controller_keys_are_checked_whichever_controller_runs() {
    let base = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    let base = base.replace("kind = \"fuzzy\"", "kind = \"computed-torque\"");
    for (line, name, problem) in [
        (
            "lqr_frequency = -5.0",
            "controller.lqr_frequency",
            "must be positive and finite, got -5",
        ),
        (
            "lqr_relinearise = 1e-9",
            "controller.lqr_relinearise",
            "must be at least the controller period (0.0001 s), got 1e-9 s",
        ),
        ("pd_kp = [1.0]", "controller.pd_kp", "has 1 entries"),
        (
            "fis = \"/nonexistent/paper.fis\"",
            "controller.fis",
            "cannot be read from",
        ),
        // A file that is not a FIS: the file named beside the reader's line.
        (
            concat!("fis = \"", env!("CARGO_MANIFEST_DIR"), "/Cargo.toml\""),
            "controller.fis",
            concat!("(", env!("CARGO_MANIFEST_DIR"), "/Cargo.toml): line "),
        ),
    ] {
        let text = base.replace("[controller]\n", &format!("[controller]\n{line}\n"));
        assert_ne!(text, base);
        let (found, message) = invalid(sim_study::Scenario::from_toml(&text).unwrap().build());
        assert_eq!(found, name, "{line}");
        assert!(
            message.starts_with(&format!("{name} {problem}")),
            "{message}"
        );
    }
    // A controller period above the default re-linearisation's 10 ms, with no LQR key: the
    // LQR re-linearises at every sample (it was refused, blaming the key nobody gave).
    let slow = base
        .replace("kind = \"computed-torque\"", "kind = \"lqr\"")
        .replace("period = 0.0001", "period = 0.02")
        .replace("record_period = 0.001", "record_period = 0.02");
    let scenario = sim_study::Scenario::from_toml(&slow).unwrap();
    assert!(scenario.build().is_ok());
    assert!(
        sim_study::study::run_one(&scenario, sim_study::ControllerKind::Lqr)
            .result
            .is_ok()
    );
}

/// Gravity beyond 1e6 m/s^2 (planar magnitude, spatial vector component) is refused naming
/// `arm.gravity`: beyond it the run stopped on a non-finite `a_ddot` at t = 0.
#[test]
fn gravity_beyond_its_bound_is_named() {
    let base = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    for (value, shown) in [("1e308", "1e308"), ("-2e6", "-2000000"), ("nan", "NaN")] {
        let text = format!("{base}\n[arm]\ngravity = {value}\n");
        let scenario = sim_study::Scenario::from_toml(&text).unwrap();
        let (name, message) = invalid(scenario.build());
        assert_eq!(name, "arm.gravity");
        assert_eq!(
            message,
            format!(
                "arm.gravity must be finite and at most 1000000 m/s^2 in magnitude, got {shown}"
            )
        );
    }
    let spatial = sim_study::Scenario::builtin_text("spatial-tracking").unwrap();
    let text = spatial.replace(
        "gravity = [0.0, 0.0, -9.81]",
        "gravity = [0.0, 1e300, -9.81]",
    );
    assert_ne!(text, spatial);
    let (name, _) = invalid(sim_study::Scenario::from_toml(&text).unwrap().build());
    assert_eq!(name, "arm.gravity[1]");
    // At the bound it runs.
    let text = format!("{base}\n[arm]\ngravity = {MAX_GRAVITY:e}\n");
    assert!(
        sim_study::Scenario::from_toml(&text)
            .unwrap()
            .build()
            .is_ok()
    );
}

/// A helix's coordinates and pitch beyond 1e6 m are named (a pitch of 1e300 failed in the
/// inverse kinematics' initial guess); an axis of any finite non-zero length is a direction.
#[test]
fn helix_out_of_scale() {
    let spatial = sim_study::Scenario::builtin_text("spatial-tracking").unwrap();
    let helix = "[reference.helix]\n";
    assert!(spatial.contains(helix));
    let with = |line: &str| {
        let text = spatial.replace(helix, &format!("{helix}{line}\n"));
        sim_study::Scenario::from_toml(&text).map(|s| s.build())
    };
    let (name, message) = invalid(with("pitch = 1e300").unwrap());
    assert_eq!(name, "reference.helix.pitch");
    assert_eq!(
        message,
        "reference.helix.pitch must be at most 1000000 m in magnitude, got 1e300"
    );
    let text = spatial.replace("center = [0.8, 0.0, 0.0]", "center = [0.8, -1e20, 0.0]");
    assert_ne!(text, spatial);
    let (name, _) = invalid(sim_study::Scenario::from_toml(&text).unwrap().build());
    assert_eq!(name, "reference.helix.center[1]");
    for axis in ["[1e308, 0.0, 0.0]", "[1e-310, 0.0, 0.0]"] {
        let text = spatial.replace("axis = [1.0, 0.0, 0.0]", &format!("axis = {axis}"));
        assert_ne!(text, spatial);
        let built = sim_study::Scenario::from_toml(&text).unwrap().build();
        assert!(built.is_ok(), "{axis}: {:?}", built.err());
    }
}

/// A path reference's continuation costs about links x coordinates a node at 2001 nodes: 100,000
/// links (within a scenario's 10^6) took 153 s before the run's first step, and could not be
/// interrupted; the bound names the arm's size.
#[test]
fn spatial_path_work_is_bounded() {
    let spatial = sim_study::Scenario::builtin_text("spatial-tracking").unwrap();
    let with = |links: usize| {
        let text = spatial.replace("links = 10", &format!("links = {links}"));
        assert_ne!(text, spatial);
        sim_study::Scenario::from_toml(&text).map(|s| s.build())
    };
    let (name, message) = invalid(with(8193).unwrap());
    assert_eq!(name, "arm.links");
    assert!(
        message.starts_with(
            "arm.links x modal coordinates must be at most 32768 for a path reference"
        ) && message.ends_with("got 8193 x 4: fewer links or harmonics"),
        "{message}"
    );
    assert_eq!(
        sim_core::reference::MAX_SPATIAL_PATH_WORK,
        8192 * 4,
        "the bound's documented sizes"
    );
}

#[test]
fn noise_negative_or_non_finite() {
    let s = LoopSettings {
        reference_noise_std: vec![0.0, -0.1],
        ..settings()
    };
    assert_eq!(invalid(build(s)).0, "noise.reference_std[1]");
    let s = LoopSettings {
        sensor_noise_std: vec![0.0, 0.0, f64::INFINITY, 0.0],
        ..settings()
    };
    assert_eq!(invalid(build(s)).0, "noise.sensor_a_dot_std[0]");
    // Finite but beyond what a run resolves: it overflowed in the controller, unnamed.
    let s = LoopSettings {
        reference_noise_std: vec![1e308, 0.02],
        ..settings()
    };
    assert_eq!(
        invalid(build(s)),
        (
            "noise.reference_std[0]".to_string(),
            "noise.reference_std[0] must be at most 1000000 (rad, rad/s), got 1e308".to_string()
        )
    );
}

#[test]
fn runaway_bound_not_positive() {
    for bound in [0.0, -1.0, f64::NAN] {
        let s = LoopSettings {
            max_modal_error: bound,
            ..settings()
        };
        assert_eq!(invalid(build(s)).0, "limits.max_modal_error", "{bound}");
    }
}

#[test]
fn torque_limits_wrong_length_or_not_positive() {
    let s = LoopSettings {
        joint_torque_limits: Some(vec![1.0; 9]),
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "limits.joint_torque_nm");
    assert!(message.contains("has 9 entries, the arm has 10 joints"));
    for bad in [0.0, -1.0, f64::NAN] {
        let mut limits = vec![1.0; 10];
        limits[3] = bad;
        let s = LoopSettings {
            joint_torque_limits: Some(limits),
            ..settings()
        };
        assert_eq!(invalid(build(s)).0, "limits.joint_torque_nm[3]", "{bad}");
    }
}

#[test]
fn actuator_limits_wrong_length_or_not_positive() {
    let s = LoopSettings {
        tau_star_limits: Some(vec![1.0; 3]),
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "limits.tau_star");
    assert!(
        message.contains("has 3 entries, the modal family has 2 coordinates"),
        "{message}"
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let s = LoopSettings {
            tau_star_limits: Some(vec![1.0, bad]),
            ..settings()
        };
        let (name, message) = invalid(build(s));
        assert_eq!(name, "limits.tau_star", "{bad}");
        assert!(message.contains("must be positive and finite"), "{message}");
    }
    // From a scenario file: one number for all, or one per coordinate, checked the same way.
    let mut scenario = sim_study::Scenario::builtin("paper-responses-step").unwrap();
    scenario.limits.tau_star = Some(sim_study::ModalTorqueLimit::PerCoordinate(vec![1.0; 3]));
    assert_eq!(invalid(scenario.build()).0, "limits.tau_star");
    scenario.limits.tau_star = Some(sim_study::ModalTorqueLimit::All(-2.0));
    assert_eq!(invalid(scenario.build()).0, "limits.tau_star");
}

#[test]
fn run_that_would_never_end() {
    // Recording only at the end keeps the record small, so only the sample count refuses it.
    let s = LoopSettings {
        duration: 1e300,
        record_period: 1e300,
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "duration");
    assert_eq!(
        message,
        format!(
            "duration must be at most {MAX_CONTROLLER_SAMPLES:e} controller periods \
             (controller.period = 0.001 s), \
             got 1e300 s"
        )
    );
}

/// Each bound on its own passes (the steps, the records, one evaluation's work), their product
/// does not: 2,000 links measuring their 2 million self pairs at 20,000 controller samples (21
/// minutes) is refused before the run, naming the duration and the estimate.
#[test]
fn a_run_whose_total_work_is_hours_is_refused() {
    let base = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    let text = format!(
        "{base}\n[arm]\nlinks = 2000\nlink_length = 0.0005\nlink_mass = 0.0005\nradius = 1e-5\n"
    );
    let scenario = sim_study::Scenario::from_toml(&text).unwrap();
    let error = scenario.build().err().unwrap();
    let message = error.to_string();
    assert!(
        message.starts_with("duration = 2 s would take an estimated 2.57e12 operations")
            && message.contains("of 1.36e5 each, 2.00e4 clearance measures of 1997001 pairs")
            && message.contains(&format!("more than the {MAX_RUN_WORK:e} a run may take")),
        "{message}"
    );
    // A tenth of it runs.
    let short =
        sim_study::Scenario::from_toml(&text.replace("duration = 2.0", "duration = 0.2")).unwrap();
    assert!(short.build().is_ok());
}

/// Each link costs its evaluations more than its `m^2` share of `M*`: 100,000 links with `K = 1`
/// for 5 s in steps of 0.1 ms (10 ms a step measured: 8 minutes, where `n m^2` alone counted 1.1
/// minutes) is refused; half a second runs.
#[test]
fn a_long_run_of_many_links_and_few_coordinates_is_refused() {
    let base = sim_study::Scenario::builtin_text("paper-tracking-fast").unwrap();
    let text = base
        .replace("duration = 1.5", "duration = 5.0")
        .replace("record_period = 0.001", "record_period = 0.5")
        .replace("links = 10\n", "links = 100000\n")
        .replace("link_length = 0.1", "link_length = 1e-5")
        .replace("link_mass = 0.1", "link_mass = 1e-5");
    let scenario = sim_study::Scenario::from_toml(&text).unwrap();
    let message = scenario.build().err().unwrap().to_string();
    assert!(
        message.starts_with("duration = 5 s would take an estimated 1.36e12 operations")
            && message.contains("2.00e5 evaluations of the reduced dynamics of 6.80e6 each"),
        "{message}"
    );
    let short =
        sim_study::Scenario::from_toml(&text.replace("duration = 5.0", "duration = 0.5")).unwrap();
    assert!(short.build().is_ok());
}

/// An MPC's solves count in the run's work: 2,000 links with four harmonics a solve of an
/// estimated 5.3e9 every 5 ms for 1 s (the dynamics of the run alone 5.1e9) is refused when the
/// controller is built, naming the duration and the controller's share; a tenth of it runs.
#[test]
fn an_mpc_whose_solves_take_hours_is_refused() {
    let base = sim_study::Scenario::builtin_text("paper-responses-step").unwrap();
    let base = base
        .replace("duration = 2.0", "duration = 1.0")
        .replace("kind = \"fuzzy\"", "kind = \"mpc\"")
        .replace(
            "initial = [0.0, 0.0]",
            "initial = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
        )
        .replace(
            "target = [0.2, -0.2]",
            "target = [0.2, -0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
        );
    let text = format!(
        "{base}\n[arm]\nlinks = 2000\nlink_length = 0.0005\nlink_mass = 0.0005\n\n[modal]\nharmonics = 4\n"
    );
    let scenario = sim_study::Scenario::from_toml(&text).unwrap();
    let error = scenario.build().err().unwrap();
    let message = error.to_string();
    assert!(
        message.starts_with("duration = 1 s would take an estimated 1.08e12 operations")
            && message.contains("2.56e5 each, 1.07e12 of the controller's own)")
            && message.contains(&format!("more than the {MAX_RUN_WORK:e} a run may take")),
        "{message}"
    );
    let short =
        sim_study::Scenario::from_toml(&text.replace("duration = 1.0", "duration = 0.1")).unwrap();
    assert!(short.build().is_ok());
}

#[test]
fn run_of_astronomically_many_rk4_steps() {
    // 0.1 s in steps of 1e-12 s: 1e11 steps, days of computing, refused up front with the count.
    let s = LoopSettings::new(Integrator::Rk4 { dt: 1e-12 }, 1e-3, 0.1);
    let (name, message) = invalid(build(s));
    assert_eq!(name, "integrator.dt");
    assert!(
        message.contains("1.000e11 RK4 steps over 0.1 s")
            && message.contains(&format!("more than the {MAX_RK4_STEPS:e}")),
        "{message}"
    );
    // A step of 1e-300 s is refused the same way, its numbers readable (no 300-digit decimal).
    let s = LoopSettings::new(Integrator::Rk4 { dt: 1e-300 }, 1e-3, 0.1);
    let (_, message) = invalid(build(s));
    assert!(message.contains("1.000e299 RK4 steps"), "{message}");
    // A duration of 1e-300 s is not a whole number of periods; the message shows it as 1e-300.
    let s = LoopSettings {
        duration: 1e-300,
        ..settings()
    };
    let (_, message) = invalid(build(s));
    assert!(message.ends_with("got 1e-300 s"), "{message}");
}

#[test]
fn run_whose_h_max_forces_astronomically_many_steps() {
    // h_max = 1e-300 s: below the resolution of t at once; 1e-12 s: 1e11 steps. Both refused up
    // front naming integrator.h_max, not reported as a stiff problem once the run starts.
    for (h_max, steps) in [(1e-300, "1e299"), (1e-12, "100000000000")] {
        let tolerances = Tolerances {
            h_max,
            ..Tolerances::default()
        };
        let s = LoopSettings::new(Integrator::DormandPrince(tolerances), 1e-3, 0.1);
        let (name, message) = invalid(build(s));
        assert_eq!(name, "integrator.h_max");
        assert_eq!(
            message,
            format!(
                "integrator.h_max = {} s would take at least {steps} steps over 0.1 s, more than \
                 the 1e9 a run may take (hours of computing): use a larger h_max or simulate less",
                lane_math::Compact(h_max)
            )
        );
    }
    // 1e-9 s (1e8 steps) is within the bound.
    let tolerances = Tolerances {
        h_max: 1e-9,
        ..Tolerances::default()
    };
    assert!(
        build(LoopSettings::new(
            Integrator::DormandPrince(tolerances),
            1e-3,
            0.1
        ))
        .is_ok()
    );
}

#[test]
fn run_too_long_to_record() {
    // 1e8 samples would be recorded: refused up front instead of failing to allocate.
    let s = LoopSettings {
        duration: 1e5,
        ..settings()
    };
    let (name, message) = invalid(build(s));
    assert_eq!(name, "record_period");
    assert!(
        message.contains(&format!("more than the {MAX_RECORDED_VALUES}")),
        "{message}"
    );
    // Recording rarely makes the same duration acceptable.
    let s = LoopSettings {
        duration: 1e3,
        record_period: 1.0,
        ..settings()
    };
    assert!(build(s).is_ok());
}

#[test]
fn non_finite_initial_state() {
    let result = Simulation::new(
        paper_model(),
        Box::new(Step::constant(&[0.0; 2]).unwrap()),
        Box::new(PdController::new(&[0.0; 2], &[0.0; 2], &[0.0; 2]).unwrap()),
        settings(),
        Some(sim_core::controller::ModalState {
            a: vec![0.0, f64::NAN],
            a_dot: vec![0.0; 2],
        }),
    );
    assert_eq!(invalid(result).0, "initial.a");
}

/// A joint-torque limit finer than the modal loop's projection resolves (`1e-10` N m was
/// exceeded 2.5 times over, silently) is refused. (The deployment MPC's box clamps exactly and
/// keeps any positive limit.)
#[test]
fn joint_torque_limits_below_the_resolution_are_refused() {
    let text = format!(
        "{}\n[limits]\njoint_torque_nm = 1e-10\n",
        sim_study::Scenario::builtin_text("paper-tracking").unwrap()
    );
    let message = sim_study::Scenario::from_toml(&text)
        .unwrap()
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(
        message.starts_with("limits.joint_torque_nm must be at least 1e-6 N m"),
        "{message}"
    );
}

/// A state (or reference) of `1e20` rad: every step rounds away and the run would report a
/// frozen coordinate tracking perfectly; it stops at once, naming the coordinate and the bound.
#[test]
fn out_of_scale_states_and_references_stop_the_run() {
    for (initial, target) in [(1e20, 1e20), (0.0, 1e300)] {
        let failure = Simulation::new(
            paper_model(),
            Box::new(Step::new(&[initial, 0.0], &[target, -0.2], 0.0).unwrap()),
            Box::new(PdController::new(&[0.0; 2], &[5.0, 5.0], &[1.0, 1.0]).unwrap()),
            LoopSettings {
                max_modal_error: 1e308,
                ..settings()
            },
            Some(sim_core::controller::ModalState {
                a: vec![initial, 0.0],
                a_dot: vec![0.0; 2],
            }),
        )
        .unwrap()
        .run()
        .unwrap_err();
        assert!(
            matches!(
                failure.error,
                SimError::OutOfScale { coordinate: 1, bound: MAX_MODAL_MAGNITUDE, t, .. } if t == 0.0
            ),
            "{}",
            failure.error
        );
    }
}

#[test]
fn initial_rates_beyond_the_scale_of_a_run_are_refused() {
    let mut scenario = sim_study::Scenario::builtin("paper-tracking").unwrap();
    scenario.initial = Some(sim_study::InitialSpec {
        a: vec![1.0, 0.0],
        a_dot: Some(vec![1e300, 0.0]),
    });
    let Err(error) = scenario.build() else {
        panic!("built")
    };
    assert_eq!(
        error.to_string(),
        "initial.a_dot[0] must be at most 1000000 in magnitude (rad/s, m/s for a prismatic joint), got 1e300"
    );
}

#[test]
fn step_reference_non_finite_or_negative_time() {
    assert!(matches!(
        Step::new(&[f64::NAN, 0.0], &[0.0; 2], 0.0),
        Err(SimError::InvalidSetting { ref name, .. }) if name == "reference.initial"
    ));
    assert!(matches!(
        Step::new(&[0.0; 2], &[0.0; 2], -1.0),
        Err(SimError::InvalidSetting { ref name, .. }) if name == "reference.time"
    ));
}

#[test]
fn sinusoid_negative_frequency() {
    assert!(matches!(
        Sinusoid::new(&[0.0; 2], &[0.1; 2], &[-1.0, 1.0], &[0.0; 2]),
        Err(SimError::InvalidSetting { ref name, .. }) if name == "reference.frequency_hz"
    ));
}

#[test]
fn path_point_out_of_reach() {
    let shape = PathShape::Polyline(vec![[0.3, 0.5], [1.5, 0.5]]);
    let err = CartesianPath::new(
        shape,
        5.0,
        1.0,
        1,
        BaseAngle::Fixed(FRAC_PI_2),
        Branch::Positive,
    )
    .unwrap_err();
    assert!(
        matches!(err, SimError::Unreachable { ref source, .. } if source.is_unreachable()),
        "{err:?}"
    );
    assert!(err.to_string().contains("is unreachable: "), "{err}");
}

#[test]
fn path_degenerate() {
    let cases = [
        (PathShape::Polyline(vec![[0.3, 0.5]]), "reference.points"),
        (
            PathShape::Polyline(vec![[0.3, 0.5], [0.3, 0.5]]),
            "reference.points",
        ),
        (
            PathShape::Polyline(vec![[0.3, 0.5], [f64::NAN, 0.5]]),
            "reference.points",
        ),
        (
            PathShape::Sine {
                amplitude: 0.1,
                wavenumber: 5.0,
                phase: 0.0,
                offset: 0.2,
                x_start: 0.2,
                x_end: 0.2,
            },
            "reference.sine.x_end",
        ),
    ];
    for (shape, setting) in cases {
        let err = CartesianPath::new(
            shape,
            5.0,
            1.0,
            1,
            BaseAngle::Fixed(FRAC_PI_2),
            Branch::Positive,
        )
        .unwrap_err();
        assert!(
            matches!(err, SimError::InvalidSetting { ref name, .. } if name == setting),
            "{err:?}"
        );
    }
    let shape = PathShape::Polyline(vec![[0.3, 0.5], [0.4, 0.5]]);
    for travel_time in [0.0, -1.0, f64::INFINITY] {
        assert!(matches!(
            CartesianPath::new(shape.clone(), travel_time, 1.0, 1, BaseAngle::Fixed(FRAC_PI_2), Branch::Positive),
            Err(SimError::InvalidSetting { ref name, .. }) if name == "reference.travel_time"
        ));
    }
}

#[test]
fn controller_gains_out_of_domain() {
    assert!(matches!(
        PdController::new(&[0.0, f64::NAN], &[0.0; 2], &[0.0; 2]),
        Err(SimError::InvalidSetting { ref name, .. }) if name == "controller offset"
    ));
    assert!(matches!(
        ComputedTorque::new(&paper_model(), &[-1.0, 1.0], &[1.0, 1.0]),
        Err(SimError::InvalidSetting { ref name, .. }) if name == "controller.kp"
    ));
    // A scenario's PD gains, whichever controller runs.
    let mut scenario = sim_study::Scenario::builtin("paper-tracking").unwrap();
    scenario.controller.pd_kp = Some(vec![-1e6, -1e6]);
    let Err(error) = scenario.build() else {
        panic!("built")
    };
    assert_eq!(
        error.to_string(),
        "controller.pd_kp must be non-negative and finite, got -1000000"
    );
    scenario.controller.pd_kp = None;
    scenario.controller.pd_kd = Some(vec![1.0, -1.0]);
    let Err(error) = scenario.build() else {
        panic!("built")
    };
    assert!(
        error
            .to_string()
            .starts_with("controller.pd_kd must be non-negative")
    );
    // Its computed-torque gains likewise (they were copied into the output's scenario.toml).
    scenario.controller.pd_kd = None;
    for (kp, kd, expected) in [
        (
            vec![f64::NAN, f64::NAN],
            None,
            "controller.kp must be non-negative and finite, got NaN",
        ),
        (
            vec![1.0, 1.0],
            Some(vec![f64::NEG_INFINITY, 1e308]),
            "controller.kd must be non-negative and finite, got -inf",
        ),
    ] {
        scenario.controller.kp = Some(kp);
        scenario.controller.kd = kd;
        let Err(error) = scenario.build() else {
            panic!("built")
        };
        assert_eq!(error.to_string(), expected);
    }
}

#[test]
fn fuzzy_controller_of_the_wrong_shape() {
    let system = fuzzy_sugeno::FuzzySystem::builder("one input")
        .input(
            "x",
            [-1.0, 1.0],
            [("z", fuzzy_sugeno::MembershipFn::gaussian(0.3, 0.0))],
        )
        .output(
            "y",
            [-1.0, 1.0],
            [("zero", fuzzy_sugeno::OutputFn::Constant(0.0))],
        )
        .rule(["z"], ["zero"])
        .build()
        .unwrap();
    let err = FuzzyController::new(system, 2).unwrap_err();
    assert!(matches!(err, SimError::InvalidSetting { ref name, .. } if name == "controller.fis"));
    assert!(err.to_string().contains("has 1 inputs and 1 outputs"));
}

/// `y' = -y`.
struct Decay;

impl OdeSystem for Decay {
    type Error = std::convert::Infallible;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error> {
        dy[0] = -y[0];
        Ok(())
    }
}

#[test]
fn ode_state_of_wrong_dimension() {
    let mut y = [1.0, 2.0];
    let err = Rk4::new(1)
        .integrate(&mut Decay, 0.0, 1.0, &mut y, 0.1)
        .unwrap_err();
    assert!(matches!(
        err,
        OdeError::Dimension {
            expected: 1,
            found: 2
        }
    ));
    assert_eq!(y, [1.0, 2.0]);
}

#[test]
fn ode_interval_or_step_out_of_domain() {
    let mut rk4 = Rk4::new(1);
    let mut y = [1.0];
    for (t0, t1, step) in [
        (0.0, f64::NAN, 0.1),
        (1.0, 0.0, 0.1),
        (0.0, 1.0, 0.0),
        (0.0, 1.0, -0.1),
        (0.0, 1.0, f64::NAN),
        (0.0, 1.0, 1e-300),
    ] {
        let err = rk4.integrate(&mut Decay, t0, t1, &mut y, step).unwrap_err();
        assert!(
            matches!(err, OdeError::InvalidSetting(_)),
            "{t0} {t1} {step}: {err:?}"
        );
        assert_eq!(y, [1.0]);
    }
}

#[test]
fn ode_non_finite_state() {
    let mut y = [f64::NAN];
    let err = Rk4::new(1)
        .integrate(&mut Decay, 0.0, 1.0, &mut y, 0.1)
        .unwrap_err();
    assert!(matches!(err, OdeError::NonFinite { t: 0.0 }));
}

#[test]
fn runaway_run_keeps_its_data() {
    let s = LoopSettings {
        max_modal_error: 1e-3,
        ..settings()
    };
    let failure = build(s).unwrap().run().unwrap_err();
    assert!(
        matches!(failure.error, SimError::RunawayError { .. }),
        "{:?}",
        failure.error
    );
    assert!(!failure.record.is_empty());
    assert!(failure.record.t.iter().all(|t| t.is_finite()));
    assert!(failure.to_string().contains("data kept up to t ="));
}

/// The issue's `step.toml`: a 0.05 s step response of the paper's arm, fuzzy at 1e-4 s, with a
/// joint torque limit of 50 N m and the recording period given.
fn step_response(record_period: f64) -> sim_study::Scenario {
    let text = format!(
        "name = \"step\"\nduration = 0.05\nalpha0 = 1.5707963267948966\nrecord_period = {record_period}\n\
         [reference]\nkind = \"step\"\ninitial = [0.0, 0.0]\ntarget = [0.2, -0.2]\ntime = 0.01\n\
         [controller]\nkind = \"fuzzy\"\nperiod = 0.0001\n\
         [integrator]\nmethod = \"rk4\"\ndt = 0.0001\n\
         [limits]\njoint_torque_nm = 50.0\n"
    );
    sim_study::Scenario::from_toml(&text).unwrap()
}

#[test]
fn limits_and_peaks_checked_between_recorded_samples() {
    // The torque spike after the step lasts less than a recording period of 0.05 s: the
    // enforced limit, the peaks and the clamped fractions must see it all the same, whatever is
    // recorded.
    let mut free = step_response(0.0001);
    free.limits.joint_torque_nm = None;
    let free = free.build().unwrap().run().unwrap().summary;
    assert!(
        free.peak_joint_torque_nm > 50.0,
        "{}",
        free.peak_joint_torque_nm
    );
    let every = step_response(0.0001)
        .build()
        .unwrap()
        .run()
        .unwrap()
        .summary;
    let sparse = step_response(0.05).build().unwrap().run().unwrap().summary;
    assert!(
        every.peak_joint_torque_nm <= 50.0,
        "{}",
        every.peak_joint_torque_nm
    );
    assert!(every.torque_projection_share.unwrap() > 0.0);
    assert_eq!(sparse.recorded_samples, 2);
    assert_eq!(every.recorded_samples, every.controller_samples);
    assert_eq!(sparse.peak_joint_torque_nm, every.peak_joint_torque_nm);
    assert_eq!(sparse.peak_joint_torques_nm, every.peak_joint_torques_nm);
    assert_eq!(sparse.peak_modal_torques_nm, every.peak_modal_torques_nm);
    assert_eq!(
        sparse.torque_projection_share,
        every.torque_projection_share
    );
    assert!(sparse.torque_limit_exceeded.is_empty() && every.torque_limit_exceeded.is_empty());
    assert_eq!(
        sparse.tau_star_clamped_fraction,
        every.tau_star_clamped_fraction
    );
    // The tracking errors are those of the recorded time series.
    assert_ne!(sparse.tip_error_rms_m, every.tip_error_rms_m);
    assert_ne!(sparse.tip_error_max_m, every.tip_error_max_m);
}

#[test]
fn an_infinite_runaway_bound_is_refused_by_simulate_as_by_sweep() {
    let mut scenario = sim_study::Scenario::builtin("paper-responses-step").unwrap();
    scenario.limits.max_modal_error = f64::INFINITY;
    let message = scenario.build().err().expect("refused").to_string();
    assert!(
        message.contains("limits.max_modal_error") && message.contains("must be finite, got inf"),
        "{message}"
    );
    // The library loop itself still takes an infinite bound (no runaway check).
    let mut s = settings();
    s.max_modal_error = f64::INFINITY;
    assert!(build(s).is_ok());
}

#[test]
fn non_regular_input_files_are_refused_not_waited_on() {
    let dir = std::env::temp_dir().join(format!("sim-core-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("controller.fis");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    if made {
        // A FIFO as a scenario file and as a scenario's `controller.fis`: refused at once.
        let message = sim_study::Scenario::resolve(fifo.to_str().unwrap())
            .expect_err("refused")
            .to_string();
        assert!(message.contains("not a regular file"), "{message}");
        let text = format!(
            "{}\n",
            sim_study::Scenario::builtin_text("paper-responses-step")
                .unwrap()
                .replace(
                    "kind = \"fuzzy\"",
                    &format!("kind = \"fuzzy\"\nfis = {:?}", fifo.to_str().unwrap())
                )
        );
        let scenario = sim_study::Scenario::from_toml(&text).unwrap();
        let message = scenario.build().err().expect("refused").to_string();
        assert!(message.contains("not a regular file"), "{message}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn run_of_too_much_work_per_step() {
    // 512 links with K = 256 (26 s a step): refused before the run, with the estimate.
    let mut scenario = sim_study::Scenario::builtin("paper-responses-step").unwrap();
    scenario.arm.links = Some(512);
    scenario.modal.harmonics = 256;
    let message = scenario.build().err().expect("refused").to_string();
    assert!(
        message.contains(
            "modal.harmonics is too many for 512 links: 512 modal coordinates take an estimated 1.342e8"
        ),
        "{message}"
    );
}
