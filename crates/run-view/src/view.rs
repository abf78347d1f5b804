//! What the page, the viewer and the GIF draw: a run as plain data ([`RunView`]), the same
//! scenario under one or more controllers ([`Scene`]), checked before anything is drawn.
//!
//! This is also the page's data format (JSON, `docs/run-view.md`): every point has 2
//! coordinates (a planar arm, in its plane) or 3 (a spatial arm); obstacles, channels, joint
//! torques with their limits and extra series (such as clearance) are optional.

use crate::error::{FieldProblem, ViewError};
use serde::{Deserialize, Serialize};

/// The most samples a run may hold (the page's data is decimated well below this).
pub const MAX_SAMPLES: usize = 100_000;
/// The most points (joints and base) an arm may have.
pub const MAX_POINTS: usize = 1_001;
/// The most obstacles (a scenario's most, [`sim_study::MAX_SCENARIO_OBSTACLES`]), channels or
/// series groups of a run.
pub const MAX_ITEMS: usize = sim_study::MAX_SCENARIO_OBSTACLES;
/// The most runs a scene may compare.
pub const MAX_RUNS: usize = 64;
/// The largest magnitude of a time or a coordinate of a run (s, m): beyond the runaway bounds of
/// any run hrm writes, and far below where the page's rounding to 0.1 mm or the drawing's
/// distances overflow.
pub const MAX_MAGNITUDE: f64 = 1e15;
/// The largest magnitude of a series value, a joint torque or a torque limit: a run of an arm
/// of heavy links writes torques beyond [`MAX_MAGNITUDE`] (`2e21` N m for links of `1e9` kg and
/// `1e4` m), and these are only rounded to significant digits.
pub const MAX_VALUE: f64 = 1e100;

/// A run as drawn: the arm's points, the reference and the time series, sample by sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunView {
    /// The run's name in the page (e.g. the controller).
    pub label: String,
    /// 2 for a planar arm drawn in its plane (x, y), 3 for a spatial arm (x, y, z).
    pub dims: usize,
    /// Sample times (s), increasing.
    pub t: Vec<f64>,
    /// Per sample, the arm's points base first, tip last, flattened (`dims` numbers a point, m).
    pub joints: Vec<Vec<f64>>,
    /// Per sample, the reference tip (`dims` numbers, m); empty when there is none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tip_ref: Vec<Vec<f64>>,
    /// Per sample, the torque of each joint (N m; joint `i` drives link `i`); empty when unknown.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_torque: Vec<Vec<f64>>,
    /// The joints' torque limits (N m, one a joint); empty when the arm has none, and then the
    /// links are coloured against the run's peak torque.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_limit: Vec<f64>,
    /// Time series drawn beside the arm, one panel each.
    #[serde(default)]
    pub series: Vec<Series>,
    /// Obstacles in the workspace.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<Obstacle>,
    /// Channels the arm moves through.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub channels: Vec<Channel>,
    /// Set when the run stopped early: why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

/// A panel of time series sharing a unit (e.g. the modal coordinates and their references).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Series {
    /// What the panel shows, e.g. `tip error`.
    pub title: String,
    /// The unit of its values, e.g. `mm`.
    pub unit: String,
    /// One name a curve.
    pub names: Vec<String>,
    /// One curve a name, one value a sample of [`RunView::t`].
    pub values: Vec<Vec<f64>>,
}

/// An obstacle: a disc in the plane, a sphere, a capsule (a segment with a radius) or an
/// axis-aligned box; points have the run's [`dims`](RunView::dims) coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Obstacle {
    /// A disc (planar) of `radius` about `centre`.
    Circle {
        /// Centre (m).
        centre: Vec<f64>,
        /// Radius (m).
        radius: f64,
    },
    /// A ball (spatial) of `radius` about `centre`.
    Sphere {
        /// Centre (m).
        centre: Vec<f64>,
        /// Radius (m).
        radius: f64,
    },
    /// The points within `radius` of the segment from `a` to `b`.
    Capsule {
        /// One end of the axis (m).
        a: Vec<f64>,
        /// The other end (m).
        b: Vec<f64>,
        /// Radius (m).
        radius: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Centre (m).
        centre: Vec<f64>,
        /// Half the side along each axis (m).
        half: Vec<f64>,
    },
}

/// A channel: a tube (or strip, planar) of `width` about a polyline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Channel {
    /// The centre line (m).
    pub points: Vec<Vec<f64>>,
    /// The channel's full width (m).
    pub width: f64,
}

/// One animation of a page: the same scenario under one or more controllers, compared side by
/// side or overlaid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The heading, e.g. the scenario's name.
    pub title: String,
    /// One line that says what to look at.
    pub caption: String,
    /// The runs (at least one).
    pub runs: Vec<RunView>,
}

