//! After `ChainData::new`, no algorithm allocates: the binary's counting allocator proves it.

use faer::Mat;
use manip_dyn::{
    ChainData, ChainModel, DerivativeData, aba, aba_derivatives, coriolis, coriolis_matrix,
    forward_dynamics, gravity, kinetic_energy, mass_matrix, nonlinear_effects, potential_energy,
    rnea, rnea_derivatives,
};
use test_support::alloc::allocations_during;

#[test]
fn per_step_algorithms_allocate_nothing() {
    // Sizes on both sides of faer's blocking thresholds, each on a fresh thread so that no
    // thread-local buffer of an earlier case hides a first-use allocation.
    for n in [1, 3, 10, 64, 100, 200, 300, 600] {
        std::thread::spawn(move || check_chain(n)).join().unwrap();
    }
}

fn check_chain(n: usize) {
    let arm = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let mut derivatives = DerivativeData::new(&arm);
    let q: Vec<f64> = (0..n).map(|i| 0.1 + 0.01 * i as f64).collect();
    let v: Vec<f64> = (0..n).map(|i| 0.5 - 0.02 * i as f64).collect();
    let tau: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64).sin()).collect();
    let mut out = vec![0.0; n];
    let mut matrix = Mat::<f64>::zeros(n, n);
    let mut energy = 0.0;

    let count = allocations_during(|| {
        rnea(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
        coriolis(&arm, &mut data, &q, &v, &mut out).unwrap();
        gravity(&arm, &mut data, &q, &mut out).unwrap();
        nonlinear_effects(&arm, &mut data, &q, &v, &mut out).unwrap();
        mass_matrix(&arm, &mut data, &q, matrix.as_mut()).unwrap();
        coriolis_matrix(&arm, &mut data, &q, &v, matrix.as_mut()).unwrap();
        aba(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
        forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut out).unwrap();
        energy += kinetic_energy(&arm, &mut data, &q, &v).unwrap();
        energy += potential_energy(&arm, &mut data, &q).unwrap();
        rnea_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &tau).unwrap();
        aba_derivatives(&arm, &mut data, &mut derivatives, &q, &v, &tau).unwrap();
    });
    assert_eq!(count, 0, "n = {n}: {count} allocations");
    assert!(energy.is_finite() && out.iter().all(|x| x.is_finite()));
    // The counter does see allocations (so the zero above means something).
    assert!(allocations_during(|| drop(ChainData::new(&arm))) > 0);
}

#[test]
fn spatial_algorithms_allocate_nothing() {
    use manip_dyn::spatial::{self, SpatialBatchData, SpatialData, SpatialDerivativeData};
    for n in [1, 7, 20, 64] {
        std::thread::spawn(move || {
            let model = spatial::SpatialModel::from_planar(
                &ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap(),
            );
            let mut data = SpatialData::new(&model);
            let mut derivatives = SpatialDerivativeData::new(&model);
            let mut batch = SpatialBatchData::new(&model);
            let q: Vec<f64> = (0..n).map(|i| 0.1 + 0.01 * i as f64).collect();
            let v: Vec<f64> = (0..n).map(|i| 0.5 - 0.02 * i as f64).collect();
            let tau: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64).sin()).collect();
            let states = 11;
            let (qs, vs, taus) = (q.repeat(states), v.repeat(states), tau.repeat(states));
            let mut many = vec![0.0; n * states];
            let mut out = vec![0.0; n];
            let mut matrix = Mat::<f64>::zeros(n, n);
            let mut jacobian = Mat::<f64>::zeros(6, n);
            let mut energy = 0.0;
            let count = allocations_during(|| {
                spatial::forward_kinematics(&model, &mut data, &q).unwrap();
                spatial::jacobian(
                    &model,
                    &mut data,
                    &q,
                    n - 1,
                    [0.1, 0.0, 0.0],
                    jacobian.as_mut(),
                )
                .unwrap();
                spatial::rnea(&model, &mut data, &q, &v, &tau, &mut out).unwrap();
                spatial::coriolis(&model, &mut data, &q, &v, &mut out).unwrap();
                spatial::gravity(&model, &mut data, &q, &mut out).unwrap();
                spatial::nonlinear_effects(&model, &mut data, &q, &v, &mut out).unwrap();
                spatial::mass_matrix(&model, &mut data, &q, matrix.as_mut()).unwrap();
                spatial::aba(&model, &mut data, &q, &v, &tau, &mut out).unwrap();
                spatial::aba_batch(&model, &mut batch, &qs, &vs, &taus, &mut many).unwrap();
                energy += spatial::kinetic_energy(&model, &mut data, &q, &v).unwrap();
                energy += spatial::potential_energy(&model, &mut data, &q).unwrap();
                spatial::rnea_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau)
                    .unwrap();
                spatial::aba_derivatives(&model, &mut data, &mut derivatives, &q, &v, &tau)
                    .unwrap();
            });
            assert_eq!(count, 0, "n = {n}: {count} allocations");
            assert!(energy.is_finite() && many.iter().all(|x| x.is_finite()));
        })
        .join()
        .unwrap();
    }
}
