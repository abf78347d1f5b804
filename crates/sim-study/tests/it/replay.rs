//! The full-chain replay (issue 10): the joint torques recorded in a run of the two-harmonic
//! `harmonic-tracking` scenario, applied to the full Lagrangian chain (`manip-dyn`, no modal
//! constraint) with the same zero-order hold, reproduce the recorded motion `theta = J a + theta_0`:
//! the reduced dynamics are the chain's dynamics on the backbone family (eq 13-15), and the only
//! difference left is the hold of the torque over a period, first order in it. The replay is open
//! loop and the upright arm's motions off the backbone family are unstable under gravity (they
//! grow like `exp(t sqrt(g / l_link))`), so it covers the first 0.05 s.

use manip_dyn::{ChainData, ChainModel};
use sim_core::ode::{OdeSystem, Rk4};
use sim_study::{ControllerKind, Scenario};

/// The full chain under a held joint torque, `y = [theta; theta_dot]`.
struct FullChain {
    model: ChainModel,
    data: ChainData,
    tau: Vec<f64>,
}

impl OdeSystem for FullChain {
    type Error = manip_dyn::DynError;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error> {
        let n = self.model.n_links();
        let (q, v) = y.split_at(n);
        let (dq, dv) = dy.split_at_mut(n);
        dq.copy_from_slice(v);
        manip_dyn::aba(&self.model, &mut self.data, q, v, &self.tau, dv)
    }
}

/// Largest joint-angle distance between the replayed chain and the recorded modal motion over
/// 0.05 s of `harmonic-tracking` with computed torque sampled every `period`.
fn replay_error(period: f64) -> f64 {
    let mut scenario = Scenario::builtin("harmonic-tracking").unwrap();
    scenario.controller.kind = ControllerKind::ComputedTorque;
    scenario.controller.period = Some(period);
    scenario.integrator = sim_study::IntegratorSpec::Rk4 { dt: period };
    scenario.record_period = Some(period);
    scenario.duration = 0.05;
    let run = scenario.build().unwrap().run().unwrap();
    let model = scenario.model().unwrap();
    assert_eq!(model.n_coords(), 4);
    let map = model.map().clone();
    let n = model.n_links();
    let mut chain = FullChain {
        data: ChainData::new(model.chain()),
        model: model.chain().clone(),
        tau: vec![0.0; n],
    };
    let record = &run.record;
    let mut theta = vec![0.0; n];
    let mut y = vec![0.0; 2 * n];
    map.joint_angles(record.a_at(0), &mut y[..n]).unwrap();
    map.joint_rates(record.a_dot_at(0), &mut y[n..]).unwrap();
    let mut rk4 = Rk4::new(2 * n);
    let mut worst: f64 = 0.0;
    for k in 0..record.len() - 1 {
        chain.tau.copy_from_slice(record.joint_torques_at(k));
        rk4.integrate(
            &mut chain,
            record.t[k],
            record.t[k + 1],
            &mut y,
            period / 10.0,
        )
        .unwrap();
        map.joint_angles(record.a_at(k + 1), &mut theta).unwrap();
        for (q, expected) in y[..n].iter().zip(&theta) {
            worst = worst.max((q - expected).abs());
        }
    }
    worst
}

#[test]
fn replayed_joint_torques_move_the_full_chain_along_the_recorded_curve() {
    let (coarse, fine) = (replay_error(2e-4), replay_error(1e-4));
    // Small, and halving with the hold period: the hold is the only difference.
    assert!(fine < 5e-5, "replay error {fine:e} rad");
    let ratio = coarse / fine;
    assert!(
        (1.6..2.5).contains(&ratio),
        "errors {coarse:e} and {fine:e}"
    );
}