impl Scene {
    /// Checks every run ([`RunView::check`]); the error names the run and the field.
    pub fn check(&self) -> Result<(), ViewError> {
        if self.runs.is_empty() || self.runs.len() > MAX_RUNS {
            return Err(ViewError::RunCount {
                title: self.title.clone(),
                count: self.runs.len(),
                max: MAX_RUNS,
            });
        }
        for run in &self.runs {
            run.check().map_err(|e| ViewError::Run {
                title: self.title.clone(),
                label: run.label.clone(),
                source: Box::new(e),
            })?;
        }
        Ok(())
    }
}

impl RunView {
    /// The number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether the run has no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The number of points of the arm (base and joints, the tip last).
    pub fn points(&self) -> usize {
        self.joints
            .first()
            .map_or(0, |j| j.len() / self.dims.max(1))
    }

    /// Checks the sizes and values: `dims` 2 or 3, at least one sample, increasing finite
    /// times, one row of the right length a sample in every per-sample field, finite
    /// coordinates, positive finite radii, widths and limits, times and coordinates at most
    /// [`MAX_MAGNITUDE`] in magnitude and series values, torques and limits at most
    /// [`MAX_VALUE`], and the sizes within [`MAX_SAMPLES`], [`MAX_POINTS`] and [`MAX_ITEMS`]. The
    /// error names the field.
    pub fn check(&self) -> Result<(), ViewError> {
        let d = self.dims;
        if d != 2 && d != 3 {
            return Err(ViewError::field("dims", FieldProblem::Dims { found: d }));
        }
        let n = self.len();
        if n == 0 || n > MAX_SAMPLES {
            return Err(count("t", n, "samples", 1, MAX_SAMPLES));
        }
        finite("t", &self.t, MAX_MAGNITUDE)?;
        if let Some(k) = self.t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(ViewError::field(
                "t",
                FieldProblem::NotIncreasing { sample: k + 1 },
            ));
        }
        let width = self.joints.first().map_or(0, Vec::len);
        if width < 2 * d || !width.is_multiple_of(d) || width / d > MAX_POINTS {
            return Err(ViewError::field(
                "joints",
                FieldProblem::PointsWidth {
                    found: width,
                    dims: d,
                    max_points: MAX_POINTS,
                },
            ));
        }
        rows("joints", &self.joints, (n, width), MAX_MAGNITUDE)?;
        if !self.tip_ref.is_empty() {
            rows("tip_ref", &self.tip_ref, (n, d), MAX_MAGNITUDE)?;
        }
        let links = width / d - 1;
        if !self.joint_torque.is_empty() {
            rows("joint_torque", &self.joint_torque, (n, links), MAX_VALUE)?;
        }
        if !self.torque_limit.is_empty() {
            if self.torque_limit.len() != links {
                return Err(ViewError::field(
                    "torque_limit",
                    FieldProblem::Limits {
                        found: self.torque_limit.len(),
                        joints: links,
                    },
                ));
            }
            positive("torque_limit", &self.torque_limit, MAX_VALUE)?;
        }
        for (what, count) in [
            ("series", self.series.len()),
            ("obstacles", self.obstacles.len()),
            ("channels", self.channels.len()),
        ] {
            if count > MAX_ITEMS {
                return Err(ViewError::field(
                    what,
                    FieldProblem::TooMany {
                        found: count,
                        max: MAX_ITEMS,
                    },
                ));
            }
        }
        for (i, s) in self.series.iter().enumerate() {
            let field = format!("series[{i}] ({:?})", s.title);
            if s.names.len() != s.values.len() || s.names.is_empty() || s.names.len() > MAX_ITEMS {
                return Err(ViewError::field(
                    field,
                    FieldProblem::SeriesNames {
                        names: s.names.len(),
                        curves: s.values.len(),
                        max: MAX_ITEMS,
                    },
                ));
            }
            for (curve, values) in s.values.iter().enumerate() {
                if values.len() != n {
                    return Err(ViewError::field(
                        format!("{field}.values[{curve}]"),
                        FieldProblem::PerSample {
                            what: "values",
                            found: values.len(),
                            samples: n,
                        },
                    ));
                }
                finite(&field, values, MAX_VALUE)?;
            }
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            // The points and the lengths (radius or half sides), each with its key.
            let (points, lengths) = match o {
                Obstacle::Circle { centre, radius } if d == 2 => {
                    (vec![("centre", centre)], ("radius", vec![*radius]))
                }
                Obstacle::Sphere { centre, radius } if d == 3 => {
                    (vec![("centre", centre)], ("radius", vec![*radius]))
                }
                Obstacle::Circle { .. } | Obstacle::Sphere { .. } => {
                    return Err(ViewError::field(field, FieldProblem::Shape { dims: d }));
                }
                Obstacle::Capsule { a, b, radius } => {
                    (vec![("a", a), ("b", b)], ("radius", vec![*radius]))
                }
                Obstacle::Box { centre, half } => {
                    (vec![("centre", centre)], ("half", half.clone()))
                }
            };
            if let Obstacle::Box { half, .. } = o
                && half.len() != d
            {
                return Err(ViewError::field(
                    format!("{field}.half"),
                    FieldProblem::Numbers {
                        found: half.len(),
                        expected: d,
                    },
                ));
            }
            for (key, p) in points {
                point(&format!("{field}.{key}"), p, d)?;
            }
            // A radius or half-side of zero, as a scenario allows, is drawn as a point or a line.
            non_negative(&format!("{field}.{}", lengths.0), &lengths.1)?;
        }
        for (i, c) in self.channels.iter().enumerate() {
            let field = format!("channels[{i}]");
            if c.points.len() < 2 || c.points.len() > MAX_SAMPLES {
                return Err(count(
                    format!("{field}.points"),
                    c.points.len(),
                    "points",
                    2,
                    MAX_SAMPLES,
                ));
            }
            for (j, p) in c.points.iter().enumerate() {
                point(&format!("{field}.points[{j}]"), p, d)?;
            }
            positive(&format!("{field}.width"), &[c.width], MAX_MAGNITUDE)?;
        }
        Ok(())
    }
}

