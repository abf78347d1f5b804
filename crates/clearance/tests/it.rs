//! Distances against brute force, gradients against finite differences.

use backbone_kin::{BaseAngle, ModalMap};
use clearance::{
    ClearanceData, ClearanceError, ClearanceModel, Obstacle, Pair, distances, joint_gradient,
    modal_gradients, place, place_planar, segment_box, segment_point, segment_segment,
};
use proptest::prelude::*;

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm(a: V) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
fn lerp(a: V, b: V, t: f64) -> V {
    [
        a[0] + t * (b[0] - a[0]),
        a[1] + t * (b[1] - a[1]),
        a[2] + t * (b[2] - a[2]),
    ]
}
fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}
/// `Rz(yaw) Ry(pitch) Rx(roll)` as a row-major matrix, built from the three elementary turns.
fn rotation(rpy: V) -> [[f64; 3]; 3] {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    let rx = [[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]];
    let ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]];
    let rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
    matmul(rz, matmul(ry, rx))
}
/// The distance from `x` to the segment `a`-`b`, by its own projection.
fn point_segment(x: V, a: V, b: V) -> f64 {
    let d = sub(b, a);
    let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let t = if len2 > 0.0 {
        ((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1] + (x[2] - a[2]) * d[2]) / len2
    } else {
        0.0
    };
    norm(sub(x, lerp(a, b, t.clamp(0.0, 1.0))))
}

