//! Each spatial algorithm against a second one over random spatial chains (random axes, origins,
//! inertias, some prismatic joints, 1 to 30 joints): RNEA against `M qdd + C qd + G`, ABA against
//! a Cholesky solve, the analytic derivatives against finite differences, the power identity
//! (`M_dot - 2C` skew), the Jacobian against differentiated poses, the batch against one state
//! at a time (same bits), and energy conservation of free motion.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, Side};
use manip_dyn::DynError;
use manip_dyn::spatial::{
    self, SpatialBatchData, SpatialData, SpatialDerivativeData, SpatialModel, aba, aba_batch,
    aba_derivatives, coriolis, forward_kinematics, jacobian, kinetic_energy, nonlinear_effects,
    potential_energy, rnea, rnea_derivatives,
};
use proptest::prelude::*;

use super::sample::{chain_and_state, snake};
use crate::common::{axpy, mat_vec, max_abs, ridders};

fn mass(model: &SpatialModel, data: &mut SpatialData, q: &[f64]) -> Mat<f64> {
    let n = model.n_links();
    let mut m = Mat::zeros(n, n);
    spatial::mass_matrix(model, data, q, m.as_mut()).unwrap();
    m
}

fn difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn rnea_is_m_qdd_plus_bias(
        (model, q, v, a) in chain_and_state(30),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let mut tau = vec![0.0; n];
        rnea(&model, &mut data, &q, &v, &a, &mut tau).unwrap();
        let m = mass(&model, &mut data, &q);
        let (mut nle, mut c, mut g) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        nonlinear_effects(&model, &mut data, &q, &v, &mut nle).unwrap();
        coriolis(&model, &mut data, &q, &v, &mut c).unwrap();
        spatial::gravity(&model, &mut data, &q, &mut g).unwrap();
        let expected = axpy(&mat_vec(&m, &a), 1.0, &nle);
        let scale = 1.0 + max_abs(&tau);
        prop_assert!(difference(&tau, &expected) < 1e-10 * scale);
        prop_assert!(difference(&nle, &axpy(&c, 1.0, &g)) < 1e-10 * scale);
        // M symmetric, and 2 T = qd^T M qd.
        for i in 0..n {
            for j in 0..n {
                prop_assert_eq!(m[(i, j)], m[(j, i)]);
            }
        }
        let twice: f64 = v.iter().zip(mat_vec(&m, &v)).map(|(x, y)| x * y).sum();
        let kinetic = kinetic_energy(&model, &mut data, &q, &v).unwrap();
        prop_assert!((2.0 * kinetic - twice).abs() < 1e-10 * (1.0 + twice.abs()));
    }

    #[test]
    fn aba_solves_the_equations_of_motion(
        (model, q, v, tau) in chain_and_state(30),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let mut qdd = vec![0.0; n];
        aba(&model, &mut data, &q, &v, &tau, &mut qdd).unwrap();
        let m = mass(&model, &mut data, &q);
        let mut nle = vec![0.0; n];
        nonlinear_effects(&model, &mut data, &q, &v, &mut nle).unwrap();
        let inverse = m.llt(Side::Lower).unwrap().inverse();
        let cholesky = mat_vec(&inverse, &axpy(&tau, -1.0, &nle));
        prop_assert!(
            difference(&qdd, &cholesky) < 1e-8 * (1.0 + max_abs(&cholesky)),
            "{qdd:?} {cholesky:?}"
        );
        // And back through the RNEA.
        let mut back = vec![0.0; n];
        rnea(&model, &mut data, &q, &v, &qdd, &mut back).unwrap();
        prop_assert!(difference(&back, &tau) < 1e-9 * (1.0 + max_abs(&tau)));
    }

    #[test]
    fn rnea_derivatives_match_finite_differences(
        (model, q, v, a) in chain_and_state(12),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let mut derivatives = SpatialDerivativeData::new(&model);
        rnea_derivatives(&model, &mut data, &mut derivatives, &q, &v, &a).unwrap();
        let mut tau = vec![0.0; n];
        rnea(&model, &mut data, &q, &v, &a, &mut tau).unwrap();
        prop_assert!(difference(derivatives.value(), &tau) < 1e-12 * (1.0 + max_abs(&tau)));
        let m = mass(&model, &mut data, &q);
        for k in 0..n {
            let unit: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == k))).collect();
            let mut scratch = SpatialData::new(&model);
            let mut tau_at = |q: &[f64], v: &[f64]| {
                let mut out = vec![0.0; n];
                rnea(&model, &mut scratch, q, v, &a, &mut out).unwrap();
                out
            };
            let (by_q, error_q) = ridders(|h| tau_at(&axpy(&q, h, &unit), &v), 0.0, 0.1);
            let (by_v, error_v) = ridders(|h| tau_at(&q, &axpy(&v, h, &unit)), 0.0, 0.1);
            for i in 0..n {
                let tolerance = |e: f64, x: f64| 1e-7 * (1.0 + x.abs()) + 10.0 * e;
                prop_assert!(
                    (derivatives.d_q()[(i, k)] - by_q[i]).abs() < tolerance(error_q, by_q[i]),
                    "d tau {i} / d q {k}: {} vs {}", derivatives.d_q()[(i, k)], by_q[i]
                );
                prop_assert!(
                    (derivatives.d_v()[(i, k)] - by_v[i]).abs() < tolerance(error_v, by_v[i]),
                    "d tau {i} / d v {k}: {} vs {}", derivatives.d_v()[(i, k)], by_v[i]
                );
                prop_assert!((derivatives.d_input()[(i, k)] - m[(i, k)]).abs() < 1e-12 * (1.0 + m[(i, k)].abs()));
            }
        }
    }

    #[test]
    fn aba_derivatives_match_finite_differences(
        (model, q, v, tau) in chain_and_state(12),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let mut derivatives = SpatialDerivativeData::new(&model);
        aba_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau).unwrap();
        let mut qdd = vec![0.0; n];
        aba(&model, &mut data, &q, &v, &tau, &mut qdd).unwrap();
        // The derivatives' qdd comes from the ABA run in the base frame: a second algorithm.
        prop_assert!(
            difference(derivatives.value(), &qdd) < 1e-10 * (1.0 + max_abs(&qdd)),
            "{:?} vs {:?}", derivatives.value(), qdd
        );
        let inverse = mass(&model, &mut data, &q).llt(Side::Lower).unwrap().inverse();
        for k in 0..n {
            let unit: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == k))).collect();
            let mut scratch = SpatialData::new(&model);
            let mut qdd_at = |q: &[f64], v: &[f64], tau: &[f64]| {
                let mut out = vec![0.0; n];
                aba(&model, &mut scratch, q, v, tau, &mut out).unwrap();
                out
            };
            let (by_q, error_q) = ridders(|h| qdd_at(&axpy(&q, h, &unit), &v, &tau), 0.0, 0.1);
            let (by_v, error_v) = ridders(|h| qdd_at(&q, &axpy(&v, h, &unit), &tau), 0.0, 0.1);
            for i in 0..n {
                let tolerance = |e: f64, x: f64| 1e-6 * (1.0 + x.abs()) + 10.0 * e;
                prop_assert!(
                    (derivatives.d_q()[(i, k)] - by_q[i]).abs() < tolerance(error_q, by_q[i]),
                    "d qdd {i} / d q {k}: {} vs {}", derivatives.d_q()[(i, k)], by_q[i]
                );
                prop_assert!(
                    (derivatives.d_v()[(i, k)] - by_v[i]).abs() < tolerance(error_v, by_v[i]),
                    "d qdd {i} / d v {k}: {} vs {}", derivatives.d_v()[(i, k)], by_v[i]
                );
                let expected = inverse[(i, k)];
                prop_assert!((derivatives.d_input()[(i, k)] - expected).abs() < 1e-8 * (1.0 + expected.abs()));
            }
        }
    }

    /// The `O(n^2)` path (`M^-1` from the articulated-body factorisation, theory.md eqs. S1-S3)
    /// against the Cholesky one: `M^-1` the inverse of the CRBA's `M`, and
    /// `d qdd / d (q, v) = -M^-1 d tau / d (q, v)` with the RNEA derivatives at the ABA's `qdd`
    /// (Carpentier and Mansard 2018, eq. 12), to 1e-10 of the largest entry.
    #[test]
    fn aba_derivatives_match_the_cholesky_path(
        (model, q, v, tau) in chain_and_state(30),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let mut derivatives = SpatialDerivativeData::new(&model);
        aba_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau).unwrap();
        let qdd = derivatives.value().to_vec();
        let inverse = mass(&model, &mut data, &q).llt(Side::Lower).unwrap().inverse();
        let mut rnea_side = SpatialDerivativeData::new(&model);
        rnea_derivatives(&model, &mut data, &mut rnea_side, &q, &v, &qdd).unwrap();
        let d_q = -(&inverse * rnea_side.d_q());
        let d_v = -(&inverse * rnea_side.d_v());
        for (ours, theirs) in [
            (derivatives.d_input(), inverse.as_ref()),
            (derivatives.d_q(), d_q.as_ref()),
            (derivatives.d_v(), d_v.as_ref()),
        ] {
            let scale = (0..n).flat_map(|j| (0..n).map(move |i| theirs[(i, j)].abs())).fold(0.0, f64::max);
            for j in 0..n {
                for i in 0..n {
                    prop_assert!(
                        (ours[(i, j)] - theirs[(i, j)]).abs() <= 1e-10 * scale,
                        "({i}, {j}): {} vs {}", ours[(i, j)], theirs[(i, j)]
                    );
                }
            }
        }
    }

    /// `qd^T (M_dot - 2 C) qd = 0` in its power form: `qd^T M_dot qd = 2 qd^T C(q, qd) qd`, with
    /// `M_dot` the derivative of `M` along `qd` by finite differences.
    #[test]
    fn m_dot_minus_two_c_is_skew(
        (model, q, v, _a) in chain_and_state(20),
    ) {
        let n = model.n_links();
        let mut data = SpatialData::new(&model);
        let (m_dot, error) = ridders(
            |h| {
                let m = mass(&model, &mut data, &axpy(&q, h, &v));
                mat_vec(&m, &v)
            },
            0.0,
            0.05,
        );
        let power: f64 = v.iter().zip(&m_dot).map(|(x, y)| x * y).sum();
        let mut c = vec![0.0; n];
        coriolis(&model, &mut data, &q, &v, &mut c).unwrap();
        let twice: f64 = 2.0 * v.iter().zip(&c).map(|(x, y)| x * y).sum::<f64>();
        prop_assert!((power - twice).abs() < 1e-7 * (1.0 + twice.abs()) + 10.0 * error * max_abs(&v) * n as f64);
    }

    #[test]
    fn jacobian_columns_are_the_velocities_of_the_point(
        (model, q, v, _a) in chain_and_state(12),
        point in [-0.3..0.3f64, -0.3..0.3f64, -0.3..0.3f64],
    ) {
        let n = model.n_links();
        let link = n - 1;
        let mut data = SpatialData::new(&model);
        let mut j = Mat::zeros(6, n);
        jacobian(&model, &mut data, &q, link, point, j.as_mut()).unwrap();
        let jv: Vec<f64> = (0..6).map(|r| (0..n).map(|k| j[(r, k)] * v[k]).sum()).collect();
        let mut scratch = SpatialData::new(&model);
        let (position, error) = ridders(
            |h| {
                forward_kinematics(&model, &mut scratch, &axpy(&q, h, &v)).unwrap();
                let pose = scratch.link_pose(link).unwrap();
                (0..3)
                    .map(|r| {
                        (0..3).map(|c| pose.rotation[r][c] * point[c]).sum::<f64>()
                            + pose.translation[r]
                    })
                    .collect()
            },
            0.0,
            0.1,
        );
        prop_assert!(difference(&jv[..3], &position) < 1e-7 * (1.0 + max_abs(&position)) + 10.0 * error);
        // Angular velocity: R_dot R^T = [w]x.
        let (r_dot, error) = ridders(
            |h| {
                forward_kinematics(&model, &mut scratch, &axpy(&q, h, &v)).unwrap();
                scratch.link_pose(link).unwrap().rotation.iter().flatten().copied().collect()
            },
            0.0,
            0.1,
        );
        forward_kinematics(&model, &mut scratch, &q).unwrap();
        let r = scratch.link_pose(link).unwrap().rotation;
        let w_hat = |a: usize, b: usize| (0..3).map(|k| r_dot[3 * a + k] * r[b][k]).sum::<f64>();
        let omega = [w_hat(2, 1), w_hat(0, 2), w_hat(1, 0)];
        prop_assert!(difference(&jv[3..], &omega) < 1e-7 * (1.0 + max_abs(&omega)) + 10.0 * error);
    }

    #[test]
    fn batch_gives_every_state_the_bits_it_gets_alone(
        (model, q, v, tau) in chain_and_state(30),
        states in 1..20usize,
    ) {
        let n = model.n_links();
        let spread = |x: &[f64], s: usize| -> Vec<f64> {
            x.iter().map(|x| x * (1.0 + 0.1 * s as f64)).collect()
        };
        let (mut qs, mut vs, mut taus) = (Vec::new(), Vec::new(), Vec::new());
        for s in 0..states {
            qs.extend(spread(&q, s));
            vs.extend(spread(&v, s));
            taus.extend(spread(&tau, s));
        }
        let mut batch = vec![0.0; n * states];
        aba_batch(&model, &mut SpatialBatchData::new(&model), &qs, &vs, &taus, &mut batch).unwrap();
        let mut data = SpatialData::new(&model);
        let mut one = vec![0.0; n];
        for s in 0..states {
            let range = s * n..(s + 1) * n;
            aba(&model, &mut data, &qs[range.clone()], &vs[range.clone()], &taus[range.clone()], &mut one).unwrap();
            let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            prop_assert_eq!(bits(&batch[range]), bits(&one));
        }
    }
}

