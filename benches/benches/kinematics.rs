//! Backbone kinematics: closed-form and chain forward kinematics, closed-form and numerical
//! inverse kinematics, the modal Jacobian of the paper's arm, and the restricted inverse of J0.

use backbone_kin::{
    BackboneCurve, Branch, HarmonicIk, ModalMap, end_point, inverse_j0, inverse_kinematics,
    tip_position,
};
use criterion::{Criterion, criterion_group, criterion_main};
use std::f64::consts::FRAC_PI_2;
use std::hint::black_box;

/// The paper's arm (10 links of 0.1 m, l = 1) at a pose on its path (eq 25), alpha0 = pi/2.
const LINKS: usize = 10;
const LINK_LENGTH: f64 = 0.1;
const ALPHA0: f64 = FRAC_PI_2;
const A: [f64; 2] = [1.2, -0.4];

fn fk(c: &mut Criterion) {
    let mut group = c.benchmark_group("fk");
    group.bench_function("closed_form", |b| {
        b.iter(|| end_point(black_box(1.0), black_box(A), black_box(ALPHA0)))
    });
    let map = ModalMap::paper_fixed_alpha0(LINKS, ALPHA0).unwrap();
    let lengths = [LINK_LENGTH; LINKS];
    let mut theta = [0.0; LINKS];
    // Joint angles from the modal map, then the chain's tip: the `fk` op's `tip_chain`.
    group.bench_function("chain_10", |b| {
        b.iter(|| {
            map.joint_angles(black_box(&A), &mut theta).unwrap();
            tip_position(&lengths, &theta)
        })
    });
    group.finish();
}

fn ik(c: &mut Criterion) {
    let mut group = c.benchmark_group("ik");
    let target = end_point(1.0, A, ALPHA0).unwrap();
    group.bench_function("closed_form", |b| {
        b.iter(|| inverse_kinematics(1.0, black_box(target), ALPHA0, Branch::Positive))
    });
    // Two harmonics from a guess 0.1 rad off a known solution, to the default 1e-14 l.
    let truth = [1.0, -0.3, 0.2, 0.1];
    let target = BackboneCurve::new(1.0, &truth, ALPHA0).unwrap().end_point();
    let mut solver = HarmonicIk::new(1.0, 2, ALPHA0).unwrap();
    let mut a = [0.0; 4];
    group.bench_function("harmonic_2", |b| {
        b.iter(|| {
            a = [1.1, -0.2, 0.1, 0.2];
            solver.solve(black_box(target), &mut a).unwrap()
        })
    });
    group.finish();
}

fn jacobian(c: &mut Criterion) {
    let mut group = c.benchmark_group("jacobian");
    group.bench_function("paper_10", |b| b.iter(|| ModalMap::paper(black_box(LINKS))));
    group.finish();
}

fn inverse_bessel(c: &mut Criterion) {
    // A value in the Newton region (the series region below 1e-2 from the top is cheaper).
    c.bench_function("inverse_j0", |b| b.iter(|| inverse_j0(black_box(0.37))));
}

criterion_group!(benches, fk, ik, jacobian, inverse_bessel);
criterion_main!(benches);
