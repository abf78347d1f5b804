//! The paper's eq 16-18 iteration: it matches the direct solve when it converges, and reports
//! divergence (with the right spectral radius) instead of returning garbage.

use crate::common::*;
use backbone_kin::ModalMap;
use manip_dyn::ChainModel;
use modal_reduce::{
    JacobiSettings, ReduceError, ReducedData, ReducedModel, forward_dynamics,
    jacobi_forward_dynamics,
};
use nalgebra::DMatrix;
use proptest::prelude::*;

/// Spectral radius of `M0*^-1 M1*` from nalgebra's general (non-symmetric) eigenvalues.
fn reference_spectral_radius(mass: &[f64], m: usize) -> f64 {
    let mut iteration = DMatrix::from_row_slice(m, m, mass);
    for j in 0..m {
        let diagonal = mass[j * m + j];
        for k in 0..m {
            iteration[(j, k)] = if j == k {
                0.0
            } else {
                mass[j * m + k] / diagonal
            };
        }
    }
    iteration
        .complex_eigenvalues()
        .iter()
        .fold(0.0, |acc, z| acc.max(z.norm()))
}

/// Plain eq-18 steps from zero: `x <- M0*^-1 (rhs - M1* x)`.
fn naive_jacobi(mass: &[f64], rhs: &[f64], steps: usize) -> Vec<f64> {
    let m = rhs.len();
    let mut x = vec![0.0; m];
    for _ in 0..steps {
        x = (0..m)
            .map(|j| {
                let off: f64 = (0..m)
                    .filter(|&k| k != j)
                    .map(|k| mass[j * m + k] * x[k])
                    .sum();
                (rhs[j] - off) / mass[j * m + j]
            })
            .collect();
    }
    x
}

proptest! {
    #![proptest_config(expensive())]

    /// Whatever the map: a converged iteration matches the direct Cholesky solve; a refusal
    /// reports the true spectral radius (>= 1), and plain iteration indeed fails there.
    #[test]
    fn jacobi_matches_direct_solve_or_reports_divergence(
        ((model, a, a_dot), tau_seed) in (model_and_state(1..=60), prop::collection::vec(-5.0..5.0f64, 5))
    ) {
        let m = model.n_coords();
        let tau_star = &tau_seed[..m];
        let mut data = ReducedData::new(&model);
        let mut direct = vec![0.0; m];
        forward_dynamics(&model, &mut data, &a, &a_dot, tau_star, &mut direct).unwrap();
        let mass = to_vec(data.mass_matrix());
        let rhs: Vec<f64> = (0..m)
            .map(|j| tau_star[j] - data.coriolis()[j] - data.gravity()[j])
            .collect();
        let reference = reference_spectral_radius(&mass, m);
        let mut iterated = vec![0.0; m];
        match jacobi_forward_dynamics(
            &model, &mut data, &a, &a_dot, tau_star, &JacobiSettings::default(), &mut iterated,
        ) {
            Ok(report) => {
                prop_assert!((report.spectral_radius - reference).abs() < 1e-9);
                prop_assert!(report.spectral_radius < 1.0);
                let residual: Vec<f64> = (0..m)
                    .map(|j| (0..m).map(|k| mass[j * m + k] * (iterated[k] - direct[k])).sum())
                    .collect();
                let scale = max_abs(&rhs) + max_abs(&mass) * max_abs(&direct);
                prop_assert!(max_abs(&residual) <= 1e-11 * scale, "{iterated:?} vs {direct:?}");
            }
            Err(ReduceError::JacobiDiverged { spectral_radius }) => {
                prop_assert!(spectral_radius >= 1.0);
                prop_assert!((spectral_radius - reference).abs() < 1e-9);
                if spectral_radius > 1.05 {
                    let x = naive_jacobi(&mass, &rhs, 400);
                    let error = relative_difference(&x, &direct, 1e-300);
                    prop_assert!(error.is_nan() || error >= 1e-3, "plain iteration converged anyway: {error}");
                }
            }
            Err(ReduceError::JacobiNotConverged { spectral_radius, iterations, .. }) => {
                // Legitimately slow: rho^iterations has not fallen below the tolerance.
                prop_assert!(spectral_radius.powi(iterations as i32) > 1e-15);
            }
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
    }

    /// With two coordinates (alpha0 held fixed) the iteration matrix is similar to
    /// [[0, rho], [rho, 0]] with rho = |M*_12| / sqrt(M*_11 M*_22) < 1: it always converges.
    #[test]
    fn two_coordinates_always_converge(
        (n, alpha0, a1, a2, tau1, tau2) in (2usize..=60, -3.0..3.0f64, -1.5..1.5f64, -1.5..1.5f64, -5.0..5.0f64, -5.0..5.0f64)
    ) {
        let model = ReducedModel::new(
            ChainModel::uniform(n, 1.0 / n as f64, 1.0 / n as f64, 9.81).unwrap(),
            ModalMap::paper_fixed_alpha0(n, alpha0).unwrap(),
        ).unwrap();
        let mut data = ReducedData::new(&model);
        let (a, a_dot, tau_star) = ([a1, a2], [a2, -a1], [tau1, tau2]);
        let mut direct = [0.0; 2];
        forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut direct).unwrap();
        let mass = data.mass_matrix();
        let expected = mass[(0, 1)].abs() / (mass[(0, 0)] * mass[(1, 1)]).sqrt();
        let mut iterated = [0.0; 2];
        let report = jacobi_forward_dynamics(
            &model, &mut data, &a, &a_dot, &tau_star, &JacobiSettings::default(), &mut iterated,
        ).unwrap();
        prop_assert!((report.spectral_radius - expected).abs() < 1e-12);
        prop_assert!(relative_difference(&iterated, &direct, 1e-12) < 1e-9);
    }
}

