//! Spatial modal arms: the reduced terms against the Newton-Euler joint torques (`J^T tau`),
//! the projection path (`J^T M J` on the chain's CRBA), the planar reduced model in the plane, the Lagrangian (kinetic energy from the chain's own
//! motion, the potential's gradient, `C*` from `M*`'s derivatives), energy conservation of free
//! motion, and bad input.

use backbone_kin::vec3::{Rotation, dot, mat_mul, mat_vec};
use backbone_kin::{BaseAngle, BasePose, ModalMap, SpatialModalMap, spatial_joint_positions};
use manip_dyn::ChainModel;
use modal_reduce::spatial::{
    SpatialLinkInertia, SpatialProjection, SpatialReducedData, SpatialReducedModel,
    spatial_forward_dynamics, spatial_joint_torques, spatial_reduced_terms,
    spatial_reduced_terms_by_projection,
};
use modal_reduce::{ReduceError, ReducedData, ReducedModel, reduced_terms};
use proptest::prelude::*;

/// A random arm: `n` links of random lengths and inertias, `K` harmonics, a random base pose
/// and gravity.
pub(crate) fn arm(n: usize, k: usize, seed: u64) -> SpatialReducedModel {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let lengths: Vec<f64> = (0..n).map(|_| 0.05 + 0.1 * next()).collect();
    let links = (0..n)
        .map(|_| {
            // Second moments of the mass along each axis, so that the principal moments obey
            // the triangle inequalities.
            let (x, y, z) = (0.01 * next(), 0.001 * next(), 0.001 * next());
            SpatialLinkInertia {
                mass: 0.05 + next(),
                principal: [y + z, x + z, x + y],
            }
        })
        .collect();
    let base = BasePose {
        xyz: [next() - 0.5, next() - 0.5, next()],
        rpy: [3.0 * next(), 3.0 * next(), 3.0 * next()],
    };
    let gravity = [next() - 0.5, next() - 0.5, -9.81];
    SpatialReducedModel::new(
        SpatialModalMap::new(&lengths, k).unwrap(),
        base,
        links,
        gravity,
    )
    .unwrap()
}

pub(crate) fn state(m: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let f = |j: usize, s: f64| ((seed as f64 + 1.0) * (j as f64 + 0.37) * s).sin();
    (
        (0..m).map(|j| 0.8 * f(j, 1.3)).collect(),
        (0..m).map(|j| 1.5 * f(j, 2.1)).collect(),
        (0..m).map(|j| 2.0 * f(j, 0.7)).collect(),
    )
}

fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * scale.max(1.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// The default `O(n m^2)` path equals the projection of the chain's CRBA mass matrix and
    /// Newton-Euler efforts (`J^T M J`, `J^T C`, `J^T G`, formed with faer) to 1e-12 relative.
    #[test]
    fn reduced_terms_equal_the_projection_of_the_full_chain(
        n in 1usize..40, k in 1usize..4, seed in 0u64..1000,
    ) {
        let model = arm(n.max(2 * k), k, seed);
        let m = model.n_coords();
        let (a, a_dot, _) = state(m, seed);
        let mut fast = SpatialReducedData::new(&model);
        spatial_reduced_terms(&model, &mut fast, &a, &a_dot).unwrap();
        let mut projected = SpatialReducedData::new(&model);
        let mut projection = SpatialProjection::new(&model).unwrap();
        prop_assert_eq!(projection.chain().n_links(), 2 * model.n_links());
        spatial_reduced_terms_by_projection(&mut projection, &mut projected, &a, &a_dot).unwrap();
        for (what, x, y) in [
            ("M*", fast.mass_matrix(), projected.mass_matrix()),
            ("C*", fast.coriolis(), projected.coriolis()),
            ("G*", fast.gravity(), projected.gravity()),
        ] {
            let scale = y.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                prop_assert!((p - q).abs() <= 1e-12 * scale, "{}[{}]: {} vs {}", what, i, p, q);
            }
        }
    }

    /// `M* a_dd + C* + G* = J^T tau` with `tau` from the Newton-Euler recursion: two algorithms.
    #[test]
    fn reduced_terms_equal_the_projected_newton_euler_torques(
        n in 1usize..25, k in 1usize..3, seed in 0u64..1000,
    ) {
        let model = arm(n.max(2 * k), k, seed);
        let n = model.n_links();
        let m = model.n_coords();
        let mut data = SpatialReducedData::new(&model);
        let (a, a_dot, a_ddot) = state(m, seed);
        spatial_reduced_terms(&model, &mut data, &a, &a_dot).unwrap();
        let mut tau = vec![0.0; 2 * n];
        spatial_joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau).unwrap();
        let map = model.map();
        let scale = tau.iter().map(|t| t.abs()).fold(0.0, f64::max);
        for c in 0..m {
            let projected: f64 = (0..2 * n).map(|j| map.row(j)[c] * tau[j]).sum();
            let lhs: f64 = (0..m).map(|l| data.mass_matrix()[c * m + l] * a_ddot[l]).sum::<f64>()
                + data.coriolis()[c] + data.gravity()[c];
            prop_assert!(close(lhs, projected, scale, 1e-12), "{} vs {}", lhs, projected);
        }
        // M* is symmetric positive definite: forward dynamics inverts it.
        let tau_star: Vec<f64> = (0..m).map(|c| {
            (0..m).map(|l| data.mass_matrix()[c * m + l] * a_ddot[l]).sum::<f64>()
                + data.coriolis()[c] + data.gravity()[c]
        }).collect();
        let mut back = vec![0.0; m];
        spatial_forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut back).unwrap();
        for (x, y) in back.iter().zip(&a_ddot) {
            prop_assert!((x - y).abs() < 1e-8 * y.abs().max(1.0), "{:?} vs {:?}", back, a_ddot);
        }
    }
}

