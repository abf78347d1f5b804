//! From a scenario to a [`Simulation`]: the arm, the reduced model, the reference, the
//! controller and the loop's settings, every setting checked and named when it fails.

use super::arm::{ArmKind, Gravity, Inertias};
use super::controllers::{ControllerSetup, per_coordinate};
use super::schema::{
    Alpha0, AngleLimit, ArmSpec, BranchSpec, IntegratorSpec, ModalTorqueLimit, NoiseSpec,
    ReferenceSpec, Scenario, TaskSpec, TorqueLimit,
};
use backbone_kin::{Branch, ModalMap};
use fuzzy_sugeno::FuzzySystem;
use manip_dyn::{ChainModel, Link};
use modal_reduce::{PlantModel, ReducedModel};
use sim_core::controller::{Controller, MAX_CLEARANCE_MARGIN_M, ModalState, MpcLimits};
use sim_core::ode::Tolerances;
use sim_core::reference::{CartesianPath, PathShape, Sinusoid, Step};
use sim_core::{ControllerFactory, Integrator, LoopSettings, Prepared, ReferenceFactory, SimError};
use sim_core::{RunNoise, Simulation};
use std::sync::Arc;

impl Scenario {
    /// The reduced model of the arm with the scenario's modal family. Refuses a family with no
    /// harmonic or more coordinates than the arm has links (its reduced mass matrix would be
    /// singular), or one whose dynamics take more than [`MAX_LOOP_WORK`](sim_core::MAX_LOOP_WORK)
    /// per evaluation.
    pub fn model(&self) -> Result<ReducedModel, SimError> {
        let chain = self.arm.to_chain()?;
        let alpha0 = self.planar_alpha0()?;
        let k = self.modal.harmonics;
        if k == 0 {
            return Err(SimError::setting("modal.harmonics", "must be at least 1"));
        }
        let n = chain.n_links();
        if k > n {
            return Err(SimError::setting(
                "modal.harmonics",
                format!("must be at most the arm's {n} links, got {k}"),
            ));
        }
        let m = self.n_coords();
        if m > n {
            return Err(SimError::setting(
                "modal.harmonics",
                format!(
                    "= {k} gives {m} modal coordinates, more than the arm's {n} links: the \
                     reduced mass matrix would be singular"
                ),
            ));
        }
        sim_core::check_loop_work(n, m)?;
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let map = ModalMap::new(&lengths, k, alpha0.base_angle())?;
        ReducedModel::new(chain, map).map_err(SimError::Model)
    }

    /// The base inclination of a planar arm: `alpha0`, required.
    pub(super) fn planar_alpha0(&self) -> Result<Alpha0, SimError> {
        self.alpha0.ok_or_else(|| {
            SimError::setting(
                "alpha0",
                "is required for a planar arm: a base angle (rad) or \"free\"",
            )
        })
    }

    /// Prepares the simulation once for any number of runs that differ in seed and noise
    /// ([`Prepared`]): checks every setting and the whole reference path, loads the `.fis` file
    /// if any, builds the reference and the controller once. Errors name the setting that
    /// failed; the loop's own limits are [`Prepared::new`]'s. The scenario's own seed and noise
    /// are the prepared settings' ([`run_noise`](Self::run_noise) gives them).
    pub fn prepare(&self) -> Result<Prepared, SimError> {
        let (model, reference, controller, settings, initial) =
            self.assemble(None, |setup| setup.prepare())?;
        Prepared::new(model, reference, controller, settings, initial)
    }

    /// Prepares the simulation as [`prepare`](Self::prepare) does, with the fuzzy system
    /// `system` (e.g. one just learned, kept in memory) in place of the `.fis` file
    /// `controller.fis` names or the paper's: the controllers built on a fuzzy system (`fuzzy`,
    /// `pd`, `fuzzy-gc`) use it, the others ignore it.
    pub fn prepare_with_system(&self, system: &FuzzySystem) -> Result<Prepared, SimError> {
        let (model, reference, controller, settings, initial) =
            self.assemble(Some(system), |setup| setup.prepare())?;
        Prepared::new(model, reference, controller, settings, initial)
    }