/// Free motion (no torques) of the universal-joint snake conserves `T + V`: classical RK4 at
/// 0.1 ms for 0.5 s from a bent, moving state.
#[test]
fn free_motion_conserves_energy() {
    let model = snake();
    let n = model.n_links();
    let mut data = SpatialData::new(&model);
    let zero = vec![0.0; n];
    let mut q: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 * 0.7).sin()).collect();
    let mut v: Vec<f64> = (0..n).map(|i| 0.5 * (i as f64 * 1.3).cos()).collect();
    let energy = |q: &[f64], v: &[f64], data: &mut SpatialData| {
        kinetic_energy(&model, data, q, v).unwrap() + potential_energy(&model, data, q).unwrap()
    };
    let start = energy(&q, &v, &mut data);
    let dt = 1e-4;
    let accel = |q: &[f64], v: &[f64], data: &mut SpatialData| {
        let mut a = vec![0.0; n];
        aba(&model, data, q, v, &zero, &mut a).unwrap();
        a
    };
    let mut largest = 0.0f64;
    for _ in 0..5000 {
        let a1 = accel(&q, &v, &mut data);
        let (q2, v2) = (axpy(&q, dt / 2.0, &v), axpy(&v, dt / 2.0, &a1));
        let a2 = accel(&q2, &v2, &mut data);
        let (q3, v3) = (axpy(&q, dt / 2.0, &v2), axpy(&v, dt / 2.0, &a2));
        let a3 = accel(&q3, &v3, &mut data);
        let (q4, v4) = (axpy(&q, dt, &v3), axpy(&v, dt, &a3));
        let a4 = accel(&q4, &v4, &mut data);
        for i in 0..n {
            q[i] += dt / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
            v[i] += dt / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
        }
        largest = largest.max((energy(&q, &v, &mut data) - start).abs());
    }
    assert!(
        largest < 1e-7 * (1.0 + start.abs()),
        "energy drift {largest} J from {start} J"
    );
}