#[test]
fn in_the_plane_the_spatial_arm_is_the_planar_reduced_model() {
    let (n, length, mass, g) = (10, 0.1, 0.1, 9.81);
    for k in [1, 2] {
        let spatial =
            SpatialReducedModel::uniform_rods(n, k, length, mass, [0.0, -g, 0.0]).unwrap();
        let planar = ReducedModel::new(
            ChainModel::uniform(n, length, mass, g).unwrap(),
            ModalMap::uniform(n, k, BaseAngle::Fixed(0.0)).unwrap(),
        )
        .unwrap();
        let (m, k2) = (4 * k, 2 * k);
        let (a_z, a_dot_z, _) = state(k2, 7);
        let a = [a_z.clone(), vec![0.0; k2]].concat();
        let a_dot = [a_dot_z.clone(), vec![0.0; k2]].concat();
        let mut data = SpatialReducedData::new(&spatial);
        spatial_reduced_terms(&spatial, &mut data, &a, &a_dot).unwrap();
        let mut planar_data = ReducedData::new(&planar);
        reduced_terms(&planar, &mut planar_data, &a_z, &a_dot_z).unwrap();
        let pm = planar_data.mass_matrix();
        for r in 0..k2 {
            for c in 0..k2 {
                let (s, p) = (data.mass_matrix()[r * m + c], pm[(r, c)]);
                assert!(
                    (s - p).abs() < 1e-12 * p.abs().max(1.0),
                    "M*[{r}][{c}] {s} vs {p}"
                );
            }
            let (sc, pc) = (data.coriolis()[r], planar_data.coriolis()[r]);
            let (sg, pg) = (data.gravity()[r], planar_data.gravity()[r]);
            assert!(
                (sc - pc).abs() < 1e-12 * pc.abs().max(1.0),
                "C*[{r}] {sc} vs {pc}"
            );
            assert!(
                (sg - pg).abs() < 1e-12 * pg.abs().max(1.0),
                "G*[{r}] {sg} vs {pg}"
            );
            // No in-plane motion couples to the out-of-plane coordinates' gravity.
            assert!(data.gravity()[k2 + r].abs() < 1e-12);
        }
    }
}

/// The chain's centres of mass and link rotations at `a`, from backbone-kin's forward
/// kinematics (independent of the recursion under test).
fn com_and_rotations(model: &SpatialReducedModel, a: &[f64]) -> (Vec<[f64; 3]>, Vec<Rotation>) {
    let map = model.map();
    let n = map.n_links();
    let mut theta = vec![0.0; 2 * n];
    map.joint_angles(a, &mut theta).unwrap();
    let mut points = vec![[0.0; 3]; n + 1];
    spatial_joint_positions(map.link_lengths(), model.base(), &theta, &mut points).unwrap();
    let coms = (0..n)
        .map(|i| std::array::from_fn(|d| 0.5 * (points[i][d] + points[i + 1][d])))
        .collect();
    let mut r = model.base().rotation();
    let rotations = theta
        .chunks_exact(2)
        .map(|pair| {
            r = mat_mul(
                mat_mul(r, backbone_kin::vec3::rot_z(pair[0])),
                backbone_kin::vec3::rot_y(pair[1]),
            );
            r
        })
        .collect();
    (coms, rotations)
}

