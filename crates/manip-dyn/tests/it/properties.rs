//! Property tests of the full chain dynamics over random arms (1-200 links) and states: each
//! algorithm against an independent one, finite differences, or a conservation law.

use crate::common::*;
use faer::Side;
use manip_dyn::{
    ChainData, aba, coriolis, forward_dynamics, gravity, kinetic_energy, nonlinear_effects,
    potential_energy, rnea,
};
use proptest::prelude::*;
use test_support::config::expensive;

proptest! {
    #![proptest_config(ProptestConfig::default())]

    #[test]
    fn mass_matrix_is_symmetric_positive_definite((arm, q, v, _a) in arm_and_state(200)) {
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let n = arm.n_links();
        for i in 0..n {
            for j in 0..n {
                prop_assert_eq!(m[(i, j)], m[(j, i)]);
            }
        }
        prop_assert!(m.llt(Side::Lower).is_ok());
        let vmv: f64 = v.iter().zip(mat_vec(&m, &v)).map(|(a, b)| a * b).sum();
        prop_assert!(vmv >= 0.0);
    }

    #[test]
    fn mass_matrix_columns_are_rnea_differences((arm, q, _v, _a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let zero = vec![0.0; n];
        let mut g = vec![0.0; n];
        rnea(&arm, &mut data, &q, &zero, &zero, &mut g).unwrap();
        let scale = max_abs_mat(&m) + max_abs(&g);
        let mut unit = vec![0.0; n];
        let mut tau = vec![0.0; n];
        for k in 0..n {
            unit[k] = 1.0;
            rnea(&arm, &mut data, &q, &zero, &unit, &mut tau).unwrap();
            unit[k] = 0.0;
            for i in 0..n {
                let column = tau[i] - g[i];
                prop_assert!((column - m[(i, k)]).abs() <= 1e-12 * scale,
                    "M[{i},{k}] = {} but RNEA gives {column}", m[(i, k)]);
            }
        }
    }

    #[test]
    fn rnea_is_m_qdd_plus_c_plus_g((arm, q, v, a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let (mut tau, mut c, mut g, mut nle) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        rnea(&arm, &mut data, &q, &v, &a, &mut tau).unwrap();
        coriolis(&arm, &mut data, &q, &v, &mut c).unwrap();
        gravity(&arm, &mut data, &q, &mut g).unwrap();
        nonlinear_effects(&arm, &mut data, &q, &v, &mut nle).unwrap();
        let ma = mat_vec(&m, &a);
        let scale = max_abs(&ma) + max_abs(&c) + max_abs(&g);
        for i in 0..n {
            prop_assert!((tau[i] - (ma[i] + c[i] + g[i])).abs() <= 1e-12 * scale);
            prop_assert!((nle[i] - (c[i] + g[i])).abs() <= 1e-12 * scale);
        }
    }

    #[test]
    fn aba_matches_cholesky_forward_dynamics((arm, q, v, tau) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let (mut by_aba, mut by_cholesky) = (vec![0.0; n], vec![0.0; n]);
        aba(&arm, &mut data, &q, &v, &tau, &mut by_aba).unwrap();
        forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut by_cholesky).unwrap();
        // Both solve the same (often ill-conditioned) system, so compare to the conditioning and
        // to the rounding of the right-hand side tau - C - G, which can cancel (a torque that
        // nearly balances gravity leaves a small qdd carrying the rounding of the large terms).
        let m = mass(&arm, &mut data, &q);
        let cond = condition_estimate(&m);
        let mut nle = vec![0.0; n];
        nonlinear_effects(&arm, &mut data, &q, &v, &mut nle).unwrap();
        let scale = max_abs(&by_cholesky) + (max_abs(&tau) + max_abs(&nle)) / max_abs_mat(&m);
        for i in 0..n {
            prop_assert!((by_aba[i] - by_cholesky[i]).abs() <= 1e-14 * cond * scale,
                "qdd[{i}]: ABA {} vs Cholesky {} (cond {cond:e})", by_aba[i], by_cholesky[i]);
        }
        // And ABA's answer satisfies eq 12 to rounding: M qdd + C + G = tau.
        let mut tau_back = vec![0.0; n];
        rnea(&arm, &mut data, &q, &v, &by_aba, &mut tau_back).unwrap();
        let residual_scale = max_abs(&tau) + max_abs(&nle) + max_abs_mat(&m) * max_abs(&by_aba);
        for i in 0..n {
            prop_assert!((tau_back[i] - tau[i]).abs() <= 1e-11 * residual_scale);
        }
    }

    #[test]
    fn coriolis_matrix_times_v_is_coriolis_vector((arm, q, v, _a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let c_mat = coriolis_mat(&arm, &mut data, &q, &v);
        let mut c = vec![0.0; n];
        coriolis(&arm, &mut data, &q, &v, &mut c).unwrap();
        let cv = mat_vec(&c_mat, &v);
        let m = mass(&arm, &mut data, &q);
        let scale = max_abs_mat(&c_mat) * max_abs(&v) * n as f64 + max_abs_mat(&m) * total_rate(&v).powi(2);
        for i in 0..n {
            prop_assert!((cv[i] - c[i]).abs() <= 1e-12 * scale, "{} vs {}", cv[i], c[i]);
        }
    }

    #[test]
    fn mass_matrix_rate_minus_twice_coriolis_is_skew((arm, q, v, _a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let c = coriolis_mat(&arm, &mut data, &q, &v);
        // dM/dt along the motion by a central difference along v.
        let h = 1e-5 / (1.0 + total_rate(&v));
        let ahead = mass(&arm, &mut data, &axpy(&q, h, &v));
        let behind = mass(&arm, &mut data, &axpy(&q, -h, &v));
        let m_dot = (&ahead - &behind) * faer::Scale(0.5 / h);
        let scale = max_abs_mat(&m_dot) + max_abs_mat(&c) + max_abs_mat(&ahead) * 1e-3;
        for i in 0..n {
            for j in 0..=i {
                let sym = (m_dot[(i, j)] - 2.0 * c[(i, j)]) + (m_dot[(j, i)] - 2.0 * c[(j, i)]);
                prop_assert!(sym.abs() <= 1e-6 * scale, "({i},{j}): {sym:e} (scale {scale:e})");
            }
        }
    }

    #[test]
    fn matrix_outputs_fill_any_faer_view((arm, q, v, _a) in arm_and_state(100)) {
        // A block of a larger matrix (column stride != n) and a transposed view (row-major).
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let (m, c) = (mass(&arm, &mut data, &q), coriolis_mat(&arm, &mut data, &q, &v));
        let mut big = faer::Mat::<f64>::zeros(n + 3, n + 2);
        manip_dyn::mass_matrix(&arm, &mut data, &q, big.as_mut().submatrix_mut(2, 1, n, n)).unwrap();
        let mut m_transposed = faer::Mat::<f64>::zeros(n, n);
        manip_dyn::mass_matrix(&arm, &mut data, &q, m_transposed.as_mut().transpose_mut()).unwrap();
        prop_assert!(m_transposed == m);
        let mut transposed = faer::Mat::<f64>::zeros(n, n);
        manip_dyn::coriolis_matrix(&arm, &mut data, &q, &v, transposed.as_mut().transpose_mut()).unwrap();
        for i in 0..n {
            for j in 0..n {
                prop_assert_eq!(big[(i + 2, j + 1)], m[(i, j)]);
                prop_assert_eq!(transposed[(j, i)], c[(i, j)]);
            }
        }
        prop_assert!((0..n + 3).all(|i| big[(i, 0)] == 0.0) && (0..n + 2).all(|j| big[(0, j)] == 0.0));
    }

    #[test]
    fn kinetic_energy_is_half_v_m_v((arm, q, v, _a) in arm_and_state(200)) {
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let vmv: f64 = v.iter().zip(mat_vec(&m, &v)).map(|(a, b)| a * b).sum();
        let t = kinetic_energy(&arm, &mut data, &q, &v).unwrap();
        prop_assert!((t - 0.5 * vmv).abs() <= 1e-12 * t.max(1e-300), "T = {t}, v'Mv/2 = {}", 0.5 * vmv);
    }
}

proptest! {
    #![proptest_config(expensive())]

    #[test]
    fn coriolis_matrix_is_built_from_christoffel_symbols((arm, q, v, _a) in arm_and_state(8)) {
        // c_ij = sum_k Gamma_ijk v_k, Gamma_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2,
        // with every dM/dq_k by a central difference.
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let h = 1e-5;
        let mut unit = vec![0.0; n];
        let dm: Vec<_> = (0..n)
            .map(|k| {
                unit[k] = 1.0;
                let d = (&mass(&arm, &mut data, &axpy(&q, h, &unit))
                    - &mass(&arm, &mut data, &axpy(&q, -h, &unit)))
                    * faer::Scale(0.5 / h);
                unit[k] = 0.0;
                d
            })
            .collect();
        let c = coriolis_mat(&arm, &mut data, &q, &v);
        let scale = max_abs_mat(&mass(&arm, &mut data, &q)) * max_abs(&v) * n as f64;
        for i in 0..n {
            for j in 0..n {
                let expected: f64 = (0..n)
                    .map(|k| 0.5 * (dm[k][(i, j)] + dm[j][(i, k)] - dm[i][(j, k)]) * v[k])
                    .sum();
                prop_assert!((c[(i, j)] - expected).abs() <= 1e-7 * scale,
                    "c[{i},{j}] = {} but the Christoffel sum gives {expected}", c[(i, j)]);
            }
        }
    }

    #[test]
    fn mass_matrix_is_the_hessian_of_kinetic_energy((arm, q, _v, _a) in arm_and_state(30)) {
        // T is quadratic in v, so polarisation gives the Hessian exactly: M_ii = 2 T(e_i),
        // M_ij = T(e_i + e_j) - T(e_i) - T(e_j).
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let mut v = vec![0.0; n];
        let mut t = |v: &[f64]| kinetic_energy(&arm, &mut data, &q, v).unwrap();
        let single: Vec<f64> = (0..n)
            .map(|i| {
                let mut e = vec![0.0; n];
                e[i] = 1.0;
                t(&e)
            })
            .collect();
        let scale = max_abs_mat(&m);
        for i in 0..n {
            prop_assert!((2.0 * single[i] - m[(i, i)]).abs() <= 1e-12 * scale);
            for j in 0..i {
                v[i] = 1.0;
                v[j] = 1.0;
                let pair = t(&v);
                v[i] = 0.0;
                v[j] = 0.0;
                prop_assert!((pair - single[i] - single[j] - m[(i, j)]).abs() <= 1e-12 * scale);
            }
        }
    }

    #[test]
    fn gravity_is_the_gradient_of_potential_energy((arm, q, _v, _a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let mut g = vec![0.0; n];
        gravity(&arm, &mut data, &q, &mut g).unwrap();
        let total_mass: f64 = arm.links().iter().map(|l| l.mass).sum();
        let scale = arm.gravity() * total_mass * (arm.total_length() + 1.0);
        let h = 1e-5;
        let mut unit = vec![0.0; n];
        for k in 0..n {
            unit[k] = 1.0;
            let up = potential_energy(&arm, &mut data, &axpy(&q, h, &unit)).unwrap();
            let down = potential_energy(&arm, &mut data, &axpy(&q, -h, &unit)).unwrap();
            unit[k] = 0.0;
            let slope = (up - down) / (2.0 * h);
            prop_assert!((slope - g[k]).abs() <= 1e-8 * scale, "G[{k}] = {} but dV/dq = {slope}", g[k]);
        }
    }

    #[test]
    fn power_balance_along_forward_dynamics((arm, q, v, tau) in arm_and_state(60)) {
        // d(T + V)/dt = v^T tau, the time derivative by a central difference along the motion
        // that ABA predicts: q(t +- h) = q +- h v + h^2/2 qdd, v(t +- h) = v +- h qdd
        // (the neglected terms cancel to O(h^2) in the central difference).
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let mut qdd = vec![0.0; n];
        aba(&arm, &mut data, &q, &v, &tau, &mut qdd).unwrap();
        let h = 1e-4 / (1.0 + total_rate(&v) + max_abs(&qdd).sqrt());
        let mut energy = |sign: f64| {
            let qs: Vec<f64> = (0..n).map(|i| q[i] + sign * h * v[i] + 0.5 * h * h * qdd[i]).collect();
            let vs = axpy(&v, sign * h, &qdd);
            kinetic_energy(&arm, &mut data, &qs, &vs).unwrap() + potential_energy(&arm, &mut data, &qs).unwrap()
        };
        let rate = (energy(1.0) - energy(-1.0)) / (2.0 * h);
        // Rounding in the difference of two energies.
        let energy_scale = energy(0.0).abs() / h * 1e-12;
        let power: f64 = v.iter().zip(&tau).map(|(a, b)| a * b).sum();
        let mut g = vec![0.0; n];
        gravity(&arm, &mut data, &q, &mut g).unwrap();
        // The scale of the individual power flows that must cancel.
        let flows: f64 = v.iter().zip(tau.iter().zip(&g)).map(|(v, (t, g))| v.abs() * (t.abs() + g.abs())).sum();
        prop_assert!((rate - power).abs() <= 1e-6 * flows + energy_scale,
            "d(T+V)/dt = {rate}, v'tau = {power}");
    }
}

/// The largest absolute angular velocity of a link, `max |v_1 + ... + v_i|`.
fn total_rate(v: &[f64]) -> f64 {
    v.iter()
        .scan(0.0, |omega, vi| {
            *omega += vi;
            Some(f64::abs(*omega))
        })
        .fold(0.0, f64::max)
}
