//! The run-view crate: the data checks, a planar run of the closed loop, the page, the GIF,
//! and the viewer script's own tests (node).

use run_view::{
    Camera, Channel, GifOptions, MAX_SAMPLES, Obstacle, PAGE_SAMPLES, RunView, Scene, Series,
    from_record, page, scene_html, strided, write_gif,
};
use sim_study::{ControllerKind, Scenario};

/// A synthetic spatial arm: `links` links of 0.1 m whose bending plane turns about the vertical
/// as time goes on (a helix that unwinds), with a sphere, a capsule, a box and a channel.
fn spatial(samples: usize, links: usize) -> RunView {
    let t: Vec<f64> = (0..samples)
        .map(|k| 2.0 * k as f64 / (samples - 1) as f64)
        .collect();
    let arm = |t: f64| -> Vec<f64> {
        let mut p = [0.0f64; 3];
        let mut out = p.to_vec();
        for i in 0..links {
            let bend = 0.15 * (i as f64 + 1.0) * (1.0 - 0.3 * t);
            let turn = 0.6 * t + 0.4 * i as f64;
            let dir = [bend.sin() * turn.cos(), bend.sin() * turn.sin(), bend.cos()];
            p = [0, 1, 2].map(|j| p[j] + 0.1 * dir[j]);
            out.extend(p);
        }
        out
    };
    let joints: Vec<Vec<f64>> = t.iter().map(|&t| arm(t)).collect();
    let tip_ref = joints
        .iter()
        .map(|row| row[row.len() - 3..].to_vec())
        .collect();
    let joint_torque: Vec<Vec<f64>> = t
        .iter()
        .map(|&t| {
            (0..links)
                .map(|i| (links - i) as f64 * (1.0 + t).sin())
                .collect()
        })
        .collect();
    let clearance = t.iter().map(|&t| 50.0 - 10.0 * t).collect();
    RunView {
        label: "synthetic spatial".into(),
        dims: 3,
        t: t.clone(),
        joints,
        tip_ref,
        joint_torque,
        torque_limit: vec![links as f64; links],
        series: vec![Series {
            title: "clearance".into(),
            unit: "mm".into(),
            names: vec!["nearest obstacle".into()],
            values: vec![clearance],
        }],
        obstacles: vec![
            Obstacle::Sphere {
                centre: vec![0.3, 0.2, 0.5],
                radius: 0.08,
            },
            Obstacle::Capsule {
                a: vec![-0.3, 0.0, 0.2],
                b: vec![-0.3, 0.0, 0.7],
                radius: 0.04,
            },
            Obstacle::Box {
                centre: vec![0.0, -0.35, 0.3],
                half: vec![0.1, 0.05, 0.2],
            },
        ],
        channels: vec![Channel {
            points: vec![vec![0.0, 0.0, 0.0], vec![0.0, 0.0, 0.9]],
            width: 0.3,
        }],
        stopped: None,
    }
}

fn planar(duration: f64, kind: ControllerKind) -> (Scenario, RunView) {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = duration;
    scenario.controller.kind = kind;
    let run = scenario.build().unwrap().run().unwrap();
    let view = from_record(&scenario, kind.name(), &run.record, None).unwrap();
    (scenario, view)
}

