//! A link against every point core (a sphere's or a circle's centre) at once, the cores side by
//! side in the lanes of a SIMD register: the operations of the one-pair
//! [`closest_to_point`](crate::closest) lane by lane, in the same order, so that each pair gets
//! the same bits as measured alone (the square root and the division are correctly rounded in
//! every lane, and nothing is fused).

use pulp::Simd;

use crate::closest::{Closest, Segment};
use crate::vector::{V, widen};

/// The most lanes of a register (AVX-512); the coordinates are padded to a multiple of it, so
/// that every register load of them is in bounds.
const PADDING: usize = 8;

/// The point cores of a model's obstacles in `D` dimensions, coordinate by coordinate, with the
/// obstacle each belongs to and its radius, padded to whole registers (at the origin, of radius
/// `-inf`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PointCores<const D: usize> {
    /// `coordinates[k][j]`: coordinate `k` of the `j`-th point core.
    coordinates: [Vec<f64>; D],
    /// The index among the obstacles of each point core.
    obstacles: Vec<usize>,
    /// The radius around each point core.
    radii: Vec<f64>,
}

impl<const D: usize> PointCores<D> {
    /// The point cores `(obstacle, center, radius)`, in their order.
    pub(crate) fn of(cores: impl Iterator<Item = (usize, V<D>, f64)>) -> Self {
        let mut points = Self {
            coordinates: std::array::from_fn(|_| Vec::new()),
            obstacles: Vec::new(),
            radii: Vec::new(),
        };
        for (obstacle, center, radius) in cores {
            for (coordinate, value) in points.coordinates.iter_mut().zip(center) {
                coordinate.push(value);
            }
            points.obstacles.push(obstacle);
            points.radii.push(radius);
        }
        let padded = points.obstacles.len().next_multiple_of(PADDING);
        for coordinate in &mut points.coordinates {
            coordinate.resize(padded, 0.0);
        }
        // A padding lane's clearance is then `+inf`: never the smallest.
        points.radii.resize(padded, f64::NEG_INFINITY);
        points
    }
}

/// Writes `link`'s closest points to every point core into `closest[obstacle]` and its
/// clearance (less `radius` and the core's radius) into `distances[obstacle]`, the slices
/// holding the link's pairs in obstacle order, and returns the smallest of those clearances
/// (`+inf` without point cores). The cores go `S::F64_LANES` at a time.
#[inline(always)]
pub(crate) fn closest_to_points<S: Simd, const D: usize>(
    simd: S,
    link: &Segment<D>,
    points: &PointCores<D>,
    radius: f64,
    (distances, closest): (&mut [f64], &mut [Closest]),
) -> f64 {
    let lanes = S::F64_LANES;
    let splat = |x: f64| simd.splat_f64s(x);
    let (zero, one) = (splat(0.0), splat(1.0));
    let start: [S::f64s; D] = std::array::from_fn(|k| splat(link.start[k]));
    let axis: [S::f64s; D] = std::array::from_fn(|k| splat(link.axis[k]));
    let inverse_length2 = splat(link.inverse_length2);
    // `direction`'s threshold: a closest point this near the core has no normal.
    let tiny = splat(1e-12 * link.length);
    let mut near = splat(f64::INFINITY);
    let count = points.obstacles.len();
    for first in (0..count).step_by(lanes) {
        let o_lanes: [&[f64]; D] =
            std::array::from_fn(|k| &points.coordinates[k][first..first + lanes]);
        let o: [S::f64s; D] = std::array::from_fn(|k| S::as_simd_f64s(o_lanes[k]).0[0]);
        // The parameter of the closest point, clamped as `f64::clamp(0.0, 1.0)` does.
        let t = if link.length2 > 0.0 {
            let mut along = simd.mul_f64s(simd.sub_f64s(o[0], start[0]), axis[0]);
            for k in 1..D {
                let term = simd.mul_f64s(simd.sub_f64s(o[k], start[k]), axis[k]);
                along = simd.add_f64s(along, term);
            }
            let t = simd.mul_f64s(along, inverse_length2);
            let t = simd.select_f64s(simd.less_than_f64s(t, zero), zero, t);
            simd.select_f64s(simd.greater_than_f64s(t, one), one, t)
        } else {
            zero
        };
        let point: [S::f64s; D] =
            std::array::from_fn(|k| simd.add_f64s(start[k], simd.mul_f64s(axis[k], t)));
        let offset: [S::f64s; D] = std::array::from_fn(|k| simd.sub_f64s(point[k], o[k]));
        let mut length2 = simd.mul_f64s(offset[0], offset[0]);
        for v in &offset[1..] {
            length2 = simd.add_f64s(length2, simd.mul_f64s(*v, *v));
        }
        // `unit_or`: the unit offset and its length where the length is positive, zeros (and a
        // zero length) elsewhere; then no normal where the length is within `tiny`.
        let length = simd.sqrt_f64s(length2);
        let scale = simd.div_f64s(one, length);
        let positive = simd.greater_than_f64s(length, zero);
        let length = simd.select_f64s(positive, length, zero);
        let dropped = simd.less_than_or_equal_f64s(length, tiny);
        let normal: [S::f64s; D] = std::array::from_fn(|k| {
            let unit = simd.select_f64s(positive, simd.mul_f64s(offset[k], scale), zero);
            simd.select_f64s(dropped, zero, unit)
        });
        // The clearances, and their smallest in every lane (`f64::min`: NaN clearances left out).
        let radii = S::as_simd_f64s(&points.radii[first..first + lanes]).0[0];
        let clearance = simd.sub_f64s(simd.sub_f64s(length, splat(radius)), radii);
        near = simd.select_f64s(simd.less_than_f64s(clearance, near), clearance, near);
        // The pairs one at a time, from the lanes.
        let mut values = [[0.0; PADDING]; 3];
        let mut points_out = [[0.0; PADDING]; D];
        let mut normals_out = [[0.0; PADDING]; D];
        for (out, value) in values.iter_mut().zip([t, length, clearance]) {
            S::as_mut_simd_f64s(&mut out[..lanes]).0[0] = value;
        }
        for k in 0..D {
            S::as_mut_simd_f64s(&mut points_out[k][..lanes]).0[0] = point[k];
            S::as_mut_simd_f64s(&mut normals_out[k][..lanes]).0[0] = normal[k];
        }
        let group = &points.obstacles[first..count.min(first + lanes)];
        for (j, &obstacle) in group.iter().enumerate() {
            closest[obstacle] = Closest {
                t: values[0][j],
                point: widen(std::array::from_fn::<_, D, _>(|k| points_out[k][j])),
                other: widen(std::array::from_fn::<_, D, _>(|k| o_lanes[k][j])),
                distance: values[1][j],
                normal: widen(std::array::from_fn::<_, D, _>(|k| normals_out[k][j])),
            };
            distances[obstacle] = values[2][j];
        }
    }
    let mut smallest = [0.0; PADDING];
    S::as_mut_simd_f64s(&mut smallest[..lanes]).0[0] = near;
    smallest[..lanes]
        .iter()
        .fold(f64::INFINITY, |a, &b| a.min(b))
}
