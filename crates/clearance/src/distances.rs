//! The clearance of every pair: link capsules against obstacles and against each other.

use pulp::{Arch, Simd, WithSimd};

use crate::closest::{
    Closest, Segment, closest_at, closest_to_box, closest_to_segment, segment_parameters,
};
use crate::cores::{Core, Cores};
use crate::data::ClearanceData;
use crate::model::ClearanceModel;
use crate::point_lanes::closest_to_points;

/// Fills every pair's clearance and closest points for the placed chain and returns the smallest
/// clearance to an obstacle and between links (each `+inf` when there is no such pair).
///
/// A link is the capsule of radius `r` around its segment `p_i`-`p_{i+1}`; the clearance is the
/// distance between the cores less the radii (`|c - o| - r - R` for a sphere or capsule of
/// radius `R`, the box's signed distance of `c` less `r`, `|c_i - c_k| - 2 r` for two links),
/// negative when they overlap. Allocation-free.
///
/// # Panics
/// If `data` was not made for `model` ([`ClearanceData::check_model`]; [`place`](crate::place)
/// and [`place_planar`](crate::place_planar) refuse such data with an error first).
pub fn distances(model: &ClearanceModel, data: &mut ClearanceData) -> (f64, f64) {
    data.assert_model(model);
    let ClearanceData {
        points,
        planar,
        segments,
        planar_segments,
        distances,
        closest,
        turns_about_z,
        self_parameters,
        ..
    } = data;
    let radius = model.radius();
    let results = (
        distances.as_mut_slice(),
        closest.as_mut_slice(),
        self_parameters.as_mut_slice(),
    );
    match model.planar_cores() {
        // A chain turning about `z` among obstacles of its plane: two dimensions suffice.
        Some(cores) if *turns_about_z => {
            for (segment, link) in planar_segments.iter_mut().zip(planar.windows(2)) {
                *segment = Segment::new(link[0], link[1]);
            }
            in_registers(EveryPair {
                radius,
                segments: planar_segments,
                cores,
                results,
            })
        }
        _ => {
            for (segment, link) in segments.iter_mut().zip(points.windows(2)) {
                *segment = Segment::new(link[0], link[1]);
            }
            in_registers(EveryPair {
                radius,
                segments,
                cores: model.cores(),
                results,
            })
        }
    }
}

/// Runs `op` in AVX2's registers of 4 lanes where the processor has them, otherwise on the
/// widest instruction set there is: for the point cores of [`closest_to_points`] (measured
/// faster than AVX-512's 8: 156 against 175 ns for ten links against six circles) and the
/// planar gradients' blocks of four coordinates.
pub(crate) fn in_registers<Op: WithSimd>(op: Op) -> Op::Output {
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = pulp::x86::V3::try_new() {
        return Arch::V3(v3).dispatch(op);
    }
    Arch::new().dispatch(op)
}

/// [`distances`] for the prepared segments of the links and the obstacles' cores, in `D`
/// dimensions, as a [`WithSimd`] operation.
struct EveryPair<'a, const D: usize> {
    radius: f64,
    segments: &'a [Segment<D>],
    cores: &'a Cores<D>,
    results: (&'a mut [f64], &'a mut [Closest], &'a mut [(f64, f64)]),
}

impl<const D: usize> WithSimd for EveryPair<'_, D> {
    type Output = (f64, f64);

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> (f64, f64) {
        let Self {
            radius,
            segments,
            cores,
            results,
        } = self;
        every_pair(simd, radius, segments, cores, results)
    }
}

/// The body of [`EveryPair`]: a link against the point cores in lanes of `S`
/// ([`closest_to_points`]), against the other cores one at a time, then the self pairs.
#[inline(always)]
fn every_pair<S: Simd, const D: usize>(
    simd: S,
    radius: f64,
    segments: &[Segment<D>],
    cores: &Cores<D>,
    (distances, closest, self_parameters): (&mut [f64], &mut [Closest], &mut [(f64, f64)]),
) -> (f64, f64) {
    let obstacles = &cores.all;
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
            let results = (&mut *distances, &mut *closest);
            let near_point = closest_to_points(simd, link, &cores.points, radius, results);
            near_obstacle = near_obstacle.min(near_point);
            for ((obstacle, distance), closest) in obstacles.iter().zip(distances).zip(closest) {
                let other_radius = match obstacle {
                    Core::Point { .. } => continue,
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
                };
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
    // Two passes, the parameters first: each has a shorter chain of dependent operations a
    // pair, so that more pairs are in flight at once (ten links' 36 pairs: about 280 against
    // 300 ns in one pass).
    for (parameters, (link, other)) in self_parameters.iter_mut().zip(others.clone()) {
        *parameters = segment_parameters(link, other);
    }
    for (((distance, closest), (link, other)), parameters) in
        pairs.zip(others).zip(self_parameters.iter())
    {
        *closest = closest_at(link, other, *parameters);
        *distance = closest.distance - 2.0 * radius;
        near_self = near_self.min(*distance);
    }
    (near_obstacle, near_self)
}
