//! The first program a researcher writes with `hrm`: a 20-link arm, its reduced forward dynamics
//! at a state, the paper's fuzzy controller evaluated once, and a closed-loop run with a
//! controller written here. CI runs it (`cargo run -p hrm --example custom_controller`).

use hrm::prelude::*;

/// Computed torque written by hand: `tau* = M* (a_ref_dd - kp e - kd e_dot) + C* + G*`, with the
/// reduced model the loop lends at every sample (planar or spatial: a `Plant`) and a workspace
/// sized once.
struct MyComputedTorque {
    data: PlantData,
    desired: Vec<f64>,
}

impl Controller for MyComputedTorque {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        let (kp, kd) = (900.0, 60.0);
        let (state, reference) = (ctx.measured, ctx.reference);
        ctx.model.terms(&mut self.data, &state.a, &state.a_dot)?;
        for (i, d) in self.desired.iter_mut().enumerate() {
            *d = reference.a_ddot[i]
                - kp * (state.a[i] - reference.a[i])
                - kd * (state.a_dot[i] - reference.a_dot[i]);
        }
        let mass = self.data.mass_matrix();
        for (i, tau) in tau_star.iter_mut().enumerate() {
            let inertia: f64 = (0..self.desired.len())
                .map(|j| mass[(i, j)] * self.desired[j])
                .sum();
            *tau = inertia + self.data.coriolis()[i] + self.data.gravity()[i];
        }
        Ok(())
    }
}

fn main() -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    // A 20-link arm of 5 cm and 50 g links (1 m, 1 kg), the paper's modal family with alpha0 = pi/2.
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let arm = ChainModel::uniform(20, 0.05, 0.05, 9.81)?;
    let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(20, alpha0)?)?;

    // The reduced forward dynamics M* a_dd + C* + G* = tau* (eq 15) at a state, with no torque.
    let mut data = ReducedData::new(&model);
    let (a, a_dot) = ([0.3, -0.2], [0.1, 0.0]);
    let mut a_ddot = [0.0; 2];
    forward_dynamics(&model, &mut data, &a, &a_dot, &[0.0, 0.0], &mut a_ddot)?;
    println!("falling freely from a = {a:?}: a_ddot = {a_ddot:.4?} rad/s^2");

    // The paper's fuzzy controller, evaluated once: 0.1 rad above the reference in a1.
    let mut fuzzy = FuzzyController::new(paper_controller(), 2)?;
    let measured = ModalState::new(&[0.1, 0.0], &[0.0, 0.0])?;
    let reference = ReferenceSample::zeros(2);
    let ctx = ControlContext {
        t: 0.0,
        measured: &measured,
        reference: &reference,
        model: (&model).into(),
        tau_star_limits: None,
    };
    let mut tau = [0.0; 2];
    fuzzy.control(&ctx, &mut tau)?;
    println!("the paper's fuzzy controller at da1 = 0.1 rad: tau* = {tau:.3?} N m");
    assert!(tau[0] < 0.0, "it pushes back");

    // A closed loop with the controller above: a step of the modal reference.
    let controller = MyComputedTorque {
        data: PlantData::new((&model).into()),
        desired: vec![0.0; 2],
    };
    let step = Step::new(&[0.0, 0.0], &[0.3, -0.2], 0.1)?;
    let mut settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-4 }, 1e-4, 1.0);
    settings.record_period = 1e-3;
    let mut simulation =
        Simulation::new(model, Box::new(step), Box::new(controller), settings, None)?;
    let run = simulation.run().map_err(|failure| failure.to_string())?;
    let last = run.record.len() - 1;
    println!(
        "after {} s: a = {:.6?} (reference {:?}), peak joint torque {:.3} N m",
        run.summary.simulated_s,
        run.record.a_at(last),
        run.record.a_ref_at(last),
        run.summary.peak_joint_torque_nm
    );
    for (a, a_ref) in run.record.a_at(last).iter().zip(run.record.a_ref_at(last)) {
        assert!((a - a_ref).abs() < 1e-6, "the step is reached");
    }
    Ok(())
}
