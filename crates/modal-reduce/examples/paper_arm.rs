//! The reduced dynamics of the paper's arm (10 links of 0.1 m and 0.1 kg) at one modal state:
//! `M*`, `C*`, `G*`, the modal accelerations under a generalised force, the joint torques that
//! realise them, and why the paper's eq-18 iteration cannot be used with three coordinates.
//!
//! Run with `cargo run -p modal-reduce --example paper_arm`.

use backbone_kin::ModalMap;
use manip_dyn::ChainModel;
use modal_reduce::{
    JacobiSettings, ReducedData, ReducedModel, forward_dynamics, jacobi_forward_dynamics,
    joint_torques, kinetic_energy, potential_energy, project_torques, reduced_terms,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
    let model = ReducedModel::new(arm.clone(), ModalMap::paper(10)?)?;
    let mut data = ReducedData::new(&model);

    let (a, a_dot) = ([0.8, -0.4, 1.2], [0.5, 0.2, -0.1]);
    // Gravity compensation plus a small push on a1: tau* = G*(a) + (0.01, 0, 0).
    reduced_terms(&model, &mut data, &a, &a_dot)?;
    let g_star = data.gravity();
    let tau_star = [g_star[0] + 0.01, g_star[1], g_star[2]];
    let mut a_ddot = [0.0; 3];
    forward_dynamics(&model, &mut data, &a, &a_dot, &tau_star, &mut a_ddot)?;

    println!("a = (a1, a2, alpha0) = {a:?}, a_dot = {a_dot:?}, tau* = {tau_star:.6?}");
    println!("M* =");
    let mass = data.mass_matrix();
    for i in 0..mass.nrows() {
        let row: Vec<String> = (0..mass.ncols())
            .map(|j| format!("{:10.6}", mass[(i, j)]))
            .collect();
        println!("    [{}]", row.join(", "));
    }
    println!("C* = {:.6?}", data.coriolis());
    println!("G* = {:.6?}", data.gravity());
    println!("a_ddot = {a_ddot:.6?}");

    let mut tau = [0.0; 10];
    joint_torques(&model, &mut data, &a, &a_dot, &a_ddot, &mut tau)?;
    let mut projected = [0.0; 3];
    project_torques(&model, &tau, &mut projected)?;
    println!("joint torques tau = {tau:.4?}");
    println!("J^T tau = {projected:.12?} (equals tau*)");
    println!(
        "T = {:.6} J, V = {:.6} J",
        kinetic_energy(&model, &mut data, &a, &a_dot)?,
        potential_energy(&model, &mut data, &a)?
    );

    // Eq 18 with three coordinates: the iteration matrix has spectral radius above 1.
    let settings = JacobiSettings::default();
    match jacobi_forward_dynamics(
        &model,
        &mut data,
        &a,
        &a_dot,
        &tau_star,
        &settings,
        &mut a_ddot,
    ) {
        Ok(report) => println!("eq 18 converged: {report:?}"),
        Err(error) => println!("eq 18, three coordinates: {error}"),
    }
    // With alpha0 held fixed (the paper's experiment) it converges.
    let fixed = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, a[2])?)?;
    let mut fixed_data = ReducedData::new(&fixed);
    let mut a_ddot2 = [0.0; 2];
    let report = jacobi_forward_dynamics(
        &fixed,
        &mut fixed_data,
        &a[..2],
        &a_dot[..2],
        &tau_star[..2],
        &settings,
        &mut a_ddot2,
    )?;
    println!(
        "eq 18, alpha0 fixed: a_ddot = {a_ddot2:.6?} after {} iterations (spectral radius {:.3})",
        report.iterations, report.spectral_radius
    );
    Ok(())
}
