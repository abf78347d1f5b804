//! Scenarios on spatial modal arms (`[arm] kind = "spatial"`): the shipped `spatial-tracking`
//! and `spatial-long` end to end, the tip path in space against its geometry, the planar special
//! case, and the refusals of the spatial keys, each naming its field.

use backbone_kin::{BasePose, spatial_tip_position};
use modal_reduce::PlantModel;
use sim_study::{ArmKind, ControllerKind, Scenario};

/// The distance of `p` from the circle of `spatial-tracking`: radius 0.15 m about the `x` axis
/// in the plane `x = 0.8` m.
fn off_circle(p: [f64; 3]) -> f64 {
    (p[0] - 0.8).hypot(p[1].hypot(p[2]) - 0.15)
}

#[test]
fn computed_torque_tracks_the_spatial_circle_below_a_millimetre() {
    for name in ["spatial-tracking", "spatial-long"] {
        let mut scenario = Scenario::builtin(name).unwrap();
        scenario.controller.kind = ControllerKind::ComputedTorque;
        let run = scenario.build().unwrap().run().unwrap();
        let s = &run.summary;
        assert!(s.tip_error_rms_m < 1e-3, "{name}: {s:?}");
        assert_eq!(s.simulated_s, 4.5);
        // The reference tip goes round the circle, out of the arm's x-y plane and back.
        let r = &run.record;
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..r.len() {
            let reference = [r.tip_ref[k][0], r.tip_ref[k][1], r.tip_ref_z[k]];
            assert!(off_circle(reference) < 1e-9, "{name} at {}", r.t[k]);
            low = low.min(reference[2]);
            high = high.max(reference[2]);
        }
        assert!(low < -0.149 && high > 0.149, "{name}: z in [{low}, {high}]");
        // The tip the record holds is the chain's at the recorded coordinates.
        let PlantModel::Spatial(model) = scenario.plant().unwrap() else {
            panic!("{name} is spatial")
        };
        let mut theta = vec![0.0; 2 * model.n_links()];
        let k = r.len() / 2;
        model.map().joint_angles(r.a_at(k), &mut theta).unwrap();
        let tip = spatial_tip_position(model.map().link_lengths(), model.base(), &theta).unwrap();
        assert_eq!(tip, [r.tip[k][0], r.tip[k][1], r.tip_z[k]]);
    }
}

#[test]
fn the_spatial_scenarios_are_what_they_say() {
    let tracking = Scenario::builtin("spatial-tracking").unwrap();
    assert_eq!(tracking.arm.kind, ArmKind::Spatial);
    assert_eq!(tracking.n_coords(), 4);
    let PlantModel::Spatial(model) = tracking.plant().unwrap() else {
        panic!("spatial")
    };
    assert_eq!((model.n_links(), model.n_coords()), (10, 4));
    assert_eq!(model.gravity(), [0.0, 0.0, -9.81]);
    assert_eq!(*model.base(), BasePose::default());
    assert!(model.links().iter().all(|l| l.mass == 0.1));
    assert_eq!(model.map().link_lengths(), [0.1; 10]);
    // A horizontal cantilever: gravity loads the out-of-plane coordinates of the straight arm.
    let long = Scenario::builtin("spatial-long").unwrap();
    assert_eq!(long.coordinate_names().len(), 8);
    let PlantModel::Spatial(model) = long.plant().unwrap() else {
        panic!("spatial")
    };
    assert_eq!((model.n_links(), model.n_coords()), (50, 8));
    // Both start at rest at the circle's first point.
    for scenario in [&tracking, &long] {
        let sim = scenario.build().unwrap();
        let start = sim.initial_state();
        assert!(start.a_dot.iter().all(|&v| v == 0.0));
        let PlantModel::Spatial(model) = scenario.plant().unwrap() else {
            panic!("spatial")
        };
        let mut theta = vec![0.0; 2 * model.n_links()];
        model.map().joint_angles(&start.a, &mut theta).unwrap();
        let tip = spatial_tip_position(model.map().link_lengths(), model.base(), &theta).unwrap();
        assert!(
            (tip[0] - 0.8).abs() < 1e-9 && (tip[1] - 0.15).abs() < 1e-9 && tip[2].abs() < 1e-9,
            "{tip:?}"
        );
    }
}