#[test]
fn the_lagrangian_gives_the_same_terms() {
    let model = arm(7, 1, 42);
    let m = model.n_coords();
    let (a, a_dot, _) = state(m, 3);
    let mut data = SpatialReducedData::new(&model);
    spatial_reduced_terms(&model, &mut data, &a, &a_dot).unwrap();
    let h = 1e-6;
    let shifted =
        |s: f64, dir: &[f64]| -> Vec<f64> { a.iter().zip(dir).map(|(x, d)| x + s * d).collect() };
    // Kinetic energy from the chain's own motion: centre-of-mass velocities and angular
    // velocities by central differences along a_dot.
    let (plus, minus) = (
        com_and_rotations(&model, &shifted(h, &a_dot)),
        com_and_rotations(&model, &shifted(-h, &a_dot)),
    );
    let (_, here) = com_and_rotations(&model, &a);
    let mut kinetic = 0.0;
    for (i, link) in model.links().iter().enumerate() {
        let v = std::array::from_fn(|d| (plus.0[i][d] - minus.0[i][d]) / (2.0 * h));
        // [w]x = R_dot R^T.
        let r_dot: Rotation = std::array::from_fn(|p| {
            std::array::from_fn(|q| (plus.1[i][p][q] - minus.1[i][p][q]) / (2.0 * h))
        });
        let rt: Rotation = std::array::from_fn(|p| std::array::from_fn(|q| here[i][q][p]));
        let wx = mat_mul(r_dot, rt);
        let w = [wx[2][1], wx[0][2], wx[1][0]];
        let body = mat_vec(&rt, w);
        let spin: f64 = (0..3).map(|d| link.principal[d] * body[d] * body[d]).sum();
        kinetic += 0.5 * (link.mass * dot(v, v) + spin);
    }
    let quadratic: f64 = (0..m)
        .map(|r| {
            (0..m)
                .map(|c| a_dot[r] * data.mass_matrix()[r * m + c] * a_dot[c])
                .sum::<f64>()
        })
        .sum();
    assert!(
        (0.5 * quadratic - kinetic).abs() < 1e-7 * kinetic,
        "{} vs {}",
        0.5 * quadratic,
        kinetic
    );
    // G* is the gradient of the potential -sum m g . c.
    let g = model.gravity();
    let potential = |x: &[f64]| -> f64 {
        let (coms, _) = com_and_rotations(&model, x);
        coms.iter()
            .zip(model.links())
            .map(|(c, l)| -l.mass * dot(g, *c))
            .sum()
    };
    for j in 0..m {
        let mut e = vec![0.0; m];
        e[j] = 1.0;
        let fd = (potential(&shifted(h, &e)) - potential(&shifted(-h, &e))) / (2.0 * h);
        assert!(
            (fd - data.gravity()[j]).abs() < 1e-6 * fd.abs().max(1.0),
            "G*[{j}] {} vs {fd}",
            data.gravity()[j]
        );
    }
    // C* = M*_dot a_dot - (1/2) grad_a (a_dot^T M* a_dot), by central differences of M*.
    let mass_at = |x: &[f64]| -> Vec<f64> {
        let mut d = SpatialReducedData::new(&model);
        spatial_reduced_terms(&model, &mut d, x, &a_dot).unwrap();
        d.mass_matrix().to_vec()
    };
    let (mp, mm) = (mass_at(&shifted(h, &a_dot)), mass_at(&shifted(-h, &a_dot)));
    for r in 0..m {
        let m_dot_a_dot: f64 = (0..m)
            .map(|c| (mp[r * m + c] - mm[r * m + c]) / (2.0 * h) * a_dot[c])
            .sum();
        let mut e = vec![0.0; m];
        e[r] = 1.0;
        let (qp, qm) = (mass_at(&shifted(h, &e)), mass_at(&shifted(-h, &e)));
        let form = |mat: &[f64]| -> f64 {
            (0..m)
                .map(|p| {
                    (0..m)
                        .map(|q| a_dot[p] * mat[p * m + q] * a_dot[q])
                        .sum::<f64>()
                })
                .sum()
        };
        let expected = m_dot_a_dot - 0.5 * (form(&qp) - form(&qm)) / (2.0 * h);
        assert!(
            (expected - data.coriolis()[r]).abs() < 1e-6 * expected.abs().max(1.0),
            "C*[{r}] {} vs {expected}",
            data.coriolis()[r]
        );
    }
}

