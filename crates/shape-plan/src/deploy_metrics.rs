//! The metrics of a follow-the-leader deployment, accumulated over its shapes: those of the
//! kinematic plan ([`follow_the_leader`](crate::follow_the_leader)) and those of a dynamic run
//! that tracks it (`docs/theory.md`, "Follow-the-leader deployment").

use crate::channel::Channel;
use crate::error::PlanError;
use crate::farthest::{FARTHEST_ALLOWANCE, FarthestScratch};
use crate::polyline::{Polyline, dist, point_segment};
use clearance::segment_segment;
use lane_math::check_finite;

/// Points per link at which the body's distance to the traced path is sampled (both ends
/// included).
pub const SAMPLES_PER_LINK: usize = 32;

/// The most work the metrics of a deployment's shapes may take ([`deploy_metric_work`]): about
/// 20 s on one core of 2026, so that a request for more is refused up front rather than hangs.
pub const MAX_DEPLOY_METRIC_WORK: f64 = 2e9;

/// The work of measuring `shapes` shapes of a chain of `links` links, in units of about 10 ns:
/// per shape, ten for each of the body's sampled points ([`SAMPLES_PER_LINK`] + 1 a link, each
/// measured against the channel and the traced path), a quarter for each measurement of the
/// wall clearance's allowance ([`FARTHEST_ALLOWANCE`] a link, the most its calls spend on
/// average), and one for each pair of links (the self clearance's bound).
pub fn deploy_metric_work(links: usize, shapes: usize) -> f64 {
    let links = links as f64;
    let points = links * (SAMPLES_PER_LINK + 1) as f64;
    let farthest = links * FARTHEST_ALLOWANCE as f64 / 4.0;
    shapes as f64 * (10.0 * points + farthest + 0.5 * links * (links - 1.0).max(0.0))
}

/// What a deployment achieved, over all its shapes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeployMetrics {
    /// The largest distance of the tip from the centreline (with the guide behind the entry),
    /// m.
    pub tip_error: f64,
    /// The largest distance of the body from the path its tip traced (joined to the entry and
    /// the guide behind it), as a percentage of the deployed length at that shape (at least the
    /// shortest link), sampled at [`SAMPLES_PER_LINK`] + 1 points a link.
    pub shape_deviation_percent: f64,
    /// The smallest clearance of the links' capsules to the channel's walls, m: the channel's
    /// radius less the link radius and the largest distance of a link's point from the
    /// centreline and the guide ([`Channel::farthest`]: exact to `1e-14` of a link's length or
    /// coordinates; where more than [`MAX_NEAR_FEATURES`](crate::MAX_NEAR_FEATURES) centreline
    /// segments lie near a link, at most `L / 128` below the exact one, never above it).
    pub min_wall_clearance: f64,
    /// The smallest clearance between two links' capsules that share no joint, m (exact;
    /// `+inf` below three links): negative where the body overlaps itself.
    pub min_self_clearance: f64,
    /// The deployed length of the last shape: the arm's length past the entry, its insertion
    /// `q`, m (at most the tip's progress along the centreline, whose chords the links are).
    pub deployed_length: f64,
}

/// The metrics of one shape of a deployment ([`DeployTracker::add`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeploySample {
    /// The tip's distance from the centreline, m.
    pub tip_error: f64,
    /// The body's largest distance from the traced path, % of the deployed length.
    pub shape_deviation_percent: f64,
    /// The body's smallest clearance to the walls, m.
    pub wall_clearance: f64,
    /// The smallest clearance between two of its links that share no joint, m.
    pub self_clearance: f64,
}

/// Accumulates [`DeployMetrics`] over the shapes of a deployment, in time order: each shape's
/// tip joins the traced path the later shapes are measured against.
///
/// ```
/// use shape_plan::{Channel, DeployTracker};
/// let channel = Channel::new(&[[0.0, 0.0], [1.0, 0.0]], 0.05)?;
/// let mut tracker = DeployTracker::new(&channel, &[0.5, 0.5], 0.01)?;
/// tracker.add(&[[-0.7, 0.0], [-0.2, 0.0], [0.3, 0.0]], 0.3);
/// let metrics = tracker.metrics();
/// assert!(metrics.tip_error < 1e-15 && metrics.shape_deviation_percent < 1e-12);
/// assert!((metrics.min_wall_clearance - 0.04).abs() < 1e-15);
/// assert_eq!(metrics.min_self_clearance, f64::INFINITY); // two links share their joint
/// # Ok::<(), shape_plan::PlanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct DeployTracker<'c> {
    channel: &'c Channel,
    link_radius: f64,
    shortest: f64,
    /// The tip's path so far.
    traced: Polyline,
    /// The work of the wall clearance's [`Channel::farthest`].
    farthest: FarthestScratch,
    metrics: DeployMetrics,
}

impl<'c> DeployTracker<'c> {
    /// A tracker of the chain of `link_lengths` (at least one, each positive), its links
    /// capsules of `link_radius` (non-negative), in `channel`.
    pub fn new(
        channel: &'c Channel,
        link_lengths: &[f64],
        link_radius: f64,
    ) -> Result<Self, PlanError> {
        check_finite("link radius", link_radius)?;
        if link_radius < 0.0 {
            return Err(PlanError::OutOfRange {
                name: "link radius",
                bound: "non-negative",
                value: link_radius,
            });
        }
        let shortest = link_lengths.iter().copied().fold(f64::INFINITY, f64::min);
        if !(shortest.is_finite() && shortest > 0.0) {
            return Err(PlanError::OutOfRange {
                name: "deploy link length",
                bound: "positive and finite, at least one link",
                value: shortest,
            });
        }
        Ok(Self {
            channel,
            link_radius,
            shortest,
            traced: Polyline::default(),
            farthest: FarthestScratch::default(),
            metrics: DeployMetrics {
                tip_error: 0.0,
                shape_deviation_percent: 0.0,
                min_wall_clearance: f64::INFINITY,
                min_self_clearance: f64::INFINITY,
                deployed_length: 0.0,
            },
        })
    }

