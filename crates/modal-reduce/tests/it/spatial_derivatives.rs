//! The analytic derivatives of the spatial reduced forward dynamics against central finite
//! differences of `spatial_forward_dynamics`, the quadratic homogeneity of `C*` in the rates
//! (`D_v a_dot = 2 C*`), `d a_ddot / d tau* = M*^-1`, and the planar model's own derivatives
//! in the plane.

use crate::spatial::{arm, state};
use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;
use modal_reduce::spatial::{
    SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel, spatial_forward_dynamics,
    spatial_reduced_derivatives,
};
use modal_reduce::{ReducedData, ReducedDerivatives, ReducedModel, reduced_derivatives};
use proptest::prelude::*;

fn forward(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
) -> Vec<f64> {
    let mut out = vec![0.0; model.n_coords()];
    spatial_forward_dynamics(model, data, a, a_dot, tau_star, &mut out).unwrap();
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Every column of `d a_ddot / d a` and `d a_ddot / d a_dot` against a central difference.
    #[test]
    fn derivatives_match_finite_differences(
        n in 1usize..16, k in 1usize..3, seed in 0u64..1000,
    ) {
        let model = arm(n.max(2 * k), k, seed);
        let m = model.n_coords();
        let (a, a_dot, tau_star) = state(m, seed + 1);
        let mut data = SpatialReducedData::new(&model);
        let mut derivatives = SpatialReducedDerivatives::new(&model);
        spatial_reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star)
            .unwrap();
        let nominal = forward(&model, &mut data, &a, &a_dot, &tau_star);
        prop_assert_eq!(derivatives.a_ddot(), &nominal[..]);
        let h = 1e-6;
        for (block, on_rates) in [(derivatives.d_a(), false), (derivatives.d_a_dot(), true)] {
            for j in 0..m {
                let shifted = |s: f64| {
                    let mut x = if on_rates { a_dot.clone() } else { a.clone() };
                    x[j] += s;
                    x
                };
                let (plus, minus) = if on_rates {
                    (
                        forward(&model, &mut data, &a, &shifted(h), &tau_star),
                        forward(&model, &mut data, &a, &shifted(-h), &tau_star),
                    )
                } else {
                    (
                        forward(&model, &mut data, &shifted(h), &a_dot, &tau_star),
                        forward(&model, &mut data, &shifted(-h), &a_dot, &tau_star),
                    )
                };
                let scale = nominal.iter().fold(1.0f64, |s, x| s.max(x.abs()));
                for i in 0..m {
                    let fd = (plus[i] - minus[i]) / (2.0 * h);
                    prop_assert!(
                        (block[(i, j)] - fd).abs() <= 1e-5 * scale.max(fd.abs()),
                        "{} ({i}, {j}): {} vs {fd}", if on_rates { "d_a_dot" } else { "d_a" },
                        block[(i, j)]
                    );
                }
            }
        }
    }

    /// `C*` is quadratic in the rates, so `D_v a_dot = 2 C*`: `d_a_dot a_dot = -2 M*^-1 C*`;
    /// and `d_tau_star M* = 1`.
    #[test]
    fn rate_derivative_is_twice_the_coriolis_vector(
        n in 2usize..30, k in 1usize..3, seed in 0u64..1000,
    ) {
        let model = arm(n.max(2 * k), k, seed);
        let m = model.n_coords();
        let (a, a_dot, tau_star) = state(m, seed + 2);
        let mut data = SpatialReducedData::new(&model);
        let mut derivatives = SpatialReducedDerivatives::new(&model);
        spatial_reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star)
            .unwrap();
        let (dv, inverse) = (derivatives.d_a_dot(), derivatives.d_tau_star());
        let coriolis = data.coriolis();
        let size = coriolis.iter().fold(1.0f64, |s, x| s.max(x.abs()));
        for i in 0..m {
            let left: f64 = (0..m).map(|j| dv[(i, j)] * a_dot[j]).sum();
            let right: f64 = (0..m).map(|j| -2.0 * inverse[(i, j)] * coriolis[j]).sum();
            let bound = (0..m).map(|j| inverse[(i, j)].abs()).sum::<f64>() * size;
            prop_assert!((left - right).abs() <= 1e-10 * bound.max(1.0), "{i}: {left} vs {right}");
            for j in 0..m {
                let product: f64 = (0..m).map(|l| inverse[(i, l)] * data.mass_matrix()[l * m + j]).sum();
                let identity = if i == j { 1.0 } else { 0.0 };
                prop_assert!((product - identity).abs() < 1e-9, "({i}, {j}): {product}");
            }
        }
    }
}

/// In the plane (`a_y = 0`, base the identity, gravity along `-y`) the in-plane block of the
/// derivatives is the planar reduced model's, and the out-of-plane coordinates stay decoupled.
#[test]
fn in_the_plane_the_derivatives_are_the_planar_ones() {
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
        let (a_z, a_dot_z, tau_z) = state(k2, 5);
        let pad = |x: &[f64]| [x.to_vec(), vec![0.0; k2]].concat();
        let mut data = SpatialReducedData::new(&spatial);
        let mut derivatives = SpatialReducedDerivatives::new(&spatial);
        spatial_reduced_derivatives(
            &spatial,
            &mut data,
            &mut derivatives,
            &pad(&a_z),
            &pad(&a_dot_z),
            &pad(&tau_z),
        )
        .unwrap();
        let mut planar_data = ReducedData::new(&planar);
        let mut planar_derivatives = ReducedDerivatives::new(&planar);
        reduced_derivatives(
            &planar,
            &mut planar_data,
            &mut planar_derivatives,
            &a_z,
            &a_dot_z,
            &tau_z,
        )
        .unwrap();
        for (s, p) in [
            (derivatives.d_a(), planar_derivatives.d_a()),
            (derivatives.d_a_dot(), planar_derivatives.d_a_dot()),
            (derivatives.d_tau_star(), planar_derivatives.d_tau_star()),
        ] {
            for i in 0..m {
                for j in 0..m {
                    let expected = if i < k2 && j < k2 {
                        p[(i, j)]
                    } else {
                        s[(i, j)]
                    };
                    assert!(
                        (s[(i, j)] - expected).abs() < 1e-10 * expected.abs().max(1.0),
                        "({i}, {j}): {} vs {expected}",
                        s[(i, j)]
                    );
                    if (i < k2) != (j < k2) {
                        assert!(s[(i, j)].abs() < 1e-10, "coupling ({i}, {j}) {}", s[(i, j)]);
                    }
                }
            }
        }
    }
}

#[test]
fn a_workspace_of_another_arm_is_refused() {
    let (small, large) = (arm(3, 1, 1), arm(4, 1, 1));
    let mut data = SpatialReducedData::new(&small);
    let mut derivatives = SpatialReducedDerivatives::new(&large);
    let x = vec![0.0; 4];
    assert!(spatial_reduced_derivatives(&small, &mut data, &mut derivatives, &x, &x, &x).is_err());
}
