//! The spatial modal family: the map against the planar one, the universal-joint chain against
//! the planar chain and finite differences, the curve's tip against the planar closed forms and
//! against chains of many links, and the tip's inverse kinematics.

use backbone_kin::{
    BackboneCurve, BaseAngle, BasePose, KinError, MAX_CURVE_STEPS, ModalMap,
    SPATIAL_CURVE_TOLERANCE, SpatialCurve, SpatialIk, SpatialModalMap, joint_positions,
    spatial_joint_positions, spatial_tip_jacobian, spatial_tip_position,
};
use proptest::prelude::*;

fn chain_tip(map: &SpatialModalMap, base: &BasePose, a: &[f64]) -> [f64; 3] {
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(a, &mut theta).unwrap();
    spatial_tip_position(map.link_lengths(), base, &theta).unwrap()
}

fn distance(p: [f64; 3], q: [f64; 3]) -> f64 {
    (0..3).map(|d| (p[d] - q[d]).powi(2)).sum::<f64>().sqrt()
}

fn rotate(r: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| r[i][j] * v[j]).sum())
}

#[test]
fn the_map_places_the_planar_rows_on_each_plane() {
    let lengths = [0.3, 0.2, 0.25, 0.1, 0.15];
    let map = SpatialModalMap::new(&lengths, 2).unwrap();
    let planar = ModalMap::new(&lengths, 2, BaseAngle::Fixed(0.0)).unwrap();
    assert_eq!(
        (map.n_joints(), map.n_coords(), map.harmonics()),
        (10, 8, 2)
    );
    for i in 0..5 {
        let (z, y) = (map.row(2 * i), map.row(2 * i + 1));
        assert_eq!(&z[..4], planar.row(i));
        assert_eq!(&y[4..], planar.row(i));
        assert!(z[4..].iter().chain(&y[..4]).all(|&v| v == 0.0));
    }
    let a = [0.3, -0.2, 0.1, 0.05, -0.4, 0.25, -0.1, 0.2];
    let mut theta = [0.0; 10];
    map.joint_angles(&a, &mut theta).unwrap();
    let (mut z, mut y) = ([0.0; 5], [0.0; 5]);
    planar.joint_angles(&a[..4], &mut z).unwrap();
    planar.joint_angles(&a[4..], &mut y).unwrap();
    for i in 0..5 {
        assert_eq!([theta[2 * i], theta[2 * i + 1]], [z[i], y[i]]);
    }
    // theta = J a, with J as stored.
    for (i, &t) in theta.iter().enumerate() {
        let dot: f64 = map.row(i).iter().zip(&a).map(|(j, x)| j * x).sum();
        assert!((dot - t).abs() < 1e-15);
    }
}

#[test]
fn without_out_of_plane_bending_the_chain_is_the_planar_chain() {
    let lengths = [0.3, 0.2, 0.25, 0.1];
    let planar_theta = [0.4, -0.7, 1.1, 0.3];
    let mut theta = [0.0; 8];
    for (i, &t) in planar_theta.iter().enumerate() {
        theta[2 * i] = t;
    }
    let mut spatial = [[0.0; 3]; 5];
    spatial_joint_positions(&lengths, &BasePose::default(), &theta, &mut spatial).unwrap();
    let mut planar = [[0.0; 2]; 5];
    joint_positions(&lengths, &planar_theta, &mut planar).unwrap();
    for (s, p) in spatial.iter().zip(&planar) {
        assert!((s[0] - p[0]).abs() < 1e-15 && (s[1] - p[1]).abs() < 1e-15 && s[2] == 0.0);
    }
}