    /// Builds the simulation with the scenario's own seed and noise: [`prepare`](Self::prepare)
    /// for one run.
    pub fn build(&self) -> Result<Simulation, SimError> {
        let prepared = self.prepare()?;
        prepared.simulation(&prepared.settings().noise())
    }

    /// Builds the simulation as [`build`](Self::build) does, with every controller the
    /// prepared simulation makes passed through `wrap` (e.g. a wrapper that stops the run when a
    /// Python user presses Ctrl-C).
    pub fn build_wrapping(
        &self,
        wrap: impl Fn(Box<dyn Controller>) -> Box<dyn Controller> + Send + Sync + 'static,
    ) -> Result<Simulation, SimError> {
        let (model, reference, controller, settings, initial) =
            self.assemble(None, |setup| setup.prepare())?;
        let controller: ControllerFactory = Arc::new(move || controller().map(&wrap));
        let prepared = Prepared::new(model, reference, controller, settings, initial)?;
        prepared.simulation(&prepared.settings().noise())
    }

    /// Builds the simulation as [`build`](Self::build) does, but closed by `controller` (a
    /// controller written elsewhere, e.g. in Python) instead of the one `controller.kind` names;
    /// `controller.period` still sets its sampling, and the other `[controller]` keys are unused.
    pub fn build_with_controller(
        &self,
        controller: Box<dyn Controller>,
    ) -> Result<Simulation, SimError> {
        let (model, reference, controller, settings, initial) =
            self.assemble(None, |_| Ok(controller))?;
        Simulation::new(model, reference()?, controller, settings, initial)
    }

    /// The clearance MPC plans to keep (m): `controller.clearance_m`, else the `[task]`'s
    /// `clearance`, else 0; `measured` is whether the scenario has links and obstacles to keep
    /// it between (`controller.clearance_m` is refused without them).
    fn clearance_margin(&self, measured: bool) -> Result<f64, SimError> {
        const FIELD: &str = "controller.clearance_m";
        let Some(margin) = self.controller.clearance_m else {
            return Ok(match &self.task {
                Some(TaskSpec::Reach { clearance, .. }) => *clearance,
                None => 0.0,
            });
        };
        if !measured {
            return Err(SimError::setting(
                FIELD,
                "is a margin to [[obstacles]] and between links: give obstacles or [arm] radius, \
                 or remove it",
            ));
        }
        if !(margin.is_finite() && (0.0..=MAX_CLEARANCE_MARGIN_M).contains(&margin)) {
            return Err(SimError::setting(
                FIELD,
                format!("must be non-negative and at most 1e3 m, got {margin}"),
            ));
        }
        Ok(margin)
    }

    /// The scenario's seed and noise ([`NoiseSpec::run_noise`]).
    pub fn run_noise(&self) -> Result<RunNoise, SimError> {
        self.noise.run_noise(self.seed, self.n_coords())
    }

