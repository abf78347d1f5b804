//! Scenarios on a URDF arm (`[arm] urdf = "FILE.urdf"`): the full spatial chain in the
//! joint-space loop of [`sim_core::run_chain_loop`], computed torque tracking a joint-space
//! reference.

use super::arm::{ArmKind, Gravity};
use super::controllers::ControllerKind;
use super::schema::{Alpha0, ArmSpec, IntegratorSpec, NoiseSpec, ReferenceSpec, Scenario};
use manip_dyn::spatial::SpatialModel;
use sim_core::{ChainFailure, ChainLoopSettings, ChainRun, SimError, run_chain_loop};

/// The refusal of a scenario key a URDF arm does not use.
fn unused(name: &str, why: &str) -> SimError {
    SimError::setting(
        name,
        format!("is not used with a URDF arm ([arm] urdf): {why}"),
    )
}

impl Scenario {
    /// The first setting the joint-space loops (a URDF arm's and a deployment's) do not use,
    /// as `(name, why)`: sensor noise, a clearance margin, the modal controllers' keys (`fis`,
    /// `out_of_range`, `pd_*`, `lqr_*`), and any limit but `limits.max_modal_error` (and
    /// `limits.joint_torque_nm` when `torque_box`: the deployment MPC's box).
    pub(super) fn unused_by_joint_space_loops(
        &self,
        torque_box: bool,
    ) -> Option<(&'static str, &'static str)> {
        if self.noise != NoiseSpec::default() {
            return Some(("noise", "the joint-space loop is noise-free"));
        }
        if self.controller.clearance_m.is_some() {
            return Some((
                "controller.clearance_m",
                "the joint-space loop keeps no clearance margin (a deployment's channel is \
                 followed by its plan)",
            ));
        }
        // The modal controllers' own keys: the joint-space loop runs computed torque (`kp`,
        // `kd` per joint) or MPC.
        let c = &self.controller;
        if let Some((name, _)) = [
            ("controller.fis", c.fis.is_some()),
            ("controller.out_of_range", c.out_of_range.is_some()),
            ("controller.pd_kp", c.pd_kp.is_some()),
            ("controller.pd_kd", c.pd_kd.is_some()),
            ("controller.lqr_frequency", c.lqr_frequency.is_some()),
            ("controller.lqr_relinearise", c.lqr_relinearise.is_some()),
        ]
        .into_iter()
        .find(|(_, given)| *given)
        {
            return Some((
                name,
                "the joint-space loop runs computed torque (kp, kd per joint) or MPC, not the \
                 modal controllers this key sets",
            ));
        }
        // The first limit given that the loop does not keep, by its own key.
        [
            (
                "limits.joint_angle_rad",
                self.limits.joint_angle_rad.is_some(),
            ),
            ("limits.tau_star", self.limits.tau_star.is_some()),
            (
                "limits.joint_torque_nm",
                !torque_box && self.limits.joint_torque_nm.is_some(),
            ),
        ]
        .into_iter()
        .find(|(_, given)| *given)
        .map(|(name, _)| {
            let why = if torque_box {
                "only limits.joint_torque_nm (the MPC's box on the joint efforts) and \
                 limits.max_modal_error bound a joint-space MPC"
            } else {
                "only limits.max_modal_error bounds the joint errors"
            };
            (name, why)
        })
    }

    /// The dynamics model of the scenario's URDF arm (`arm.urdf`, a regular file of at most
    /// [`robot_desc::MAX_URDF_BYTES`]) under gravity `(0, 0, -arm.gravity)` (ROS's convention,
    /// 9.81 m/s^2 by default; or the vector `arm.gravity`), or `None` for a modal arm.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming `arm.urdf` for a file that cannot be read or is not
    /// a URDF serial chain with at least one movable joint, and naming a planar arm key given
    /// with it.
    pub fn urdf_model(&self) -> Result<Option<SpatialModel>, SimError> {
        Ok(self.urdf_arm()?.map(|(_, model)| model))
    }