/// A box given by its own row-major rotation, for the brute-force reference.
struct TestBox {
    center: V,
    half: V,
    rot: [[f64; 3]; 3],
}
impl TestBox {
    fn local(&self, x: V) -> V {
        let d = sub(x, self.center);
        let r = self.rot;
        [
            r[0][0] * d[0] + r[1][0] * d[1] + r[2][0] * d[2],
            r[0][1] * d[0] + r[1][1] * d[1] + r[2][1] * d[2],
            r[0][2] * d[0] + r[1][2] * d[1] + r[2][2] * d[2],
        ]
    }
    fn world(&self, q: V) -> V {
        let r = self.rot;
        let mut x = self.center;
        for i in 0..3 {
            for k in 0..3 {
                x[i] += r[i][k] * q[k];
            }
        }
        x
    }
    /// Signed distance: outside, the distance to the clamped point; inside, minus the distance
    /// to the nearest face.
    fn sdf(&self, x: V) -> f64 {
        let q = self.local(x);
        let inside = (0..3).all(|k| q[k].abs() <= self.half[k]);
        if inside {
            -(0..3)
                .map(|k| self.half[k] - q[k].abs())
                .fold(f64::INFINITY, f64::min)
        } else {
            let c: Vec<f64> = (0..3)
                .map(|k| q[k] - q[k].clamp(-self.half[k], self.half[k]))
                .collect();
            (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
        }
    }
    /// A grid of points on the surface, `per_side` a face side.
    fn surface(&self, per_side: usize) -> Vec<V> {
        let mut points = Vec::new();
        for face in 0..3 {
            let (u, v) = ((face + 1) % 3, (face + 2) % 3);
            for sign in [-1.0, 1.0] {
                for i in 0..=per_side {
                    for j in 0..=per_side {
                        let mut q = [0.0; 3];
                        q[face] = sign * self.half[face];
                        q[u] = self.half[u] * (2.0 * i as f64 / per_side as f64 - 1.0);
                        q[v] = self.half[v] * (2.0 * j as f64 / per_side as f64 - 1.0);
                        points.push(self.world(q));
                    }
                }
            }
        }
        points
    }
}

/// The smallest of a convex function on `[0, 1]`: dense samples, then golden section.
fn convex_min(f: impl Fn(f64) -> f64) -> f64 {
    let n = 4000;
    let best = (0..=n)
        .map(|i| i as f64 / n as f64)
        .min_by(|a, b| f(*a).total_cmp(&f(*b)))
        .unwrap();
    let (mut lo, mut hi) = (
        (best - 1.0 / n as f64).max(0.0),
        (best + 1.0 / n as f64).min(1.0),
    );
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(x1) < f(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    f(0.5 * (lo + hi)).min(f(best))
}

fn v3() -> impl Strategy<Value = V> {
    prop::array::uniform3(-1.0..1.0f64)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn segment_point_matches_sampling(a in v3(), b in v3(), o in v3()) {
        let found = segment_point(a, b, o);
        let reference = convex_min(|t| norm(sub(lerp(a, b, t), o)));
        prop_assert!((found.distance - reference).abs() < 1e-9);
        prop_assert!((norm(sub(found.point, o)) - found.distance).abs() < 1e-12);
    }

    #[test]
    fn segment_segment_matches_sampling(a in v3(), b in v3(), c in v3(), d in v3()) {
        let found = segment_segment(a, b, c, d);
        let reference = convex_min(|t| point_segment(lerp(a, b, t), c, d));
        prop_assert!((found.distance - reference).abs() < 1e-9, "{} vs {}", found.distance, reference);
        prop_assert!((norm(sub(found.point, found.other)) - found.distance).abs() < 1e-12);
    }

    #[test]
    fn segment_box_matches_sampling(
        a in v3(), b in v3(), center in prop::array::uniform3(-0.5..0.5f64),
        half in prop::array::uniform3(0.05..0.6f64), rpy in prop::array::uniform3(-3.0..3.0f64),
    ) {
        let reference_box = TestBox { center, half, rot: rotation(rpy) };
        let Obstacle::Box { center, half_extents, axes } = Obstacle::cuboid(center, half, rpy).unwrap()
            else { unreachable!() };
        let found = segment_box(a, b, center, half_extents, &axes);
        let reference = convex_min(|t| reference_box.sdf(lerp(a, b, t)));
        prop_assert!((found.distance - reference).abs() < 1e-8, "{} vs {}", found.distance, reference);
        prop_assert!((reference_box.sdf(found.point) - found.distance).abs() < 1e-12);
        prop_assert!(reference_box.sdf(found.other).abs() < 1e-12);
    }

    /// The distance from the segment to the sampled surface of a box it does not touch: the
    /// samples lie on the surface, so they bound the distance from above within their spacing.
    #[test]
    fn segment_box_matches_surface_samples(
        a in v3(), b in v3(), half in prop::array::uniform3(0.05..0.3f64),
        rpy in prop::array::uniform3(-3.0..3.0f64),
    ) {
        let center = [1.5, 0.2, -0.1];
        let reference_box = TestBox { center, half, rot: rotation(rpy) };
        let Obstacle::Box { center, half_extents, axes } = Obstacle::cuboid(center, half, rpy).unwrap()
            else { unreachable!() };
        let found = segment_box(a, b, center, half_extents, &axes);
        let per_side = 60;
        let sampled = reference_box.surface(per_side).into_iter()
            .map(|y| point_segment(y, a, b)).fold(f64::INFINITY, f64::min);
        let spacing = 2.0 * half.iter().copied().fold(0.0, f64::max) / per_side as f64;
        prop_assert!(found.distance > 0.0);
        prop_assert!(sampled >= found.distance - 1e-12);
        prop_assert!(sampled - found.distance <= spacing, "{} vs {}", sampled, found.distance);
    }
}

#[test]
fn planar_rectangle_is_a_box_of_infinite_height() {
    let rectangle =
        Obstacle::cuboid([0.4, 0.1, 0.0], [0.1, 0.2, f64::INFINITY], [0.0, 0.0, 0.3]).unwrap();
    let Obstacle::Box {
        center,
        half_extents,
        axes,
    } = rectangle
    else {
        unreachable!()
    };
    let tall = TestBox {
        center,
        half: [0.1, 0.2, 1e6],
        rot: rotation([0.0, 0.0, 0.3]),
    };
    for (a, b) in [
        ([0.0, 0.0, 0.0], [1.0, 0.5, 0.0]),
        ([0.0, -0.5, 0.0], [0.0, 0.5, 0.0]),
        ([0.38, 0.1, 0.0], [0.42, 0.12, 0.0]),
    ] {
        let found = segment_box(a, b, center, half_extents, &axes);
        let reference = convex_min(|t| tall.sdf(lerp(a, b, t)));
        assert!((found.distance - reference).abs() < 1e-8);
    }
}

/// Pairs over every kind of obstacle around a planar 8-link chain.
fn planar_model() -> (ClearanceModel, Vec<f64>) {
    let obstacles = vec![
        Obstacle::circle([0.35, 0.25], 0.05).unwrap(),
        Obstacle::capsule([0.1, -0.3, 0.0], [0.5, -0.2, 0.0], 0.03).unwrap(),
        Obstacle::cuboid(
            [0.6, 0.1, 0.0],
            [0.05, 0.08, f64::INFINITY],
            [0.0, 0.0, 0.4],
        )
        .unwrap(),
        Obstacle::cuboid([0.2, 0.4, 0.05], [0.05, 0.1, 0.1], [0.2, -0.1, 0.7]).unwrap(),
    ];
    (
        ClearanceModel::new(8, 0.012, obstacles).unwrap(),
        vec![0.1, 0.12, 0.09, 0.1, 0.11, 0.1, 0.08, 0.1],
    )
}

/// Obstacles of the plane only (circles, a capsule, rectangles straight and turned), which
/// `distances` measures in two dimensions for a chain placed by `place_planar`.
fn in_plane_model() -> (ClearanceModel, Vec<f64>) {
    let obstacles = vec![
        Obstacle::circle([0.35, 0.25], 0.05).unwrap(),
        Obstacle::circle([0.3, 0.1], 0.0).unwrap(),
        Obstacle::capsule([0.1, -0.3, 0.0], [0.5, -0.2, 0.0], 0.03).unwrap(),
        Obstacle::capsule([0.2, 0.2, 0.0], [0.2, 0.2, 0.0], 0.01).unwrap(),
        Obstacle::cuboid(
            [0.6, 0.1, 0.0],
            [0.05, 0.08, f64::INFINITY],
            [0.0, 0.0, 0.4],
        )
        .unwrap(),
        Obstacle::cuboid([0.25, 0.3, 0.0], [0.1, 0.04, f64::INFINITY], [0.0; 3]).unwrap(),
    ];
    (
        ClearanceModel::new(8, 0.012, obstacles).unwrap(),
        vec![0.1, 0.12, 0.09, 0.1, 0.11, 0.1, 0.08, 0.1],
    )
}

fn planar_distances(model: &ClearanceModel, lengths: &[f64], theta: &[f64]) -> Vec<f64> {
    let mut data = ClearanceData::new(model, 0).unwrap();
    place_planar(model, &mut data, lengths, theta).unwrap();
    distances(model, &mut data);
    data.distances().to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn planar_chains_measure_the_same_in_two_dimensions(
        theta in prop::collection::vec(-2.5..2.5f64, 8),
    ) {
        // The same chain placed as a general one is measured in three dimensions.
        let (model, lengths) = in_plane_model();
        let mut data = ClearanceData::new(&model, 0).unwrap();
        place_planar(&model, &mut data, &lengths, &theta).unwrap();
        let near = distances(&model, &mut data);
        let mut general = ClearanceData::new(&model, 0).unwrap();
        let (points, axes) = (data.points().to_vec(), data.axes().to_vec());
        place(&model, &mut general, &points, &axes).unwrap();
        prop_assert_eq!(near, distances(&model, &mut general));
        prop_assert_eq!(data.distances(), general.distances());
        prop_assert_eq!(data.closest(), general.closest());
    }

    #[test]
    fn point_cores_in_lanes_give_the_bits_of_one_pair(
        points in prop::collection::vec(v3(), 4),
        centers in prop::collection::vec(v3(), 1..12),
        radius in 0.0..0.1f64,
        snap in 0..4usize,
        in_plane in any::<bool>(),
    ) {
        // Spheres (circles when in the plane) mixed with a capsule, measured a register of
        // them at a time, against each pair alone; with a centre on a joint point and a link
        // of zero length among the cases.
        let flat = |v: V| if in_plane { [v[0], v[1], 0.0] } else { v };
        let mut points: Vec<V> = points.into_iter().map(flat).collect();
        let mut centers: Vec<V> = centers.into_iter().map(flat).collect();
        if snap == 1 {
            points[2] = points[1];
        } else if snap == 2 {
            centers[0] = points[1];
        } else if snap == 3 {
            // Off the joint, across link 1, by 3e-12 of its length: a normal kept, just.
            let d = sub(points[2], points[1]);
            let across = [-d[1], d[0], 0.0];
            let scale = 3e-12 * norm(d) / norm(across);
            centers[0] = flat(lerp(points[1], [points[1][0] + across[0], points[1][1] + across[1], points[1][2]], scale));
        }
        let mut obstacles: Vec<Obstacle> = centers
            .iter()
            .enumerate()
            .map(|(i, &c)| Obstacle::sphere(c, 0.01 * i as f64).unwrap())
            .collect();
        obstacles.insert(1, Obstacle::capsule(flat([0.1, 0.2, 0.3]), flat([0.4, 0.1, 0.2]), 0.02).unwrap());
        let model = ClearanceModel::new(3, radius, obstacles).unwrap();
        let mut data = ClearanceData::new(&model, 0).unwrap();
        if in_plane && snap != 1 {
            // The points' planar chain, placed by angles (two dimensions; a planar chain has
            // no link of zero length).
            let mut lengths = vec![0.0; 3];
            let mut theta = vec![0.0; 3];
            let mut heading = 0.0;
            for i in 0..3 {
                let d = sub(points[i + 1], points[i]);
                lengths[i] = (d[0] * d[0] + d[1] * d[1]).sqrt();
                let angle = d[1].atan2(d[0]);
                theta[i] = angle - heading;
                heading = angle;
            }
            place_planar(&model, &mut data, &lengths, &theta).unwrap();
            points = data.points().to_vec();
        } else {
            place(&model, &mut data, &points, &[[0.0, 0.0, 1.0]; 3]).unwrap();
        }
        distances(&model, &mut data);
        for (pair, (&distance, closest)) in data.distances().iter().zip(data.closest()).enumerate() {
            let Pair::Obstacle { link, obstacle } = model.pairs()[pair] else { continue };
            let Obstacle::Sphere { center, radius: other } = model.obstacles()[obstacle] else {
                continue;
            };
            let alone = segment_point(points[link], points[link + 1], center);
            let bits = |c: &clearance::Closest| {
                let fields = [c.t, c.distance];
                let vectors = [c.point, c.other, c.normal];
                fields.into_iter().chain(vectors.into_iter().flatten()).map(f64::to_bits).collect::<Vec<_>>()
            };
            prop_assert_eq!(bits(closest), bits(&alone), "pair {}", pair);
            prop_assert_eq!(distance.to_bits(), (alone.distance - radius - other).to_bits());
        }
    }

    #[test]
    fn joint_gradients_match_finite_differences(
        theta in prop::collection::vec(-1.2..1.2f64, 8), in_plane in any::<bool>(),
    ) {
        // With an obstacle out of the plane, or every one in it (two dimensions).
        let (model, lengths) = if in_plane { in_plane_model() } else { planar_model() };
        let mut data = ClearanceData::new(&model, 0).unwrap();
        place_planar(&model, &mut data, &lengths, &theta).unwrap();
        distances(&model, &mut data);
        let mut gradient = vec![0.0; 8];
        for pair in 0..model.pairs().len() {
            joint_gradient(&model, &data, pair, &mut gradient).unwrap();
            for j in 0..8 {
                let along = |step: f64| {
                    let mut moved = theta.clone();
                    moved[j] += step;
                    planar_distances(&model, &lengths, &moved)[pair]
                };
                prop_assert!(matches_a_side(gradient[j], along),
                    "pair {:?} joint {}: {}", model.pairs()[pair], j, gradient[j]);
            }
        }
    }

    #[test]
    fn modal_gradients_match_finite_differences(
        a in prop::collection::vec(-1.5..1.5f64, 5), harmonics in 1..=2usize, free in any::<bool>(),
    ) {
        let (model, lengths) = planar_model();
        // Two to five coordinates: each count the gradients unroll for, and one they do not.
        let base = if free { BaseAngle::Free } else { BaseAngle::Fixed(0.3) };
        let map = ModalMap::new(&lengths, harmonics, base).unwrap();
        let m = map.n_coords();
        let a = a[..m].to_vec();
        let mut data = ClearanceData::new(&model, m).unwrap();
        let mut theta = vec![0.0; 8];
        map.joint_angles(&a, &mut theta).unwrap();
        place_planar(&model, &mut data, &lengths, &theta).unwrap();
        // The same chain placed as a general one: the six-number prefix sums.
        let mut general = ClearanceData::new(&model, m).unwrap();
        let (points, axes) = (data.points().to_vec(), data.axes().to_vec());
        place(&model, &mut general, &points, &axes).unwrap();
        distances(&model, &mut general);
        modal_gradients(&model, &mut general, &map).unwrap();
        distances(&model, &mut data);
        modal_gradients(&model, &mut data, &map).unwrap();
        let at = |a: &[f64]| {
            let mut theta = vec![0.0; 8];
            map.joint_angles(a, &mut theta).unwrap();
            planar_distances(&model, &lengths, &theta)
        };
        let mut joint = vec![0.0; 8];
        for pair in 0..model.pairs().len() {
            // J^T of the joint gradient, the chain rule done the long way.
            joint_gradient(&model, &data, pair, &mut joint).unwrap();
            for l in 0..m {
                let chain: f64 = (0..8).map(|j| map.entry(j, l) * joint[j]).sum();
                prop_assert!((data.modal_gradient(pair)[l] - chain).abs() < 1e-12);
                prop_assert!((general.modal_gradient(pair)[l] - chain).abs() < 1e-12);
                let along = |step: f64| {
                    let mut moved = a.clone();
                    moved[l] += step;
                    at(&moved)[pair]
                };
                prop_assert!(matches_a_side(data.modal_gradient(pair)[l], along),
                    "pair {:?} coordinate {}", model.pairs()[pair], l);
            }
        }
    }
}

/// Whether `slope` is the derivative of `f` at 0 from one side or the other, by second-order
/// one-sided differences: a closest point near a kink of the distance (a box's edge, a deep link
/// through a sphere's centre) has the derivative of its own feature, which a central difference
/// straddling the kink would average with the other's.
fn matches_a_side(slope: f64, f: impl Fn(f64) -> f64) -> bool {
    let h = 1e-6;
    let at = [-2.0, -1.0, 0.0, 1.0, 2.0].map(|k| f(k * h));
    let forward = (-3.0 * at[2] + 4.0 * at[3] - at[4]) / (2.0 * h);
    let backward = (3.0 * at[2] - 4.0 * at[1] + at[0]) / (2.0 * h);
    (slope - forward).abs() < 1e-6 || (slope - backward).abs() < 1e-6
}

/// Rodrigues' rotation of `v` about the unit `axis` by `angle`.
fn rotate(axis: V, angle: f64, v: V) -> V {
    let (s, c) = angle.sin_cos();
    let d = axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2];
    let x = [
        axis[1] * v[2] - axis[2] * v[1],
        axis[2] * v[0] - axis[0] * v[2],
        axis[0] * v[1] - axis[1] * v[0],
    ];
    [0, 1, 2].map(|i| v[i] * c + x[i] * s + axis[i] * d * (1.0 - c))
}

/// A spatial chain: joint `i` turns about its local axis, links along the local `x`.
fn spatial_chain(theta: &[f64], local_axes: &[V]) -> (Vec<V>, Vec<V>) {
    let mut frame = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (mut points, mut axes) = (vec![[0.0; 3]], Vec::new());
    for (angle, local) in theta.iter().zip(local_axes) {
        let axis = [0, 1, 2].map(|k| (0..3).map(|c| frame[c][k] * local[c]).sum::<f64>());
        axes.push(axis);
        frame = frame.map(|column| rotate(axis, *angle, column));
        let last = *points.last().unwrap();
        points.push([0, 1, 2].map(|k| last[k] + 0.1 * frame[0][k]));
    }
    (points, axes)
}

#[test]
fn spatial_joint_gradients_match_finite_differences() {
    let locals: Vec<V> = (0..6)
        .map(|i| {
            if i % 2 == 0 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            }
        })
        .collect();
    let model = ClearanceModel::new(
        6,
        0.01,
        vec![
            Obstacle::sphere([0.3, 0.1, 0.1], 0.05).unwrap(),
            Obstacle::capsule([0.2, -0.2, -0.1], [0.3, 0.2, -0.15], 0.02).unwrap(),
            Obstacle::cuboid([0.45, 0.0, 0.05], [0.03, 0.1, 0.05], [0.3, 0.2, 0.1]).unwrap(),
        ],
    )
    .unwrap();
    let theta = [0.3, -0.4, 0.7, 0.5, -0.9, 1.1];
    let evaluate = |theta: &[f64]| {
        let (points, axes) = spatial_chain(theta, &locals);
        let mut data = ClearanceData::new(&model, 0).unwrap();
        place(&model, &mut data, &points, &axes).unwrap();
        distances(&model, &mut data);
        data
    };
    let data = evaluate(&theta);
    let mut gradient = [0.0; 6];
    let h = 1e-6;
    for pair in 0..model.pairs().len() {
        joint_gradient(&model, &data, pair, &mut gradient).unwrap();
        for j in 0..6 {
            let (mut plus, mut minus) = (theta, theta);
            plus[j] += h;
            minus[j] -= h;
            let fd = (evaluate(&plus).distances()[pair] - evaluate(&minus).distances()[pair])
                / (2.0 * h);
            assert!(
                (gradient[j] - fd).abs() < 1e-6,
                "pair {pair} joint {j}: {} vs {fd}",
                gradient[j]
            );
        }
    }
}

