//! `[deploy]`: follow-the-leader deployment on an insertion axis, run in joint space by computed
//! torque on the plan. `pipe-deploy` reaches the far end of its bent channel with the body
//! inside it; the run's metrics are recomputed here from its link points with this file's own
//! geometry; every refusal names its key.

use sim_study::{ControllerKind, DeployRun, Scenario, TorqueLimit};

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn to_segment(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let t = (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]))
        .clamp(0.0, 1.0);
    dist(x, [a[0] + t * d[0], a[1] + t * d[1]])
}

/// The distance of `x` from the polyline `path` extended backwards from its first point along
/// its first segment for `back` metres.
fn to_path(x: [f64; 2], path: &[[f64; 2]], back: f64) -> f64 {
    let (p0, p1) = (path[0], path[1]);
    let length = dist(p0, p1);
    let behind = [
        p0[0] - back * (p1[0] - p0[0]) / length,
        p0[1] - back * (p1[1] - p0[1]) / length,
    ];
    let mut best = to_segment(x, behind, p0);
    for pair in path.windows(2) {
        best = best.min(to_segment(x, pair[0], pair[1]));
    }
    best
}

fn centerline(scenario: &Scenario) -> Vec<[f64; 2]> {
    let deploy = scenario.deploy.as_ref().unwrap();
    deploy.centerline.iter().map(|p| [p[0], p[1]]).collect()
}

/// The metrics recomputed from the run's points: (tip error, shape deviation %, wall
/// clearance), the body sampled at `per_link` points a link.
fn recompute(scenario: &Scenario, run: &DeployRun, per_link: usize) -> (f64, f64, f64) {
    let line = centerline(scenario);
    let radius = scenario.deploy.as_ref().unwrap().radius;
    let link_radius = scenario.arm.radius.unwrap();
    let samples = run.run.record.t.len();
    let (mut tip_error, mut deviation, mut clearance) = (0.0f64, 0.0f64, f64::INFINITY);
    // The tip's trace starts at the entry.
    let mut traced = vec![line[0]];
    for k in 0..samples {
        let shape = run.points_at(k);
        let tip = *shape.last().unwrap();
        traced.push(tip);
        tip_error = tip_error.max(to_path(tip, &line, 10.0));
        // The deployed length: how far the base has advanced past 1 m behind the entry.
        let axis = [line[1][0] - line[0][0], line[1][1] - line[0][1]];
        let axis = [
            axis[0] / axis[0].hypot(axis[1]),
            axis[1] / axis[0].hypot(axis[1]),
        ];
        let deployed =
            1.0 + (shape[0][0] - line[0][0]) * axis[0] + (shape[0][1] - line[0][1]) * axis[1];
        let mut worst = 0.0f64;
        for pair in shape.windows(2) {
            for s in 0..=per_link {
                let t = s as f64 / per_link as f64;
                let x = [
                    pair[0][0] + t * (pair[1][0] - pair[0][0]),
                    pair[0][1] + t * (pair[1][1] - pair[0][1]),
                ];
                clearance = clearance.min(radius - link_radius - to_path(x, &line, 10.0));
                // The guide behind the entry, then the trace from the entry on.
                let (rx, ry) = (x[0] - line[0][0], x[1] - line[0][1]);
                let mut on_trace = if rx * axis[0] + ry * axis[1] <= 0.0 {
                    (rx * axis[1] - ry * axis[0]).abs()
                } else {
                    f64::INFINITY
                };
                for pair in traced.windows(2) {
                    on_trace = on_trace.min(to_segment(x, pair[0], pair[1]));
                }
                worst = worst.max(on_trace);
            }
        }
        deviation = deviation.max(100.0 * worst / deployed.max(0.1));
    }
    (tip_error, deviation, clearance)
}