    /// The scenario's parts: the model, a factory of its reference (built once), the
    /// controller `controller` makes from the setup (with the fuzzy system `system` if given),
    /// the loop's settings and the initial state.
    #[allow(clippy::type_complexity)]
    fn assemble<C>(
        &self,
        system: Option<&FuzzySystem>,
        controller: impl FnOnce(&ControllerSetup<'_>) -> Result<C, SimError>,
    ) -> Result<
        (
            PlantModel,
            ReferenceFactory,
            C,
            LoopSettings,
            Option<ModalState>,
        ),
        SimError,
    > {
        if self.deploy.is_some() {
            return Err(SimError::setting(
                "deploy",
                "runs in joint space with the arm's insertion axis (Scenario::run_deploy, as \
                 `hrm simulate` runs it), not in the modal loop",
            ));
        }
        let model = self.plant()?;
        let m = model.plant().n_coords();
        let period = self.controller_period()?;
        let mut settings = LoopSettings::new(self.integrator.build(), period, self.duration);
        settings.record_period = self.record_period.unwrap_or(period);
        let noise = self.run_noise()?;
        settings.seed = noise.seed;
        settings.reference_noise_std = noise.reference_std;
        settings.sensor_noise_std = noise.sensor_std;
        // One rule for `simulate` and `sweep`: a scenario's bound is finite, so that every
        // scenario that runs can also be written to a shard file (JSON has no infinity).
        if self.limits.max_modal_error == f64::INFINITY {
            return Err(SimError::setting(
                "limits.max_modal_error",
                "must be finite, got inf (a shard file cannot hold it): give a large bound such \
                 as 1e6 rad for no practical runaway check",
            ));
        }
        settings.max_modal_error = self.limits.max_modal_error;
        settings.joint_torque_limits = self.limits.joint_torque_nm.as_ref().map(|l| match l {
            TorqueLimit::All(limit) => vec![*limit; model.plant().n_joints()],
            TorqueLimit::PerJoint(limits) => limits.clone(),
        });
        settings.joint_angle_limits = self.limits.joint_angle_rad.as_ref().map(|l| match l {
            AngleLimit::All(limit) => vec![*limit; model.plant().n_joints()],
            AngleLimit::PerJoint(limits) => limits.clone(),
        });
        settings.clearance = self.clearance_model(model.plant().n_links(), self.workspace())?;
        settings.tau_star_limits = match &self.limits.tau_star {
            None => None,
            Some(ModalTorqueLimit::All(limit)) => Some(vec![*limit; m]),
            Some(ModalTorqueLimit::PerCoordinate(limits)) => {
                per_coordinate("limits.tau_star", Some(limits), m)?
            }
        };
        // The settings, the run's work among them, are checked before a [task]'s plan, which
        // may take seconds.
        settings.check(model.plant())?;
        let reference = match (self.planned_reference(&model)?, &model) {
            (Some(planned), _) => Prepared::reference_clones(planned),
            (None, PlantModel::Planar(planar)) => self.reference.build(
                planar.chain().total_length(),
                self.modal.harmonics,
                self.planar_alpha0()?,
                m,
            )?,
            (None, PlantModel::Spatial(spatial)) => self.spatial_reference(spatial)?,
        };
        let limits = MpcLimits {
            joint_torque_limits: settings.joint_torque_limits.clone(),
            joint_angle_limits: settings.joint_angle_limits.clone(),
            joint_angle_approach_s: sim_core::JOINT_ANGLE_APPROACH_S.max(period),
            clearance: settings.clearance.clone(),
            clearance_margin_m: self.clearance_margin(settings.clearance.is_some())?,
        };
        let controller = controller(&ControllerSetup {
            spec: &self.controller,
            model: &model,
            period,
            reference: &reference,
            system,
            limits: &limits,
        })?;
        let initial = match &self.initial {
            None => None,
            Some(i) => {
                let a = per_coordinate("initial.a", Some(&i.a), m)?.unwrap_or_default();
                let a_dot = per_coordinate("initial.a_dot", i.a_dot.as_deref(), m)?
                    .unwrap_or_else(|| vec![0.0; m]);
                Some(ModalState { a, a_dot })
            }
        };
        Ok((model, reference, controller, settings, initial))
    }

    /// The controller's sampling period (s): `controller.period`, or the RK4 step without it.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming `controller.period` when the `dopri5` integrator has
    /// none.
    pub fn controller_period(&self) -> Result<f64, SimError> {
        match (self.controller.period, self.integrator) {
            (Some(period), _) => Ok(period),
            (None, IntegratorSpec::Rk4 { dt }) => Ok(dt),
            (None, IntegratorSpec::Dopri5 { .. }) => Err(SimError::setting(
                "controller.period",
                "is required with the dopri5 integrator",
            )),
        }
    }
}

impl NoiseSpec {
    /// The noise with `seed` for `m` coordinates, one standard deviation per coordinate (`m` on
    /// the reference, `2m` on the sensors: the coordinates, then the rates; zeros where not
    /// given). The error names the noise field whose length is not `m`.
    pub fn run_noise(&self, seed: u64, m: usize) -> Result<RunNoise, SimError> {
        let noise = |name: &str, values: &Option<Vec<f64>>| {
            per_coordinate(name, values.as_deref(), m).map(|v| v.unwrap_or_else(|| vec![0.0; m]))
        };
        let reference_std = noise("noise.reference_std", &self.reference_std)?;
        let mut sensor_std = noise("noise.sensor_a_std", &self.sensor_a_std)?;
        sensor_std.extend(noise("noise.sensor_a_dot_std", &self.sensor_a_dot_std)?);
        Ok(RunNoise {
            seed,
            reference_std,
            sensor_std,
        })
    }
}

impl ArmSpec {
    /// The chain: `links` uniform beams of `link_length` and `link_mass` (the paper's by
    /// default), with per-link `lengths`, `masses` and `inertias` overriding; all given sizes must
    /// agree, and the arm has between 1 and [`manip_dyn::MAX_LINKS`] links, checked before any
    /// per-link array is allocated.
    pub fn to_chain(&self) -> Result<ChainModel, SimError> {
        if self.urdf.is_some() {
            return Err(SimError::setting(
                "arm.urdf",
                "names a spatial chain, which runs only in the joint-space loop \
                 (`hrm simulate --scenario FILE` runs it; Python and sweeps run modal arms), not as a planar arm",
            ));
        }
        if self.kind == ArmKind::Spatial {
            return Err(SimError::setting(
                "arm.kind",
                "is \"spatial\": a spatial arm's model is Scenario::spatial_model",
            ));
        }
        for (name, given) in [
            ("arm.joints", self.joints.is_some()),
            ("arm.base", self.base.is_some()),
        ] {
            if given {
                return Err(SimError::setting(
                    name,
                    "is used only by a spatial arm ([arm] kind = \"spatial\")",
                ));
            }
        }
        let gravity = match self.gravity {
            None => 9.81,
            Some(gravity @ Gravity::Magnitude(g)) => {
                gravity.check()?;
                g
            }
            Some(Gravity::Vector(_)) => {
                return Err(SimError::setting(
                    "arm.gravity",
                    "of a planar arm is a magnitude along -y (m/s^2), not a vector",
                ));
            }
        };
        let inertias = match &self.inertias {
            None => None,
            Some(Inertias::PerLink(values)) => Some(values),
            Some(Inertias::Principal(_)) => {
                return Err(SimError::setting(
                    "arm.inertias",
                    "of a planar arm gives one inertia per link (kg m^2, about the joint axis), \
                     not [Ixx, Iyy, Izz] triples",
                ));
            }
        };
        let n = self.link_count(inertias.map(Vec::len))?;
        let links = self.links(n, inertias.map(Vec::as_slice))?;
        ChainModel::new(links, gravity)
            .map_err(|e| SimError::setting("arm", format!("is invalid: {e}")))
    }

