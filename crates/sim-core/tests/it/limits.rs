//! The loop's enforced joint limits (`LoopSettings::joint_torque_limits`, `joint_angle_limits`):
//! each applied `tau*` against the closest point of the joint-torque polytope found by brute
//! force (every vertex, edge and the interior of the two-dimensional polytope), with the
//! polytope built from RNEA on the full chain rather than the loop's own joint torques; joint
//! angles that stay within their limits where the free run leaves them.

use backbone_kin::ModalMap;
use manip_dyn::{ChainData, ChainModel};
use modal_reduce::{ReducedData, ReducedModel};
use sim_core::controller::{ControlContext, Controller, ControllerError, PdController};
use sim_core::reference::Step;
use sim_core::{ControlSample, Integrator, LoopHooks, LoopSettings, SimError, Simulation};
use std::f64::consts::FRAC_PI_2;
use std::sync::{Arc, Mutex};

fn paper_model() -> ReducedModel {
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::paper_fixed_alpha0(10, FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

/// A stiff PD law whose own outputs are kept, to compare with what the loop applied.
struct Logged {
    inner: PdController,
    outputs: Arc<Mutex<Vec<Vec<f64>>>>,
}

impl Controller for Logged {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau: &mut [f64],
    ) -> Result<(), ControllerError> {
        self.inner.control(ctx, tau)?;
        self.outputs.lock().unwrap().push(tau.to_vec());
        Ok(())
    }
}

/// Every sample the loop took.
#[derive(Default)]
struct Samples(Vec<ControlSample>);

impl LoopHooks for Samples {
    fn observe(&mut self, sample: &ControlSample) {
        self.0.push(sample.clone());
    }
}

/// A step response of the paper's arm from rest at `from` under a stiff PD law, with
/// `settings` changed by `edit`: the controller's outputs and the samples.
fn step_from(
    from: [f64; 2],
    edit: impl FnOnce(&mut LoopSettings),
) -> Result<(Vec<Vec<f64>>, Vec<ControlSample>), SimError> {
    let outputs = Arc::new(Mutex::new(Vec::new()));
    let controller = Logged {
        inner: PdController::new(&[0.0; 2], &[40.0, 20.0], &[2.0, 1.0]).unwrap(),
        outputs: Arc::clone(&outputs),
    };
    let mut settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 0.3);
    edit(&mut settings);
    let mut sim = Simulation::new(
        paper_model(),
        Box::new(Step::new(&from, &[0.4, -0.3], 0.02).unwrap()),
        Box::new(controller),
        settings,
        None,
    )?;
    let mut samples = Samples::default();
    sim.run_with(&mut samples).map_err(|f| f.error)?;
    let outputs = outputs.lock().unwrap().clone();
    Ok((outputs, samples.0))
}

/// The error of a run that must fail (without printing the samples of one that did not).
fn refused<T>(result: Result<T, SimError>) -> SimError {
    match result {
        Ok(_) => panic!("the run was not refused"),
        Err(error) => error,
    }
}

/// [`step_from`] the straight arm.
fn step_run(
    edit: impl FnOnce(&mut LoopSettings),
) -> Result<(Vec<Vec<f64>>, Vec<ControlSample>), SimError> {
    step_from([0.0, 0.0], edit)
}

/// The joint torques `A tau* + b` of the paper's arm at `(a, a_dot)` by RNEA on the full chain:
/// `b` at `tau* = 0` and `A`'s columns at the unit torques, each through the reduced forward
/// dynamics (eq 15) and then `tau = RNEA(q, q_dot, J a_ddot)`.
fn affine_torques(model: &ReducedModel, a: &[f64], a_dot: &[f64]) -> (Vec<[f64; 2]>, Vec<f64>) {
    let mut data = ReducedData::new(model);
    let mut chain_data = ChainData::new(model.chain());
    let map = model.map();
    let (mut q, mut v, mut qdd, mut tau) = ([0.0; 10], [0.0; 10], [0.0; 10], [0.0; 10]);
    map.joint_angles(a, &mut q).unwrap();
    map.joint_rates(a_dot, &mut v).unwrap();
    let mut at = |tau_star: [f64; 2]| {
        let mut a_ddot = [0.0; 2];
        modal_reduce::forward_dynamics(model, &mut data, a, a_dot, &tau_star, &mut a_ddot).unwrap();
        map.joint_rates(&a_ddot, &mut qdd).unwrap();
        manip_dyn::rnea(model.chain(), &mut chain_data, &q, &v, &qdd, &mut tau).unwrap();
        tau
    };
    let b = at([0.0, 0.0]);
    let (e1, e2) = (at([1.0, 0.0]), at([0.0, 1.0]));
    let columns = (0..10).map(|j| [e1[j] - b[j], e2[j] - b[j]]).collect();
    (columns, b.to_vec())
}