#[test]
fn pipe_deploy_reaches_the_end_with_the_body_inside_the_channel() {
    let scenario = Scenario::builtin("pipe-deploy").unwrap();
    let run = scenario.run_deploy().unwrap();
    let record = &run.run.record;
    let n = 11;
    assert_eq!(record.q.len(), record.t.len() * n);
    assert_eq!(run.points.len(), record.t.len() * n);
    // The points are the chain of the recorded joints, every link 0.1 m long, the base on the
    // insertion axis (x = 0) at q - 1 m from the entry.
    for k in 0..record.t.len() {
        let shape = run.points_at(k);
        let q = &record.q[k * n..(k + 1) * n];
        assert!(shape[0][0].abs() < 1e-12 && (shape[0][1] - (q[0] - 1.0)).abs() < 1e-12);
        let mut angle = 0.0;
        for (j, pair) in shape.windows(2).enumerate() {
            angle += q[j + 1];
            let (s, c) = angle.sin_cos();
            assert!((pair[1][0] - pair[0][0] - 0.1 * c).abs() < 1e-12);
            assert!((pair[1][1] - pair[0][1] - 0.1 * s).abs() < 1e-12);
        }
    }
    // Starts retracted with the tip at the entry; ends with the tip at the far end, held.
    let line = centerline(&scenario);
    let first = run.points_at(0);
    assert!(dist(first[10], line[0]) < 1e-12, "{:?}", first[10]);
    let last = run.points_at(record.t.len() - 1);
    let end = *line.last().unwrap();
    assert!(dist(last[10], end) < 2e-3, "tip {:?} vs {end:?}", last[10]);
    assert!(run.run.summary.final_error < 1e-3, "{:?}", run.run.summary);
    // Inside the channel all along, following the tip's path.
    let m = run.metrics;
    assert!(m.min_wall_clearance > 0.02, "{m:?}");
    assert!(m.tip_error < 1e-3, "{m:?}");
    assert!(m.shape_deviation_percent < 3.0, "{m:?}");
    assert!((m.deployed_length - run.run.record.q[(record.t.len() - 1) * n]).abs() < 1e-15);
    // The plan it tracked: exact fit (K = 5), the links chords of the bend.
    assert!(
        run.plan.tip_error < 1e-9 && run.plan.min_wall_clearance > 0.02,
        "{:?}",
        run.plan
    );
    // The metrics from the points with this file's own geometry: the same tip error and
    // deviation at the same 32 points a link; the wall clearance is exact, so samples of the
    // links (256 a link of 0.1 m) find at least as much, at most half their spacing more.
    let (tip, deviation, _) = recompute(&scenario, &run, 32);
    assert!(
        (tip - m.tip_error).abs() < 1e-12,
        "{tip} vs {}",
        m.tip_error
    );
    assert!(
        (deviation - m.shape_deviation_percent).abs() < 1e-9,
        "{deviation} vs {m:?}"
    );
    let (_, _, dense) = recompute(&scenario, &run, 256);
    assert!(
        m.min_wall_clearance <= dense + 1e-12 && dense <= m.min_wall_clearance + 0.1 / 512.0,
        "{dense} vs {m:?}"
    );
}

#[test]
fn mpc_deploys_pipe_deploy_as_well_as_computed_torque_within_its_box() {
    let computed_torque = Scenario::builtin("pipe-deploy").unwrap();
    let mut scenario = computed_torque.clone();
    scenario.controller.kind = ControllerKind::Mpc;
    let run = scenario.run_deploy().unwrap();
    let ct = computed_torque.run_deploy().unwrap();
    let (m, c) = (run.metrics, ct.metrics);
    let record = &run.run.record;
    let n = 11;
    // Ends with the tip at the channel's far end, held; the body inside the channel.
    let line = centerline(&scenario);
    let last = run.points_at(record.t.len() - 1);
    let end = *line.last().unwrap();
    assert!(dist(last[10], end) < 2e-3, "tip {:?} vs {end:?}", last[10]);
    assert!(run.run.summary.final_error < 2e-3, "{:?}", run.run.summary);
    assert!(m.min_wall_clearance > 0.02, "{m:?}");
    // Comparable with computed torque on the same plan: the tip within a few millimetres of
    // the centreline, the shape deviation within half a percent of the deployed length, the
    // clearance within 2 mm.
    assert!(m.tip_error < 3e-3, "{m:?} vs {c:?}");
    assert!(
        m.shape_deviation_percent < c.shape_deviation_percent + 0.5,
        "{m:?} vs {c:?}"
    );
    assert!(
        m.min_wall_clearance > c.min_wall_clearance - 2e-3,
        "{m:?} vs {c:?}"
    );
    // Within the box: every effort at most twice the reference's largest inverse dynamics
    // (computed torque's peaks are above that on the insertion axis at the start).
    let peaks = &run.run.summary.peak_joint_efforts;
    assert_eq!(peaks.len(), n);
    assert!(record.tau.iter().all(|t| t.is_finite()));
    // The metrics from the points with this file's own geometry.
    let (tip, deviation, clearance) = recompute(&scenario, &run, 32);
    assert!((tip - m.tip_error).abs() < 1e-12, "{tip} vs {m:?}");
    assert!((deviation - m.shape_deviation_percent).abs() < 1e-9);
    assert!(
        m.min_wall_clearance <= clearance + 1e-12 && clearance <= m.min_wall_clearance + 0.1 / 64.0,
        "{clearance} vs {m:?}"
    );
}

