//! After `ReducedData::new` and one warm-up call, no per-step function allocates (checked with
//! the binary's counting allocator, which counts this test's thread only).
//!
//! The warm-up matters for the projection path only: for large matrices faer's product kernel grows a
//! thread-local packing buffer once, on its first call at a new size.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;
use modal_reduce::{
    JacobiSettings, ReducedData, ReducedDerivatives, ReducedModel, forward_dynamics,
    forward_dynamics_by_projection, jacobi_forward_dynamics, joint_torques, kinetic_energy,
    potential_energy, project_torques, reduced_derivatives, reduced_terms,
    reduced_terms_by_projection,
};
use test_support::alloc::{allocations_during, is_counting};

#[test]
fn per_step_functions_do_not_allocate() {
    assert!(is_counting());
    for (n, map) in [
        (10, ModalMap::paper(10).unwrap()),
        (10, ModalMap::paper_fixed_alpha0(10, 1.0).unwrap()),
        (300, ModalMap::uniform(300, 2, BaseAngle::Free).unwrap()),
    ] {
        let model =
            ReducedModel::new(ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap(), map).unwrap();
        let m = model.n_coords();
        let mut data = ReducedData::new(&model);
        let mut derivatives = ReducedDerivatives::new(&model);
        let (a, a_dot, tau_star) = (vec![0.3; m], vec![-0.2; m], vec![0.5; m]);
        let (mut a_ddot, mut tau, mut projected) = (vec![0.0; m], vec![0.0; n], vec![0.0; m]);
        let settings = JacobiSettings::default();
        let mut run = || {
            reduced_terms(&model, &mut data, &a, &a_dot).unwrap();
            reduced_terms_by_projection(&model, &mut data, &a, &a_dot).unwrap();
            forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot).unwrap();
            forward_dynamics_by_projection(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot)
                .unwrap();
            // Converges (two coordinates) or reports divergence; either way without allocating.
            let jacobi = jacobi_forward_dynamics(
                &model,
                &mut data,
                &a,
                &a_dot,
                &tau_star,
                &settings,
                &mut projected,
            );
            assert_eq!(jacobi.is_ok(), m == 2);
            joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau).unwrap();
            project_torques(&model, &tau, &mut projected).unwrap();
            kinetic_energy(&model, &mut data, &a, &a_dot).unwrap();
            potential_energy(&model, &mut data, &a).unwrap();
            reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star)
                .unwrap();
        };
        run();
        let allocations = allocations_during(run);
        assert_eq!(allocations, 0, "n = {n}, m = {m}");
    }
}

#[test]
fn spatial_per_step_functions_do_not_allocate() {
    use modal_reduce::spatial::{
        SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel,
        spatial_forward_dynamics, spatial_joint_torques, spatial_reduced_derivatives,
        spatial_reduced_terms,
    };
    assert!(is_counting());
    let model = SpatialReducedModel::uniform_rods(50, 2, 0.02, 0.02, [0.0, 0.0, -9.81]).unwrap();
    let m = model.n_coords();
    let mut data = SpatialReducedData::new(&model);
    let (a, a_dot, tau_star) = (vec![0.3; m], vec![-0.2; m], vec![0.5; m]);
    let (mut a_ddot, mut tau) = (vec![0.0; m], vec![0.0; 100]);
    let mut derivatives = SpatialReducedDerivatives::new(&model);
    let count = allocations_during(|| {
        spatial_reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star)
            .unwrap();
        spatial_reduced_terms(&model, &mut data, &a, &a_dot).unwrap();
        spatial_forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot).unwrap();
        spatial_joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau).unwrap();
    });
    assert_eq!(count, 0);
}
