//! The clearance of every pair: link capsules against obstacles and against each other.

use crate::closest::{Closest, segment_box, segment_point, segment_segment};
use crate::data::ClearanceData;
use crate::model::{ClearanceModel, Pair};
use crate::obstacle::Obstacle;

/// Fills every pair's clearance and closest points for the placed chain and returns the smallest
/// clearance to an obstacle and between links (each `+inf` when there is no such pair).
///
/// A link is the capsule of radius `r` around its segment `p_i`-`p_{i+1}`; the clearance is the
/// distance between the cores less the radii (`|c - o| - r - R` for a sphere or capsule of
/// radius `R`, the box's signed distance of `c` less `r`, `|c_i - c_k| - 2 r` for two links),
/// negative when they overlap. Allocation-free.
pub fn distances(model: &ClearanceModel, data: &mut ClearanceData) -> (f64, f64) {
    let radius = model.radius();
    let points = &data.points;
    let (mut near_obstacle, mut near_self) = (f64::INFINITY, f64::INFINITY);
    for ((pair, distance), closest) in model
        .pairs()
        .iter()
        .zip(data.distances.iter_mut())
        .zip(data.closest.iter_mut())
    {
        match *pair {
            Pair::Obstacle { link, obstacle } => {
                let (a, b) = (points[link], points[link + 1]);
                let (found, other_radius) = closest_to(&model.obstacles()[obstacle], a, b);
                *distance = found.distance - radius - other_radius;
                *closest = found;
                near_obstacle = near_obstacle.min(*distance);
            }
            Pair::Links { link, other } => {
                let found = segment_segment(
                    points[link],
                    points[link + 1],
                    points[other],
                    points[other + 1],
                );
                *distance = found.distance - 2.0 * radius;
                *closest = found;
                near_self = near_self.min(*distance);
            }
        }
    }
    (near_obstacle, near_self)
}

/// The closest points of the segment `a`-`b` to an obstacle's core and the obstacle's radius.
#[inline]
fn closest_to(obstacle: &Obstacle, a: [f64; 3], b: [f64; 3]) -> (Closest, f64) {
    match obstacle {
        Obstacle::Sphere { center, radius } => (segment_point(a, b, *center), *radius),
        Obstacle::Capsule { from, to, radius } => (segment_segment(a, b, *from, *to), *radius),
        Obstacle::Box {
            center,
            half_extents,
            axes,
        } => (segment_box(a, b, *center, *half_extents, axes), 0.0),
    }
}
