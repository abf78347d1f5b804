//! Hand checks against closed forms: Spong's two-link planar arm, the pendulum, the straight
//! chain at rest, and quantities about the base computed directly from link positions.

use crate::common::*;
use manip_dyn::{
    ChainData, ChainModel, Link, aba, coriolis, forward_dynamics, gravity, kinetic_energy,
    potential_energy, rnea,
};
use proptest::prelude::*;

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale.max(1.0)
}

proptest! {
    /// Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control", the two-link planar arm
    /// (eqs 7.84-7.87 in the 2006 edition): `lc` the distance of each centre of mass from its
    /// joint, `I` the inertia about the centre of mass, `q2` relative.
    #[test]
    fn two_link_arm_matches_spong(
        (l1, l2) in (0.1..2.0f64, 0.1..2.0f64),
        (m1, m2) in (0.1..5.0f64, 0.1..5.0f64),
        (f1, f2) in (-0.2..1.2f64, -0.2..1.2f64),
        (k1, k2) in (0.01..0.3f64, 0.01..0.3f64),
        g in 0.0..20.0f64,
        q in prop::array::uniform2(-3.2..3.2f64),
        v in prop::array::uniform2(-3.0..3.0f64),
        a in prop::array::uniform2(-5.0..5.0f64),
    ) {
        let (lc1, lc2) = (f1 * l1, f2 * l2);
        let (i1, i2) = (k1 * m1 * l1 * l1, k2 * m2 * l2 * l2);
        let arm = ChainModel::new(
            vec![Link::new(l1, m1, lc1, i1).unwrap(), Link::new(l2, m2, lc2, i2).unwrap()],
            g,
        )
        .unwrap();
        let (c2, s1, s12) = (q[1].cos(), q[0].sin(), (q[0] + q[1]).sin());
        let (c1, c12) = (q[0].cos(), (q[0] + q[1]).cos());
        let d11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2) + i1 + i2;
        let d12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
        let d22 = m2 * lc2 * lc2 + i2;
        let h = -m2 * l1 * lc2 * q[1].sin();
        let c_vec = [2.0 * h * v[0] * v[1] + h * v[1] * v[1], -h * v[0] * v[0]];
        let c_mat = [[h * v[1], h * v[1] + h * v[0]], [-h * v[0], 0.0]];
        let g_vec = [
            (m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12,
            m2 * lc2 * g * c12,
        ];
        let potential = m1 * g * lc1 * s1 + m2 * g * (l1 * s1 + lc2 * s12);

        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let scale = d11;
        prop_assert!(close(m[(0, 0)], d11, scale));
        prop_assert!(close(m[(0, 1)], d12, scale) && close(m[(1, 0)], d12, scale));
        prop_assert!(close(m[(1, 1)], d22, scale));

        let c = coriolis_mat(&arm, &mut data, &q, &v);
        let c_scale = h.abs() * 9.0 + 1e-300;
        for i in 0..2 {
            for j in 0..2 {
                prop_assert!(close(c[(i, j)], c_mat[i][j], c_scale), "C[{i},{j}] = {} vs {}", c[(i, j)], c_mat[i][j]);
            }
        }
        let mut out = [0.0; 2];
        coriolis(&arm, &mut data, &q, &v, &mut out).unwrap();
        prop_assert!(close(out[0], c_vec[0], c_scale) && close(out[1], c_vec[1], c_scale));
        gravity(&arm, &mut data, &q, &mut out).unwrap();
        let g_scale = (m1 + m2) * g * (l1 + l2) * 2.0;
        prop_assert!(close(out[0], g_vec[0], g_scale) && close(out[1], g_vec[1], g_scale));
        let v_pot = potential_energy(&arm, &mut data, &q).unwrap();
        prop_assert!(close(v_pot, potential, g_scale));

        // tau = M a + C + G, and forward dynamics inverts it.
        let tau = [
            d11 * a[0] + d12 * a[1] + c_vec[0] + g_vec[0],
            d12 * a[0] + d22 * a[1] + c_vec[1] + g_vec[1],
        ];
        let tau_scale = scale * 10.0 + c_scale * 9.0 + g_scale;
        rnea(&arm, &mut data, &q, &v, &a, &mut out).unwrap();
        prop_assert!(close(out[0], tau[0], tau_scale) && close(out[1], tau[1], tau_scale));
        let t = kinetic_energy(&arm, &mut data, &q, &v).unwrap();
        let t_closed = 0.5 * (d11 * v[0] * v[0] + 2.0 * d12 * v[0] * v[1] + d22 * v[1] * v[1]);
        prop_assert!(close(t, t_closed, scale * 9.0));
        let det = d11 * d22 - d12 * d12;
        let qdd = [
            (d22 * (tau[0] - c_vec[0] - g_vec[0]) - d12 * (tau[1] - c_vec[1] - g_vec[1])) / det,
            (d11 * (tau[1] - c_vec[1] - g_vec[1]) - d12 * (tau[0] - c_vec[0] - g_vec[0])) / det,
        ];
        aba(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
        prop_assert!((out[0] - a[0]).abs() < 1e-8 && (out[1] - a[1]).abs() < 1e-8, "{out:?} vs {a:?}");
        prop_assert!((qdd[0] - a[0]).abs() < 1e-8 && (qdd[1] - a[1]).abs() < 1e-8);
        forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
        prop_assert!((out[0] - a[0]).abs() < 1e-8 && (out[1] - a[1]).abs() < 1e-8);
    }

    /// A compound pendulum: `(I + m c^2) qdd = tau - m g c cos q`, no velocity terms.
    #[test]
    fn pendulum(link in link(), g in 0.0..20.0f64, q in -3.2..3.2f64, v in -5.0..5.0f64, tau in -5.0..5.0f64) {
        let arm = ChainModel::new(vec![link], g).unwrap();
        let mut data = ChainData::new(&arm);
        let pivot_inertia = link.inertia + link.mass * link.com * link.com;
        let weight_moment = link.mass * g * link.com * q.cos();
        let mut qdd = [0.0];
        aba(&arm, &mut data, &[q], &[v], &[tau], &mut qdd).unwrap();
        let expected = (tau - weight_moment) / pivot_inertia;
        prop_assert!((qdd[0] - expected).abs() <= 1e-12 * expected.abs().max(1.0));
        let mut c = [1.0];
        coriolis(&arm, &mut data, &[q], &[v], &mut c).unwrap();
        prop_assert!(c[0].abs() <= 1e-15 * (link.mass * link.com.abs() * link.length * v * v).max(1e-300));
        let t = kinetic_energy(&arm, &mut data, &[q], &[v]).unwrap();
        prop_assert!((t - 0.5 * pivot_inertia * v * v).abs() <= 1e-12 * t.max(1e-300));
    }

    /// Quantities about the base joint from link positions computed here: `M_00` is the polar
    /// moment of the whole arm about the base, `G_0` the moment of its weight, and the last
    /// joint moves only the last link.
    #[test]
    fn base_and_tip_entries_from_link_positions((arm, q, _v, _a) in arm_and_state(200)) {
        let n = arm.n_links();
        let mut data = ChainData::new(&arm);
        let m = mass(&arm, &mut data, &q);
        let com = com_positions(&arm, &q);
        let polar: f64 = arm.links().iter().zip(&com)
            .map(|(l, r)| l.inertia + l.mass * (r[0] * r[0] + r[1] * r[1]))
            .sum();
        prop_assert!((m[(0, 0)] - polar).abs() <= 1e-12 * polar);
        let last = arm.links()[n - 1];
        let tip = last.inertia + last.mass * last.com * last.com;
        prop_assert!((m[(n - 1, n - 1)] - tip).abs() <= 1e-12 * tip);
        let mut g = vec![0.0; n];
        gravity(&arm, &mut data, &q, &mut g).unwrap();
        let weight_moment: f64 = arm.links().iter().zip(&com).map(|(l, r)| l.mass * arm.gravity() * r[0]).sum();
        let total_mass: f64 = arm.links().iter().map(|l| l.mass).sum();
        let scale = arm.gravity() * total_mass * arm.total_length();
        prop_assert!((g[0] - weight_moment).abs() <= 1e-12 * scale);
    }
}

/// The straight horizontal chain of `n` uniform links at rest: joint `i` (0-based) carries the
/// `n - i` links beyond it, whose weights act at `(j + 1/2) L` from it, so
/// `G_i = m g L (n - i)^2 / 2`.
#[test]
fn straight_uniform_chain_holds_its_weight() {
    for n in [1, 2, 3, 10, 100] {
        let (length, link_mass, g) = (0.1, 0.1, 9.81);
        let arm = ChainModel::uniform(n, length, link_mass, g).unwrap();
        let mut data = ChainData::new(&arm);
        let mut tau = vec![0.0; n];
        gravity(&arm, &mut data, &vec![0.0; n], &mut tau).unwrap();
        for (i, t) in tau.iter().enumerate() {
            let expected = link_mass * g * length * ((n - i) as f64).powi(2) / 2.0;
            assert!(
                (t - expected).abs() <= 1e-12 * expected,
                "n = {n}, joint {i}: {t} vs {expected}"
            );
        }
        // Folded straight up (first joint at pi/2), gravity loads no joint.
        let mut up = vec![0.0; n];
        up[0] = std::f64::consts::FRAC_PI_2;
        gravity(&arm, &mut data, &up, &mut tau).unwrap();
        assert!(
            tau.iter()
                .all(|t| t.abs() <= 1e-12 * link_mass * g * length * (n * n) as f64)
        );
    }
}