/// At ordinary poses of the paper's arm with all three coordinates the spectral radius is 1-1.6,
/// so eq 18 diverges: reported, not returned.
#[test]
fn paper_arm_with_three_coordinates_diverges() {
    let model = paper_arm();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [f64::NAN; 3];
    let poses = [
        [0.0, 0.0, 0.0],
        [0.5, 0.3, 1.0],
        [1.0, -0.5, 0.3],
        [0.2, 0.2, std::f64::consts::FRAC_PI_2],
        [-0.8, 0.4, 2.0],
    ];
    for a in poses {
        let result = jacobi_forward_dynamics(
            &model,
            &mut data,
            &a,
            &[0.3, -0.2, 0.1],
            &[1.0, 0.5, -0.5],
            &JacobiSettings::default(),
            &mut a_ddot,
        );
        match result {
            Err(ReduceError::JacobiDiverged { spectral_radius }) => {
                assert!(
                    (1.0..1.6).contains(&spectral_radius),
                    "{a:?}: {spectral_radius}"
                );
                let reference = reference_spectral_radius(&to_vec(data.mass_matrix()), 3);
                assert!((spectral_radius - reference).abs() < 1e-9);
            }
            other => panic!("{a:?}: expected divergence, got {other:?}"),
        }
    }
    let message = jacobi_forward_dynamics(
        &model,
        &mut data,
        &[0.5, 0.3, 1.0],
        &[0.0; 3],
        &[0.0; 3],
        &JacobiSettings::default(),
        &mut a_ddot,
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("diverges") && message.contains("spectral radius"),
        "{message}"
    );
}

/// Too few iterations for a slowly converging case: an error that says so, not a half-way value.
#[test]
fn slow_convergence_is_reported() {
    let model = ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, 1.0).unwrap(),
    )
    .unwrap();
    let mut data = ReducedData::new(&model);
    let mut a_ddot = [0.0; 2];
    let settings = JacobiSettings {
        tolerance: 1e-14,
        max_iterations: 2,
    };
    let result = jacobi_forward_dynamics(
        &model,
        &mut data,
        &[0.4, 0.2],
        &[0.0; 2],
        &[1.0, 1.0],
        &settings,
        &mut a_ddot,
    );
    assert!(
        matches!(
            result,
            Err(ReduceError::JacobiNotConverged { iterations: 2, .. })
        ),
        "{result:?}"
    );
}
