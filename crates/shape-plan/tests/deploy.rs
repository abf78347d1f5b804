//! Follow-the-leader deployment: exact on straight channels, the body on its tip's path in a
//! bent one, the metrics against the test's own geometry.

use clearance::segment_segment;
use lane_math::{Classify, ErrorClass};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shape_plan::{Channel, DeployTracker, MAX_NEAR_FEATURES, PlanError, follow_the_leader};

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
    assert!(channel.point_at(f64::NAN).iter().all(|x| x.is_nan()));
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
    // A link of no length is named, not read as an infinite centreline ratio.
    let straight = Channel::new(&[[0.0, 0.0], [0.0, 1.0]], 0.03).unwrap();
    let zero = follow_the_leader(&straight, &[0.1, 0.0, 0.1], 0.01, 1, 0.1, 4).unwrap_err();
    assert_eq!(text(zero), "link length must be positive and finite, got 0");
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
    // A straight channel: the arm's 1 m, found by bisection on the tip's progress.
    let PlanError::ArmTooShort { depth, reach } = short else {
        panic!("{short:?}");
    };
    assert_eq!(depth, 2.0);
    assert!((reach - 1.0).abs() <= 1e-12, "{reach}");
    let short = text(short);
    assert!(
        short.starts_with("deploy.centerline's length 2 m is more than the arm reaches"),
        "{short}"
    );
    assert!(short.contains("too short"));
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

/// The distance of `x` from the guide behind `centerline[0]` (the ray back along the first
/// segment) and the centreline, measured as the test's own geometry: every segment.
fn centreline_distance(centerline: &[[f64; 2]], x: [f64; 2]) -> f64 {
    let point_segment = |a: [f64; 2], b: [f64; 2]| {
        let d = [b[0] - a[0], b[1] - a[1]];
        let t = (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]))
            .clamp(0.0, 1.0);
        dist(x, [a[0] + t * d[0], a[1] + t * d[1]])
    };
    let (e, f) = (centerline[0], centerline[1]);
    let u = [(f[0] - e[0]) / dist(e, f), (f[1] - e[1]) / dist(e, f)];
    let behind = ((x[0] - e[0]) * u[0] + (x[1] - e[1]) * u[1]).min(0.0);
    let guide = dist(x, [e[0] + behind * u[0], e[1] + behind * u[1]]);
    centerline.windows(2).fold(guide, |best, pair| {
        best.min(point_segment(pair[0], pair[1]))
    })
}

#[test]
fn the_farthest_point_of_a_link_cutting_a_corner_is_where_both_walls_are_equally_far() {
    // A right-angle corner: along the link from (0, 0.3) to (0.6, 1) the distances to the two
    // legs are 0.6 t and 0.7 (1 - t), equal at t = 7/13, where the link is 0.42/1.3 from the
    // centreline; the 33 samples of the traced path miss that point by 2 mm.
    let channel = Channel::new(&[[0.0, 0.0], [0.0, 1.0], [1.0, 1.0]], 0.5).unwrap();
    let mut scratch = shape_plan::FarthestScratch::default();
    let farthest = channel.farthest([0.0, 0.3], [0.6, 1.0], &mut scratch);
    assert!((farthest - 0.42 / 1.3).abs() < 1e-13, "{farthest}");
    let sampled = (0..=32)
        .map(|s| {
            let t = f64::from(s) / 32.0;
            channel.distance([0.6 * t, 0.3 + 0.7 * t])
        })
        .fold(0.0, f64::max);
    assert!(farthest - sampled > 1e-3, "{sampled}");
}

