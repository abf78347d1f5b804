//! Property tests of the reduced dynamics over random arms (1-200 links), random modal maps
//! (1-2 harmonics, 1-3 in one test; `alpha0` free or fixed) and random states, against independent references:
//! the full chain's mass matrix, brute-force energies, finite differences and Lagrange's
//! equations.

use crate::common::*;
use modal_reduce::{
    ReducedData, ReducedModel, forward_dynamics, forward_dynamics_by_projection, joint_torques,
    kinetic_energy, potential_energy, project_torques, reduced_terms, reduced_terms_by_projection,
};
use nalgebra::DMatrix;
use proptest::prelude::*;

/// `(M*, C*, G*)` of the default path as vectors.
fn fast_terms(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    reduced_terms(model, data, a, a_dot).expect("fast terms");
    (
        to_vec(data.mass_matrix()),
        data.coriolis().to_vec(),
        data.gravity().to_vec(),
    )
}

/// `a_dot^T M*(a) a_dot`.
fn quadratic_form(model: &ReducedModel, data: &mut ReducedData, a: &[f64], a_dot: &[f64]) -> f64 {
    let m = model.n_coords();
    let (mass, _, _) = fast_terms(model, data, a, a_dot);
    (0..m)
        .map(|j| {
            (0..m)
                .map(|k| a_dot[j] * mass[j * m + k] * a_dot[k])
                .sum::<f64>()
        })
        .sum()
}

/// The default path's `M*`, `C*` and `G*` against the projection path's, to 1e-12 relative.
fn fast_path_is_the_projection(
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), TestCaseError> {
    let mut data = ReducedData::new(model);
    let (mass, coriolis, gravity) = fast_terms(model, &mut data, a, a_dot);
    reduced_terms_by_projection(model, &mut data, a, a_dot).unwrap();
    let mass_projected = to_vec(data.mass_matrix());
    let errors = [
        relative_difference(&mass, &mass_projected, 0.0),
        relative_difference(&coriolis, data.coriolis(), 1e-300),
        relative_difference(&gravity, data.gravity(), 1e-300),
    ];
    prop_assert!(errors.iter().all(|&e| e < 1e-12), "M*, C*, G*: {errors:?}");
    Ok(())
}

/// `a + h d`.
fn shifted(a: &[f64], d: &[f64], h: f64) -> Vec<f64> {
    a.iter().zip(d).map(|(x, y)| x + h * y).collect()
}