    /// The `n` links of `lengths` and `masses` (or `link_length` and `link_mass`, default 0.1 m
    /// and 0.1 kg), each checked as a uniform beam (`Link::uniform_beam`: positive and finite,
    /// with a beam inertia `m L^2 / 12` positive and finite in double precision, which bounds a
    /// link's length away from underflow and overflow), with the planar `inertias` about the
    /// joints replacing the beams' where given. A spatial arm's links are checked the same way.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the list entry or the scalar that is out of range, or
    /// the scalar given beside its list (`link_length` with `lengths`, `link_mass` with `masses`).
    pub(crate) fn links(&self, n: usize, inertias: Option<&[f64]>) -> Result<Vec<Link>, SimError> {
        const WHAT: &str = "the arm's per-link arrays";
        // A list and its scalar both given is ambiguous: the scalar would be silently unused.
        for (list, scalar, name, plural) in [
            (
                self.lengths.is_some(),
                self.link_length,
                "length",
                "lengths",
            ),
            (self.masses.is_some(), self.link_mass, "mass", "masses"),
        ] {
            if let (true, Some(value)) = (list, scalar) {
                return Err(SimError::setting(
                    format!("arm.link_{name}"),
                    format!(
                        "= {} is not used beside arm.{plural} (one per link): give arm.{plural} \
                         or arm.link_{name}, not both",
                        lane_math::Compact(value)
                    ),
                ));
            }
        }
        let per_link = |array: &Option<Vec<f64>>, scalar: f64| match array {
            Some(values) => Ok(values.clone()),
            None => lane_math::try_filled(n, scalar, WHAT),
        };
        let lengths = per_link(&self.lengths, self.link_length.unwrap_or(0.1))?;
        let masses = per_link(&self.masses, self.link_mass.unwrap_or(0.1))?;
        // A lone link has no index: name the link's real one, and the field the value came from.
        let arm_error = |i: usize, e: manip_dyn::DynError| {
            let field = match e {
                manip_dyn::DynError::InvalidLinkParameter {
                    quantity: "length", ..
                } => match self.lengths {
                    Some(_) => format!("arm.lengths[{i}]"),
                    None => "arm.link_length".to_string(),
                },
                manip_dyn::DynError::InvalidLinkParameter {
                    quantity: "mass", ..
                } => match self.masses {
                    Some(_) => format!("arm.masses[{i}]"),
                    None => "arm.link_mass".to_string(),
                },
                manip_dyn::DynError::InvalidLinkParameter {
                    quantity: "inertia",
                    ..
                } if inertias.is_some() => format!("arm.inertias[{i}]"),
                _ => "arm".to_string(),
            };
            SimError::setting(field, format!("is invalid: {}", e.at_link(i)))
        };
        let mut links = lane_math::try_with_capacity(n, WHAT)?;
        for i in 0..n {
            let beam = Link::uniform_beam(lengths[i], masses[i]).map_err(|e| arm_error(i, e))?;
            let link = match inertias {
                Some(inertias) => Link::new(beam.length, beam.mass, beam.com, inertias[i])
                    .map_err(|e| arm_error(i, e))?,
                None => beam,
            };
            links.push(link);
        }
        Ok(links)
    }