/// A finite but huge gravity, with the efforts that balance it at rest (`tau = G`, so `qdd`
/// is rounding while `d qdd / d q = -M^-1 d G / d q` grows with `g`): every result of the
/// spatial derivatives is finite, or the call says it overflowed (never an infinity or NaN in
/// the matrices). The gravities walk through the range where the entries of the product
/// `-M^-1 d tau / d q` overflow before those of `d tau / d q`.
#[test]
fn spatial_derivatives_report_overflow_not_return_it() {
    let snake = snake();
    let n = snake.n_links();
    let q: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 * 0.7).sin()).collect();
    let v = vec![0.0; n];
    let (mut overflowed, mut finite) = (0, 0);
    for step in 0..=48 {
        let g = 10f64.powf(296.0 + 0.25 * f64::from(step));
        let model = SpatialModel::new(
            snake.joints().to_vec(),
            snake.links().to_vec(),
            [0.0, 0.0, -g],
        )
        .unwrap();
        let mut data = SpatialData::new(&model);
        let mut derivatives = SpatialDerivativeData::new(&model);
        let mut tau = vec![0.0; n];
        if spatial::gravity(&model, &mut data, &q, &mut tau).is_err() {
            continue;
        }
        for forward in [true, false] {
            let result = if forward {
                aba_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau)
            } else {
                rnea_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau)
            };
            match result {
                Ok(()) => {
                    finite += 1;
                    for m in [derivatives.d_q(), derivatives.d_v(), derivatives.d_input()] {
                        for j in 0..n {
                            for i in 0..n {
                                assert!(m[(i, j)].is_finite(), "{g:e}: ({i}, {j})");
                            }
                        }
                    }
                    assert!(derivatives.value().iter().all(|x| x.is_finite()));
                }
                Err(DynError::NonFiniteResult { .. }) => overflowed += 1,
                Err(other) => panic!("{g:e}: {other}"),
            }
        }
    }
    assert!(
        finite > 0 && overflowed > 0,
        "{finite} finite, {overflowed} overflowed"
    );
}

