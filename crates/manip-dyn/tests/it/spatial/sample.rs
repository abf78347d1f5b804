//! Random spatial chains: random axes (about a fifth prismatic), origins and inertias, 1 to 30
//! joints, any gravity.

use manip_dyn::spatial::{SpatialJoint, SpatialLink, SpatialModel, Transform};
use proptest::collection::vec;
use proptest::prelude::*;

/// A unit vector from three numbers (not all small).
fn unit() -> impl Strategy<Value = [f64; 3]> {
    [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64]
        .prop_filter("not too short", |v| {
            v.iter().map(|x| x * x).sum::<f64>() > 0.05
        })
        .prop_map(|v| {
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.map(|x| x / norm)
        })
}

fn joint() -> impl Strategy<Value = SpatialJoint> {
    (
        0..5u8,
        unit(),
        [-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64],
        [-0.3..0.3f64, -0.3..0.3f64, -0.3..0.3f64],
    )
        .prop_map(|(kind, axis, rpy, xyz)| {
            let origin = Transform::from_rpy(rpy, xyz);
            if kind == 0 {
                SpatialJoint::prismatic(axis, origin)
            } else {
                SpatialJoint::revolute(axis, origin)
            }
        })
}

fn link() -> impl Strategy<Value = SpatialLink> {
    (
        0.05..2.0f64,
        [-0.2..0.2f64, -0.2..0.2f64, -0.2..0.2f64],
        [1e-3..2e-2f64, 1e-3..2e-2f64, 1e-3..2e-2f64],
        [-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64],
    )
        .prop_map(|(mass, com, second, rpy)| {
            // Principal moments from non-negative second moments: the triangle inequalities hold.
            let [a, b, c] = second.map(|s| s * mass);
            let principal = [b + c, a + c, a + b];
            let r = Transform::from_rpy(rpy, [0.0; 3]).rotation;
            let inertia = [0, 1, 2]
                .map(|i| [0, 1, 2].map(|j| (0..3).map(|k| r[i][k] * principal[k] * r[j][k]).sum()));
            SpatialLink { mass, com, inertia }
        })
}

/// A random chain of `n` joints.
pub fn chain(n: usize) -> impl Strategy<Value = SpatialModel> {
    (
        vec(joint(), n),
        vec(link(), n),
        [-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64],
    )
        .prop_map(|(joints, links, g)| SpatialModel::new(joints, links, g).unwrap())
}

/// A chain of 1 to `max` joints and a state `(q, v, a)`.
pub fn chain_and_state(
    max: usize,
) -> impl Strategy<Value = (SpatialModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    prop_oneof![1..=max.min(6), 1..=max].prop_flat_map(|n| {
        (
            chain(n),
            vec(-3.0..3.0f64, n),
            vec(-2.0..2.0f64, n),
            vec(-5.0..5.0f64, n),
        )
    })
}

/// The 10-link universal-joint snake: 20 revolute joints alternating `z` and `y`, links of
/// 0.1 m and 0.1 kg (the pitch joint of each pair at its yaw joint, the link's rod split evenly
/// between the two bodies, as MuJoCo needs no massless body), gravity along `-z`.
pub fn snake() -> SpatialModel {
    let mut joints = Vec::new();
    let mut links = Vec::new();
    for i in 0..20 {
        let reach = if i == 0 || i % 2 == 1 { 0.0 } else { 0.1 };
        let axis = if i % 2 == 0 {
            [0.0, 0.0, 1.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        joints.push(SpatialJoint::revolute(
            axis,
            Transform::translation([reach, 0.0, 0.0]),
        ));
        links.push(SpatialLink::cuboid(
            0.05,
            [0.1, 0.01, 0.01],
            [0.05, 0.0, 0.0],
        ));
    }
    SpatialModel::new(joints, links, [0.0, 0.0, -9.81]).unwrap()
}

/// A massless link (the cross of a universal joint written as two revolute joints).
pub const MASSLESS: SpatialLink = SpatialLink {
    mass: 0.0,
    com: [0.0; 3],
    inertia: [[0.0; 3]; 3],
};

/// A random chain of 2 to `max` joints whose even-numbered links but the last are massless
/// (every massless link has a link with mass beyond it), and a state `(q, v, tau)`.
pub fn massless_chain_and_state(
    max: usize,
) -> impl Strategy<Value = (SpatialModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    (2..=max).prop_flat_map(|n| {
        (
            vec(joint(), n),
            vec(link(), n),
            [-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64],
            vec(-3.0..3.0f64, n),
            vec(-2.0..2.0f64, n),
            vec(-5.0..5.0f64, n),
        )
            .prop_map(move |(joints, mut links, g, q, v, tau)| {
                for link in links.iter_mut().take(n - 1).step_by(2) {
                    *link = MASSLESS;
                }
                (SpatialModel::new(joints, links, g).unwrap(), q, v, tau)
            })
    })
}

/// The universal-joint snake of [`snake`] as URDF writes it: each yaw joint moves a massless
/// cross, its pitch joint (at the same point) the whole 0.1 kg, 0.1 m link.
pub fn massless_snake() -> SpatialModel {
    let joints = snake().joints().to_vec();
    let links = (0..20)
        .map(|i| {
            if i % 2 == 0 {
                MASSLESS
            } else {
                SpatialLink::cuboid(0.1, [0.1, 0.01, 0.01], [0.05, 0.0, 0.0])
            }
        })
        .collect();
    SpatialModel::new(joints, links, [0.0, 0.0, -9.81]).unwrap()
}