/// The relative change of the energy `T + V` of free motion (`tau* = 0`) of a 10-link arm over
/// `steps` RK4 steps of `dt`, from a moving state.
fn energy_drift(dt: f64, steps: usize) -> f64 {
    let model = arm(10, 1, 5);
    let m = model.n_coords();
    let mut data = SpatialReducedData::new(&model);
    let (mut a, mut a_dot, _) = state(m, 11);
    let energy = |data: &mut SpatialReducedData, a: &[f64], a_dot: &[f64]| -> f64 {
        spatial_reduced_terms(&model, data, a, a_dot).unwrap();
        let t: f64 = (0..m)
            .map(|r| {
                (0..m)
                    .map(|c| a_dot[r] * data.mass_matrix()[r * m + c] * a_dot[c])
                    .sum::<f64>()
            })
            .sum();
        let (coms, _) = com_and_rotations(&model, a);
        let v: f64 = coms
            .iter()
            .zip(model.links())
            .map(|(c, l)| -l.mass * dot(model.gravity(), *c))
            .sum();
        0.5 * t + v
    };
    let start = energy(&mut data, &a, &a_dot);
    let zero = vec![0.0; m];
    let accel = |data: &mut SpatialReducedData, a: &[f64], v: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; m];
        spatial_forward_dynamics(&model, data, a, v, &zero, &mut out).unwrap();
        out
    };
    let axpy = |x: &[f64], s: f64, d: &[f64]| -> Vec<f64> {
        x.iter().zip(d).map(|(p, q)| p + s * q).collect()
    };
    for _ in 0..steps {
        let k1 = (a_dot.clone(), accel(&mut data, &a, &a_dot));
        let (a2, v2) = (axpy(&a, 0.5 * dt, &k1.0), axpy(&a_dot, 0.5 * dt, &k1.1));
        let k2 = (v2.clone(), accel(&mut data, &a2, &v2));
        let (a3, v3) = (axpy(&a, 0.5 * dt, &k2.0), axpy(&a_dot, 0.5 * dt, &k2.1));
        let k3 = (v3.clone(), accel(&mut data, &a3, &v3));
        let (a4, v4) = (axpy(&a, dt, &k3.0), axpy(&a_dot, dt, &k3.1));
        let k4 = (v4.clone(), accel(&mut data, &a4, &v4));
        for j in 0..m {
            a[j] += dt / 6.0 * (k1.0[j] + 2.0 * k2.0[j] + 2.0 * k3.0[j] + k4.0[j]);
            a_dot[j] += dt / 6.0 * (k1.1[j] + 2.0 * k2.1[j] + 2.0 * k3.1[j] + k4.1[j]);
        }
    }
    let end = energy(&mut data, &a, &a_dot);
    (end - start).abs() / start.abs().max(1.0)
}

#[test]
fn free_motion_conserves_energy() {
    let drift = energy_drift(1e-4, 2000);
    assert!(drift < 1e-8, "energy drift {drift:e}");
}

/// The energy error of RK4 shrinks as `dt^4` (to the integrator's order): halving the step over
/// the same 0.4 s divides it by about 16 (at least 10 here).
#[test]
fn free_motion_energy_error_has_the_integrators_order() {
    let coarse = energy_drift(4e-3, 100);
    let fine = energy_drift(2e-3, 200);
    assert!(
        coarse > 1e3 * f64::EPSILON && coarse / fine > 10.0 && coarse / fine < 40.0,
        "drift {coarse:e} at 4 ms, {fine:e} at 2 ms: ratio {}",
        coarse / fine
    );
}