#[test]
fn a_planar_run_is_drawn_from_its_modal_coordinates() {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = 0.3;
    let run = scenario.build().unwrap().run().unwrap();
    let view = from_record(&scenario, "fuzzy", &run.record, None).unwrap();
    assert_eq!(
        (view.dims, view.points(), view.len()),
        (2, 11, run.record.len())
    );
    for (k, row) in view.joints.iter().enumerate() {
        // Base at the origin, every link 0.1 m long, the last point the recorded tip.
        assert_eq!(&row[..2], &[0.0, 0.0]);
        for link in row.chunks_exact(2).collect::<Vec<_>>().windows(2) {
            let length = (link[1][0] - link[0][0]).hypot(link[1][1] - link[0][1]);
            assert!((length - 0.1).abs() < 1e-12, "{length}");
        }
        let tip = &row[20..];
        assert!((tip[0] - run.record.tip[k][0]).abs() < 1e-12);
        assert!((tip[1] - run.record.tip[k][1]).abs() < 1e-12);
    }
    let titles: Vec<&str> = view.series.iter().map(|s| s.title.as_str()).collect();
    assert_eq!(
        titles,
        ["tip error", "modal coordinates", "modal torques tau*"]
    );
    assert_eq!(view.series[2].names, ["tau*_1", "tau*_2"]);
    // A free base angle's torque keeps the angle's whole name.
    let mut free = Scenario::builtin("free-base-tracking").unwrap();
    free.duration = 0.01;
    let free_run = free.build().unwrap().run().unwrap();
    let free_view = from_record(&free, "pd", &free_run.record, None).unwrap();
    assert_eq!(
        free_view.series[2].names,
        ["tau*_1", "tau*_2", "tau*_alpha0"]
    );
    // The tip error series is the distance from the tip to the reference, in mm.
    let k = view.len() - 1;
    let (tip, reference) = (run.record.tip[k], run.record.tip_ref[k]);
    let expected = 1e3 * (tip[0] - reference[0]).hypot(tip[1] - reference[1]);
    assert!((view.series[0].values[0][k] - expected).abs() < 1e-12);
    assert_eq!(view.joint_torque[k], run.record.joint_torques_at(k));
    // A record of another scenario is refused.
    let mut other = Scenario::builtin("paper-tracking").unwrap();
    other.arm.links = Some(12);
    assert!(from_record(&other, "x", &run.record, None).is_err());
    // An arm beyond what the viewer draws is refused naming the links, not the page's field.
    let mut long = Scenario::builtin("paper-tracking").unwrap();
    long.arm.links = Some(1001);
    assert_eq!(
        from_record(&long, "x", &run.record, None)
            .unwrap_err()
            .to_string(),
        "arm.links: the viewer draws at most 1000 links, the arm of scenario paper-tracking has 1001"
    );
    // An arm of the same links but another length draws another tip: refused, not drawn wrong.
    let mut longer = Scenario::builtin("paper-tracking").unwrap();
    longer.arm.link_length = Some(0.2);
    let message = from_record(&longer, "x", &run.record, None)
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("the arm of scenario paper-tracking puts the tip 0.36")
            && message.ends_with(
                "m from the recorded tip at t = 0 s: the record was not made with this arm"
            ),
        "{message}"
    );
}

#[test]
fn a_record_longer_than_the_viewer_holds_is_drawn_at_strided_samples() {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.duration = 10.05;
    scenario.controller.kind = ControllerKind::Pd;
    scenario.record_period = Some(1e-4);
    // An obstacle of radius zero (a point, as a scenario allows) is drawn too.
    scenario.obstacles = vec![sim_study::ObstacleSpec::Circle {
        center: vec![0.3, 0.3],
        radius: 0.0,
    }];
    scenario.arm.radius = Some(0.01);
    let run = scenario.build().unwrap().run().unwrap();
    let samples = run.record.len();
    assert!(samples > MAX_SAMPLES, "{samples}");
    let view = from_record(&scenario, "pd", &run.record, None).unwrap();
    let picked = strided(samples, MAX_SAMPLES - 1);
    assert!(view.len() <= MAX_SAMPLES && view.len() == picked.len());
    for (k, (&t, &sample)) in view.t.iter().zip(&picked).enumerate() {
        assert_eq!(t, run.record.t[sample]);
        let tip = &view.joints[k][20..];
        assert!((tip[0] - run.record.tip[sample][0]).abs() < 1e-12);
    }
    assert_eq!(view.t.last(), run.record.t.last());
    assert_eq!(view.obstacles.len(), 1);
}