#[test]
fn the_farthest_point_of_random_links_in_random_channels_is_the_dense_samples_largest() {
    // Random walks of 3 to 40 points as centrelines and random segments around them: the answer
    // lies between the largest of 20,001 samples of the segment (less 1e-14 of its scale) and
    // that largest plus the half sample spacing the distance (1-Lipschitz) can rise between two
    // samples.
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut scratch = shape_plan::FarthestScratch::default();
    for case in 0..300 {
        let mut centerline = vec![[0.0, 0.0]];
        for _ in 0..rng.random_range(2..40) {
            let last = centerline[centerline.len() - 1];
            let angle: f64 = rng.random_range(-3.0..3.0);
            let step = rng.random_range(0.01..0.3);
            centerline.push([last[0] + step * angle.cos(), last[1] + step * angle.sin()]);
        }
        let channel = Channel::new(&centerline, 0.1).unwrap();
        let mut around = || [rng.random_range(-1.0..1.5), rng.random_range(-1.0..1.5)];
        let (p, q) = (around(), around());
        let farthest = channel.farthest(p, q, &mut scratch);
        let samples = 20_000;
        let sampled = (0..=samples)
            .map(|s| {
                let t = f64::from(s) / f64::from(samples);
                let x = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                centreline_distance(&centerline, x)
            })
            .fold(0.0, f64::max);
        let length = dist(p, q);
        assert!(
            farthest >= sampled - 1e-14 * length.max(1.5) - 1e-15
                && farthest <= sampled + 0.5 * length / f64::from(samples) + 1e-15,
            "case {case}: {farthest} against {sampled} sampled"
        );
    }
}

#[test]
fn a_link_among_more_centreline_segments_than_the_bound_takes_is_never_overstated() {
    // 2,000 collinear points: every segment within reach of the link, more than
    // MAX_NEAR_FEATURES, so the distance is sampled, and the answer is never below the exact
    // farthest distance (0.03 m, at the link's end) nor above it by more than L / 128.
    let centerline: Vec<[f64; 2]> = (0..2000).map(|k| [f64::from(k) / 1999.0, 0.0]).collect();
    let channel = Channel::new(&centerline, 0.1).unwrap();
    let mut scratch = shape_plan::FarthestScratch::default();
    let (p, q) = ([0.2, 0.01], [0.5, 0.03]);
    let farthest = channel.farthest(p, q, &mut scratch);
    let length = dist(p, q);
    assert!(
        farthest >= 0.03 && farthest <= 0.03 + length / 128.0,
        "{farthest}"
    );
    // A few segments near it: exact.
    let sparse = Channel::new(&[[0.0, 0.0], [0.4, 0.0], [1.0, 0.0]], 0.1).unwrap();
    assert!((sparse.farthest(p, q, &mut scratch) - 0.03).abs() < 1e-16);
}

#[test]
fn a_link_along_a_zigzag_spends_no_more_than_its_allowance_and_never_overstates() {
    // 200 segments zigzagging across the link: a hundred humps of the distance, nearly equal,
    // each for the branch and bound to resolve, past one call's allowance.
    let centerline: Vec<[f64; 2]> = (0..=200)
        .map(|k| [f64::from(k) * 1e-3, if k % 2 == 0 { 2e-3 } else { -2e-3 }])
        .collect();
    let channel = Channel::new(&centerline, 0.1).unwrap();
    let (p, q) = ([0.02, 1e-4], [0.18, -1e-4]);
    let samples = 200_000;
    let sampled = (0..=samples)
        .map(|s| {
            let t = f64::from(s) / f64::from(samples);
            channel.distance([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])])
        })
        .fold(0.0, f64::max);
    let spacing = dist(p, q) / f64::from(samples);
    let mut fresh = shape_plan::FarthestScratch::default();
    let capped = channel.farthest(p, q, &mut fresh);
    assert!(
        fresh.allowance() < MAX_NEAR_FEATURES,
        "{}",
        fresh.allowance()
    );
    assert!(capped >= sampled - 1e-15, "{capped} against {sampled}");
    // What cheap calls left unspent pays for it: the exact answer.
    let mut funded = shape_plan::FarthestScratch::default();
    for _ in 0..200 {
        channel.farthest([0.1, 0.5], [0.1, 0.5001], &mut funded);
    }
    let exact = channel.farthest(p, q, &mut funded);
    assert!(
        exact >= sampled - 1e-15 && exact <= sampled + 0.5 * spacing,
        "{exact} against {sampled}"
    );
    // Past the allowance: a bound, at or above the exact answer and within the sampled bound.
    assert!(
        capped >= exact - 1e-15 && capped <= exact + dist(p, q) / 64.0,
        "{capped} against {exact}"
    );
}
