//! Follow-the-leader deployment: exact on straight channels, the body on its tip's path in a
//! bent one, the metrics against the test's own geometry.

use clearance::segment_segment;
use lane_math::{Classify, ErrorClass};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shape_plan::{Channel, DeployTracker, PlanError, follow_the_leader};

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Straight up 0.2 m, a quarter circle of radius 0.3 m turning right, then 0.3 m along `+x`.
fn bent() -> Vec<[f64; 2]> {
    let mut points = vec![[0.0, 0.0], [0.0, 0.2]];
    for k in 1..=60 {
        let t = std::f64::consts::FRAC_PI_2 * f64::from(k) / 60.0;
        points.push([0.3 - 0.3 * t.cos(), 0.2 + 0.3 * t.sin()]);
    }
    points.push([0.6, 0.5]);
    points
}

#[test]
fn a_straight_channel_is_followed_exactly() {
    let channel = Channel::new(&[[0.0, 0.0], [0.0, 1.0]], 0.03).unwrap();
    let deployment = follow_the_leader(&channel, &[0.1; 10], 0.01, 1, 0.6, 12).unwrap();
    for frame in &deployment.frames {
        assert!((frame.insertion - frame.progress).abs() < 1e-12);
        let tip = frame.points[10];
        assert!(tip[0].abs() < 1e-12 && (tip[1] - frame.progress).abs() < 1e-12);
        assert!(frame.modal.iter().all(|a| a.abs() < 1e-12));
    }
    let m = deployment.metrics;
    assert!(m.tip_error < 1e-12 && m.shape_deviation_percent < 1e-9);
    assert!((m.min_wall_clearance - 0.02).abs() < 1e-12);
}

#[test]
fn in_a_bent_channel_the_body_follows_the_tip() {
    let channel = Channel::new(&bent(), 0.04).unwrap();
    let lengths = [0.1; 10];
    // Five harmonics: J is square and the fit is the exact follow-the-leader chain.
    let exact = follow_the_leader(&channel, &lengths, 0.01, 5, 0.75, 150).unwrap();
    let centerline = bent();
    let to_path = |x: [f64; 2]| {
        let mut best = if x[1] <= 0.0 {
            x[0].abs()
        } else {
            f64::INFINITY
        };
        for pair in centerline.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let t = (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]))
                .clamp(0.0, 1.0);
            best = best.min(dist(x, [a[0] + t * d[0], a[1] + t * d[1]]));
        }
        best
    };
    for frame in exact.frames.iter().step_by(15) {
        // Every joint on the path (the axis or the centreline), every link of its length.
        for (k, p) in frame.points.iter().enumerate() {
            assert!(
                to_path(*p) < 2e-4,
                "joint {k} at {}: {}",
                frame.progress,
                to_path(*p)
            );
        }
        for pair in frame.points.windows(2) {
            assert!((dist(pair[0], pair[1]) - 0.1).abs() < 1e-12);
        }
        assert!(dist(frame.points[10], channel.point_at(frame.progress)) < 1e-9);
    }
    let m = exact.metrics;
    assert!(m.tip_error < 1e-9, "{}", m.tip_error);
    // Between joints the links are chords of the arc: sagitta L^2 / (8 R) = 4.2 mm at most.
    assert!(
        m.shape_deviation_percent < 5.0,
        "{}",
        m.shape_deviation_percent
    );
    assert!(m.min_wall_clearance > 0.0 && m.min_wall_clearance < 0.03);
    // One harmonic cannot hold the straight guide and the bend: the metric shows it.
    let coarse = follow_the_leader(&channel, &lengths, 0.01, 1, 0.75, 150).unwrap();
    assert!(coarse.metrics.shape_deviation_percent > 2.0 * m.shape_deviation_percent);
    assert!(coarse.metrics.tip_error > 1e-3);
}