#[test]
fn folded_chain_collides_with_itself_and_adjacent_links_are_not_pairs() {
    let model = ClearanceModel::new(4, 0.01, Vec::new()).unwrap();
    assert_eq!(
        model.pairs(),
        &[
            Pair::Links { link: 0, other: 2 },
            Pair::Links { link: 0, other: 3 },
            Pair::Links { link: 1, other: 3 }
        ]
    );
    let mut data = ClearanceData::new(&model, 0).unwrap();
    // A hairpin: links 0 and 2 run antiparallel 0.015 apart, less than the 0.02 of two radii.
    let pi = std::f64::consts::PI;
    let lengths = [0.1, 0.015, 0.1, 0.1];
    place_planar(&model, &mut data, &lengths, &[0.0, pi / 2.0, pi / 2.0, 0.0]).unwrap();
    let (near_obstacle, near_self) = distances(&model, &mut data);
    assert_eq!(near_obstacle, f64::INFINITY);
    assert!((data.distances()[0] - (0.015 - 0.02)).abs() < 1e-12);
    assert!((near_self - (0.015 - 0.02)).abs() < 1e-12);
    assert_eq!(data.min_self_clearance(&model), near_self);
}

#[test]
fn circle_clearance_is_the_textbook_distance() {
    // A straight chain along x, a circle above its middle.
    let model =
        ClearanceModel::new(5, 0.01, vec![Obstacle::circle([0.25, 0.2], 0.05).unwrap()]).unwrap();
    let mut data = ClearanceData::new(&model, 0).unwrap();
    place_planar(&model, &mut data, &[0.1; 5], &[0.0; 5]).unwrap();
    let (near, _) = distances(&model, &mut data);
    assert!((near - (0.2 - 0.05 - 0.01)).abs() < 1e-15);
    let mut gradient = [0.0; 5];
    joint_gradient(&model, &data, 2, &mut gradient).unwrap();
    // Turning the base by dtheta lifts x = 0.25 by 0.25 dtheta, towards the circle.
    assert!((gradient[0] + 0.25).abs() < 1e-15 && (gradient[2] + 0.05).abs() < 1e-15);
    assert_eq!(gradient[3], 0.0);
}

