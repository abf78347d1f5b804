//! The paper's arm (ten uniform links of 0.1 m and 0.1 kg) at a curled, moving pose: the terms
//! of eq 12, both forward dynamics, and the energy balance.
//!
//! Run with `cargo run -p manip-dyn --example paper_chain`.

use manip_dyn::faer::Mat;
use manip_dyn::{
    ChainData, ChainModel, DynError, aba, coriolis, coriolis_matrix, forward_dynamics, gravity,
    kinetic_energy, mass_matrix, potential_energy,
};

fn main() -> Result<(), DynError> {
    const N: usize = 10;
    let arm = ChainModel::uniform(N, 0.1, 0.1, 9.81)?;
    let mut data = ChainData::new(&arm);

    // A pose along a gentle curve, every joint turning at 0.5 rad/s, no torque.
    let q: Vec<f64> = (0..N).map(|i| if i == 0 { 0.6 } else { 0.15 }).collect();
    let v = vec![0.5; N];
    let tau = vec![0.0; N];

    let mut m = Mat::<f64>::zeros(N, N);
    mass_matrix(&arm, &mut data, &q, m.as_mut())?;
    let (mut c, mut g) = (vec![0.0; N], vec![0.0; N]);
    coriolis(&arm, &mut data, &q, &v, &mut c)?;
    gravity(&arm, &mut data, &q, &mut g)?;
    println!("M(q) (kg m^2):");
    for i in 0..N {
        let row: Vec<String> = (0..N).map(|j| format!("{:8.5}", m[(i, j)])).collect();
        println!("  {}", row.join(" "));
    }
    println!("C(q, v) (N m): {}", fmt(&c));
    println!("G(q)    (N m): {}", fmt(&g));

    // The Coriolis matrix reproduces the vector: C(q, v) v.
    let mut c_mat = Mat::<f64>::zeros(N, N);
    coriolis_matrix(&arm, &mut data, &q, &v, c_mat.as_mut())?;
    let cv_error = (0..N)
        .map(|i| ((0..N).map(|j| c_mat[(i, j)] * v[j]).sum::<f64>() - c[i]).abs())
        .fold(0.0, f64::max);
    println!("max |C_mat v - C| = {cv_error:.1e}");

    // Released with no torque: the O(n) articulated-body recursion and the Cholesky solve agree.
    let (mut by_aba, mut by_cholesky) = (vec![0.0; N], vec![0.0; N]);
    aba(&arm, &mut data, &q, &v, &tau, &mut by_aba)?;
    forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut by_cholesky)?;
    println!("qdd (ABA)      (rad/s^2): {}", fmt(&by_aba));
    let gap = by_aba
        .iter()
        .zip(&by_cholesky)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!("max |ABA - Cholesky| = {gap:.1e}");

    // With no torque, T + V is constant: its rate along the motion is 0 (central difference).
    let h = 1e-6;
    let mut energy = |sign: f64| -> Result<f64, DynError> {
        let qs: Vec<f64> = (0..N)
            .map(|i| q[i] + sign * h * v[i] + 0.5 * h * h * by_aba[i])
            .collect();
        let vs: Vec<f64> = (0..N).map(|i| v[i] + sign * h * by_aba[i]).collect();
        Ok(kinetic_energy(&arm, &mut data, &qs, &vs)? + potential_energy(&arm, &mut data, &qs)?)
    };
    let total = energy(0.0)?;
    let rate = (energy(1.0)? - energy(-1.0)?) / (2.0 * h);
    println!("T + V = {total:.6} J, d(T + V)/dt = {rate:.1e} W");
    Ok(())
}

fn fmt(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v:8.4}"))
        .collect::<Vec<_>>()
        .join(" ")
}