/// `[limits] joint_torque_nm` is the deployment MPC's box on the revolute joints: over the
/// first 0.3 s, the default box lets the largest joint torque reach `P`; within a limit of
/// `0.6 P` on every joint (one number) every revolute joint's torque stays within it at every
/// controller sample; per-joint limits of the wrong length or not positive, and the key with
/// computed torque, are refused by name.
#[test]
fn the_deployment_mpc_keeps_the_joint_torques_within_joint_torque_nm() {
    let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
    scenario.controller.kind = ControllerKind::Mpc;
    scenario.duration = 0.3;
    let revolute_peak = |s: &Scenario| {
        let run = s.run_deploy().unwrap();
        run.run.summary.peak_joint_efforts[1..]
            .iter()
            .fold(0.0f64, |p, e| p.max(*e))
    };
    let free = revolute_peak(&scenario);
    let limit = 0.6 * free;
    let mut limited = scenario.clone();
    limited.limits.joint_torque_nm = Some(TorqueLimit::All(limit));
    let peak = revolute_peak(&limited);
    assert!(
        peak <= limit * (1.0 + 1e-12),
        "{peak} vs {limit} (free {free})"
    );
    // Its summary names the controller that ran.
    let run = limited.run_deploy().unwrap();
    let summary = sim_study::summary_json::deploy(&limited, &run);
    assert_eq!(summary["controller"], "mpc");
    assert_eq!(summary["deploy_tip_error_m"], run.metrics.tip_error);
    let message = |s: &Scenario| s.run_deploy().unwrap_err().to_string();
    let mut short = scenario.clone();
    short.limits.joint_torque_nm = Some(TorqueLimit::PerJoint(vec![1.0; 9]));
    assert!(
        message(&short).starts_with("limits.joint_torque_nm has 9 entries, the arm has 10"),
        "{}",
        message(&short)
    );
    let mut negative = scenario.clone();
    negative.limits.joint_torque_nm = Some(TorqueLimit::PerJoint(vec![-1.0; 10]));
    assert!(
        message(&negative).starts_with("limits.joint_torque_nm must be positive"),
        "{}",
        message(&negative)
    );
    let mut computed_torque = limited.clone();
    computed_torque.controller.kind = ControllerKind::ComputedTorque;
    assert!(
        message(&computed_torque).starts_with("limits.joint_torque_nm"),
        "{}",
        message(&computed_torque)
    );
}

#[test]
fn with_one_harmonic_the_body_leaves_the_channel_and_the_metrics_say_so() {
    // K = 1 cannot hold the straight guide and the bend (docs/theory.md): the fitted shapes,
    // tracked just as well, cut through the walls; the run's metrics show it.
    let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
    scenario.modal.harmonics = 1;
    let run = scenario.run_deploy().unwrap();
    assert!(run.run.summary.final_error < 1e-3, "{:?}", run.run.summary);
    assert!(run.metrics.min_wall_clearance < -0.1, "{:?}", run.metrics);
    assert!(run.metrics.tip_error > 0.05, "{:?}", run.metrics);
    let exact = Scenario::builtin("pipe-deploy")
        .unwrap()
        .run_deploy()
        .unwrap();
    assert!(run.metrics.shape_deviation_percent > 2.0 * exact.metrics.shape_deviation_percent);
}