#[test]
fn bad_data_is_refused_naming_the_field() {
    let good = spatial(5, 4);
    good.check().unwrap();
    type Spoil = Box<dyn Fn(&mut RunView)>;
    let cases: Vec<(&str, Spoil)> = vec![
        ("dims", Box::new(|r| r.dims = 4)),
        ("t: 0 samples", Box::new(|r| r.t.clear())),
        ("t: not increasing", Box::new(|r| r.t[2] = r.t[1])),
        ("t: value 3 is NaN", Box::new(|r| r.t[3] = f64::NAN)),
        (
            "joints: 4 rows",
            Box::new(|r| {
                r.joints.pop();
            }),
        ),
        (
            "joints[1]: 14 numbers",
            Box::new(|r| {
                r.joints[1].pop();
            }),
        ),
        (
            "joints[2]: value 0 is inf",
            Box::new(|r| r.joints[2][0] = f64::INFINITY),
        ),
        // Finite, but beyond what the page's rounding (to 0.1 mm) and drawing can hold.
        (
            "joints[2]: value 1 is 2e304, more than 1e15 in magnitude",
            Box::new(|r| r.joints[2][1] = 2e304),
        ),
        (
            "t: value 4 is 1e16, more than 1e15 in magnitude",
            Box::new(|r| r.t[4] = 1e16),
        ),
        (
            "obstacles[1].radius: 1e300, more than 1e15 in magnitude",
            Box::new(|r| {
                if let Obstacle::Capsule { radius, .. } = &mut r.obstacles[1] {
                    *radius = 1e300;
                }
            }),
        ),
        (
            "tip_ref[0]: 2 numbers",
            Box::new(|r| {
                r.tip_ref[0].pop();
            }),
        ),
        (
            "joint_torque: 4 rows",
            Box::new(|r| {
                r.joint_torque.pop();
            }),
        ),
        (
            "torque_limit: 3 limits",
            Box::new(|r| {
                r.torque_limit.pop();
            }),
        ),
        ("torque_limit: -1", Box::new(|r| r.torque_limit[0] = -1.0)),
        (
            "series[0] (\"clearance\").values[0]: 4 values",
            Box::new(|r| {
                r.series[0].values[0].pop();
            }),
        ),
        (
            "series[0] (\"clearance\"): 2 names for 1 curves",
            Box::new(|r| {
                r.series[0].names.push("x".into());
            }),
        ),
        (
            "obstacles[0]: a circle is planar",
            Box::new(|r| {
                r.obstacles[0] = Obstacle::Circle {
                    centre: vec![0.0, 0.0],
                    radius: 1.0,
                };
            }),
        ),
        (
            "obstacles[1].radius: -0.001, expected a finite non-negative",
            Box::new(|r| {
                if let Obstacle::Capsule { radius, .. } = &mut r.obstacles[1] {
                    *radius = -0.001;
                }
            }),
        ),
        (
            "obstacles[2].half: 2 numbers",
            Box::new(|r| {
                if let Obstacle::Box { half, .. } = &mut r.obstacles[2] {
                    half.pop();
                }
            }),
        ),
        (
            "channels[0].points: 1 points",
            Box::new(|r| {
                r.channels[0].points.pop();
            }),
        ),
        (
            "obstacles[2].half: value 1 is 2e15, more than 1e15 in magnitude",
            Box::new(|r| {
                if let Obstacle::Box { half, .. } = &mut r.obstacles[2] {
                    half[1] = 2e15;
                }
            }),
        ),
        (
            "channels[0].points[1]: value 0 is NaN, not finite",
            Box::new(|r| r.channels[0].points[1][0] = f64::NAN),
        ),
        (
            "channels[0].width: NaN",
            Box::new(|r| r.channels[0].width = f64::NAN),
        ),
    ];
    for (expected, spoil) in cases {
        let mut run = good.clone();
        spoil(&mut run);
        let err = run.check().unwrap_err().to_string();
        assert!(err.starts_with(expected), "{expected}: {err}");
    }
    let empty = Scene {
        title: "s".into(),
        caption: String::new(),
        runs: Vec::new(),
    };
    assert!(
        empty
            .check()
            .unwrap_err()
            .to_string()
            .contains("runs: 0 runs")
    );
    // JSON from elsewhere (Python, a file) goes through the same checks after parsing.
    let text = serde_json::to_string(&good).unwrap();
    let back: RunView = serde_json::from_str(&text).unwrap();
    assert_eq!(back, good);
    let unknown = text.replacen("\"dims\"", "\"dimz\"", 1);
    assert!(serde_json::from_str::<RunView>(&unknown).is_err());
}

