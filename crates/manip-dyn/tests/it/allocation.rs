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
