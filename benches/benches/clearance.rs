//! Signed distances (issue 30): the 10-link arm's capsules against 10 obstacles (and its self
//! pairs), with their gradients with respect to the modal coordinates.

use backbone_kin::ModalMap;
use clearance::{
    ClearanceData, ClearanceModel, Obstacle, distances, modal_gradients, place_planar,
};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn clearance(c: &mut Criterion) {
    let mut group = c.benchmark_group("clearance");
    let lengths = [0.1; 10];
    let map = ModalMap::paper(10).unwrap();
    // Ten obstacles around the paper's arm: six circles, two capsules and two boxes.
    let mut obstacles: Vec<Obstacle> = (0..6)
        .map(|i| {
            let angle = 0.4 + 0.4 * f64::from(i);
            Obstacle::circle([0.6 * angle.cos(), 0.6 * angle.sin()], 0.05).unwrap()
        })
        .collect();
    obstacles.push(Obstacle::capsule([0.3, 0.8, 0.0], [0.5, 0.7, 0.0], 0.03).unwrap());
    obstacles.push(Obstacle::capsule([-0.4, 0.5, 0.0], [-0.5, 0.2, 0.0], 0.03).unwrap());
    obstacles
        .push(Obstacle::cuboid([0.0, 1.05, 0.0], [0.2, 0.05, f64::INFINITY], [0.0; 3]).unwrap());
    obstacles.push(
        Obstacle::cuboid([0.8, 0.3, 0.0], [0.05, 0.1, f64::INFINITY], [0.0, 0.0, 0.3]).unwrap(),
    );
    let model = ClearanceModel::new(10, 0.01, obstacles).unwrap();
    let mut data = ClearanceData::new(&model, map.n_coords()).unwrap();
    let a = [0.5, 0.2, 1.5];
    let mut theta = [0.0; 10];
    map.joint_angles(&a, &mut theta).unwrap();
    group.bench_function("distances_10x10", |b| {
        b.iter(|| {
            place_planar(&model, &mut data, &lengths, black_box(&theta)).unwrap();
            black_box(distances(&model, &mut data))
        })
    });
    group.bench_function("gradients_10x10", |b| {
        b.iter(|| {
            place_planar(&model, &mut data, &lengths, black_box(&theta)).unwrap();
            let near = distances(&model, &mut data);
            modal_gradients(&model, &mut data, &map).unwrap();
            black_box((near, data.modal_gradient(0)[0]))
        })
    });
    group.finish();
}

criterion_group!(benches, clearance);
criterion_main!(benches);