#[test]
fn deployments_refuse_what_they_cannot_do() {
    let text = |e: PlanError| e.to_string();
    assert!(text(Channel::new(&[[0.0, 0.0]], 0.03).unwrap_err()).contains("at least 2 points"));
    assert!(
        text(Channel::new(&[[0.0, 0.0], [0.0, 0.0]], 0.03).unwrap_err()).contains("segment length")
    );
    assert!(
        text(Channel::new(&[[0.0, 0.0], [0.0, 1.0]], 0.0).unwrap_err()).contains("deploy radius")
    );
    // Points closer than a nanometre, and a radius below one.
    let close = [[0.0, 0.0], [0.0, 1e-320], [0.0, 2e-320]];
    assert_eq!(
        text(Channel::new(&close, 0.03).unwrap_err()),
        "deploy centerline segment length must be at least 1e-9 m (consecutive points distinct), \
         got 1e-320"
    );
    assert!(Channel::new(&[[0.0, 0.0], [0.0, 1e-9]], 1e-9).is_ok());
    assert_eq!(
        text(Channel::new(&[[0.0, 0.0], [0.0, 1.0]], 1e-316).unwrap_err()),
        "deploy radius must be from 1e-9 m to 1e6 m, got 1e-316"
    );
    assert!(
        text(Channel::new(&[[f64::NAN, 0.0], [0.0, 1.0]], 0.1).unwrap_err()).contains("finite")
    );
    let channel = Channel::new(&[[0.0, 0.0], [0.0, 3.0]], 0.03).unwrap();
    let short = follow_the_leader(&channel, &[0.1; 10], 0.01, 1, 2.0, 10).unwrap_err();
    assert!(text(short).contains("too short"));
    let deep = follow_the_leader(&channel, &[0.1; 10], 0.01, 1, 4.0, 10).unwrap_err();
    assert!(text(deep).contains("deploy depth"));
    let steps = follow_the_leader(&channel, &[0.1; 10], 0.01, 1, 0.5, usize::MAX).unwrap_err();
    assert!(text(steps).contains("deploy steps"));
    let tiny = follow_the_leader(&channel, &[1e-9; 10], 0.0, 1, 0.0, 10).unwrap_err();
    assert!(text(tiny).contains("shortest link"));
    let far = Channel::new(&[[1e12, 0.0], [1e12, 1.0]], 0.03).unwrap_err();
    assert!(text(far).contains("deploy centerline coordinate must be within 1e6 m"));
    let narrow = follow_the_leader(&channel, &[0.1; 10], 0.03, 1, 0.5, 10).unwrap_err();
    assert!(text(narrow).starts_with("deploy radius (the arm must fit in the channel)"));
}

#[test]
fn a_centreline_that_turns_back_is_refused_as_the_body_would_fold() {
    // Up 0.4 m, then straight back down: once the tip is a link past the turn, the last link
    // lies over the one two before it.
    let channel = Channel::new(&[[0.0, 0.0], [0.0, 0.4], [0.0, 0.2]], 0.04).unwrap();
    let error = follow_the_leader(&channel, &[0.1; 10], 0.01, 5, 0.6, 60).unwrap_err();
    assert!(
        matches!(error, PlanError::DeployFoldsOnItself { progress, clearance }
            if progress > 0.5 && progress < 0.52 && clearance < -0.019),
        "{error:?}"
    );
    assert!(
        error
            .to_string()
            .starts_with("deploy centerline folds the arm onto itself")
    );
    assert_eq!(error.class(), ErrorClass::Unreachable);
    // The same turn on a hairpin wide enough for the body is followed.
    let wide = Channel::new(&[[0.0, 0.0], [0.0, 0.4], [0.3, 0.4], [0.3, 0.2]], 0.04).unwrap();
    let deployment = follow_the_leader(&wide, &[0.1; 10], 0.01, 5, 0.6, 60).unwrap();
    assert!(deployment.metrics.min_self_clearance > 0.0);
}

#[test]
fn self_clearance_is_the_smallest_over_links_that_share_no_joint() {
    // A U of three links 0.3 m apart (links 0 and 2 parallel): 0.3 - 2 r.
    let channel = Channel::new(&[[0.0, 0.0], [1.0, 0.0]], 1.0).unwrap();
    let mut tracker = DeployTracker::new(&channel, &[1.0, 0.3, 1.0], 0.01).unwrap();
    let sample = tracker.add(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.3], [0.0, 0.3]], 1.0);
    assert!((sample.self_clearance - 0.28).abs() < 1e-15);
    // Random chains: the skipped pairs never held the smallest (brute force over every pair).
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let n = rng.random_range(3..14);
        let mut points = vec![[0.0, 0.0]];
        let mut heading: f64 = 0.0;
        for _ in 0..n {
            heading += rng.random_range(-2.5..2.5);
            let last = points[points.len() - 1];
            let length = rng.random_range(0.05..0.2);
            points.push([
                last[0] + length * heading.cos(),
                last[1] + length * heading.sin(),
            ]);
        }
        let radius = rng.random_range(0.0..0.03);
        let mut tracker = DeployTracker::new(&channel, &vec![0.1; n], radius).unwrap();
        let found = tracker.add(&points, 1.0).self_clearance;
        let space = |p: [f64; 2]| [p[0], p[1], 0.0];
        let mut brute = f64::INFINITY;
        for i in 0..n {
            for k in i + 2..n {
                let pair = segment_segment(
                    space(points[i]),
                    space(points[i + 1]),
                    space(points[k]),
                    space(points[k + 1]),
                );
                brute = brute.min(pair.distance - 2.0 * radius);
            }
        }
        assert_eq!(found.to_bits(), brute.to_bits(), "{points:?}");
        assert_eq!(
            tracker.metrics().min_self_clearance.to_bits(),
            brute.to_bits()
        );
    }
}