proptest! {
    #![proptest_config(expensive())]

    /// The default O(n m^2) path equals the projection of the full model to 1e-12.
    #[test]
    fn fast_path_equals_the_projection((model, a, a_dot) in model_and_state(1..=200)) {
        fast_path_is_the_projection(&model, &a, &a_dot)?;
    }

    /// So it does with up to three harmonics: `m` up to 7, where one state's coordinates no
    /// longer sit in one register (AVX2) or on stack arrays (`m > 5`) and the kernel takes them
    /// one a number.
    #[test]
    fn every_layout_equals_the_projection(
        (model, a, a_dot) in model_with_harmonics(6..=120, 3).prop_flat_map(|model| {
            let m = model.n_coords();
            (
                Just(model),
                prop::collection::vec(-1.5..1.5f64, m),
                prop::collection::vec(-2.0..2.0f64, m),
            )
        })
    ) {
        fast_path_is_the_projection(&model, &a, &a_dot)?;
    }

    /// M* equals J^T M J with M from the full chain's mass matrix, by plain loops.
    #[test]
    fn mass_matrix_is_the_projection_of_the_full_one((model, a, a_dot) in model_and_state(1..=200)) {
        let (n, m) = (model.n_links(), model.n_coords());
        let mut data = ReducedData::new(&model);
        let (mass, _, _) = fast_terms(&model, &mut data, &a, &a_dot);
        let theta = joint_angles(model.map(), &a);
        let mut full = faer::Mat::<f64>::zeros(n, n);
        let mut chain_data = manip_dyn::ChainData::new(model.chain());
        manip_dyn::mass_matrix(model.chain(), &mut chain_data, &theta, full.as_mut()).unwrap();
        let j = |i: usize, k: usize| model.map().entry(i, k);
        let mass_times_j: Vec<f64> = (0..n * m)
            .map(|ic| (0..n).map(|k| full[(ic / m, k)] * j(k, ic % m)).sum())
            .collect();
        let projected: Vec<f64> = (0..m * m)
            .map(|rc| (0..n).map(|i| j(i, rc / m) * mass_times_j[i * m + rc % m]).sum())
            .collect();
        prop_assert!(relative_difference(&mass, &projected, 0.0) < 1e-12);
    }

    /// M* is exactly symmetric and positive definite.
    #[test]
    fn mass_matrix_is_symmetric_positive_definite((model, a, a_dot) in model_and_state(1..=200)) {
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let (mass, _, _) = fast_terms(&model, &mut data, &a, &a_dot);
        for j in 0..m {
            for k in 0..m {
                prop_assert_eq!(mass[j * m + k], mass[k * m + j]);
            }
        }
        let eigenvalues = DMatrix::from_row_slice(m, m, &mass).symmetric_eigenvalues();
        prop_assert!(eigenvalues.min() > 0.0, "eigenvalues {eigenvalues}");
    }

    /// 1/2 a_dot^T M* a_dot is the chain's kinetic energy at theta_dot = J a_dot, both from the
    /// definition and from `kinetic_energy`; `potential_energy` matches the definition too.
    #[test]
    fn energies_match_the_definitions((model, a, a_dot) in model_and_state(1..=200)) {
        let mut data = ReducedData::new(&model);
        let quadratic = 0.5 * quadratic_form(&model, &mut data, &a, &a_dot);
        let theta = joint_angles(model.map(), &a);
        let theta_dot = joint_rates(model.map(), &a_dot);
        let (kinetic, potential) = brute_energy(model.chain(), &theta, &theta_dot);
        prop_assert!((quadratic - kinetic).abs() <= 1e-12 * kinetic, "{quadratic} vs {kinetic}");
        let reduced_kinetic = kinetic_energy(&model, &mut data, &a, &a_dot).unwrap();
        prop_assert!((reduced_kinetic - kinetic).abs() <= 1e-12 * kinetic);
        // Potential energy: compare on the scale g sum(m) l.
        let chain = model.chain();
        let scale = chain.gravity() * chain.links().iter().map(|l| l.mass).sum::<f64>()
            * chain.total_length();
        let reduced_potential = potential_energy(&model, &mut data, &a).unwrap();
        prop_assert!((reduced_potential - potential).abs() <= 1e-12 * scale.max(1e-300));
    }

    /// G* is the gradient of the potential energy V(J a + theta_0) (central differences of the
    /// brute-force V).
    #[test]
    fn gravity_is_the_gradient_of_the_potential((model, a, a_dot) in model_and_state(1..=200)) {
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let (_, _, gravity) = fast_terms(&model, &mut data, &a, &a_dot);
        let potential = |x: &[f64]| {
            let theta = joint_angles(model.map(), x);
            brute_energy(model.chain(), &theta, &vec![0.0; theta.len()]).1
        };
        let h = 1e-5;
        let numeric: Vec<f64> = (0..m)
            .map(|k| {
                let mut e = vec![0.0; m];
                e[k] = 1.0;
                (potential(&shifted(&a, &e, h)) - potential(&shifted(&a, &e, -h))) / (2.0 * h)
            })
            .collect();
        let chain = model.chain();
        let scale = chain.gravity() * chain.links().iter().map(|l| l.mass).sum::<f64>()
            * chain.total_length();
        prop_assert!(relative_difference(&gravity, &numeric, scale.max(1e-300)) < 1e-7,
            "{gravity:?} vs {numeric:?}");
    }

    /// C* satisfies Lagrange's equation for the reduced Lagrangian:
    /// C* = (d/dt M*) a_dot - 1/2 grad_a (a_dot^T M* a_dot), by central differences of M*.
    #[test]
    fn coriolis_satisfies_lagranges_equation((model, a, a_dot) in model_and_state(1..=200)) {
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let (mass, coriolis, _) = fast_terms(&model, &mut data, &a, &a_dot);
        let h = 1e-5;
        let (ahead, _, _) = fast_terms(&model, &mut data, &shifted(&a, &a_dot, h), &a_dot);
        let (behind, _, _) = fast_terms(&model, &mut data, &shifted(&a, &a_dot, -h), &a_dot);
        let numeric: Vec<f64> = (0..m)
            .map(|j| {
                let mass_rate: f64 = (0..m)
                    .map(|k| (ahead[j * m + k] - behind[j * m + k]) / (2.0 * h) * a_dot[k])
                    .sum();
                let mut e = vec![0.0; m];
                e[j] = 1.0;
                let gradient = (quadratic_form(&model, &mut data, &shifted(&a, &e, h), &a_dot)
                    - quadratic_form(&model, &mut data, &shifted(&a, &e, -h), &a_dot))
                    / (2.0 * h);
                mass_rate - 0.5 * gradient
            })
            .collect();
        let scale = max_abs(&mass) * max_abs(&a_dot).powi(2);
        prop_assert!(relative_difference(&coriolis, &numeric, scale.max(1e-300)) < 1e-7,
            "{coriolis:?} vs {numeric:?}");
    }

    /// The joint torques of a modal motion project back onto the generalised forces that
    /// produced it: J^T tau = tau*; and both forward-dynamics paths agree.
    #[test]
    fn joint_torques_project_onto_the_modal_forces(
        ((model, a, a_dot), tau_seed) in (model_and_state(1..=200), prop::collection::vec(-5.0..5.0f64, 5))
    ) {
        let (n, m) = (model.n_links(), model.n_coords());
        let tau_star = &tau_seed[..m];
        let mut data = ReducedData::new(&model);
        let mut a_ddot = vec![0.0; m];
        forward_dynamics(&model, &mut data, &a, &a_dot, tau_star, &mut a_ddot).unwrap();
        let (mass, coriolis, gravity) =
            (to_vec(data.mass_matrix()), data.coriolis().to_vec(), data.gravity().to_vec());
        let mut tau = vec![0.0; n];
        joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau).unwrap();
        let mut projected = vec![0.0; m];
        project_torques(&model, &tau, &mut projected).unwrap();
        let scale = max_abs(tau_star) + max_abs(&coriolis) + max_abs(&gravity)
            + max_abs(&mass) * max_abs(&a_ddot);
        prop_assert!(relative_difference(&projected, tau_star, scale) < 1e-11,
            "{projected:?} vs {tau_star:?}");

        let mut a_ddot_projected = vec![0.0; m];
        forward_dynamics_by_projection(&model, &mut data, &a, &a_dot, tau_star, &mut a_ddot_projected).unwrap();
        // Compare through M*, which removes the conditioning of the solve.
        let difference: Vec<f64> = (0..m)
            .map(|j| (0..m).map(|k| mass[j * m + k] * (a_ddot[k] - a_ddot_projected[k])).sum())
            .collect();
        prop_assert!(max_abs(&difference) <= 1e-11 * scale);
    }
}