/// Joint-space dynamics do not depend on where the base frame's origin is: the snake with its
/// first joint 10^6 m from the base gives the derivatives of the snake at the base to a few
/// ulps of the entries' scale (the world-frame sums once lost digits as `m |p|^2` cancelled,
/// 3% off `d qdd` at 10^6 m).
#[test]
fn derivatives_do_not_depend_on_the_base_offset() {
    let snake = snake();
    let n = snake.n_links();
    let q: Vec<f64> = (0..n).map(|i| 0.4 * (i as f64 * 0.9).sin()).collect();
    let v: Vec<f64> = (0..n).map(|i| 0.7 * (i as f64 * 1.3).cos()).collect();
    let input: Vec<f64> = (0..n).map(|i| 0.05 * (i as f64 * 0.5).sin()).collect();
    let shifted = |offset: [f64; 3]| {
        let mut joints = snake.joints().to_vec();
        joints[0].origin.translation = offset;
        SpatialModel::new(joints, snake.links().to_vec(), [0.0, 0.0, -9.81]).unwrap()
    };
    let evaluate = |model: &SpatialModel, forward: bool| {
        let mut data = SpatialData::new(model);
        let mut d = SpatialDerivativeData::new(model);
        if forward {
            aba_derivatives(model, &mut data, &mut d, &q, &v, &input).unwrap();
        } else {
            rnea_derivatives(model, &mut data, &mut d, &q, &v, &input).unwrap();
        }
        let flat = |m: faer::MatRef<'_, f64>| -> Vec<f64> {
            (0..n)
                .flat_map(|j| (0..n).map(move |i| m[(i, j)]))
                .collect()
        };
        let mut all = d.value().to_vec();
        for m in [d.d_q(), d.d_v(), d.d_input()] {
            all.extend(flat(m));
        }
        all
    };
    for forward in [true, false] {
        let near = evaluate(&shifted([0.0; 3]), forward);
        let far = evaluate(&shifted([1e6, -3e5, 2e5]), forward);
        let scale = near.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        let error = near
            .iter()
            .zip(&far)
            .fold(0.0_f64, |e, (a, b)| e.max((a - b).abs()));
        assert!(
            error <= 1e-12 * scale,
            "forward {forward}: {error:e} of {scale:e}"
        );
    }
}