#[test]
fn spatial_arms_refuse_bad_input() {
    let map = SpatialModalMap::uniform(3, 1).unwrap();
    let rod = SpatialLinkInertia::rod(0.1, 1.0);
    let base = BasePose::default();
    let g = [0.0, 0.0, -9.81];
    // More links than a map holds is refused, not cut to the limit.
    let message = SpatialReducedModel::uniform_rods(usize::MAX, 1, 0.1, 0.1, g)
        .unwrap_err()
        .to_string();
    assert!(message.contains("links"), "{message}");
    assert!(matches!(
        SpatialReducedModel::new(map.clone(), base, vec![rod; 2], g),
        Err(ReduceError::Dimension {
            name: "link inertias",
            expected: 3,
            found: 2
        })
    ));
    let broken = SpatialLinkInertia {
        mass: 1.0,
        principal: [1.0, 0.2, 0.3],
    };
    let err = SpatialReducedModel::new(map.clone(), base, vec![rod, broken, rod], g).unwrap_err();
    assert!(
        err.to_string().contains("link 1") && err.to_string().contains("triangle"),
        "{err}"
    );
    let negative = SpatialLinkInertia { mass: -1.0, ..rod };
    assert!(SpatialReducedModel::new(map.clone(), base, vec![negative; 3], g).is_err());
    assert!(matches!(
        SpatialReducedModel::new(map.clone(), base, vec![rod; 3], [0.0, f64::NAN, 0.0]),
        Err(ReduceError::NonFinite {
            name: "gravity",
            index: Some(1),
            ..
        })
    ));
    assert!(matches!(
        SpatialReducedModel::uniform_rods(3, 2, 0.1, 0.1, g),
        Err(ReduceError::RankDeficient { .. })
    ));
    let model = SpatialReducedModel::new(map, base, vec![rod; 3], g).unwrap();
    let mut data = SpatialReducedData::new(&model);
    assert!(matches!(
        spatial_reduced_terms(&model, &mut data, &[0.0; 3], &[0.0; 4]),
        Err(ReduceError::Dimension { name: "a", .. })
    ));
    assert!(matches!(
        spatial_reduced_terms(
            &model,
            &mut data,
            &[0.0; 4],
            &[0.0, f64::INFINITY, 0.0, 0.0]
        ),
        Err(ReduceError::NonFinite {
            name: "a_dot",
            index: Some(1),
            ..
        })
    ));
    let other = SpatialReducedModel::uniform_rods(4, 1, 0.1, 0.1, g).unwrap();
    assert!(matches!(
        spatial_reduced_terms(&other, &mut data, &[0.0; 4], &[0.0; 4]),
        Err(ReduceError::Dimension {
            name: "workspace links",
            ..
        })
    ));
    let mut tau = [0.0; 5];
    assert!(matches!(
        spatial_joint_torques(&model, &mut data, &[0.0; 4], &[0.0; 4], &[0.0; 4], &mut tau),
        Err(ReduceError::Dimension {
            name: "joint torques",
            ..
        })
    ));
    assert!(matches!(
        spatial_reduced_terms(&model, &mut data, &[1e300; 4], &[1e300; 4]),
        Err(ReduceError::NonFiniteResult { .. })
    ));
}

/// The forward dynamics and the terms test their inputs' values only through their results
/// (one test of the results, then the inputs named only when it fails): every NaN or infinity
/// in any entry of `a`, `a_dot` or `tau_star` is still reported by the input's name and index,
/// for `m = 4`, `8` (the sizes with their own code) and `12`, `a_ddot` is left as it was, and a
/// workspace that saw one gives the same bits on the next good call.
#[test]
fn a_non_finite_input_is_named_though_the_results_are_tested() {
    for (k, n) in [(1, 10), (2, 11), (3, 13)] {
        let model = arm(n, k, 7);
        let m = model.n_coords();
        let mut data = SpatialReducedData::new(&model);
        let (a, a_dot, tau_star) = state(m, 3);
        let mut good = vec![0.0; m];
        spatial_forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut good).unwrap();
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for (input, name) in [(0, "a"), (1, "a_dot"), (2, "tau_star")] {
                for index in 0..m {
                    let mut inputs = [a.clone(), a_dot.clone(), tau_star.clone()];
                    inputs[input][index] = bad;
                    let [x, v, t] = &inputs;
                    let mut out = vec![0.0; m];
                    let err =
                        spatial_forward_dynamics(&model, &mut data, x, v, t, &mut out).unwrap_err();
                    assert!(
                        matches!(err, ReduceError::NonFinite { name: found, index: Some(i), .. }
                            if found == name && i == index),
                        "m = {m}, {name}[{index}] = {bad}: {err}"
                    );
                    if input < 2 {
                        let err = spatial_reduced_terms(&model, &mut data, x, v).unwrap_err();
                        assert!(
                            matches!(err, ReduceError::NonFinite { name: found, index: Some(i), .. }
                                if found == name && i == index),
                            "terms, m = {m}, {name}[{index}] = {bad}: {err}"
                        );
                    }
                }
            }
        }
        // Finite inputs too large for double precision: a result that is not finite, named.
        let huge = vec![1e300; m];
        let mut out = vec![0.0; m];
        assert!(matches!(
            spatial_forward_dynamics(&model, &mut data, &huge, &huge, &tau_star, &mut out),
            Err(ReduceError::NonFiniteResult { .. })
        ));
        // A buffer for `a_ddot` holding NaN is only written to.
        let mut again = vec![f64::NAN; m];
        spatial_forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut again).unwrap();
        assert_eq!(
            again.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            good.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}
