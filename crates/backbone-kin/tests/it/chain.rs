//! Forward kinematics of the discrete chain: an independent rotation-composition algorithm, and
//! the aliasing law that relates the chain's tip to the closed-form end point (model notes:
//! the chain tip is the midpoint rule applied to eqs 3-4).

use backbone_kin::{ModalMap, end_point, joint_positions, tip_position};
use proptest::prelude::*;
use std::f64::consts::PI;

/// `J_n(x)` for any integer `n`, with `J_{-n} = (-1)^n J_n`.
fn bessel(n: i32, x: f64) -> f64 {
    let value = libm::jn(n.abs(), x);
    if n < 0 && n % 2 != 0 { -value } else { value }
}

/// Joint positions by composing rotation matrices (no angle sums): `R_i = R_{i-1} Rot(theta_i)`.
fn positions_by_rotations(lengths: &[f64], theta: &[f64]) -> Vec<[f64; 2]> {
    let mut points = vec![[0.0, 0.0]];
    let (mut c, mut s) = (1.0, 0.0);
    for (&length, &angle) in lengths.iter().zip(theta) {
        let (sa, ca) = angle.sin_cos();
        (c, s) = (c * ca - s * sa, s * ca + c * sa);
        let last = *points.last().unwrap();
        points.push([last[0] + length * c, last[1] + length * s]);
    }
    points
}

/// Tip of the paper's chain: `n` equal links of length `link`, joint angles `J (a1, a2, alpha0)`.
fn paper_chain_tip(n: usize, link: f64, a: [f64; 3]) -> [f64; 2] {
    let map = ModalMap::paper(n).unwrap();
    let mut theta = vec![0.0; n];
    map.joint_angles(&a, &mut theta).unwrap();
    tip_position(&vec![link; n], &theta).unwrap()
}

/// `sum_{m >= from} |J_{mn}(A)|`, the size of the aliasing terms `±m` from `from` on (over
/// eight of them: `J_{mn}(A)` falls faster than geometrically in `m` for `A` below `2n`).
fn aliasing_tail(n: usize, amplitude: f64, from: i32) -> f64 {
    (from..from + 8)
        .map(|m| bessel(m * n as i32, amplitude).abs())
        .sum()
}

/// The aliasing terms `m = ±1, ±2` of the midpoint rule: chain tip minus closed form is
/// `l exp(i (alpha0 + a2)) sum_{m != 0} (-1)^m J_{mn}(A) exp(-i m n beta)`.
fn predicted_aliasing(
    n: usize,
    length: f64,
    amplitude: f64,
    beta: f64,
    alpha0: f64,
    a2: f64,
) -> [f64; 2] {
    let n = n as i32;
    let (mut re, mut im) = (0.0, 0.0);
    for m in [-2, -1, 1, 2] {
        let c = if m % 2 == 0 { 1.0 } else { -1.0 } * bessel(m * n, amplitude);
        let phase = -f64::from(m * n) * beta;
        re += c * phase.cos();
        im += c * phase.sin();
    }
    let (sin, cos) = (alpha0 + a2).sin_cos();
    [
        length * (cos * re - sin * im),
        length * (sin * re + cos * im),
    ]
}

proptest! {
    /// Angle accumulation against rotation composition, for arbitrary link lengths; the tip is
    /// the last joint position and every link keeps its length.
    #[test]
    fn positions_match_rotation_composition(
        chain in prop::collection::vec((0.01f64..2.0, -PI..PI), 1..40),
    ) {
        let (lengths, theta): (Vec<f64>, Vec<f64>) = chain.into_iter().unzip();
        let mut points = vec![[f64::NAN; 2]; lengths.len() + 1];
        joint_positions(&lengths, &theta, &mut points).unwrap();
        let reference = positions_by_rotations(&lengths, &theta);
        let scale: f64 = lengths.iter().sum();
        for (p, q) in points.iter().zip(&reference) {
            prop_assert!((p[0] - q[0]).abs() <= 1e-13 * scale && (p[1] - q[1]).abs() <= 1e-13 * scale);
        }
        prop_assert_eq!(*points.last().unwrap(), tip_position(&lengths, &theta).unwrap());
        for (i, &length) in lengths.iter().enumerate() {
            let link = (points[i + 1][0] - points[i][0]).hypot(points[i + 1][1] - points[i][1]);
            prop_assert!((link - length).abs() <= 1e-13 * scale);
        }
    }

    /// The discrete chain on the curve ends within `2 l |J_n(A)|` of eqs 3-4, and the difference
    /// is exactly the predicted aliasing of the midpoint rule.
    #[test]
    fn chain_tip_differs_from_closed_form_only_by_aliasing(
        n in 4usize..40,
        link in 0.01f64..1.0,
        amplitude in 0.0f64..2.4,
        beta in -PI..PI,
        alpha0 in -PI..PI,
    ) {
        let (a1, a2) = (amplitude * beta.cos(), amplitude * beta.sin());
        let length = n as f64 * link;
        let chain = paper_chain_tip(n, link, [a1, a2, alpha0]);
        let closed = end_point(length, [a1, a2], alpha0).unwrap();
        let difference = [chain[0] - closed[0], chain[1] - closed[1]];
        let bound = 2.0 * length * aliasing_tail(n, amplitude, 1);
        let rounding = 1e-14 * length;
        prop_assert!(difference[0].hypot(difference[1]) <= bound + rounding, "{difference:?} vs bound {bound}");
        let predicted = predicted_aliasing(n, length, amplitude, beta, alpha0, a2);
        // The terms from m = ±3 on (at n = 4 and A = 2.4 those of ±4 are 1.4e-12 of the length,
        // above the rounding).
        let rest = 2.0 * length * aliasing_tail(n, amplitude, 3);
        prop_assert!((difference[0] - predicted[0]).hypot(difference[1] - predicted[1]) <= rest + rounding);
    }
}

#[test]
fn aliasing_bound_is_attained_for_ten_links() {
    // n = 10, l = 1: the worst chain-versus-closed-form distance over the mode direction beta
    // is 2 l |J_10(A)| (5.2e-13, 5.3e-10, 1.0e-7, 2.0e-6 at A = 0.5, 1, 1.7, 2.3). The model
    // notes quote 4e-13, 4e-10, 3e-8, 6e-7: single-pose measurements under this bound.
    for (amplitude, notes) in [(0.5, 4e-13), (1.0, 4e-10), (1.7, 3e-8), (2.3, 6e-7)] {
        let worst = (0..720)
            .map(|k| {
                let beta = PI * f64::from(k) / 360.0;
                let a = [amplitude * beta.cos(), amplitude * beta.sin(), 0.2];
                let chain = paper_chain_tip(10, 0.1, a);
                let closed = end_point(1.0, [a[0], a[1]], a[2]).unwrap();
                (chain[0] - closed[0]).hypot(chain[1] - closed[1])
            })
            .fold(0.0, f64::max);
        let bound = 2.0 * libm::jn(10, amplitude).abs();
        assert!(worst <= bound + 1e-15, "A = {amplitude}: {worst} > {bound}");
        assert!(
            worst >= 0.95 * bound,
            "A = {amplitude}: {worst} well below {bound}"
        );
        assert!(
            notes <= bound,
            "A = {amplitude}: the notes' {notes} exceeds the bound {bound}"
        );
    }
}
