//! The error type of this crate.

use lane_math::{Classify, Compact, ErrorClass};

/// Why a run or scene could not be drawn: a field outside the format (named as in the JSON of
/// `docs/run-view.md`), a record that does not fit its scenario, or a GIF or page that could not
/// be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ViewError {
    /// A field of a run, or an option, outside the format.
    #[error("{field}: {problem}")]
    Field {
        /// The field, e.g. `t`, `joints[3]`, `series[0] ("tip error")`, `gif fps`.
        field: String,
        /// What is wrong with it.
        problem: FieldProblem,
    },
    /// A scene without runs or with too many.
    #[error("scene {title:?}: runs: {count} runs, expected 1 to {max}")]
    RunCount {
        /// The scene's title.
        title: String,
        /// Its number of runs.
        count: usize,
        /// The most runs a scene may have.
        max: usize,
    },
    /// A run of a scene was refused.
    #[error("scene {title:?}, run {label:?}: {source}")]
    Run {
        /// The scene's title.
        title: String,
        /// The run's label.
        label: String,
        /// Why.
        source: Box<ViewError>,
    },
    /// A GIF would need more frames than [`MAX_FRAMES`](crate::MAX_FRAMES).
    #[error(
        "gif: {seconds:.3} s of run at {fps} frames a second and speed {} make {frames:.4e} \
         frames, more than {max}; raise the speed or lower the rate",
        Compact(*.speed)
    )]
    TooManyFrames {
        /// The run's duration (s).
        seconds: f64,
        /// Frames a second.
        fps: u32,
        /// Seconds of run a second of GIF.
        speed: f64,
        /// The frames needed (counted in floating point: beyond `usize` when the speed is tiny).
        frames: f64,
        /// The limit.
        max: usize,
    },
    /// The frames of a GIF times its pixels exceed what one is drawn with.
    #[error(
        "gif: {frames} frames of {width} x {height} pixels make {pixels:.3e} pixels to draw, \
         more than {max:e}; lower the size, the rate or the run's length shown (raise the speed)"
    )]
    TooManyPixels {
        /// The frames.
        frames: usize,
        /// Width (pixels).
        width: u32,
        /// Height (pixels).
        height: u32,
        /// Frames times width times height.
        pixels: f64,
        /// The limit.
        max: f64,
    },
    /// The picture of a GIF's frames could not be allocated.
    #[error("gif: cannot allocate the picture")]
    Picture,
    /// The GIF encoder failed (e.g. writing to its output).
    #[error("gif: {0}")]
    Gif(#[from] gif::EncodingError),
    /// A scene could not be written as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A record does not fit its scenario's arm.
    #[error("the record does not match scenario {scenario}: {joints} joints, {samples} samples")]
    RecordMismatch {
        /// The scenario's name.
        scenario: String,
        /// The record's joints.
        joints: usize,
        /// The record's samples.
        samples: usize,
    },
    /// An arm with more links than the viewer draws.
    #[error(
        "arm.links: the viewer draws at most {max} links, the arm of scenario {scenario} has {links}"
    )]
    TooManyLinks {
        /// The scenario's name.
        scenario: String,
        /// The arm's links.
        links: usize,
        /// The most the viewer draws (`MAX_POINTS - 1`).
        max: usize,
    },
    /// The scenario's arm does not put the tip where the record says it was.
    #[error(
        "the arm of scenario {scenario} puts the tip {} m from the recorded tip at t = {t} s: the record was not made with this arm",
        lane_math::Compact(*distance)
    )]
    TipMismatch {
        /// The scenario's name.
        scenario: String,
        /// The first sample's time where the tips differ (s).
        t: f64,
        /// Their distance (m).
        distance: f64,
    },
    /// The scenario's model could not be built.
    #[error(transparent)]
    Model(#[from] sim_core::SimError),
    /// The arm's kinematics refused a recorded state.
    #[error(transparent)]
    Kinematics(#[from] backbone_kin::KinError),
    /// The clearance of a recorded state could not be measured.
    #[error(transparent)]
    Clearance(#[from] clearance::ClearanceError),
}

/// What is wrong with a field: the `problem` of [`ViewError::Field`], phrased to follow the
/// field's name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldProblem {
    /// `dims` is neither 2 nor 3.
    #[error("{found}, expected 2 (planar) or 3 (spatial)")]
    Dims {
        /// The value given.
        found: usize,
    },
    /// A count outside its range.
    #[error("{found}{}, expected {min} to {max}", spaced(unit))]
    Count {
        /// The count given.
        found: usize,
        /// What is counted (`samples`, `points`, `pixels`), or empty.
        unit: &'static str,
        /// The least allowed.
        min: usize,
        /// The most allowed.
        max: usize,
    },
    /// More items than allowed.
    #[error("{found}, more than {max}")]
    TooMany {
        /// The count given.
        found: usize,
        /// The limit.
        max: usize,
    },
    /// A value beyond the magnitude a run's numbers may have.
    #[error(
        "{}{}, more than {} in magnitude",
        value_at(*index),
        lane_math::Compact(*value),
        lane_math::Compact(*max)
    )]
    TooLarge {
        /// Its index (0-based) in a list of numbers, `None` for a single number.
        index: Option<usize>,
        /// The value.
        value: f64,
        /// The largest magnitude allowed.
        max: f64,
    },
    /// A value that is not finite.
    #[error("{}{value}, not finite", value_at(*index))]
    NotFinite {
        /// Its index (0-based) in a list of numbers, `None` for a single number.
        index: Option<usize>,
        /// The value.
        value: f64,
    },
    /// A value that must be finite and non-negative.
    #[error("{value}, expected a finite non-negative number")]
    Negative {
        /// The value.
        value: f64,
    },
    /// A value that must be finite and positive.
    #[error("{value}, expected a finite positive number")]
    NotPositive {
        /// The value.
        value: f64,
    },
    /// Times that do not increase.
    #[error("not increasing at sample {sample}")]
    NotIncreasing {
        /// The sample (0-based) not after the one before it.
        sample: usize,
    },
    /// A sample's row of joint positions of the wrong width.
    #[error("{found} numbers a sample, expected {dims} a point for 2 to {max_points} points")]
    PointsWidth {
        /// The numbers a sample.
        found: usize,
        /// The coordinates of a point.
        dims: usize,
        /// The most points.
        max_points: usize,
    },
    /// Torque limits not one a joint.
    #[error("{found} limits, expected one a joint ({joints})")]
    Limits {
        /// The limits given.
        found: usize,
        /// The joints.
        joints: usize,
    },
    /// A series' names not one a curve.
    #[error("{names} names for {curves} curves, expected one name a curve (1 to {max})")]
    SeriesNames {
        /// The names given.
        names: usize,
        /// The curves given.
        curves: usize,
        /// The most curves.
        max: usize,
    },
    /// Rows or values not one a sample.
    #[error("{found} {what}, expected one a sample ({samples})")]
    PerSample {
        /// `rows` or `values`.
        what: &'static str,
        /// The number given.
        found: usize,
        /// The samples.
        samples: usize,
    },
    /// A row or a list of numbers of the wrong length.
    #[error("{found} numbers, expected {expected}")]
    Numbers {
        /// The numbers given.
        found: usize,
        /// The numbers expected.
        expected: usize,
    },
    /// A point of the wrong dimension.
    #[error("a point of {found} coordinates, expected {dims}")]
    Point {
        /// The coordinates given.
        found: usize,
        /// The run's dimension.
        dims: usize,
    },
    /// A circle in a spatial run or a sphere in a planar one.
    #[error("a circle is planar and a sphere spatial; this run has dims {dims}")]
    Shape {
        /// The run's dimension.
        dims: usize,
    },
}

/// ` unit`, or nothing for no unit.
fn spaced(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

impl ViewError {
    /// A [`ViewError::Field`].
    pub(crate) fn field(field: impl Into<String>, problem: FieldProblem) -> Self {
        Self::Field {
            field: field.into(),
            problem,
        }
    }
}

impl Classify for ViewError {
    /// A wrapped model or kinematics error keeps its class; every other error is invalid input.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Model(error) => error.class(),
            Self::Kinematics(error) => error.class(),
            Self::Clearance(error) => error.class(),
            Self::Run { source, .. } => source.class(),
            _ => ErrorClass::InvalidInput,
        }
    }
}

/// `value 3 is ` before the 4th value of a list, nothing before a single number.
fn value_at(index: Option<usize>) -> String {
    index.map_or_else(String::new, |index| format!("value {index} is "))
}