/// A prismatic joint's position beyond `MAX_PRISMATIC_POSITION` is refused by every algorithm
/// alike, naming the joint (at `1e160` `rnea` answered while `rnea_derivatives` said "tau is not
/// finite"); revolute angles of any finite size are taken.
#[test]
fn far_prismatic_positions_are_refused_alike() {
    use manip_dyn::spatial::{MAX_PRISMATIC_POSITION, SpatialJoint, SpatialLink, Transform};
    let slide = SpatialJoint::prismatic([0.0, 0.0, 1.0], Transform::translation([0.1, 0.0, 0.0]));
    let turn = SpatialJoint::revolute([0.0, 0.0, 1.0], Transform::translation([0.1, 0.0, 0.0]));
    let link = SpatialLink::cuboid(1.0, [0.1, 0.02, 0.02], [0.05, 0.0, 0.0]);
    let model = SpatialModel::new(vec![turn, slide], vec![link; 2], [0.0, 0.0, -9.81]).unwrap();
    let mut data = SpatialData::new(&model);
    let mut derivatives = SpatialDerivativeData::new(&model);
    let zero = [0.0; 2];
    let mut out = [0.0; 2];
    let at_bound = [1e200, MAX_PRISMATIC_POSITION];
    rnea(&model, &mut data, &at_bound, &zero, &zero, &mut out).unwrap();
    rnea_derivatives(&model, &mut data, &mut derivatives, &at_bound, &zero, &zero).unwrap();
    let far = [0.0, -1e160];
    let expected = "joint 1: position q must be at most 1e9 m in magnitude (a prismatic joint), \
                    got -1e160";
    let errors = [
        rnea(&model, &mut data, &far, &zero, &zero, &mut out).unwrap_err(),
        rnea_derivatives(&model, &mut data, &mut derivatives, &far, &zero, &zero).unwrap_err(),
        aba(&model, &mut data, &far, &zero, &zero, &mut out).unwrap_err(),
        potential_energy(&model, &mut data, &far).unwrap_err(),
    ];
    for error in errors {
        assert!(
            matches!(error, DynError::InvalidJoint { index: 1, .. }),
            "{error:?}"
        );
        assert_eq!(error.to_string(), expected);
    }
}
