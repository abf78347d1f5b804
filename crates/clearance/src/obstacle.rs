//! Obstacles: spheres (circles for a planar arm), capsules and boxes, and their signed distance
//! to a point.

use crate::error::ClearanceError;
use crate::vector::{V, V3, dot, lerp, scale, sub, to_local};
use lane_math::check_finite;

/// One obstacle, in world coordinates (a planar arm moves in the plane `z = 0`).
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// A ball of `radius` around `center`; in the plane `z = 0` a circle.
    Sphere {
        /// The centre.
        center: V3,
        /// The radius, non-negative.
        radius: f64,
    },
    /// The points within `radius` of the segment `from`-`to`.
    Capsule {
        /// One end of the axis.
        from: V3,
        /// The other end of the axis.
        to: V3,
        /// The radius, non-negative.
        radius: f64,
    },
    /// The box `|R^T (x - center)|_k <= half_extents_k`; a half-extent may be infinite (a
    /// rectangle of the plane is a box of infinite half-height).
    Box {
        /// The centre.
        center: V3,
        /// Half the side lengths along the box's own axes, positive.
        half_extents: V3,
        /// The box's axes in world coordinates: the columns of `R`.
        axes: [V3; 3],
    },
}

impl Obstacle {
    /// A circle of the plane `z = 0` (a sphere centred in it).
    pub fn circle(center: [f64; 2], radius: f64) -> Result<Self, ClearanceError> {
        Self::sphere([center[0], center[1], 0.0], radius)
    }

    /// A sphere.
    pub fn sphere(center: V3, radius: f64) -> Result<Self, ClearanceError> {
        check_point("sphere center", center)?;
        check_radius(radius)?;
        Ok(Self::Sphere { center, radius })
    }

    /// A capsule around the segment `from`-`to`.
    pub fn capsule(from: V3, to: V3, radius: f64) -> Result<Self, ClearanceError> {
        check_point("capsule from", from)?;
        check_point("capsule to", to)?;
        check_radius(radius)?;
        Ok(Self::Capsule { from, to, radius })
    }

    /// A box turned by roll, pitch and yaw (URDF's convention, `R = Rz(yaw) Ry(pitch) Rx(roll)`).
    /// Half-extents must be positive, at most [`MAX_OBSTACLE_EXTENT`] or `f64::INFINITY`, which
    /// makes the box a slab (a planar rectangle with an infinite `z` half-extent).
    pub fn cuboid(center: V3, half_extents: V3, rpy: V3) -> Result<Self, ClearanceError> {
        check_point("box center", center)?;
        rpy.iter().try_for_each(|&x| check_finite("box rpy", x))?;
        for h in half_extents {
            if h.is_nan() || h <= 0.0 || (h > MAX_OBSTACLE_EXTENT && h.is_finite()) {
                return Err(ClearanceError::OutOfRange {
                    name: "box half_extents",
                    bound: "positive, and at most 1e15 or infinite (m)",
                    value: h,
                });
            }
        }
        let (sr, cr) = rpy[0].sin_cos();
        let (sp, cp) = rpy[1].sin_cos();
        let (sy, cy) = rpy[2].sin_cos();
        let axes = [
            [cy * cp, sy * cp, -sp],
            [cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr],
            [cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr],
        ];
        Ok(Self::Box {
            center,
            half_extents,
            axes,
        })
    }

    /// The signed distance from `point` to the obstacle's surface: negative inside.
    pub fn signed_distance(&self, point: V3) -> f64 {
        match self {
            Self::Sphere { center, radius } => norm(sub(point, *center)) - radius,
            Self::Capsule { from, to, radius } => {
                let axis = sub(*to, *from);
                let length2 = dot(axis, axis);
                let t = if length2 > 0.0 {
                    (dot(sub(point, *from), axis) / length2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                norm(sub(point, lerp(*from, *to, t))) - radius
            }
            Self::Box {
                center,
                half_extents,
                axes,
            } => box_signed_distance(to_local(axes, sub(point, *center)), *half_extents),
        }
    }
}

/// The signed distance of the local point `q` to the box `|q_k| <= h_k`.
pub(crate) fn box_signed_distance<const D: usize>(q: V<D>, h: V<D>) -> f64 {
    let mut outside = 0.0;
    let mut deepest = f64::NEG_INFINITY;
    for k in 0..D {
        let gap = q[k].abs() - h[k];
        outside += gap.max(0.0) * gap.max(0.0);
        deepest = deepest.max(gap);
    }
    outside.sqrt() + deepest.min(0.0)
}

pub(crate) fn norm<const D: usize>(v: V<D>) -> f64 {
    dot(v, v).sqrt()
}

/// `v / |v|`, or `fallback` when `v` is zero.
pub(crate) fn unit_or<const D: usize>(v: V<D>, fallback: V<D>) -> (V<D>, f64) {
    let length = norm(v);
    if length > 0.0 {
        (scale(v, 1.0 / length), length)
    } else {
        (fallback, 0.0)
    }
}

/// The largest magnitude of an obstacle's coordinates, radius and finite half-extents (m): the
/// squares and sums of the distances stay far from overflow (a clearance is then finite), and
/// an obstacle a billion kilometres away is still one.
pub const MAX_OBSTACLE_EXTENT: f64 = 1e15;

fn check_point(name: &'static str, point: V3) -> Result<(), ClearanceError> {
    point.iter().try_for_each(|&x| check_finite(name, x))?;
    if let Some(&value) = point.iter().find(|x| x.abs() > MAX_OBSTACLE_EXTENT) {
        return Err(ClearanceError::OutOfRange {
            name,
            bound: "at most 1e15 in magnitude (m)",
            value,
        });
    }
    Ok(())
}

fn check_radius(radius: f64) -> Result<(), ClearanceError> {
    check_finite("obstacle radius", radius)?;
    if !(0.0..=MAX_OBSTACLE_EXTENT).contains(&radius) {
        return Err(ClearanceError::OutOfRange {
            name: "obstacle radius",
            bound: "non-negative and at most 1e15 (m)",
            value: radius,
        });
    }
    Ok(())
}