/// With `a_y = 0` the spatial arm bends in its `x-y` plane: a modal step in the in-plane
/// coordinates under gravity along `-y` runs the planar arm's loop (the spatial model's
/// in-plane block equals the planar reduced model, `modal-reduce`'s tests), so the closed loops
/// agree to rounding.
#[test]
fn a_spatial_arm_in_its_plane_runs_the_planar_loop() {
    let planar = Scenario::from_toml(
        r#"
        name = "planar"
        duration = 0.3
        alpha0 = 0.0
        arm = { gravity = 9.81 }
        reference = { kind = "step", target = [0.2, -0.1], time = 0.05 }
        controller = { kind = "computed-torque" }
        integrator = { method = "rk4", dt = 1e-3 }
        "#,
    )
    .unwrap();
    let spatial = Scenario::from_toml(
        r#"
        name = "spatial"
        duration = 0.3
        arm = { kind = "spatial", gravity = [0.0, -9.81, 0.0] }
        reference = { kind = "step", target = [0.2, -0.1, 0.0, 0.0], time = 0.05 }
        controller = { kind = "computed-torque" }
        integrator = { method = "rk4", dt = 1e-3 }
        "#,
    )
    .unwrap();
    let p = planar.build().unwrap().run().unwrap();
    let s = spatial.build().unwrap().run().unwrap();
    assert_eq!(p.record.len(), s.record.len());
    for k in 0..p.record.len() {
        for i in 0..2 {
            let (x, y) = (p.record.a_at(k)[i], s.record.a_at(k)[i]);
            assert!(
                (x - y).abs() < 1e-10,
                "a{} at {}: {x} vs {y}",
                i + 1,
                p.record.t[k]
            );
        }
        assert!(s.record.a_at(k)[2..].iter().all(|&a| a.abs() < 1e-12));
        assert!(s.record.tip_z[k].abs() < 1e-12);
        let (pt, st) = (p.record.tip[k], s.record.tip[k]);
        assert!((pt[0] - st[0]).abs() < 1e-10 && (pt[1] - st[1]).abs() < 1e-10);
    }
}