#[test]
fn decimation_bounds_the_page_and_keeps_the_run_ends() {
    let run = spatial(2001, 6);
    let small = run.decimated(100);
    small.check().unwrap();
    assert!(small.len() <= 101);
    assert_eq!(small.t[0], run.t[0]);
    assert_eq!(*small.t.last().unwrap(), *run.t.last().unwrap());
    // Coordinates to 0.1 mm, series to 4 significant digits of their peak.
    for (a, b) in small
        .joints
        .last()
        .unwrap()
        .iter()
        .zip(run.joints.last().unwrap())
    {
        assert!((a - b).abs() <= 0.5e-4 + 1e-15, "{a} {b}");
    }
    let peak = 50.0;
    for (&a, k) in small.series[0].values[0].iter().zip(strided(2001, 100)) {
        assert!((a - run.series[0].values[0][k]).abs() <= 0.5e-3 * peak / 10.0 + 1e-12);
    }
    let scene = Scene {
        title: "spatial".into(),
        caption: "c".into(),
        runs: vec![run],
    };
    let full = scene_html(&scene, 100_000).unwrap().len();
    let cut = scene_html(&scene, 100).unwrap().len();
    assert!(cut * 10 < full, "{cut} vs {full}");
}

/// Torques of heavy arms (a run of 1e9 kg links writes 2e21 N m) and series near the subnormals
/// are drawn: the page's data holds numbers, never `null` (the rounding of a peak of `5e-324`
/// to four digits overflowed its scale).
#[test]
fn extreme_but_recorded_values_reach_the_page_as_numbers() {
    let mut run = spatial(5, 4);
    for (k, row) in run.joint_torque.iter_mut().enumerate() {
        row[0] = -2.12e21 * (k as f64 + 1.0);
    }
    run.torque_limit[0] = 1e22;
    run.series[0].values[0] = vec![0.0, f64::from_bits(1), 1e-310, 0.0, 1e-310];
    run.check().unwrap();
    let scene = Scene {
        title: "extremes".into(),
        caption: String::new(),
        runs: vec![run],
    };
    let html = scene_html(&scene, 100).unwrap();
    assert!(!html.contains("null"), "{html}");
    assert!(html.contains("[-1.06e+22,"), "{html}");
}

#[test]
fn the_page_is_self_contained_and_its_data_cannot_end_the_script() {
    let (_, fuzzy) = planar(0.2, ControllerKind::Fuzzy);
    let mut pd = planar(0.2, ControllerKind::Pd).1;
    pd.label = "pd </script><script>alert(1)</script>".into();
    pd.stopped = Some("|a| > pi & \"quoted\"".into());
    let scene = Scene {
        title: "paper-tracking <short>".into(),
        caption: "two controllers".into(),
        runs: vec![fuzzy, pd],
    };
    let html = page("T & U", "intro", &[scene], PAGE_SAMPLES).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.ends_with("</html>\n"));
    assert!(!html.contains("http://") && !html.contains("https://") && !html.contains("src="));
    assert_eq!(
        html.matches("</script>").count(),
        2,
        "only the data's and the viewer's"
    );
    assert!(html.contains("<h3>paper-tracking &lt;short&gt;</h3>"));
    // One scene under its own title: the heading is not repeated.
    let (_, run) = planar(0.2, ControllerKind::Pd);
    let alone = Scene {
        title: "paper-tracking".into(),
        caption: "one run".into(),
        runs: vec![run],
    };
    let single = page("paper-tracking", "intro", &[alone], PAGE_SAMPLES).unwrap();
    assert!(single.contains("<h1>paper-tracking</h1>") && !single.contains("<h3>"));
    assert!(!run_view::SCRIPT.contains("</script"));
    // The data parses back to the decimated runs.
    let start = html.find("application/json\">").unwrap() + "application/json\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    let scene: Scene = serde_json::from_str(&html[start..end]).unwrap();
    assert_eq!(scene.runs[1].label, "pd </script><script>alert(1)</script>");
    scene.check().unwrap();
    // hrm knows its page, and only its page, by the signature in its head.
    let start = |text: &[u8]| text[..text.len().min(run_view::SIGNATURE_WITHIN)].to_vec();
    assert!(run_view::written_by_hrm(&start(html.as_bytes())));
    for other in [
        "my notes: the files here were written by hrm, run 3 looked odd",
        "<!DOCTYPE html><p>written by hrm</p>",
        "<html><meta name=\"generator\" content=\"written by hrm\">",
    ] {
        assert!(!run_view::written_by_hrm(other.as_bytes()), "{other}");
    }
    let frame = run_view::iframe(&html, 600);
    assert!(frame.starts_with("<iframe srcdoc=\"&lt;!DOCTYPE html&gt;"));
    assert!(!frame[8..].contains('"') || frame.matches('"').count() == 6);
}