    /// [`urdf_model`](Self::urdf_model) with the URDF's chain it was built from (its joints'
    /// `<limit>` and `<dynamics>`).
    ///
    /// # Errors
    /// As [`urdf_model`](Self::urdf_model).
    pub fn urdf_arm(&self) -> Result<Option<(robot_desc::Robot, SpatialModel)>, SimError> {
        let ArmSpec {
            urdf: Some(path),
            kind,
            joints,
            base,
            links,
            link_length,
            link_mass,
            gravity,
            lengths,
            masses,
            inertias,
            radius,
        } = &self.arm
        else {
            return Ok(None);
        };
        let planar = [
            ("arm.kind", *kind != ArmKind::Planar),
            ("arm.joints", joints.is_some()),
            ("arm.base", base.is_some()),
            ("arm.links", links.is_some()),
            ("arm.link_length", link_length.is_some()),
            ("arm.link_mass", link_mass.is_some()),
            ("arm.lengths", lengths.is_some()),
            ("arm.masses", masses.is_some()),
            ("arm.inertias", inertias.is_some()),
        ];
        if let Some((name, _)) = planar.iter().find(|(_, given)| *given) {
            return Err(unused(name, "the URDF describes the links"));
        }
        if radius.is_some() || !self.obstacles.is_empty() {
            return Err(unused(
                if radius.is_some() {
                    "arm.radius"
                } else {
                    "obstacles"
                },
                "the joint-space loop measures no clearance",
            ));
        }
        let invalid = |what: String| SimError::setting("arm.urdf", what);
        let text = crate::read_text_file(path, robot_desc::MAX_URDF_BYTES as u64)
            .map_err(|e| invalid(format!("cannot be read from {}: {e}", path.display())))?;
        let robot = robot_desc::read_urdf(&text)
            .map_err(|e| invalid(format!("({}): {e}", path.display())))?
            .robot;
        if robot.n_joints() == 0 {
            return Err(invalid(format!(
                "({}) has no movable joint (revolute, continuous or prismatic)",
                path.display()
            )));
        }
        let gravity = gravity.unwrap_or(Gravity::Magnitude(9.81));
        gravity.check()?;
        let gravity = gravity.spatial();
        let model = robot_desc::to_spatial(&robot, gravity)
            .map_err(|e| invalid(format!("({}): {e}", path.display())))?;
        Ok(Some((robot, model)))
    }

