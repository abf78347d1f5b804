//! The clearance of every pair: link capsules against obstacles and against each other.

use crate::closest::{Closest, segment_box, segment_point, segment_segment};
use crate::data::ClearanceData;
use crate::model::ClearanceModel;
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
    let obstacles = model.obstacles();
    // The pairs in the model's order: link-major against every obstacle, then (i, k >= i + 2).
    let split = model.n_obstacle_pairs();
    let (obstacle_distances, self_distances) = data.distances.split_at_mut(split);
    let (obstacle_closest, self_closest) = data.closest.split_at_mut(split);
    let mut near_obstacle = f64::INFINITY;
    if !obstacles.is_empty() {
        for ((link, distances), closest) in points
            .windows(2)
            .zip(obstacle_distances.chunks_exact_mut(obstacles.len()))
            .zip(obstacle_closest.chunks_exact_mut(obstacles.len()))
        {
            let (a, b) = (link[0], link[1]);
            for ((obstacle, distance), closest) in obstacles.iter().zip(distances).zip(closest) {
                let (found, other_radius) = closest_to(obstacle, a, b);
                *distance = found.distance - radius - other_radius;
                *closest = found;
                near_obstacle = near_obstacle.min(*distance);
            }
        }
    }
    let mut near_self = f64::INFINITY;
    let mut pair = 0;
    for link in 0..points.len().saturating_sub(1) {
        let (a, b) = (points[link], points[link + 1]);
        for other in points[link + 2..].windows(2) {
            let found = segment_segment(a, b, other[0], other[1]);
            let distance = found.distance - 2.0 * radius;
            self_distances[pair] = distance;
            self_closest[pair] = found;
            near_self = near_self.min(distance);
            pair += 1;
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
