//! The planar chain described as a spatial chain (joints about `z`, links along `x`, gravity
//! along `-y`) gives the planar algorithms' results to 1e-12.
//!
//! For the forward quantities (RNEA, `G`, `M`, energies) the two algorithms sum the same terms in
//! different orders, a few ulps apart. Forward dynamics solves `M qdd = b`: two backward-stable
//! solutions (each with a residual of a few ulps of `|M| |qdd| + |b|`, checked here) differ by up
//! to about `cond(M) eps |qdd|`, whatever the summation order. On these arms (`cond(M)` up to
//! 1e7) the ABAs agree to 3.2e-13 relative over 5000 samples, at most 11 `cond(M) eps`: the test
//! holds them to 1e-12, or to `16 cond(M) eps` for an arm too ill-conditioned for 1e-12 to be
//! attainable by any two solvers.

use faer::Mat;
use manip_dyn::spatial::{self, SpatialData, SpatialModel};
use manip_dyn::{ChainData, aba, gravity, kinetic_energy, mass_matrix, potential_energy, rnea};
use proptest::prelude::*;

use crate::common::{arm_and_state, max_abs};

/// Largest difference, relative to the larger magnitude and a floor of 1.
fn close(a: &[f64], b: &[f64]) -> f64 {
    let scale = max_abs(a).max(max_abs(b)).max(1.0);
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

fn flat(m: &Mat<f64>) -> Vec<f64> {
    (0..m.ncols())
        .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)]))
        .collect()
}

proptest! {
    #[test]
    fn spatial_planar_chain_matches_the_planar_algorithms(
        (chain, q, v, a) in arm_and_state(30),
    ) {
        let n = chain.n_links();
        let model = SpatialModel::from_planar(&chain);
        let (mut planar, mut data) = (ChainData::new(&chain), SpatialData::new(&model));
        let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);

        rnea(&chain, &mut planar, &q, &v, &a, &mut x).unwrap();
        spatial::rnea(&model, &mut data, &q, &v, &a, &mut y).unwrap();
        prop_assert!(close(&x, &y) < 1e-12, "rnea {x:?} {y:?}");

        gravity(&chain, &mut planar, &q, &mut x).unwrap();
        spatial::gravity(&model, &mut data, &q, &mut y).unwrap();
        prop_assert!(close(&x, &y) < 1e-12, "gravity {x:?} {y:?}");

        let (mut mp, mut ms) = (Mat::zeros(n, n), Mat::zeros(n, n));
        mass_matrix(&chain, &mut planar, &q, mp.as_mut()).unwrap();
        spatial::mass_matrix(&model, &mut data, &q, ms.as_mut()).unwrap();
        prop_assert!(close(&flat(&mp), &flat(&ms)) < 1e-12, "mass matrix");

        aba(&chain, &mut planar, &q, &v, &a, &mut x).unwrap();
        spatial::aba(&model, &mut data, &q, &v, &a, &mut y).unwrap();
        let eigenvalues = ms.as_ref().self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        let condition = eigenvalues.iter().fold(0.0f64, |m, e| m.max(*e))
            / eigenvalues.iter().fold(f64::INFINITY, |m, e| m.min(*e));
        let bound = 1e-12f64.max(16.0 * condition * f64::EPSILON);
        prop_assert!(close(&x, &y) < bound, "aba {x:?} {y:?}, cond(M) {condition:e}");
        // Each is backward stable: M qdd - (tau - C - G) within a few ulps.
        let mut bias = vec![0.0; n];
        spatial::nonlinear_effects(&model, &mut data, &q, &v, &mut bias).unwrap();
        let b: Vec<f64> = a.iter().zip(&bias).map(|(t, h)| t - h).collect();
        for z in [&x, &y] {
            let residual = (0..n)
                .map(|i| ((0..n).map(|j| ms[(i, j)] * z[j]).sum::<f64>() - b[i]).abs())
                .fold(0.0, f64::max);
            // `b = tau - (C + G)` is formed in floating point: its rounding scales with its
            // terms, not with the difference.
            let scale = max_abs(&flat(&ms)) * max_abs(z) + max_abs(&a) + max_abs(&bias);
            prop_assert!(residual < 1e-14 * scale, "residual {residual:e} of {scale:e}");
        }

        let kinetic = [
            kinetic_energy(&chain, &mut planar, &q, &v).unwrap(),
            spatial::kinetic_energy(&model, &mut data, &q, &v).unwrap(),
        ];
        prop_assert!(close(&kinetic[..1], &kinetic[1..]) < 1e-12, "kinetic {kinetic:?}");
        let potential = [
            potential_energy(&chain, &mut planar, &q).unwrap(),
            spatial::potential_energy(&model, &mut data, &q).unwrap(),
        ];
        prop_assert!(close(&potential[..1], &potential[1..]) < 1e-12, "potential {potential:?}");
    }
}