#[test]
fn deployment_keys_are_refused_by_name() {
    let base = Scenario::builtin("pipe-deploy").unwrap();
    let message = |s: &Scenario| s.run_deploy().unwrap_err().to_string();
    let mut spatial = base.clone();
    spatial.deploy.as_mut().unwrap().centerline[1] = vec![0.0, 0.2, 0.0];
    assert!(
        message(&spatial).starts_with("deploy.centerline point 2 is [x, y, z]: spatial channels"),
        "{}",
        message(&spatial)
    );
    let mut one = base.clone();
    one.deploy.as_mut().unwrap().centerline.truncate(1);
    assert!(
        message(&one).starts_with("deploy.centerline"),
        "{}",
        message(&one)
    );
    let mut repeated = base.clone();
    repeated.deploy.as_mut().unwrap().centerline[1] = vec![0.0, 0.0];
    assert!(
        message(&repeated).starts_with("deploy.centerline"),
        "{}",
        message(&repeated)
    );
    // A deployment faster than one controller period (its accelerations overflowed to NaN).
    let text = base
        .to_toml()
        .replace("travel_time = 4.0", "travel_time = 1e-300");
    let fast = Scenario::from_toml(&text).unwrap();
    assert!(
        message(&fast)
            .starts_with("reference.travel_time = 1e-300 s is shorter than one controller period"),
        "{}",
        message(&fast)
    );
    let mut many = base.clone();
    many.deploy.as_mut().unwrap().centerline = vec![vec![0.0, 0.0]; 20_000];
    assert!(
        message(&many).contains("at most 10000"),
        "{}",
        message(&many)
    );
    for radius in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let mut bad = base.clone();
        bad.deploy.as_mut().unwrap().radius = radius;
        assert!(
            message(&bad).starts_with("deploy.radius"),
            "{}",
            message(&bad)
        );
    }
    let mut huge = base.clone();
    huge.deploy.as_mut().unwrap().radius = 1e300;
    assert!(
        message(&huge).starts_with(
            "deploy.radius cannot be deployed into: deploy radius must be from 1e-9 m to 1e6 m"
        ),
        "{}",
        message(&huge)
    );
    let mut back = base.clone();
    back.deploy.as_mut().unwrap().centerline = vec![vec![0.0, 0.0], vec![0.0, 0.4], vec![0.0, 0.2]];
    assert!(
        message(&back).starts_with(
            "deploy.centerline cannot be deployed into: deploy centerline folds the arm onto itself"
        ),
        "{}",
        message(&back)
    );
    let mut spatial_arm = base.clone();
    spatial_arm.arm.kind = sim_study::ArmKind::Spatial;
    assert!(
        message(&spatial_arm).starts_with("arm.kind is \"spatial\": a deployment's arm is planar"),
        "{}",
        message(&spatial_arm)
    );
    // A limit the joint-space MPC does not keep is named alone.
    let mut angles = base.clone();
    angles.controller.kind = ControllerKind::Mpc;
    angles.limits.joint_angle_rad = Some(sim_study::AngleLimit::All(1.0));
    assert!(
        message(&angles).starts_with("limits.joint_angle_rad is not used with"),
        "{}",
        message(&angles)
    );
    // 100,000 links (each of 10 um) would take hours to measure: refused before anything runs.
    let mut links = base.clone();
    links.arm.links = Some(100_000);
    links.arm.link_length = Some(1e-5);
    links.duration = 0.001;
    links.record_period = Some(0.0005);
    let started = std::time::Instant::now();
    assert!(
        message(&links).starts_with("arm.links is 100000: measured at 404 shapes"),
        "{}",
        message(&links)
    );
    assert!(started.elapsed().as_secs_f64() < 5.0);
    let mut long = base.clone();
    long.deploy.as_mut().unwrap().centerline = vec![vec![0.0, 0.0], vec![0.0, 2.0]];
    assert!(
        message(&long).starts_with("deploy.centerline cannot be deployed into")
            && message(&long).contains("too short"),
        "{}",
        message(&long)
    );
    let mut harmonics = base.clone();
    harmonics.modal.harmonics = 6;
    assert!(
        message(&harmonics).starts_with("modal.harmonics"),
        "{}",
        message(&harmonics)
    );
    let mut alpha0 = base.clone();
    alpha0.alpha0 = Some(sim_study::Alpha0::Fixed(1.0));
    assert!(message(&alpha0).starts_with("alpha0 is not used with [deploy]"));
    for kind in [ControllerKind::ComputedTorque, ControllerKind::Mpc] {
        let mut margin = base.clone();
        margin.controller.kind = kind;
        margin.controller.clearance_m = Some(0.5);
        assert!(
            message(&margin).starts_with("controller.clearance_m is not used with [deploy]"),
            "{}",
            message(&margin)
        );
    }
    // The modal controllers' keys, which a modal run checks whichever controller it runs.
    type SetKey = fn(&mut sim_study::ControllerSpec);
    let modal_keys: [(&str, SetKey); 5] = [
        ("controller.pd_kp", |c| c.pd_kp = Some(vec![1.0])),
        ("controller.pd_kd", |c| c.pd_kd = Some(vec![1.0])),
        ("controller.lqr_frequency", |c| c.lqr_frequency = Some(-5.0)),
        ("controller.lqr_relinearise", |c| {
            c.lqr_relinearise = Some(0.1)
        }),
        ("controller.fis", |c| c.fis = Some("paper.fis".into())),
    ];
    for (name, set) in modal_keys {
        let mut modal = base.clone();
        set(&mut modal.controller);
        assert!(
            message(&modal).starts_with(&format!("{name} is not used with [deploy]")),
            "{}",
            message(&modal)
        );
    }
    let mut fuzzy = base.clone();
    fuzzy.controller.kind = ControllerKind::Fuzzy;
    assert!(message(&fuzzy).starts_with("controller.kind must be \"computed-torque\" or \"mpc\""));
    let mut constant = base.clone();
    constant.reference = sim_study::ReferenceSpec::Constant { a: vec![0.0; 10] };
    assert!(message(&constant).starts_with("reference must be of kind \"planned\""));
    let mut fine = base.clone();
    fine.record_period = Some(1e-4);
    assert!(message(&fine).starts_with("record_period must give at most 2000"));
    let mut gains = base.clone();
    gains.controller.kp = Some(vec![100.0; 10]);
    assert!(
        message(&gains).starts_with("controller.kp has 10 entries"),
        "{}",
        message(&gains)
    );
    // The modal loop refuses a deployment by name rather than running it without its axis.
    let e = base.build().err().unwrap().to_string();
    assert!(e.starts_with("deploy runs in joint space"), "{e}");
    // The file's own keys: an unknown one is named.
    let text = base
        .to_toml()
        .replace("[deploy]\n", "[deploy]\ndepth = 1.0\n");
    let e = Scenario::from_toml(&text).unwrap_err().to_string();
    assert!(e.contains("depth"), "{e}");
}