    /// The number of links: `links`, or the length of the per-link lists given (`lengths`,
    /// `masses`, and `inertias` of `inertias` entries), which must agree; 10 by default, at least
    /// 1 and at most [`manip_dyn::MAX_LINKS`]. Checked before any per-link array is allocated.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] naming the list whose count disagrees, or `arm.links`.
    pub fn link_count(&self, inertias: Option<usize>) -> Result<usize, SimError> {
        // The count and the field that gave it first.
        let mut n = self.links.map(|k| (k, "arm.links"));
        for (name, count) in [
            ("arm.lengths", self.lengths.as_ref().map(Vec::len)),
            ("arm.masses", self.masses.as_ref().map(Vec::len)),
            ("arm.inertias", inertias),
        ] {
            if let Some(count) = count {
                match n {
                    Some((k, _)) if k != count => {
                        return Err(SimError::setting(
                            name,
                            format!("has {count} entries but the arm has {k} links"),
                        ));
                    }
                    Some(_) => {}
                    None => n = Some((count, name)),
                }
            }
        }
        let (n, given_by) = n.unwrap_or((10, "arm.links"));
        if n == 0 {
            let problem = if given_by == "arm.links" {
                "must be at least 1"
            } else {
                "is empty: an arm has at least 1 link"
            };
            return Err(SimError::setting(given_by, problem));
        }
        if n > manip_dyn::MAX_LINKS {
            return Err(SimError::setting(
                "arm.links",
                format!("must be at most {}, got {n}", manip_dyn::MAX_LINKS),
            ));
        }
        Ok(n)
    }
}

impl ReferenceSpec {
    /// The reference of `m` coordinates for a curve of length `length` with `harmonics`
    /// harmonics and base angle `alpha0`, built once (a path's inverse kinematics solved
    /// once), and cloned for each run.
    pub(super) fn build(
        &self,
        length: f64,
        harmonics: usize,
        alpha0: Alpha0,
        m: usize,
    ) -> Result<ReferenceFactory, SimError> {
        let given = |name: &str, values: &[f64]| {
            per_coordinate(name, Some(values), m).map(Option::unwrap_or_default)
        };
        let or_zero = |name: &str, values: &Option<Vec<f64>>| {
            per_coordinate(name, values.as_deref(), m).map(|v| v.unwrap_or_else(|| vec![0.0; m]))
        };
        Ok(match self {
            ReferenceSpec::Constant { a } => {
                Prepared::reference_clones(Step::constant(&given("reference.a", a)?)?)
            }
            ReferenceSpec::Step {
                initial,
                target,
                time,
            } => Prepared::reference_clones(Step::new(
                &or_zero("reference.initial", initial)?,
                &given("reference.target", target)?,
                *time,
            )?),
            ReferenceSpec::Sinusoid {
                offset,
                amplitude,
                frequency_hz,
                phase,
            } => Prepared::reference_clones(Sinusoid::new(
                &or_zero("reference.offset", offset)?,
                &given("reference.amplitude", amplitude)?,
                &given("reference.frequency_hz", frequency_hz)?,
                &or_zero("reference.phase", phase)?,
            )?),
            ReferenceSpec::Planned { .. } => {
                return Err(SimError::setting(
                    "reference",
                    "of kind \"planned\" is built from the scenario's [task] (Scenario::plan)",
                ));
            }
            ReferenceSpec::Path {
                travel_time,
                branch,
                sine,
                points,
                helix,
            } => {
                if helix.is_some() {
                    return Err(SimError::setting(
                        "reference.helix",
                        "is a path in space, for a spatial arm ([arm] kind = \"spatial\"); a \
                         planar arm's path is a `sine` or `points`",
                    ));
                }
                let shape = match (sine, points) {
                    (Some(s), None) => PathShape::Sine {
                        amplitude: s.amplitude,
                        wavenumber: s.wavenumber,
                        phase: s.phase,
                        offset: s.offset,
                        x_start: s.x_start,
                        x_end: s.x_end,
                    },
                    (None, Some(points)) => PathShape::Polyline(points.clone()),
                    _ => {
                        return Err(SimError::setting(
                            "reference",
                            "of kind \"path\" needs exactly one of `sine` or `points`",
                        ));
                    }
                };
                let branch = match branch {
                    BranchSpec::Positive => Branch::Positive,
                    BranchSpec::Negative => Branch::Negative,
                };
                Prepared::reference_clones(CartesianPath::new(
                    shape,
                    *travel_time,
                    length,
                    harmonics,
                    alpha0.base_angle(),
                    branch,
                )?)
            }
        })
    }
}

impl IntegratorSpec {
    fn build(self) -> Integrator {
        match self {
            IntegratorSpec::Rk4 { dt } => Integrator::Rk4 { dt },
            IntegratorSpec::Dopri5 {
                rtol,
                atol,
                h_max,
                max_steps,
            } => {
                let defaults = Tolerances::default();
                Integrator::DormandPrince(Tolerances {
                    rtol,
                    atol,
                    h_max: h_max.unwrap_or(defaults.h_max),
                    max_steps: max_steps.unwrap_or(defaults.max_steps),
                    ..defaults
                })
            }
        }
    }
}
