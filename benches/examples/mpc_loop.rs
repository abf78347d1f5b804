//! hrm's MPC in a closed loop, beside Crocoddyl's in benches/crocoddyl/mpc.py (issue 34): the
//! arm of 1 m and 1 kg split into `n` equal links (`n` = 10 and 30, `alpha0 = pi/2` fixed,
//! `m = 2`), the default MPC (`MpcSettings::uniform`: 60 nodes of 5 ms, at most 5 iterations a
//! solve) with `tau*` limits of 3 times each coordinate's peak inverse-dynamics torque along the
//! reference, re-planned every 5 ms from the measured state with the first planned torque held
//! in between, the reduced model integrated by RK4 at 1 ms, for 1 s of the sinusoid of
//! benches/benches/mpc.rs from rest at its start. Prints `mpc_loop/<n>/tip_rms_m <metres> m`,
//! the RMS over the plans of the distance between the tip and the reference's tip (the figure
//! `cargo xtask bench --check` reads), and the largest.
//!
//! ```sh
//! cargo run --release -p hrm-benches --example mpc_loop
//! ```

use backbone_kin::{ModalMap, tip_position};
use manip_dyn::ChainModel;
use modal_reduce::{ReducedData, ReducedModel, forward_dynamics, reduced_terms};
use optimal_ctl::{Mpc, MpcSettings};
use sim_core::ode::{OdeSystem, Rk4};
use sim_core::reference::{Reference, ReferenceSample, Sinusoid};

const LOOP_SECONDS: f64 = 1.0;
const PLANT_STEP: f64 = 0.001;
/// The limits' factor over the peak inverse-dynamics torque, benches/crocoddyl/mpc.py's (whose
/// full arm falls over at 1.2 and 2).
const LIMIT_FACTOR: f64 = 3.0;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn main() -> Result<()> {
    for n in [10, 30] {
        let (rms, peak) = closed_loop(n)?;
        println!("mpc_loop/{n}/tip_rms_m {rms:.6e} m");
        println!("  check: largest tip error {:.3} mm", peak * 1e3);
    }
    Ok(())
}

/// The reference of benches/benches/mpc.rs: 0.3 rad and 0.1 rad at 1 Hz about `(1, 0)`.
fn sinusoid() -> Result<Sinusoid> {
    Ok(Sinusoid::new(
        &[1.0, 0.0],
        &[0.3, 0.1],
        &[1.0, 1.0],
        &[0.0, 0.5],
    )?)
}

/// The tip of the arm at modal coordinates `a`.
fn tip(map: &ModalMap, lengths: &[f64], a: &[f64], theta: &mut [f64]) -> Result<[f64; 2]> {
    map.joint_angles(a, theta)?;
    Ok(tip_position(lengths, theta)?)
}

/// The RMS and largest tip error of the closed loop of `n` links.
fn closed_loop(n: usize) -> Result<(f64, f64)> {
    let length = 1.0 / n as f64;
    let map = ModalMap::paper_fixed_alpha0(n, std::f64::consts::FRAC_PI_2)?;
    let model = ReducedModel::new(
        ChainModel::uniform(n, length, 1.0 / n as f64, 9.81)?,
        map.clone(),
    )?;
    let mut data = ReducedData::new(&model);
    let mut reference = sinusoid()?;
    let mut settings = MpcSettings::uniform(2);
    let (h, horizon) = (settings.step, settings.horizon);
    let plans = (LOOP_SECONDS / h).round() as usize;
    // The limits: LIMIT_FACTOR times each coordinate's peak of M*(r) a_ref_dd + C*(r) + G*(r) (eq 15).
    let mut sample = ReferenceSample::zeros(2);
    let mut peak = [0.0f64; 2];
    for k in 0..plans + horizon {
        reference.sample(k as f64 * h, &mut sample)?;
        reduced_terms(&model, &mut data, &sample.a, &sample.a_dot)?;
        for (i, p) in peak.iter_mut().enumerate() {
            let mut tau = data.coriolis()[i] + data.gravity()[i];
            for (j, acc) in sample.a_ddot.iter().enumerate() {
                tau += data.mass_matrix()[(i, j)] * acc;
            }
            *p = p.max(tau.abs());
        }
    }
    settings.tau_star_limits = Some(peak.iter().map(|p| LIMIT_FACTOR * p.max(1e-6)).collect());
    let mut mpc = Mpc::new(&model, &settings)?;

    let lengths = vec![length; n];
    let mut theta = vec![0.0; n];
    reference.sample(0.0, &mut sample)?;
    // y = (a, a_dot): from rest at the reference's start.
    let mut y = [sample.a[0], sample.a[1], 0.0, 0.0];
    let mut rk4 = Rk4::new(4);
    let (mut tau, mut sum, mut largest) = ([0.0; 2], 0.0, 0.0f64);
    for k in 0..=plans {
        let t = k as f64 * h;
        reference.sample(t, &mut sample)?;
        let here = tip(&map, &lengths, &y[..2], &mut theta)?;
        let there = tip(&map, &lengths, &sample.a, &mut theta)?;
        let error = (here[0] - there[0]).hypot(here[1] - there[1]);
        sum += error * error;
        largest = largest.max(error);
        if k == plans {
            break;
        }
        for j in 0..=horizon {
            reference.sample(t + j as f64 * h, &mut sample)?;
            mpc.set_reference(&model, j, &sample.a, &sample.a_dot, &sample.a_ddot)?;
        }
        let (a, a_dot) = y.split_at(2);
        mpc.solve(&model, a, a_dot)?;
        // The first planned torque (the plan starts at the measured state), held for 5 ms.
        mpc.control(0.0, a, a_dot, &mut tau)?;
        mpc.shift(1);
        let mut plant = Plant {
            model: &model,
            data: &mut data,
            tau,
        };
        rk4.integrate(&mut plant, t, t + h, &mut y, PLANT_STEP)?;
    }
    Ok(((sum / (plans + 1) as f64).sqrt(), largest))
}

/// The reduced model at constant `tau*`, `y = (a, a_dot)`.
struct Plant<'a> {
    model: &'a ReducedModel,
    data: &'a mut ReducedData,
    tau: [f64; 2],
}

impl OdeSystem for Plant<'_> {
    type Error = modal_reduce::ReduceError;

    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> std::result::Result<(), Self::Error> {
        let (a, a_dot) = y.split_at(2);
        let (da, dv) = dy.split_at_mut(2);
        da.copy_from_slice(a_dot);
        forward_dynamics(self.model, self.data, a, a_dot, &self.tau, dv)
    }
}