#[test]
fn the_base_pose_moves_and_turns_the_whole_chain() {
    let lengths = [0.3, 0.2, 0.25];
    let theta = [0.4, -0.2, -0.7, 0.5, 1.1, 0.1];
    let base = BasePose {
        xyz: [0.1, -0.2, 0.3],
        rpy: [0.3, -0.5, 1.2],
    };
    let (mut moved, mut home) = ([[0.0; 3]; 4], [[0.0; 3]; 4]);
    spatial_joint_positions(&lengths, &base, &theta, &mut moved).unwrap();
    spatial_joint_positions(&lengths, &BasePose::default(), &theta, &mut home).unwrap();
    let r = base.rotation();
    // An orthonormal rotation, and the chain is the home chain turned and moved.
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            assert!((dot - f64::from(u8::from(i == j))).abs() < 1e-15);
        }
    }
    for (m, h) in moved.iter().zip(&home) {
        let expected: [f64; 3] = std::array::from_fn(|d| rotate(r, *h)[d] + base.xyz[d]);
        assert!(distance(*m, expected) < 1e-15);
    }
}

proptest! {
    #[test]
    fn the_tip_jacobian_matches_finite_differences(
        theta in prop::collection::vec(-1.5f64..1.5, 2..=16),
        rpy in prop::array::uniform3(-3.0f64..3.0),
    ) {
        let n = theta.len() / 2;
        let theta = &theta[..2 * n];
        let lengths: Vec<f64> = (0..n).map(|i| 0.1 + 0.02 * i as f64).collect();
        let base = BasePose { xyz: [0.5, -0.1, 0.2], rpy };
        let mut jacobian = vec![0.0; 3 * 2 * n];
        let tip = spatial_tip_jacobian(&lengths, &base, theta, &mut jacobian).unwrap();
        prop_assert_eq!(tip, spatial_tip_position(&lengths, &base, theta).unwrap());
        let h = 1e-6;
        for j in 0..2 * n {
            let mut plus = theta.to_vec();
            let mut minus = theta.to_vec();
            plus[j] += h;
            minus[j] -= h;
            let (p, m) = (
                spatial_tip_position(&lengths, &base, &plus).unwrap(),
                spatial_tip_position(&lengths, &base, &minus).unwrap(),
            );
            for d in 0..3 {
                let fd = (p[d] - m[d]) / (2.0 * h);
                prop_assert!((fd - jacobian[d * 2 * n + j]).abs() < 1e-8, "d {} j {}", d, j);
            }
        }
    }
}

#[test]
fn a_curve_bending_in_one_plane_has_the_planar_closed_forms() {
    let length = 1.3;
    for (k, planar_modes) in [(1, vec![0.8, -0.4]), (2, vec![0.6, 0.3, -0.2, 0.4])] {
        let planar = BackboneCurve::new(length, &planar_modes, 0.0)
            .unwrap()
            .end_point();
        let zeros = vec![0.0; 2 * k];
        // In-plane (about z): the planar curve in the x-y plane.
        let in_plane = [planar_modes.clone(), zeros.clone()].concat();
        let tip = SpatialCurve::new(length, k, &in_plane, BasePose::default())
            .unwrap()
            .tip(1e-13)
            .unwrap();
        assert!(
            distance(tip.position, [planar[0], planar[1], 0.0]) < 1e-12,
            "{tip:?}"
        );
        assert!(tip.error_estimate <= 1e-13);
        // Out of plane (about y): the same curve turned down into the x-z plane.
        let out_of_plane = [zeros, planar_modes].concat();
        let tip = SpatialCurve::new(length, k, &out_of_plane, BasePose::default())
            .unwrap()
            .tip(1e-13)
            .unwrap();
        assert!(
            distance(tip.position, [planar[0], 0.0, -planar[1]]) < 1e-12,
            "{tip:?}"
        );
    }
}

#[test]
fn the_error_estimate_is_honest() {
    let a = [0.9, -0.5, -0.7, 0.6];
    let base = BasePose {
        xyz: [0.0, 0.0, 1.0],
        rpy: [0.2, 0.4, -0.3],
    };
    let curve = SpatialCurve::new(1.0, 1, &a, base).unwrap();
    let exact = curve.tip(1e-14).unwrap();
    for tolerance in [1e-4, 1e-6, 1e-8, 1e-10] {
        let tip = curve.tip(tolerance).unwrap();
        let error = distance(tip.position, exact.position);
        assert!(tip.error_estimate <= tolerance);
        assert!(
            error <= 2.0 * tip.error_estimate + 1e-14,
            "{tolerance}: {error} vs {tip:?}"
        );
    }
    // The frame at the tip stays a rotation.
    let r = exact.rotation;
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            assert!((dot - f64::from(u8::from(i == j))).abs() < 1e-12);
        }
    }
}