    /// Runs the scenario on its URDF arm: computed torque (`controller.kp`, `controller.kd`, one
    /// entry per joint, defaults 2500 and 100) every `controller.period` (default the RK4 step)
    /// tracking the reference in joint coordinates (`constant`, `step` or `sinusoid`, one entry
    /// per movable joint in chain order), from rest at `initial.a` (default the reference at
    /// `t = 0`), the plant integrated by RK4 with the ABA; `limits.max_modal_error` bounds each
    /// joint's error. `alpha0` and `modal` are not used.
    ///
    /// # Errors
    /// As [`urdf_model`](Self::urdf_model) (and [`SimError::InvalidSetting`] naming `arm.urdf`
    /// for a planar arm); [`SimError::InvalidSetting`] naming the key for a controller other
    /// than computed torque, the dopri5 integrator, a path reference, noise, torque limits or
    /// arrays of the wrong length; the run's errors ([`run_chain_loop`]), with the run up to the
    /// stop ([`ChainFailure`]).
    pub fn run_chain(&self) -> Result<ChainRun, ChainFailure> {
        let (robot, model) = self.urdf_arm()?.ok_or_else(|| {
            SimError::setting("arm.urdf", "is required to run a scenario in joint space")
        })?;
        let joint_limits = JointLimits::of(&robot)?;
        let n = model.n_links();
        if n > sim_core::MAX_COORDINATES {
            return Err(SimError::setting(
                "arm.urdf",
                format!(
                    "has {n} movable joints, more than the {} a joint-space run follows",
                    sim_core::MAX_COORDINATES
                ),
            )
            .into());
        }
        if self.controller.kind != ControllerKind::ComputedTorque {
            return Err(SimError::setting(
                "controller.kind",
                format!(
                    "must be \"computed-torque\" with a URDF arm ([arm] urdf: computed torque on \
                     the full chain in joint space is the only controller), got \"{}\"",
                    self.controller.kind
                ),
            )
            .into());
        }
        let IntegratorSpec::Rk4 { dt } = self.integrator else {
            return Err(unused(
                "integrator.method = \"dopri5\"",
                "the joint-space loop integrates by RK4",
            )
            .into());
        };
        if matches!(self.reference, ReferenceSpec::Path { .. }) {
            return Err(unused(
                "reference.kind = \"path\"",
                "a joint-space reference is constant, step or sinusoid",
            )
            .into());
        }
        if let Some((name, why)) = self.unused_by_joint_space_loops(false) {
            return Err(unused(name, why).into());
        }
        if self.modal.harmonics != 1 {
            return Err(unused(
                "modal.harmonics",
                "the chain's joints are its coordinates, no modal family",
            )
            .into());
        }
        let mut reference =
            self.reference
                .build(0.0, self.modal.harmonics, Alpha0::Fixed(0.0), n)?()?;
        let q0 = match &self.initial {
            Some(initial) => {
                if initial.a_dot.is_some() {
                    return Err(unused("initial.a_dot", "the chain starts at rest").into());
                }
                initial.a.clone()
            }
            None => {
                let mut sample = sim_core::reference::ReferenceSample::zeros(n);
                reference.sample(0.0, &mut sample)?;
                sample.a
            }
        };
        check_moves_mass(&robot, &model, &q0)?;
        let (kp, kd) = self.controller.computed_torque_gains(n)?;
        let period = self.controller_period()?;
        let settings = ChainLoopSettings {
            duration: self.duration,
            period,
            dt,
            record_period: self.record_period.unwrap_or(period),
            kp,
            kd,
            max_joint_error: self.limits.max_modal_error,
            effort_limits: joint_limits.efforts,
            position_limits: joint_limits.positions,
            damping: joint_limits.damping,
        };
        run_chain_loop(&model, reference.as_mut(), &q0, &settings)
    }
}

/// Refuses, before the run, a chain whose mass matrix is singular at the initial joint
/// positions `q0`: a joint that moves no mass or inertia there (every link beyond it massless,
/// or only point masses on its axis), which the forward dynamics could not integrate from
/// `t = 0`. Other problems of `q0` (its length, a value out of range) are the loop's to name.
///
/// # Errors
/// [`SimError::InvalidSetting`] naming `arm.urdf`, the joint (by its URDF name and its place
/// in the chain, counted from 1) and its child link.
fn check_moves_mass(
    robot: &robot_desc::Robot,
    model: &SpatialModel,
    q0: &[f64],
) -> Result<(), SimError> {
    match manip_dyn::spatial::singular_joint(model, q0) {
        Some(index) => {
            let joint = &robot.joints[index];
            Err(SimError::setting(
                "arm.urdf",
                format!(
                    "joint {} ({}): moves no mass or inertia at the initial positions (its link \
                     {} and every link beyond massless, or their masses on its axis), so the \
                     chain's mass matrix is singular: give a link beyond it a mass and inertia",
                    index + 1,
                    lane_math::one_line(&joint.name),
                    lane_math::one_line(&joint.child.name),
                ),
            ))
        }
        None => Ok(()),
    }
}

/// What the joint-space loop keeps of a URDF's `<limit>` and `<dynamics>`, one entry per
/// movable joint (each list empty when no joint sets it): the effort limits (`effort`; absent
/// or 0, urdfdom's default, for none), the position ranges ([`robot_desc::Joint::position_range`]:
/// a missing `lower` or `upper` is 0) and the viscous damping.
struct JointLimits {
    efforts: Vec<f64>,
    positions: Vec<[f64; 2]>,
    damping: Vec<f64>,
}