/// Every spatial key out of its domain is refused with one line naming the field.
#[test]
fn spatial_keys_out_of_their_domain_are_named() {
    let base = Scenario::builtin_text("spatial-tracking").unwrap();
    let refused = |from: &str, to: &str, field: &str| {
        assert!(base.contains(from), "{from}");
        let text = base.replacen(from, to, 1);
        let message = match Scenario::from_toml(&text) {
            Err(e) => e.to_string(),
            Ok(scenario) => scenario.build().err().expect(field).to_string(),
        };
        assert!(message.contains(field), "{field}: {message}");
        assert!(!message.contains('\n'), "{message}");
    };
    let inertias = "links = 10\ninertias = [[0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [1.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4], [0.0, 1e-4, 1e-4]]";
    refused("links = 10", inertias, "arm.inertias[3]");
    refused(
        "links = 10",
        "links = 10\ninertias = [1e-4, 1e-4]",
        "arm.inertias",
    );
    refused(
        "links = 10",
        "links = 10\ninertias = [[0.0, 1e-4]]",
        "arm.inertias",
    );
    refused(
        "link_length = 0.1",
        "lengths = [0.1, 0.1, -0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1]",
        "arm.lengths[2]",
    );
    refused("link_mass = 0.1", "link_mass = nan", "arm.link_mass");
    refused(
        "xyz = [0.0, 0.0, 0.0]",
        "xyz = [0.0, 1e308, 0.0]",
        "arm.base.xyz is invalid: base xyz must be at most 1000000000 m from the origin",
    );
    // A rod's inertia m L^2 / 12 overflows: the length the user gave is named.
    refused(
        "link_length = 0.1",
        "link_length = 1e300",
        "arm.link_length",
    );
    refused(
        "link_length = 0.1",
        "lengths = [0.1, 0.1, 1e300, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1]",
        "arm.lengths[2]",
    );
    refused("link_mass = 0.1", "masses = [0.1, 0.1]", "arm.masses");
    refused("links = 10", "links = 0", "arm.links");
    refused("links = 10", "links = 2000000", "arm.links");
    refused(
        "gravity = [0.0, 0.0, -9.81]",
        "gravity = [0.0, inf, -9.81]",
        "arm.gravity",
    );
    refused(
        "gravity = [0.0, 0.0, -9.81]",
        "gravity = [0.0, -9.81]",
        "gravity",
    );
    refused(
        "rpy = [0.0, 0.0, 0.0]",
        "rpy = [0.0, nan, 0.0]",
        "arm.base.rpy",
    );
    refused(
        "xyz = [0.0, 0.0, 0.0]",
        "xyz = [0.0, 0.0, 0.0]\nquat = 1",
        "quat",
    );
    refused(
        "joints = \"universal\"",
        "joints = \"alternating\"",
        "joints",
    );
    refused("harmonics = 1", "harmonics = 6", "modal.harmonics");
    refused("harmonics = 1", "harmonics = 0", "modal.harmonics");
    refused("seed = 1", "seed = 1\nalpha0 = 1.0", "alpha0");
    refused(
        "axis = [1.0, 0.0, 0.0]",
        "axis = [0.0, 0.0, 0.0]",
        "reference.helix.axis",
    );
    refused(
        "start = [0.8, 0.15, 0.0]",
        "start = [0.8, 0.0, 0.0]",
        "reference.helix.start",
    );
    refused(
        "start = [0.8, 0.15, 0.0]",
        "start = [0.8, 0.15, 0.0]\nturns = -1.0",
        "reference.helix.turns",
    );
    refused(
        "start = [0.8, 0.15, 0.0]",
        "start = [1.8, 0.15, 0.0]",
        "unreachable",
    );
    refused(
        "[reference.helix]",
        "[reference.sine]",
        "unknown field `axis`",
    );
    refused("kind = \"spatial\"", "kind = \"spherical\"", "spherical");
    // The planar arm refuses the spatial keys, and the spatial arm the planar ones.
    let planar = Scenario::builtin_text("paper-tracking").unwrap();
    for (extra, field) in [
        ("joints = \"universal\"", "arm.joints"),
        ("base = { xyz = [0.0, 0.0, 1.0] }", "arm.base"),
        ("inertias = [[0.0, 1e-4, 1e-4]]", "arm.inertias"),
    ] {
        let text = planar.replacen("links = 10", &format!("links = 10\n{extra}"), 1);
        let message = Scenario::from_toml(&text)
            .unwrap()
            .build()
            .err()
            .unwrap()
            .to_string();
        assert!(message.starts_with(field), "{message}");
    }
    let text = planar.replacen("gravity = 9.81", "gravity = [0.0, -9.81, 0.0]", 1);
    let message = Scenario::from_toml(&text)
        .unwrap()
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(message.starts_with("arm.gravity"), "{message}");
    let text = base.replacen(
        "[reference.helix]",
        "sine = { amplitude = 0.1, wavenumber = 1.0, x_start = 0.5, x_end = 0.6 }\n[reference.helix]",
        1,
    );
    let message = Scenario::from_toml(&text)
        .unwrap()
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(
        message.starts_with("reference of kind \"path\" on a spatial arm"),
        "{message}"
    );
}

/// A spatial scenario written out reads back equal, and keeps its keys.
#[test]
fn a_spatial_scenario_round_trips() {
    for name in ["spatial-tracking", "spatial-long"] {
        let scenario = Scenario::builtin(name).unwrap();
        let text = scenario.to_toml();
        assert!(text.contains("kind = \"spatial\""), "{text}");
        assert_eq!(Scenario::from_toml(&text).unwrap(), scenario);
    }
}