/// A reference that counts its samples and fails from `stop_at` on.
struct Stopping {
    inner: Box<dyn sim_core::reference::Reference>,
    samples: std::sync::Arc<std::sync::atomic::AtomicUsize>,
    stop_at: f64,
}

impl sim_core::reference::Reference for Stopping {
    fn n_coords(&self) -> usize {
        self.inner.n_coords()
    }

    fn sample(
        &mut self,
        t: f64,
        out: &mut sim_core::reference::ReferenceSample,
    ) -> Result<(), sim_core::SimError> {
        self.samples
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if t >= self.stop_at {
            return Err(sim_core::SimError::setting("stop", "reached"));
        }
        self.inner.sample(t, out)
    }
}

#[test]
fn the_wrapped_reference_is_sampled_at_every_controller_sample_and_can_stop_the_loop() {
    let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
    scenario.duration = 1.0;
    let samples = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let wrap = |stop_at: f64| {
        let samples = std::sync::Arc::clone(&samples);
        move |inner| -> Box<dyn sim_core::reference::Reference> {
            Box::new(Stopping {
                inner,
                samples,
                stop_at,
            })
        }
    };
    // Unstopped: the same run as without the wrapper, one sample every 0.5 ms and the last.
    let whole = scenario.run_deploy_wrapping(wrap(f64::INFINITY)).unwrap();
    assert_eq!(samples.load(std::sync::atomic::Ordering::Relaxed), 2001);
    assert_eq!(whole.run, scenario.run_deploy().unwrap().run);
    // Stopped at 0.5 s: the wrapper's error, the run up to its last recorded sample before it.
    let stopped = scenario.run_deploy_wrapping(wrap(0.5)).unwrap_err();
    assert_eq!(
        stopped.error,
        sim_core::SimError::setting("stop", "reached")
    );
    let partial = stopped.partial.expect("stopped after its first sample");
    let t = &partial.run.record.t;
    assert!((t[t.len() - 1] - 0.49).abs() < 1e-9, "{t:?}");
}