/// A count outside `min..=max`.
pub(crate) fn count(
    field: impl Into<String>,
    found: usize,
    unit: &'static str,
    min: usize,
    max: usize,
) -> ViewError {
    ViewError::field(
        field,
        FieldProblem::Count {
            found,
            unit,
            min,
            max,
        },
    )
}

/// Every value of `values` finite and at most `max` in magnitude.
fn finite(field: &str, values: &[f64], max: f64) -> Result<(), ViewError> {
    if let Some((index, value)) = lane_math::first_non_finite(values) {
        let index = listed(values, index);
        return Err(ViewError::field(
            field,
            FieldProblem::NotFinite { index, value },
        ));
    }
    bounded(field, values, max)
}

/// Every value of `values` at most `max` in magnitude (NaN passes: the callers refuse it with
/// their own message first).
fn bounded(field: &str, values: &[f64], max: f64) -> Result<(), ViewError> {
    match values.iter().position(|v| v.abs() > max) {
        Some(index) => Err(ViewError::field(
            field,
            FieldProblem::TooLarge {
                index: listed(values, index),
                value: values[index],
                max,
            },
        )),
        None => Ok(()),
    }
}

/// The index of a value in a list of several, `None` for a field of one number.
fn listed(values: &[f64], index: usize) -> Option<usize> {
    (values.len() > 1).then_some(index)
}

/// Every value of `values` finite, positive and at most `max`.
pub(crate) fn positive(field: &str, values: &[f64], max: f64) -> Result<(), ViewError> {
    match values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        Some(&value) => Err(ViewError::field(field, FieldProblem::NotPositive { value })),
        None => bounded(field, values, max),
    }
}

/// Finite non-negative `values`, at most [`MAX_MAGNITUDE`] (lengths).
fn non_negative(field: &str, values: &[f64]) -> Result<(), ViewError> {
    match values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        Some(&value) => Err(ViewError::field(field, FieldProblem::Negative { value })),
        None => bounded(field, values, MAX_MAGNITUDE),
    }
}

/// A point of `d` finite coordinates.
fn point(field: &str, p: &[f64], d: usize) -> Result<(), ViewError> {
    if p.len() != d {
        return Err(ViewError::field(
            field,
            FieldProblem::Point {
                found: p.len(),
                dims: d,
            },
        ));
    }
    finite(field, p, MAX_MAGNITUDE)
}

/// `n` rows of `width` finite numbers, each at most `max` in magnitude.
fn rows(
    field: &str,
    rows: &[Vec<f64>],
    (n, width): (usize, usize),
    max: f64,
) -> Result<(), ViewError> {
    if rows.len() != n {
        return Err(ViewError::field(
            field,
            FieldProblem::PerSample {
                what: "rows",
                found: rows.len(),
                samples: n,
            },
        ));
    }
    for (k, row) in rows.iter().enumerate() {
        if row.len() != width {
            return Err(ViewError::field(
                format!("{field}[{k}]"),
                FieldProblem::Numbers {
                    found: row.len(),
                    expected: width,
                },
            ));
        }
        finite(&format!("{field}[{k}]"), row, max)?;
    }
    Ok(())
}