/// The point of `{x : |A x + b| <= limit}` closest to `x0` in the plane, by brute force: `x0`
/// itself, its projection onto every boundary line and every intersection of two, the closest
/// of those inside (to `slack`).
fn brute_force(rows: &[[f64; 2]], b: &[f64], limit: f64, x0: [f64; 2]) -> [f64; 2] {
    let mut lines = Vec::new();
    for (row, b) in rows.iter().zip(b) {
        lines.push((*row, limit - b));
        lines.push(([-row[0], -row[1]], limit + b));
    }
    let inside = |x: [f64; 2]| {
        lines
            .iter()
            .all(|(g, h)| g[0] * x[0] + g[1] * x[1] <= h + 1e-9 * (1.0 + h.abs()))
    };
    let mut candidates = vec![x0];
    for (g, h) in &lines {
        let norm = g[0] * g[0] + g[1] * g[1];
        let excess = (g[0] * x0[0] + g[1] * x0[1] - h) / norm;
        candidates.push([x0[0] - excess * g[0], x0[1] - excess * g[1]]);
    }
    for (i, (g, h)) in lines.iter().enumerate() {
        for (f, k) in &lines[i + 1..] {
            let det = g[0] * f[1] - g[1] * f[0];
            if det.abs() > 1e-12 {
                candidates.push([(h * f[1] - g[1] * k) / det, (g[0] * k - h * f[0]) / det]);
            }
        }
    }
    let distance = |x: &[f64; 2]| (x[0] - x0[0]).hypot(x[1] - x0[1]);
    candidates
        .into_iter()
        .filter(|x| inside(*x))
        .min_by(|x, y| distance(x).total_cmp(&distance(y)))
        .expect("the polytope is not empty")
}