#[test]
fn bad_input_is_refused_with_the_field_named() {
    let refusal = |r: Result<Obstacle, ClearanceError>| r.unwrap_err().to_string();
    assert!(refusal(Obstacle::circle([f64::NAN, 0.0], 1.0)).contains("sphere center"));
    assert!(refusal(Obstacle::circle([0.0, 0.0], -1.0)).contains("obstacle radius"));
    assert!(
        refusal(Obstacle::cuboid([0.0; 3], [1.0, 0.0, 1.0], [0.0; 3])).contains("half_extents")
    );
    assert!(
        refusal(Obstacle::cuboid([0.0; 3], [1.0, f64::NAN, 1.0], [0.0; 3]))
            .contains("half_extents")
    );
    let model = ClearanceModel::new(3, f64::INFINITY, Vec::new()).unwrap_err();
    assert!(model.to_string().contains("link radius"));
    let too_many = ClearanceModel::new(100_000, 0.01, Vec::new()).unwrap_err();
    assert!(matches!(too_many, ClearanceError::TooMany { .. }));
    let model = ClearanceModel::new(3, 0.01, Vec::new()).unwrap();
    let mut data = ClearanceData::new(&model, 0).unwrap();
    assert!(place_planar(&model, &mut data, &[0.1; 3], &[0.0; 2]).is_err());
    assert!(place(&model, &mut data, &[[0.0; 3]; 4], &[[0.0, 0.0, 2.0]; 3]).is_err());
    let mut gradient = [0.0; 3];
    assert!(joint_gradient(&model, &data, 1, &mut gradient).is_err());
}