    /// Reserves room for `shapes` more [`add`](Self::add)s, so that they allocate nothing.
    ///
    /// # Errors
    /// [`PlanError::OutOfRange`] when the memory cannot be reserved.
    pub fn reserve(&mut self, shapes: usize) -> Result<(), PlanError> {
        self.traced
            .try_reserve(shapes)
            .map_err(|_| PlanError::OutOfRange {
                name: "deployment samples",
                bound: "within the memory available",
                value: shapes as f64,
            })
    }

    /// Adds the shape of joint points `points` (base first, the tip last, at least one) at the
    /// deployed length `deployed` (m) and returns its own metrics: the tip's distance from the
    /// centreline, the body's largest distance from the traced path (this tip included) over
    /// `max(deployed, shortest link)`, the body's smallest clearance to the walls and between
    /// its links that share no joint.
    pub fn add(&mut self, points: &[[f64; 2]], deployed: f64) -> DeploySample {
        let tip = points.last().copied().unwrap_or(self.channel.entry());
        self.traced.push(tip);
        let channel = self.channel;
        let mut sample = DeploySample {
            tip_error: channel.distance(tip),
            shape_deviation_percent: 0.0,
            wall_clearance: f64::INFINITY,
            self_clearance: self_clearance(points, self.link_radius),
        };
        let mut deviation: f64 = 0.0;
        for pair in points.windows(2) {
            let farthest = channel.farthest(pair[0], pair[1], &mut self.farthest);
            sample.wall_clearance = sample
                .wall_clearance
                .min(channel.radius() - self.link_radius - farthest);
            for s in 0..=SAMPLES_PER_LINK {
                let t = s as f64 / SAMPLES_PER_LINK as f64;
                let x = [
                    pair[0][0] + t * (pair[1][0] - pair[0][0]),
                    pair[0][1] + t * (pair[1][1] - pair[0][1]),
                ];
                deviation = deviation.max(traced_distance(channel, &self.traced, x));
            }
        }
        sample.shape_deviation_percent = 100.0 * deviation / deployed.max(self.shortest);
        let metrics = &mut self.metrics;
        metrics.tip_error = metrics.tip_error.max(sample.tip_error);
        metrics.shape_deviation_percent = metrics
            .shape_deviation_percent
            .max(sample.shape_deviation_percent);
        metrics.min_wall_clearance = metrics.min_wall_clearance.min(sample.wall_clearance);
        metrics.min_self_clearance = metrics.min_self_clearance.min(sample.self_clearance);
        metrics.deployed_length = deployed;
        sample
    }

    /// The metrics of the shapes added so far.
    pub fn metrics(&self) -> DeployMetrics {
        self.metrics
    }
}

/// The smallest clearance between two links of the chain of joint points `points` that share no
/// joint (capsules of `radius`; `+inf` below three links), each pair's exact segment distance
/// ([`clearance::segment_segment`]) unless a lower bound already reaches the smallest found: a
/// link lies within half its length of its midpoint, so two links are at least the distance
/// of their midpoints less both half-lengths apart (most pairs of a body along a channel are
/// then skipped after a few multiplications and one square root).
fn self_clearance(points: &[[f64; 2]], radius: f64) -> f64 {
    let space = |p: [f64; 2]| [p[0], p[1], 0.0];
    let middle = |link: &[[f64; 2]]| {
        [
            0.5 * (link[0][0] + link[1][0]),
            0.5 * (link[0][1] + link[1][1]),
        ]
    };
    let half = |link: &[[f64; 2]]| {
        let d = [link[1][0] - link[0][0], link[1][1] - link[0][1]];
        0.5 * (d[0] * d[0] + d[1] * d[1]).sqrt()
    };
    let mut smallest = f64::INFINITY;
    for (i, link) in points.windows(2).enumerate() {
        let (centre, reach_of_link) = (middle(link), half(link));
        for other in points.get(i + 2..).unwrap_or(&[]).windows(2) {
            let other_half = half(other);
            // The pair is skipped when its midpoints lie at least `reach` apart; a relative
            // slack far above the rounding keeps every pair that could hold the smallest.
            let halves = reach_of_link + other_half;
            let reach = smallest + halves + 2.0 * radius + 1e-9 * halves;
            let offset = middle(other);
            let apart2 = (offset[0] - centre[0]).powi(2) + (offset[1] - centre[1]).powi(2);
            if reach <= 0.0 || apart2 >= reach * reach {
                continue;
            }
            let closest = segment_segment(
                space(link[0]),
                space(link[1]),
                space(other[0]),
                space(other[1]),
            );
            smallest = smallest.min(closest.distance - 2.0 * radius);
        }
    }
    smallest
}

/// The distance of `x` from the tip's traced polyline joined to the entry and the guide behind
/// it.
fn traced_distance(channel: &Channel, traced: &Polyline, x: [f64; 2]) -> f64 {
    let (e, d) = (channel.entry(), channel.axis());
    let along = ((x[0] - e[0]) * d[0] + (x[1] - e[1]) * d[1]).min(0.0);
    let mut best = dist(x, [e[0] + along * d[0], e[1] + along * d[1]]);
    if let Some(first) = traced.first() {
        best = best.min(point_segment(x, e, first));
    }
    best.min(traced.distance(x))
}
