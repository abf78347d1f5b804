//! A planar channel for follow-the-leader deployment: its centreline, the guide behind its
//! entry, and distances to them.

use crate::error::PlanError;
use crate::polyline::{Polyline, dist};
use lane_math::check_finite;

/// The most centreline points a [`Channel`] accepts.
pub const MAX_CENTERLINE_POINTS: usize = 100_000;
/// The largest magnitude of a centreline coordinate (m): at `1e6` m a coordinate's rounding is
/// `1e-10` m, so that the deployment's metrics keep their sub-micrometre meaning (a channel a
/// million kilometres out would round them to millimetres).
pub const MAX_CENTERLINE_EXTENT: f64 = 1e6;

/// The shortest centreline segment and the smallest radius (m): a nanometre, ten times the
/// rounding of a coordinate at [`MAX_CENTERLINE_EXTENT`] (points `1e-320` m apart made a channel
/// whose deployed length came out negative).
pub const MIN_CENTERLINE_SCALE: f64 = 1e-9;

/// A planar channel: a centreline polyline (the plane `z = 0`) and its radius.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    points: Vec<[f64; 2]>,
    /// The same points, chunked for distance queries.
    line: Polyline,
    /// Arc length at each point.
    arcs: Vec<f64>,
    radius: f64,
}

impl Channel {
    /// A channel along `centerline` (at least two points, consecutive points at least
    /// [`MIN_CENTERLINE_SCALE`] apart, each coordinate within [`MAX_CENTERLINE_EXTENT`]) of
    /// `radius` (from [`MIN_CENTERLINE_SCALE`] to [`MAX_CENTERLINE_EXTENT`]).
    pub fn new(centerline: &[[f64; 2]], radius: f64) -> Result<Self, PlanError> {
        if centerline.len() < 2 {
            return Err(PlanError::Dimension {
                name: "deploy centerline (at least 2 points)",
                expected: 2,
                found: centerline.len(),
            });
        }
        if centerline.len() > MAX_CENTERLINE_POINTS {
            return Err(PlanError::TooMany {
                name: "deploy centerline points",
                got: centerline.len(),
                max: MAX_CENTERLINE_POINTS,
            });
        }
        check_finite("deploy radius", radius)?;
        if !(MIN_CENTERLINE_SCALE..=MAX_CENTERLINE_EXTENT).contains(&radius) {
            return Err(PlanError::OutOfRange {
                name: "deploy radius",
                bound: "from 1e-9 m to 1e6 m",
                value: radius,
            });
        }
        for x in centerline.iter().flatten() {
            check_finite("deploy centerline coordinate", *x)?;
            if x.abs() > MAX_CENTERLINE_EXTENT {
                return Err(PlanError::OutOfRange {
                    name: "deploy centerline coordinate",
                    bound: "within 1e6 m of the origin",
                    value: *x,
                });
            }
        }
        let mut arcs = vec![0.0];
        for pair in centerline.windows(2) {
            let step = dist(pair[0], pair[1]);
            if step.is_nan() || step < MIN_CENTERLINE_SCALE {
                return Err(PlanError::OutOfRange {
                    name: "deploy centerline segment length",
                    bound: "at least 1e-9 m (consecutive points distinct)",
                    value: step,
                });
            }
            arcs.push(arcs.last().copied().unwrap_or(0.0) + step);
        }
        Ok(Self {
            points: centerline.to_vec(),
            line: Polyline::new(centerline),
            arcs,
            radius,
        })
    }

    /// The centreline's polyline.
    pub(crate) fn line(&self) -> &Polyline {
        &self.line
    }

    /// The centreline's length.
    pub fn length(&self) -> f64 {
        self.arcs.last().copied().unwrap_or(0.0)
    }

    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The entry `P_0`.
    pub fn entry(&self) -> [f64; 2] {
        self.points[0]
    }

    /// The insertion axis's direction `d` (unit).
    pub fn axis(&self) -> [f64; 2] {
        let (a, b) = (self.points[0], self.points[1]);
        let length = dist(a, b);
        [(b[0] - a[0]) / length, (b[1] - a[1]) / length]
    }

    /// `Gamma(sigma)`: on the axis behind the entry for `sigma <= 0`, on the centreline beyond
    /// (held at its end past its length); NaN coordinates for a NaN `sigma`.
    pub fn point_at(&self, sigma: f64) -> [f64; 2] {
        if sigma <= 0.0 || sigma.is_nan() {
            let (e, d) = (self.entry(), self.axis());
            return [e[0] + sigma * d[0], e[1] + sigma * d[1]];
        }
        let k = self
            .arcs
            .partition_point(|&s| s <= sigma)
            .min(self.points.len() - 1);
        let (a, b) = (self.points[k - 1], self.points[k]);
        let t = ((sigma - self.arcs[k - 1]) / (self.arcs[k] - self.arcs[k - 1])).min(1.0);
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }

    /// The distance of `x` from the guide (the axis behind the entry) and the centreline.
    pub fn distance(&self, x: [f64; 2]) -> f64 {
        self.guide_distance(x).min(self.line.distance(x))
    }

    /// The distance of `x` from the guide, the ray `E - s d`, `s >= 0`.
    pub(crate) fn guide_distance(&self, x: [f64; 2]) -> f64 {
        let (e, d) = (self.entry(), self.axis());
        let along = ((x[0] - e[0]) * d[0] + (x[1] - e[1]) * d[1]).min(0.0);
        dist(x, [e[0] + along * d[0], e[1] + along * d[1]])
    }
}