#[test]
fn the_gif_shows_the_arm_moving_over_its_path() {
    let (_, run) = planar(0.5, ControllerKind::Fuzzy);
    let options = GifOptions {
        width: 200,
        height: 150,
        fps: 20,
        speed: 0.5,
    };
    let mut bytes = Vec::new();
    write_gif(&run, &options, &mut bytes).unwrap();
    assert!(run_view::written_by_hrm(
        &bytes[..bytes.len().min(run_view::SIGNATURE_WITHIN)]
    ));
    assert!(!run_view::written_by_hrm(b"GIF89a written by hrm"));
    let mut decoder = gif::DecodeOptions::new();
    decoder.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = decoder.read_info(&bytes[..]).unwrap();
    assert_eq!((decoder.width(), decoder.height()), (200, 150));
    let mut frames = 0;
    let mut changed = 0;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        frames += 1;
        if frames > 1 && frame.buffer.chunks_exact(4).any(|p| p[3] != 0) {
            changed += 1;
        }
    }
    // 0.5 s of run at half speed and 20 frames a second: 21 frames, the arm moving in each.
    assert_eq!(frames, 21);
    assert!(changed >= 15, "{changed}");
    // The first frame: the arm's base and tip where the camera puts them, the tip on the path.
    let camera = Camera::fit(
        &run.joints
            .iter()
            .flat_map(|r| r.chunks_exact(2).map(|p| [p[0], p[1], 0.0]))
            .chain(run.tip_ref.iter().map(|p| [p[0], p[1], 0.0]))
            .collect::<Vec<_>>(),
        2,
        200.0,
        150.0,
    );
    let mut pixmap = tiny_skia_pixmap(200, 150);
    run_view::draw_frame(&mut pixmap, &run, &camera, 0.0);
    let pixel = |p: [f64; 3]| {
        let i = 4 * (p[1].round() as usize * 200 + p[0].round() as usize);
        pixmap.data()[i..i + 3].to_vec()
    };
    assert_eq!(
        pixel(camera.project([0.0, 0.0, 0.0])),
        [34, 34, 34],
        "the base"
    );
    let middle = &run.joints[0][10..14];
    let link = camera.project([
        0.5 * (middle[0] + middle[2]),
        0.5 * (middle[1] + middle[3]),
        0.0,
    ]);
    let colour = pixel(link);
    assert!(colour != [255, 255, 255], "a link at {link:?}");
    // Refusals: options and an overlong animation.
    // 1e-19 asks for more frames than `usize` counts (the count once wrapped to 0 and wrote an
    // empty GIF).
    for speed in [1e-4, 1e-19, 1e-300] {
        let slow = GifOptions { speed, ..options };
        assert!(
            write_gif(&run, &slow, Vec::new())
                .unwrap_err()
                .to_string()
                .contains("frames"),
            "{speed}"
        );
    }
    // The count is the true one, not a saturated integer.
    let slowest = GifOptions {
        speed: 1e-300,
        ..options
    };
    let message = write_gif(&run, &slowest, Vec::new())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("speed 1e-300 make 1.0000e301 frames"),
        "{message}"
    );
    // Frames within their bound whose pixels together are not: refused before drawing.
    let large = GifOptions {
        width: 2000,
        height: 2000,
        fps: 50,
        speed: 0.0126,
    };
    let message = write_gif(&run, &large, Vec::new()).unwrap_err().to_string();
    assert!(
        message.contains(" frames of 2000 x 2000 pixels make ")
            && message.contains("pixels to draw, more than 2e9"),
        "{message}"
    );
    let wide = GifOptions {
        width: 0,
        ..options
    };
    assert!(
        write_gif(&run, &wide, Vec::new())
            .unwrap_err()
            .to_string()
            .contains("gif width: 0")
    );
    let mut spatial_gif = Vec::new();
    write_gif(&spatial(40, 8), &options, &mut spatial_gif).unwrap();
    assert_eq!(&spatial_gif[..6], b"GIF89a");
}

fn tiny_skia_pixmap(w: u32, h: u32) -> tiny_skia::Pixmap {
    tiny_skia::Pixmap::new(w, h).unwrap()
}

