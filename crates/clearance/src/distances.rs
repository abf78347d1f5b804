//! The clearance of every pair: link capsules against obstacles and against each other.

use crate::closest::{Closest, Segment, closest_to_box, closest_to_point, closest_to_segment};
use crate::cores::Core;
use crate::data::ClearanceData;
use crate::model::ClearanceModel;

/// Fills every pair's clearance and closest points for the placed chain and returns the smallest
/// clearance to an obstacle and between links (each `+inf` when there is no such pair).
///
/// A link is the capsule of radius `r` around its segment `p_i`-`p_{i+1}`; the clearance is the
/// distance between the cores less the radii (`|c - o| - r - R` for a sphere or capsule of
/// radius `R`, the box's signed distance of `c` less `r`, `|c_i - c_k| - 2 r` for two links),
/// negative when they overlap. Allocation-free.
pub fn distances(model: &ClearanceModel, data: &mut ClearanceData) -> (f64, f64) {
    let ClearanceData {
        points,
        planar,
        segments,
        planar_segments,
        distances,
        closest,
        turns_about_z,
        ..
    } = data;
    let radius = model.radius();
    let results = (distances.as_mut_slice(), closest.as_mut_slice());
    match model.planar_cores() {
        // A chain turning about `z` among obstacles of its plane: two dimensions suffice.
        Some(cores) if *turns_about_z => {
            for (segment, link) in planar_segments.iter_mut().zip(planar.windows(2)) {
                *segment = Segment::new(link[0], link[1]);
            }
            every_pair(radius, planar_segments, cores, results)
        }
        _ => {
            for (segment, link) in segments.iter_mut().zip(points.windows(2)) {
                *segment = Segment::new(link[0], link[1]);
            }
            every_pair(radius, segments, model.cores(), results)
        }
    }
}

/// [`distances`] for the prepared segments of the links and the obstacles' cores, in `D`
/// dimensions.
#[inline]
fn every_pair<const D: usize>(
    radius: f64,
    segments: &[Segment<D>],
    obstacles: &[Core<D>],
    (distances, closest): (&mut [f64], &mut [Closest]),
) -> (f64, f64) {
    // The pairs in the model's order: link-major against every obstacle, then (i, k >= i + 2).
    let split = segments.len() * obstacles.len();
    let (obstacle_distances, self_distances) = distances.split_at_mut(split);
    let (obstacle_closest, self_closest) = closest.split_at_mut(split);
    let mut near_obstacle = f64::INFINITY;
    if !obstacles.is_empty() {
        for ((link, distances), closest) in segments
            .iter()
            .zip(obstacle_distances.chunks_exact_mut(obstacles.len()))
            .zip(obstacle_closest.chunks_exact_mut(obstacles.len()))
        {
            for ((obstacle, distance), closest) in obstacles.iter().zip(distances).zip(closest) {
                let other_radius = closest_to(obstacle, link, closest);
                *distance = closest.distance - radius - other_radius;
                near_obstacle = near_obstacle.min(*distance);
            }
        }
    }
    let mut near_self = f64::INFINITY;
    let pairs = self_distances.iter_mut().zip(self_closest.iter_mut());
    let others = segments.iter().enumerate().flat_map(|(i, link)| {
        segments
            .get(i + 2..)
            .unwrap_or(&[])
            .iter()
            .map(move |other| (link, other))
    });
    for ((distance, closest), (link, other)) in pairs.zip(others) {
        *closest = closest_to_segment(link, other);
        *distance = closest.distance - 2.0 * radius;
        near_self = near_self.min(*distance);
    }
    (near_obstacle, near_self)
}

/// Writes the closest points of a link's segment to an obstacle's core into `closest` and
/// returns the obstacle's radius.
#[inline]
fn closest_to<const D: usize>(core: &Core<D>, link: &Segment<D>, closest: &mut Closest) -> f64 {
    match core {
        Core::Point { center, radius } => {
            *closest = closest_to_point(link, *center);
            *radius
        }
        Core::Segment { axis, radius } => {
            *closest = closest_to_segment(link, axis);
            *radius
        }
        Core::Box {
            center,
            half_extents,
            axes,
        } => {
            *closest = closest_to_box(link, *center, *half_extents, axes);
            0.0
        }
    }
}