#[test]
fn data_of_another_model_and_chains_beyond_the_extent_are_refused() {
    let circle = |x: f64| Obstacle::circle([x, 0.0], 1.0).unwrap();
    let one = ClearanceModel::new(3, 0.01, vec![circle(5.0)]).unwrap();
    let three = ClearanceModel::new(3, 0.01, vec![circle(5.0), circle(6.0), circle(7.0)]).unwrap();
    let mut data = ClearanceData::new(&one, 0).unwrap();
    let message = place_planar(&three, &mut data, &[0.1; 3], &[0.1; 3])
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        "clearance data's pairs (made for another model) has 4 entries, expected 10"
    );
    assert!(place(&three, &mut data, &[[0.0; 3]; 4], &[[0.0, 0.0, 1.0]; 3]).is_err());
    place_planar(&one, &mut data, &[0.1; 3], &[0.1; 3]).unwrap();
    let mut gradient = [0.0; 3];
    assert!(joint_gradient(&three, &data, 0, &mut gradient).is_err());
    let map = ModalMap::new(&[0.1; 3], 1, BaseAngle::Fixed(0.0)).unwrap();
    assert!(modal_gradients(&three, &mut data, &map).is_err());
    let distances = std::panic::catch_unwind(|| {
        distances(&three, &mut data.clone());
    });
    assert!(distances.is_err());
    assert!(std::panic::catch_unwind(|| data.min_obstacle_clearance(&three)).is_err());
    // A pair index past the last is named as such, usize::MAX included.
    let message = joint_gradient(&one, &data, usize::MAX, &mut gradient)
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("pair index must be less than"),
        "{message}"
    );
    // Links of 1e300 m put the chain beyond the extent the geometry keeps to scale.
    let message = place_planar(&one, &mut data, &[1e300; 3], &[0.1; 3])
        .unwrap_err()
        .to_string();
    assert_eq!(
        message,
        "joint point coordinate must be at most 1e15 m in magnitude (MAX_OBSTACLE_EXTENT), got \
         9.950041652780259e299"
    );
    let far = [
        [0.0; 3],
        [2e15, 0.0, 0.0],
        [3e15, 0.0, 0.0],
        [4e15, 0.0, 0.0],
    ];
    assert!(place(&one, &mut data, &far, &[[0.0, 0.0, 1.0]; 3]).is_err());
}