impl JointLimits {
    /// The limits of `robot`'s joints.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming `arm.urdf` and the joint for a dry friction
    /// (`<dynamics friction>` above 0), which the loop does not simulate.
    fn of(robot: &robot_desc::Robot) -> Result<Self, SimError> {
        let joints = &robot.joints;
        if let Some((i, joint, friction)) = joints.iter().enumerate().find_map(|(i, joint)| {
            let friction = joint.dynamics.and_then(|d| d.friction)?;
            (friction > 0.0).then_some((i, joint, friction))
        }) {
            return Err(SimError::setting(
                "arm.urdf",
                format!(
                    "joint {} ({}): <dynamics friction=\"{friction}\"> (dry friction) is not \
                     simulated by the joint-space loop: remove it or set it to 0",
                    i + 1,
                    lane_math::one_line(&joint.name),
                ),
            ));
        }
        let limit = |joint: &robot_desc::Joint| joint.limits.unwrap_or_default();
        let efforts: Vec<f64> = joints
            .iter()
            .map(|joint| match limit(joint).effort {
                Some(effort) if effort > 0.0 => effort,
                _ => f64::INFINITY,
            })
            .collect();
        let positions: Vec<[f64; 2]> = joints
            .iter()
            .map(robot_desc::Joint::position_range)
            .collect();
        let damping: Vec<f64> = joints
            .iter()
            .map(|joint| joint.dynamics.and_then(|d| d.damping).unwrap_or(0.0))
            .collect();
        let any = |values: &[f64], none: f64| values.iter().any(|&v| v != none);
        Ok(Self {
            efforts: if any(&efforts, f64::INFINITY) {
                efforts
            } else {
                Vec::new()
            },
            positions: if positions.iter().flatten().any(|v| v.is_finite()) {
                positions
            } else {
                Vec::new()
            },
            damping: if any(&damping, 0.0) {
                damping
            } else {
                Vec::new()
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    fn example(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/urdf-arm")
            .join(name)
    }

    #[test]
    fn the_example_step_converges_in_joint_space() {
        let scenario = Scenario::load(&example("step.toml")).unwrap();
        assert_eq!(
            scenario.arm.urdf,
            Some(std::fs::canonicalize(example("arm7.urdf")).unwrap())
        );
        let run = scenario.run_chain().unwrap();
        let summary = &run.summary;
        // e'' + 40 e' + 400 e = 0 after the step at 0.1 s: (1 + 20 t) exp(-20 t) of the step's
        // 1.1 rad norm after 0.9 s is 2e-7 rad; the zero-order hold leaves O(1e-4) of it.
        assert!(summary.final_error < 1e-5, "{summary:?}");
        let step = [0.5, 0.4, 0.3, 0.6, 0.2, 0.5, 0.4];
        for (max, jump) in summary.joint_error_max.iter().zip(step) {
            assert!((max - jump).abs() < 1e-9, "{max} vs {jump}");
        }
        assert!(
            summary
                .joint_error_rms
                .iter()
                .all(|e| e.is_finite() && *e > 0.0)
        );
        let sine = Scenario::load(&example("sine.toml"))
            .unwrap()
            .run_chain()
            .unwrap();
        assert!(sine.summary.final_error < 5e-3, "{:?}", sine.summary);
    }

    #[test]
    fn the_urdf_limits_and_damping_act_on_the_run() {
        // arm7.urdf's efforts: 150, 150, 80, 80, 40, 20, 10 N m; the sine asks more of joints
        // 2, 4 and 6, which saturate at theirs.
        let sine = Scenario::load(&example("sine.toml")).unwrap();
        let run = sine.run_chain().unwrap();
        let efforts = [150.0, 150.0, 80.0, 80.0, 40.0, 20.0, 10.0];
        let peaks = &run.summary.peak_joint_efforts;
        assert!(peaks.iter().zip(efforts).all(|(p, e)| *p <= e), "{peaks:?}");
        for joint in [1, 3, 5] {
            assert_eq!(peaks[joint], efforts[joint]);
        }
        assert!(run.summary.effort_limited_share > 0.0);
        // The same arm written with damping and with friction.
        let text = std::fs::read_to_string(example("arm7.urdf")).unwrap();
        let dir = std::env::temp_dir().join(format!("hrm-chain-dynamics-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let with = |dynamics: &str| {
            let path = dir.join("arm.urdf");
            let edited = text.replacen("</joint>", &format!("{dynamics}</joint>"), 1);
            std::fs::write(&path, edited).unwrap();
            let mut scenario = Scenario::load(&example("step.toml")).unwrap();
            scenario.arm.urdf = Some(path);
            scenario.run_chain()
        };
        let step = Scenario::load(&example("step.toml"))
            .unwrap()
            .run_chain()
            .unwrap();
        let damped = with("<dynamics damping=\"0.5\"/>").unwrap();
        assert_ne!(damped.record.q, step.record.q);
        // The last link and the tool welded to it without their inertials: refused before the
        // run, by name.
        let mut massless_tip = text.clone();
        for _ in 0..2 {
            let tip = massless_tip.rfind("<inertial>").unwrap();
            let end = massless_tip.rfind("</inertial>").unwrap() + "</inertial>".len();
            massless_tip.replace_range(tip..end, "");
        }
        std::fs::write(dir.join("tip.urdf"), &massless_tip).unwrap();
        let mut scenario = Scenario::load(&example("step.toml")).unwrap();
        scenario.arm.urdf = Some(dir.join("tip.urdf"));
        let e = scenario.run_chain().unwrap_err().to_string();
        assert!(
            e.starts_with("arm.urdf joint 7 (joint7): moves no mass or inertia at the initial"),
            "{e}"
        );
        let e = with("<dynamics friction=\"2\"/>").unwrap_err().to_string();
        assert!(
            e.starts_with("arm.urdf joint 1 (joint1): <dynamics friction=\"2\"> (dry friction)"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_urdf_arm_refuses_what_it_does_not_use() {
        let mut scenario = Scenario::load(&example("step.toml")).unwrap();
        let message = |s: &Scenario| s.run_chain().unwrap_err().to_string();
        scenario.controller.kind = ControllerKind::Fuzzy;
        assert!(message(&scenario).starts_with("controller.kind must be \"computed-torque\""));
        assert!(
            scenario
                .build()
                .err()
                .unwrap()
                .to_string()
                .starts_with("arm.urdf names a spatial")
        );
        scenario.controller.kind = ControllerKind::ComputedTorque;
        scenario.arm.links = Some(3);
        assert!(message(&scenario).starts_with("arm.links is not used with a URDF arm"));
        scenario.arm.links = None;
        scenario.controller.kp = Some(vec![1.0; 6]);
        assert!(
            message(&scenario).starts_with("controller.kp has 6 entries, the model has 7"),
            "{}",
            message(&scenario)
        );
        scenario.controller.kp = None;
        scenario.modal.harmonics = 3;
        assert_eq!(
            message(&scenario),
            "modal.harmonics is not used with a URDF arm ([arm] urdf): the chain's joints are \
             its coordinates, no modal family"
        );
        scenario.modal.harmonics = 1;
        scenario.arm.urdf = Some(example("missing.urdf"));
        assert!(message(&scenario).starts_with("arm.urdf cannot be read from"));
        scenario.arm.urdf = Some(example("step.toml"));
        assert!(
            message(&scenario).starts_with("arm.urdf ("),
            "{}",
            message(&scenario)
        );
        scenario.arm.urdf = Some(example(""));
        assert!(
            message(&scenario).contains("directory"),
            "{}",
            message(&scenario)
        );
    }
}
