//! What a link is measured against: an obstacle's core in `D` dimensions.

use crate::closest::Segment;
use crate::obstacle::Obstacle;
use crate::point_lanes::PointCores;
use crate::vector::{V, planar};

/// What a link is measured against, in `D` dimensions: an obstacle's core (a point, a segment
/// prepared once, or a box) and the radius around it. Three dimensions hold every obstacle; two
/// hold those of the plane `z = 0` ([`Core::planar`]), which a chain turning about `z` meets the
/// same way without the third coordinate's zeros.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Core<const D: usize> {
    /// A sphere's (or circle's) centre and radius.
    Point { center: V<D>, radius: f64 },
    /// A capsule's axis and radius.
    Segment { axis: Segment<D>, radius: f64 },
    /// A box: its centre, half-extents and axes (the columns of its rotation).
    Box {
        center: V<D>,
        half_extents: V<D>,
        axes: [V<D>; D],
    },
}

/// The cores of a model's obstacles in `D` dimensions, in their order, and the point cores
/// among them again, coordinate by coordinate, for measuring a link against all of them at once.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cores<const D: usize> {
    /// Every obstacle's core.
    pub(crate) all: Vec<Core<D>>,
    /// The point cores of [`all`](Self::all).
    pub(crate) points: PointCores<D>,
}

impl<const D: usize> Cores<D> {
    /// The cores `all`, with their point cores gathered.
    pub(crate) fn new(all: Vec<Core<D>>) -> Self {
        let points = PointCores::of(all.iter().enumerate().filter_map(
            |(index, core)| match *core {
                Core::Point { center, radius } => Some((index, center, radius)),
                _ => None,
            },
        ));
        Self { all, points }
    }
}

impl Core<3> {
    /// The core of `obstacle`.
    pub(crate) fn of(obstacle: &Obstacle) -> Self {
        match *obstacle {
            Obstacle::Sphere { center, radius } => Self::Point { center, radius },
            Obstacle::Capsule { from, to, radius } => Self::Segment {
                axis: Segment::new(from, to),
                radius,
            },
            Obstacle::Box {
                center,
                half_extents,
                axes,
            } => Self::Box {
                center,
                half_extents,
                axes,
            },
        }
    }
}

impl Core<2> {
    /// The core of `obstacle` in the plane `z = 0`, or `None` when the obstacle reaches out of
    /// it differently from its section: a sphere or capsule off the plane, a box turned about
    /// another axis than `z`, off the plane, or of finite height.
    pub(crate) fn planar(obstacle: &Obstacle) -> Option<Self> {
        match *obstacle {
            Obstacle::Sphere { center, radius } => (center[2] == 0.0).then_some(Self::Point {
                center: planar(center),
                radius,
            }),
            Obstacle::Capsule { from, to, radius } => {
                (from[2] == 0.0 && to[2] == 0.0).then_some(Self::Segment {
                    axis: Segment::new(planar(from), planar(to)),
                    radius,
                })
            }
            Obstacle::Box {
                center,
                half_extents,
                axes,
            } => {
                let about_z = axes[0][2] == 0.0
                    && axes[1][2] == 0.0
                    && axes[2] == [0.0, 0.0, 1.0]
                    && center[2] == 0.0
                    && half_extents[2] == f64::INFINITY;
                about_z.then_some(Self::Box {
                    center: planar(center),
                    half_extents: planar(half_extents),
                    axes: [planar(axes[0]), planar(axes[1])],
                })
            }
        }
    }
}