/// A shortened `spatial-tracking` in a sweep: every run of every noise level and controller
/// completes, the noise-free runs equal the scenario's own run, and the noisy ones differ.
#[test]
fn a_sweep_runs_on_a_spatial_scenario() {
    use sim_study::study::{Shard, StoredOutcome, SweepConfig, SweepSettings, for_each_run};
    let mut scenario = Scenario::builtin("spatial-tracking").unwrap();
    scenario.duration = 0.3;
    let settings = SweepSettings {
        controllers: vec![ControllerKind::ComputedTorque, ControllerKind::FuzzyGc],
        noise_levels: vec![0.0, 1e-3],
        seeds: 2,
        ..SweepSettings::default()
    };
    let config = SweepConfig::new(scenario.clone(), settings).unwrap();
    let mut results = Vec::new();
    for_each_run(
        &config,
        Shard::WHOLE,
        || {},
        |run| {
            results.push(run);
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(results.len(), 2 * 2 * 2);
    for run in &results {
        let StoredOutcome::Completed(metrics) = &run.outcome else {
            panic!("{run:?}")
        };
        let mut alone = scenario.clone();
        alone.controller.kind = run.controller;
        let own = alone.build().unwrap().run().unwrap().summary;
        if run.noise_level == 0.0 {
            assert_eq!(metrics.tip_error_rms_m, own.tip_error_rms_m, "{run:?}");
        } else {
            assert_ne!(metrics.tip_error_rms_m, own.tip_error_rms_m, "{run:?}");
        }
        assert!(metrics.tip_error_rms_m.is_finite());
    }
}

/// Imitation on a spatial arm: computed torque's demonstrations on modal steps and sines of the
/// 10-link spatial arm (in both bending planes) are recorded with the `4m = 16` scheduled inputs
/// and computed torque's own forces, and a fuzzy controller learned from them reproduces those
/// forces to a tenth of their spread and is accepted by the loop as the arm's controller (whether it
/// tracks depends on the training, which this small one does not settle); a planar family with as many coordinates (`K = 2`) is
/// refused as another family.
#[test]
fn imitation_learns_on_a_spatial_arm() {
    use sim_study::imitation::{self, ImitationOptions};
    let demonstration = |reference: &str| {
        Scenario::from_toml(&format!(
            "name = \"spatial-demo\"\nduration = 0.6\narm = {{ kind = \"spatial\" }}\n\
             reference = {reference}\ncontroller = {{ kind = \"computed-torque\" }}\n\
             integrator = {{ method = \"rk4\", dt = 1e-3 }}\n"
        ))
        .unwrap()
    };
    let step = demonstration("{ kind = \"step\", target = [0.2, -0.1, 0.15, 0.05], time = 0.05 }");
    // A sine in every coordinate, so that the reference accelerations vary too.
    let sine = demonstration(
        "{ kind = \"sinusoid\", offset = [0.1, 0.0, 0.1, 0.0], amplitude = [0.15, 0.1, 0.1, 0.05], frequency_hz = [1.0, 1.5, 0.8, 1.2] }",
    );
    // Two sets per coordinate (16 rules), the consequents fitted by least squares.
    let options = ImitationOptions {
        sets: 2,
        epochs: 2,
        step: 0.0,
        stride: 5,
        ..ImitationOptions::default()
    };
    let data = imitation::record(&[step.clone(), sine], &options).unwrap();
    assert_eq!((data.n_inputs(), data.n_outputs()), (16, 4));
    assert_eq!(data.column_name(4), "daz1_dot");
    let learned = imitation::train(&data, &options, |_, _| {}).unwrap();
    // Each force reproduced to a tenth of its spread in the data.
    let errors = imitation::rmse(&learned.system, &data).unwrap();
    for (i, error) in errors.iter().enumerate() {
        let [low, high] = data.column_range(16 + i);
        assert!(
            *error < 0.1 * (high - low),
            "tau*_{i}: {error} of [{low}, {high}]"
        );
    }
    let mut fuzzy = step.clone();
    fuzzy.controller.kind = ControllerKind::Fuzzy;
    fuzzy.duration = 0.05;
    let prepared = fuzzy.prepare_with_system(&learned.system).unwrap();
    let run = prepared
        .simulation(&prepared.settings().noise())
        .unwrap()
        .run()
        .unwrap();
    assert!(run.summary.tip_error_rms_m.is_finite());
    let mut planar = Scenario::builtin("paper-responses-step").unwrap();
    planar.modal.harmonics = 2;
    let err = imitation::record(&[step, planar], &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("must share their modal coordinates"), "{err}");
}