/// The chain of `n` equal links converges to its curve, at first order where both planes bend:
/// each universal joint turns about `z` and then about `y`, a Lie-Trotter splitting of the frame
/// equation whose commutator term `(1/2) [z, y]` per link adds up to `O(1 / n)` (measured: 8.0,
/// 4.1, 2.1, 1.05 cm at 16, 32, 64, 128 links for this pose, ratios 1.95-1.99). Bending in one
/// plane, the splitting is exact and the chain is the planar midpoint rule, spectrally accurate
/// with equal links.
/// A base far from the origin (`1e9` m, within the bounds of a base) moves the tip and nothing
/// else: the displacement is integrated from the base, so the base's rounding never reaches
/// the error estimate (it was refused as "too oscillatory" at `1e9` m, and off by `5e-10` m at
/// `1e6`).
#[test]
fn a_far_base_moves_the_curve_whole() {
    let a = [0.1; 8];
    let rpy = [0.2, 0.4, -0.3];
    let near = SpatialCurve::new(1.0, 2, &a, BasePose { xyz: [0.0; 3], rpy }).unwrap();
    let near = near.tip(1e-12).unwrap();
    for x in [1e6, 1e9] {
        let xyz = [x, -x, 0.5 * x];
        let far = SpatialCurve::new(1.0, 2, &a, BasePose { xyz, rpy }).unwrap();
        let far = far.tip(1e-12).unwrap();
        assert_eq!(far.steps, near.steps);
        assert_eq!(far.error_estimate, near.error_estimate);
        assert_eq!(far.rotation, near.rotation);
        let moved: [f64; 3] = std::array::from_fn(|d| xyz[d] + near.position[d]);
        assert_eq!(far.position, moved);
    }
}

#[test]
fn chains_of_more_links_converge_to_the_curve() {
    let a = [0.9, -0.5, -0.7, 0.6];
    let curve = SpatialCurve::new(1.0, 1, &a, BasePose::default())
        .unwrap()
        .tip(1e-14)
        .unwrap();
    let errors: Vec<f64> = [16, 32, 64, 128]
        .iter()
        .map(|&n| {
            let map = SpatialModalMap::new(&vec![1.0 / n as f64; n], 1).unwrap();
            distance(chain_tip(&map, &BasePose::default(), &a), curve.position)
        })
        .collect();
    for pair in errors.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!((1.9..2.1).contains(&ratio), "{errors:?}");
    }
    assert!((0.07..0.09).contains(&errors[0]), "{errors:?}");
    // One plane only: the planar chain, spectrally accurate with equal links.
    let planar = [0.9, -0.5, 0.0, 0.0];
    let curve = SpatialCurve::new(1.0, 1, &planar, BasePose::default())
        .unwrap()
        .tip(1e-14)
        .unwrap();
    let errors: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| {
            let map = SpatialModalMap::new(&vec![1.0 / n as f64; n], 1).unwrap();
            distance(
                chain_tip(&map, &BasePose::default(), &planar),
                curve.position,
            )
        })
        .collect();
    assert!(errors.iter().all(|&e| e < 1e-12), "{errors:?}");
}

#[test]
fn the_tip_inverse_kinematics_lands_on_reachable_targets() {
    let base = BasePose {
        xyz: [0.0, 0.0, 0.5],
        rpy: [0.0, 0.0, 0.3],
    };
    for k in [1, 2] {
        let map = SpatialModalMap::new(&[0.1; 10], k).unwrap();
        let mut ik = SpatialIk::new(map.clone(), base).unwrap();
        let mut solved = 0;
        let cases = 40;
        for case in 0..cases {
            // Targets the family reaches: the tips of known coordinates.
            let known: Vec<f64> = (0..4 * k)
                .map(|j| 0.8 * ((case * 7 + j * 3) as f64 * 0.61).sin())
                .collect();
            let target = chain_tip(&map, &base, &known);
            let mut a: Vec<f64> = known.iter().map(|x| 0.7 * x + 0.05).collect();
            if ik.solve(target, &mut a).is_ok() {
                solved += 1;
                let tip = chain_tip(&map, &base, &a);
                assert!(distance(tip, target) <= ik.options().tolerance * 1.0 + 1e-15);
            }
        }
        assert_eq!(solved, cases, "K = {k}");
    }
}