#[test]
fn the_applied_torque_is_the_closest_within_the_joint_torque_limits() {
    let limit = 3.0;
    let (free_outputs, free) = step_run(|_| ()).unwrap();
    let free_peak = free
        .iter()
        .zip(&free_outputs)
        .map(|(s, _)| {
            let (rows, b) = affine_torques(&paper_model(), &s.state.a, &s.state.a_dot);
            rows.iter()
                .zip(&b)
                .map(|(r, b)| (r[0] * s.tau_star[0] + r[1] * s.tau_star[1] + b).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    assert!(
        free_peak > 1.5 * limit,
        "the free run must break the limit: {free_peak}"
    );

    let (outputs, samples) = step_run(|s| s.joint_torque_limits = Some(vec![limit; 10])).unwrap();
    let model = paper_model();
    let mut acted = 0;
    for (sample, wanted) in samples.iter().zip(&outputs) {
        let (rows, b) = affine_torques(&model, &sample.state.a, &sample.state.a_dot);
        let best = brute_force(&rows, &b, limit, [wanted[0], wanted[1]]);
        let scale = 1.0 + wanted[0].abs() + wanted[1].abs();
        for i in 0..2 {
            assert!(
                (sample.tau_star[i] - best[i]).abs() < 1e-7 * scale,
                "t = {}: applied {:?}, closest {best:?}, wanted {wanted:?}",
                sample.t,
                sample.tau_star
            );
        }
        assert_eq!(sample.projected, sample.tau_star != wanted[..]);
        acted += usize::from(sample.projected);
        // The joint torques applied are within the limit.
        for (row, b) in rows.iter().zip(&b) {
            let tau = row[0] * sample.tau_star[0] + row[1] * sample.tau_star[1] + b;
            assert!(tau.abs() <= limit * (1.0 + 1e-9), "t = {}: {tau}", sample.t);
        }
    }
    assert!(acted > 10, "{acted}");
}

#[test]
fn a_practically_free_joint_changes_no_projection() {
    // The base joint's limit far above any torque it meets (here never reached, so the run is
    // the one with 100 N m there) must leave the projection onto the other joints' limits as
    // it was: each limit is its own scale in the projection's tolerance.
    let limits = |base: f64| {
        let mut limits = vec![3.0; 10];
        limits[0] = base;
        limits
    };
    let (_, reference) = step_run(|s| s.joint_torque_limits = Some(limits(100.0))).unwrap();
    assert!(reference.iter().filter(|s| s.projected).count() > 10);
    for base in [1e12, 1e300] {
        let (_, samples) = step_run(|s| s.joint_torque_limits = Some(limits(base))).unwrap();
        assert_eq!(samples.len(), reference.len());
        for (sample, expected) in samples.iter().zip(&reference) {
            assert_eq!(sample.tau_star, expected.tau_star, "t = {}", sample.t);
        }
    }
}

#[test]
fn joint_angles_stay_within_their_limits() {
    let model = paper_model();
    let peak = |samples: &[ControlSample]| {
        let mut peaks = [0.0f64; 10];
        let mut theta = [0.0; 10];
        for s in samples {
            model.map().joint_angles(&s.state.a, &mut theta).unwrap();
            for (p, t) in peaks.iter_mut().zip(theta) {
                *p = p.max(t.abs());
            }
        }
        peaks
    };
    let (_, free) = step_run(|_| ()).unwrap();
    let free_peaks = peak(&free);
    // The base joint stands at pi/2; the others bend up to free_peaks[j]: limit them to 70 %.
    let mut limits: Vec<f64> = free_peaks.iter().map(|p| 0.7 * p).collect();
    limits[0] = 3.0;
    let (_, limited) = step_run(|s| s.joint_angle_limits = Some(limits.clone())).unwrap();
    let limited_peaks = peak(&limited);
    for j in 1..10 {
        assert!(free_peaks[j] > limits[j]);
        assert!(
            limited_peaks[j] <= limits[j] * (1.0 + 1e-6),
            "joint {}: {} > {}",
            j + 1,
            limited_peaks[j],
            limits[j]
        );
        // ... and approach them: the limit binds, the arm is not merely held back.
        assert!(limited_peaks[j] > 0.9 * limits[j], "joint {}", j + 1);
    }
    assert!(limited.iter().any(|s| s.projected));
}

#[test]
fn limits_that_cannot_hold_the_arm_stop_the_run_and_a_start_beyond_them_is_refused() {
    // 0.1 N m cannot hold the bent arm against gravity: no modal torque keeps all ten joints
    // within it.
    let error = refused(step_from([0.4, -0.3], |s| {
        s.joint_torque_limits = Some(vec![0.1; 10])
    }));
    assert!(matches!(error, SimError::JointLimits { .. }), "{error}");
    assert!(
        error.to_string().starts_with("joint limits at t = "),
        "{error}"
    );
    // The base joint starts at pi/2, beyond a limit of 1 rad.
    let error = refused(step_run(|s| s.joint_angle_limits = Some(vec![1.0; 10])));
    assert!(
        error
            .to_string()
            .starts_with("limits.joint_angle_rad is 1 rad for joint 1, which starts"),
        "{error}"
    );
    for (limits, message) in [
        (
            vec![1.0; 9],
            "limits.joint_angle_rad has 9 entries, the arm has 10 joints",
        ),
        (vec![-1.0; 10], "limits.joint_angle_rad must be positive"),
        (
            vec![2.0, 2.0, 2.0, -1.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0],
            "limits.joint_angle_rad[3] must be positive and finite, got -1",
        ),
    ] {
        let error = refused(step_run(|s| s.joint_angle_limits = Some(limits)));
        assert!(error.to_string().starts_with(message), "{error}");
    }
    let mut limits = vec![100.0; 10];
    limits[9] = f64::NAN;
    let error = refused(step_run(|s| s.joint_torque_limits = Some(limits)));
    assert_eq!(
        error.to_string(),
        "limits.joint_torque_nm[9] must be positive and finite, got NaN"
    );
}

/// The front ends' checks of coordinates and rates name the entry of one state or of a batch,
/// for a value beyond the scale a run resolves and for one that is not finite.
#[test]
fn front_end_coordinates_and_rates_name_the_entry() {
    let message = |r: Result<(), SimError>| r.unwrap_err().to_string();
    assert_eq!(
        message(sim_core::check_coordinates("a", &[0.1, f64::NAN], 2)),
        "a[1] must be finite, got NaN"
    );
    assert_eq!(
        message(sim_core::check_rates(
            "a_dot",
            &[0.0, 0.0, 0.0, f64::INFINITY],
            2
        )),
        "a_dot[1, 1] must be finite, got inf"
    );
    assert_eq!(
        message(sim_core::check_coordinates("a", &[-1e17], 1)),
        "a[0] must be at most 1000000 in magnitude (rad), got -1e17"
    );
    assert!(sim_core::check_coordinates("a", &[1e6, -1e6], 2).is_ok());
}