#[test]
fn torque_colours_match_the_viewer() {
    // The stops of viewer.js's torqueColour.
    assert_eq!(run_view::torque_colour(0.0), [49, 99, 170]);
    assert_eq!(run_view::torque_colour(0.4), [44, 160, 44]);
    assert_eq!(run_view::torque_colour(-0.7), [240, 170, 20]);
    assert_eq!(run_view::torque_colour(1.0), [214, 39, 40]);
    assert_eq!(run_view::torque_colour(1.01), [120, 0, 20]);
    assert_eq!(run_view::torque_colour(0.2), [47, 130, 107]);
    // The camera from above: x to the right, y up the picture.
    let camera = Camera {
        yaw: 0.0,
        pitch: 90.0,
        target: [0.0; 3],
        scale: 100.0,
        size: [200.0, 100.0],
    };
    let p = camera.project([1.0, 0.5, 0.0]);
    assert!((p[0] - 200.0).abs() < 1e-9 && (p[1] - 0.0).abs() < 1e-9);
}

/// The viewer script's own tests (`node --test`): skipped when node is missing, unless
/// `HRM_REQUIRE_ENGINES=1` (CI), where a missing node fails.
#[test]
fn viewer_script_tests_pass_under_node() {
    let Some(node) = test_support::engine::program("node", "nodejs") else {
        return;
    };
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    let out = std::process::Command::new(node)
        .arg("--test")
        .arg(assets.join("viewer.test.js"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("# fail 0") && !text.contains("# pass 0"),
        "{text}"
    );
}

#[test]
fn a_run_among_obstacles_draws_them_and_its_clearance() {
    let mut scenario = Scenario::builtin("narrow-gap").unwrap();
    scenario.duration = 0.2;
    let run = scenario.build().unwrap().run().unwrap();
    let view = from_record(&scenario, "computed-torque", &run.record, None).unwrap();
    // The two circles of the scenario, as circles of the plane.
    let circles: Vec<([f64; 2], f64)> = view
        .obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Circle { centre, radius } => ([centre[0], centre[1]], *radius),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(circles.len(), 2);
    assert_eq!(circles[0].1, 0.03);
    let clearance = view.series.iter().find(|s| s.title == "clearance").unwrap();
    assert_eq!(clearance.names, ["to the obstacles", "between links"]);
    // Recomputed here from the drawn points: the distance from each circle's centre to each
    // link's segment, less the circle's and the link's (1 cm) radii; and between links that
    // share no joint, sampled densely along both segments less twice the radius.
    let on =
        |a: [f64; 2], b: [f64; 2], s: f64| [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
    for (k, row) in view.joints.iter().enumerate() {
        let p: Vec<[f64; 2]> = row.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        let mut near = f64::INFINITY;
        for link in p.windows(2) {
            let (a, b) = (link[0], link[1]);
            let d = [b[0] - a[0], b[1] - a[1]];
            for &(c, r) in &circles {
                let s = (((c[0] - a[0]) * d[0] + (c[1] - a[1]) * d[1])
                    / (d[0] * d[0] + d[1] * d[1]))
                    .clamp(0.0, 1.0);
                let q = on(a, b, s);
                near = near.min((c[0] - q[0]).hypot(c[1] - q[1]) - r - 0.01);
            }
        }
        assert!(
            (clearance.values[0][k] - 1e3 * near).abs() < 1e-9,
            "sample {k}"
        );
        if k % 50 == 0 {
            let mut near_self = f64::INFINITY;
            for i in 0..p.len() - 1 {
                for j in i + 2..p.len() - 1 {
                    for s in 0..=100 {
                        for u in 0..=100 {
                            let x = on(p[i], p[i + 1], f64::from(s) / 100.0);
                            let y = on(p[j], p[j + 1], f64::from(u) / 100.0);
                            near_self = near_self.min((x[0] - y[0]).hypot(x[1] - y[1]) - 0.02);
                        }
                    }
                }
            }
            // Sampling finds the closest points to within 1 mm of arc (0.5 mm off).
            let found = clearance.values[1][k];
            assert!(
                found <= 1e3 * near_self + 1e-9 && found > 1e3 * near_self - 1.0,
                "{k}"
            );
        }
    }
    // The loop's minimum over every controller sample is at most the recorded samples'.
    let recorded = clearance.values[0]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let looped = 1e3 * run.summary.min_clearance_m.unwrap();
    assert!(
        looped <= recorded + 1e-9 && looped > recorded - 1.0,
        "{looped} {recorded}"
    );
}