#[test]
fn solve_evaluable_starts_from_a_quarter_bend_and_lands_where_the_curve_is_evaluated() {
    // From its default guess (a quarter bend in each plane) on the chain of 10 links of 0.1 m,
    // K = 2: the chain's tip lands on the target, the answer's curve is evaluated, and with a
    // guess it is the solve from that guess.
    let base = BasePose::default();
    let map = SpatialModalMap::new(&[0.1; 10], 2).unwrap();
    let mut ik = SpatialIk::new(map.clone(), base).unwrap();
    let known = [0.6, -0.2, 0.3, 0.1, -0.1, 0.05, 0.2, -0.1];
    let target = chain_tip(&map, &base, &known);
    let mut quarter = [1.0; 8];
    SpatialIk::default_guess(&mut quarter);
    assert_eq!(quarter, [0.25, 0.0, 0.25, 0.0, 0.25, 0.0, 0.25, 0.0]);
    let mut a = [f64::NAN; 8];
    let report = ik.solve_evaluable(target, None, &mut a).unwrap();
    assert!(distance(chain_tip(&map, &base, &a), target) <= ik.options().tolerance + 1e-15);
    let mut from_quarter = quarter;
    assert_eq!(ik.solve(target, &mut from_quarter).unwrap(), report);
    assert_eq!(a, from_quarter);
    map.curve_tip(&a, base).unwrap();
    let guess = [0.5, -0.1, 0.2, 0.0, 0.0, 0.0, 0.1, 0.0];
    let mut from_guess = guess;
    ik.solve(target, &mut from_guess).unwrap();
    ik.solve_evaluable(target, Some(&guess), &mut a).unwrap();
    assert_eq!(a, from_guess);
}

#[test]
fn the_spatial_family_refuses_bad_input() {
    let base = BasePose::default();
    assert!(matches!(
        SpatialModalMap::uniform(0, 1),
        Err(KinError::NoLinks)
    ));
    assert!(matches!(
        SpatialModalMap::uniform(3, 0),
        Err(KinError::NoHarmonics)
    ));
    assert!(matches!(
        SpatialModalMap::uniform(1_000_000, 16),
        Err(KinError::TooMany { .. })
    ));
    let map = SpatialModalMap::uniform(3, 1).unwrap();
    let mut theta = [0.0; 6];
    assert!(matches!(
        map.joint_angles(&[0.0; 3], &mut theta),
        Err(KinError::Dimension {
            expected: 4,
            found: 3,
            ..
        })
    ));
    assert!(matches!(
        map.joint_angles(&[0.0, f64::NAN, 0.0, 0.0], &mut theta),
        Err(KinError::NonFinite { .. })
    ));
    assert!(matches!(
        spatial_tip_position(&[1.0, 1.0], &base, &[0.0; 3]),
        Err(KinError::Dimension { .. })
    ));
    let bad_base = BasePose {
        xyz: [0.0, f64::INFINITY, 0.0],
        rpy: [0.0; 3],
    };
    assert!(matches!(
        spatial_tip_position(&[1.0], &bad_base, &[0.0; 2]),
        Err(KinError::NonFinite {
            name: "base xyz",
            ..
        })
    ));
    assert!(matches!(
        SpatialCurve::new(1.0, 1, &[0.0; 3], base),
        Err(KinError::Dimension { .. })
    ));
    assert!(matches!(
        SpatialCurve::new(-1.0, 1, &[0.0; 4], base),
        Err(KinError::NonPositiveLength { .. })
    ));
    let wild = SpatialCurve::new(1.0, 1, &[1e6, 0.0, 1e6, 0.0], base).unwrap();
    assert!(matches!(
        wild.tip(1e-12),
        Err(KinError::TooOscillatory { .. })
    ));
    assert!(matches!(
        wild.tip(0.0),
        Err(KinError::NonPositiveLength { .. })
    ));
    // Amplitudes of 3000 turn the frame 2 pi 12000 rad over the curve: grids of 8, 16, ...
    // steps sample the oscillation at one phase and agree on a wrong tip, so the steps start
    // where they resolve the turning (here beyond the budget: refused, not answered).
    let aliased = SpatialCurve::new(1.0, 1, &[3000.0; 4], base).unwrap();
    match aliased.tip(1e-12) {
        Err(KinError::TooOscillatory { needed, max }) => {
            assert_eq!(max, MAX_CURVE_STEPS);
            assert!(needed > 4.8e6, "{needed}");
        }
        other => panic!("{other:?}"),
    }
    // The budget shrinks with the harmonics, whose steps cost more.
    let fast = SpatialCurve::new(1.0, 16, &[30.0; 64], base).unwrap();
    assert!(matches!(
        fast.tip(1e-12),
        Err(KinError::TooOscillatory { max, .. }) if max == MAX_CURVE_STEPS / 16
    ));
    // A moderate curve starts at the steps that resolve its turning, 2 pi 3.8 / 0.5 = 48.
    let moderate = SpatialCurve::new(1.0, 1, &[2.0, -1.0, 0.5, 0.3], base).unwrap();
    let tip = moderate.tip(1e-12).unwrap();
    assert!(tip.error_estimate <= 1e-12 && tip.steps >= 96, "{tip:?}");
    let mut ik = SpatialIk::new(map, base).unwrap();
    let mut a = [0.1; 4];
    assert!(matches!(
        ik.solve([3.0, 0.0, 0.1], &mut a),
        Err(KinError::OutOfReach { .. })
    ));
    // A target at the edge of double precision is that far, not infinitely far (the sum of
    // squares overflows; the scaled distance does not).
    let far = ik.solve([1e308, 0.0, 0.0], &mut a).unwrap_err();
    assert!(matches!(far, KinError::OutOfReach { r, .. } if r == 1e308));
    assert!(far.to_string().contains("r = 1e308 exceeds"), "{far}");
    let near = [1e-200, 2e-200, 2e-200];
    assert_eq!(backbone_kin::vec3::distance(near, [0.0; 3]), 3e-200);
    assert!(matches!(
        ik.solve([0.3, f64::NAN, 0.1], &mut a),
        Err(KinError::NonFinite {
            name: "target y",
            ..
        })
    ));
    let _ = SPATIAL_CURVE_TOLERANCE;
}

/// Arms of links of `1e-200` m (whose squared errors underflow) and `1e150` m (whose squares
/// overflow): the solver never reports a target it did not reach as reached.
#[test]
fn the_residual_of_tiny_and_huge_arms_never_reads_as_zero() {
    for scale in [1e-200, 1.0, 1e150] {
        let map = SpatialModalMap::new(&[scale; 2], 1).unwrap();
        let base = BasePose::default();
        let target = [scale, 0.5 * scale, 0.3 * scale];
        let mut ik = SpatialIk::new(map.clone(), base).unwrap();
        let mut a = [0.25, 0.0, 0.25, 0.0];
        let guess_tip = chain_tip(&map, &base, &a);
        let miss = (0..3).fold(0.0_f64, |d, k| d.hypot(guess_tip[k] - target[k]));
        assert!(miss > 0.1 * scale, "{scale}: the guess is {miss} away");
        match ik.solve(target, &mut a) {
            Ok(report) => {
                let tip = chain_tip(&map, &base, &a);
                let error = (0..3).fold(0.0_f64, |d, k| d.hypot(tip[k] - target[k]));
                assert!(error <= 1e-12 * scale, "{scale}: {error}");
                assert!(report.residual <= 1e-12 * scale && report.iterations > 0);
            }
            // At 1e-200 m the Jacobian's squares underflow: no step is defined.
            Err(error) => assert!(
                matches!(error, KinError::NotConverged { residual, .. }
                    | KinError::Stationary { residual, .. } if residual > 0.0),
                "{scale}: {error:?}"
            ),
        }
    }
}
