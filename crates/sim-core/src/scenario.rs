//! Scenarios: a closed-loop experiment described in a TOML file (arm, `alpha0`, reference,
//! controller, integrator, step sizes, duration, noise, seed), and the paper's experiments
//! shipped with the crate.
//!
//! ```toml
//! name = "step"
//! duration = 2.0          # s
//! alpha0 = 1.5707963267948966
//! seed = 1
//! record_period = 0.001   # s, default: the controller period
//!
//! [arm]                   # defaults: the paper's 10 links of 0.1 m and 0.1 kg, g = 9.81
//! links = 10
//!
//! [reference]             # kind = "constant" | "step" | "sinusoid" | "path"
//! kind = "step"
//! initial = [0.0, 0.0]
//! target = [0.2, -0.2]
//! time = 0.1
//!
//! [controller]            # kind = "fuzzy" | "pd" | "computed-torque" | "fuzzy-gc"
//! kind = "fuzzy"
//! period = 0.0001         # s, default: the RK4 step
//!
//! [integrator]            # method = "rk4" (dt) | "dopri5" (rtol, atol, h_max, max_steps)
//! method = "rk4"
//! dt = 0.0001
//!
//! [noise]                 # standard deviations, default 0
//! reference_std = [0.0, 0.0]
//! sensor_a_std = [0.0, 0.0]
//! sensor_a_dot_std = [0.0, 0.0]
//!
//! [limits]
//! max_modal_error = 3.14  # rad, runaway bound
//! joint_torque_nm = 5.0   # or one limit per joint
//! ```

use crate::controller::{ComputedTorque, Controller, FuzzyController, ModalState, PdController};
use crate::error::SimError;
use crate::ode::Tolerances;
use crate::reference::{CartesianPath, PathShape, Reference, Sinusoid, Step};
use crate::simulation::{Integrator, LoopSettings, Simulation};
use backbone_kin::{BaseAngle, Branch, ModalMap};
use fuzzy_sugeno::FuzzySystem;
use manip_dyn::{ChainModel, Link};
use modal_reduce::ReducedModel;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The scenarios shipped with the crate, by name: the paper's experiments (section 5).
const BUILTIN: &[(&str, &str)] = &[
    (
        "paper-tracking",
        include_str!("../scenarios/paper-tracking.toml"),
    ),
    (
        "paper-responses-step",
        include_str!("../scenarios/paper-responses-step.toml"),
    ),
    (
        "paper-responses-sine",
        include_str!("../scenarios/paper-responses-sine.toml"),
    ),
    (
        "paper-responses-noise",
        include_str!("../scenarios/paper-responses-noise.toml"),
    ),
];

/// Why a scenario could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario file {path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        message: String,
    },
    /// The text is not a valid scenario; the message gives the line, column and problem.
    #[error("scenario {origin} is malformed: {message}")]
    Parse {
        /// The file or built-in name.
        origin: String,
        /// What is wrong, and where.
        message: String,
    },
    /// Neither a built-in scenario nor an existing file.
    #[error("'{name}' is neither a built-in scenario ({available}) nor a scenario file")]
    Unknown {
        /// The name asked for.
        name: String,
        /// The built-in names.
        available: String,
    },
}

/// A closed-loop experiment. Build it with [`Scenario::build`]; every field is public so that a
/// caller can adjust a loaded scenario (another controller, noise level or seed) before building.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name.
    pub name: String,
    /// What the scenario shows.
    #[serde(default)]
    pub description: String,
    /// Simulated time (s).
    pub duration: f64,
    /// The fixed base inclination `alpha0` (rad).
    pub alpha0: f64,
    /// Seed of the noise sources. TOML integers stop at `2^63 - 1`: larger seeds are written
    /// (and may be given) as a decimal string, `seed = "18446744073709551615"`.
    #[serde(default, with = "seed_text")]
    pub seed: u64,
    /// Recording period (s); default: the controller period.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record_period: Option<f64>,
    /// The arm.
    #[serde(default)]
    pub arm: ArmSpec,
    /// The initial state; default: at rest at the reference's value at `t = 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialSpec>,
    /// The reference for `(a1, a2)`.
    pub reference: ReferenceSpec,
    /// The controller.
    #[serde(default)]
    pub controller: ControllerSpec,
    /// The integrator.
    pub integrator: IntegratorSpec,
    /// Noise levels.
    #[serde(default)]
    pub noise: NoiseSpec,
    /// Runaway bound and torque limits.
    #[serde(default)]
    pub limits: LimitsSpec,
}

/// The arm: the paper's by default; per-link arrays override the scalars.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmSpec {
    /// Number of links (default 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub links: Option<usize>,
    /// Length of every link (m, default 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link_length: Option<f64>,
    /// Mass of every link (kg, default 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link_mass: Option<f64>,
    /// Gravitational acceleration along `-y` (m/s^2, default 9.81).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<f64>,
    /// Per-link lengths (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lengths: Option<Vec<f64>>,
    /// Per-link masses (kg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub masses: Option<Vec<f64>>,
    /// Per-link inertias about the centre of mass (kg m^2; default: uniform beams).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertias: Option<Vec<f64>>,
}

/// The initial modal state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// `(a1, a2)` (rad).
    pub a: [f64; 2],
    /// `(a1_dot, a2_dot)` (rad/s), default zero.
    #[serde(default)]
    pub a_dot: [f64; 2],
}

/// The reference for `(a1, a2)`, tagged by `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ReferenceSpec {
    /// A constant `a` (rad).
    Constant {
        /// The value.
        a: [f64; 2],
    },
    /// `initial` until `time` (s), then `target` (rad).
    Step {
        /// Before the step (default zero).
        #[serde(default)]
        initial: [f64; 2],
        /// After the step.
        target: [f64; 2],
        /// When (s, default 0).
        #[serde(default)]
        time: f64,
    },
    /// `offset + amplitude sin(2 pi frequency_hz t + phase)` per coordinate.
    Sinusoid {
        /// Offsets (rad, default zero).
        #[serde(default)]
        offset: [f64; 2],
        /// Amplitudes (rad).
        amplitude: [f64; 2],
        /// Frequencies (Hz).
        frequency_hz: [f64; 2],
        /// Phases (rad, default zero).
        #[serde(default)]
        phase: [f64; 2],
    },
    /// A tip path followed through the inverse kinematics: exactly one of `sine` or `points`.
    Path {
        /// Time along the path (s); the end point is held afterwards.
        travel_time: f64,
        /// Sign branch of `a1` (default positive, the paper's).
        #[serde(default)]
        branch: BranchSpec,
        /// `y = amplitude sin(wavenumber x + phase) + offset`, at constant speed in `x`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        sine: Option<SineSpec>,
        /// A polyline `[[x, y], ...]` (m), at constant speed along it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        points: Option<Vec<[f64; 2]>>,
    },
}

/// The sign branch of `a1` in the inverse kinematics (eq 6).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BranchSpec {
    /// `a1 >= 0`.
    #[default]
    Positive,
    /// `a1 <= 0`.
    Negative,
}

/// A sine tip path `y = amplitude sin(wavenumber x + phase) + offset`, `x` from `x_start` to
/// `x_end`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SineSpec {
    /// Amplitude (m).
    pub amplitude: f64,
    /// Wavenumber (rad/m).
    pub wavenumber: f64,
    /// Phase (rad, default 0).
    #[serde(default)]
    pub phase: f64,
    /// Offset (m, default 0).
    #[serde(default)]
    pub offset: f64,
    /// First `x` (m).
    pub x_start: f64,
    /// Last `x` (m).
    pub x_end: f64,
}

/// Which controller closes the loop.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ControllerKind {
    /// The paper's fuzzy controller, or the `.fis` system given.
    #[default]
    Fuzzy,
    /// The fuzzy controller's linearisation at the origin ([`PdController::from_fuzzy_slope`]).
    Pd,
    /// Computed torque with the exact reduced model ([`ComputedTorque`]).
    ComputedTorque,
    /// The fuzzy controller plus gravity compensation `G*`.
    FuzzyGc,
}

impl ControllerKind {
    /// Every controller, in the order of the paper's comparison.
    pub const ALL: [ControllerKind; 4] = [
        ControllerKind::Fuzzy,
        ControllerKind::Pd,
        ControllerKind::ComputedTorque,
        ControllerKind::FuzzyGc,
    ];

    /// The name used in scenario files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ControllerKind::Fuzzy => "fuzzy",
            ControllerKind::Pd => "pd",
            ControllerKind::ComputedTorque => "computed-torque",
            ControllerKind::FuzzyGc => "fuzzy-gc",
        }
    }
}

impl fmt::Display for ControllerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ControllerKind {
    type Err = SimError;

    /// Parses `fuzzy`, `pd`, `computed-torque` or `fuzzy-gc`.
    fn from_str(s: &str) -> Result<Self, SimError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                SimError::setting(
                    "controller",
                    format!("must be one of fuzzy, pd, computed-torque, fuzzy-gc, got '{s}'"),
                )
            })
    }
}

/// The controller and its sampling.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// Which controller (default fuzzy).
    #[serde(default)]
    pub kind: ControllerKind,
    /// Sampling period (s); default: the RK4 step (required with `dopri5`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// A `.fis` file replacing the paper's fuzzy system (for fuzzy, pd and fuzzy-gc); a relative
    /// path is relative to the scenario file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fis: Option<PathBuf>,
    /// Computed-torque stiffness per coordinate (1/s^2, default 2500: 50 rad/s).
    #[serde(default = "default_kp")]
    pub kp: [f64; 2],
    /// Computed-torque damping per coordinate (1/s, default 100: critically damped).
    #[serde(default = "default_kd")]
    pub kd: [f64; 2],
}

fn default_kp() -> [f64; 2] {
    [2500.0; 2]
}

fn default_kd() -> [f64; 2] {
    [100.0; 2]
}

impl Default for ControllerSpec {
    fn default() -> Self {
        Self {
            kind: ControllerKind::default(),
            period: None,
            fis: None,
            kp: default_kp(),
            kd: default_kd(),
        }
    }
}

/// The integrator between controller samples, tagged by `method`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "kebab-case", deny_unknown_fields)]
pub enum IntegratorSpec {
    /// Fixed-step RK4.
    Rk4 {
        /// The step (s).
        dt: f64,
    },
    /// Adaptive Dormand-Prince 5(4).
    Dopri5 {
        /// Relative tolerance (default 1e-9).
        #[serde(default = "default_rtol")]
        rtol: f64,
        /// Absolute tolerance (default 1e-12).
        #[serde(default = "default_atol")]
        atol: f64,
        /// Largest step (s, default unbounded).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        h_max: Option<f64>,
        /// Most steps per controller period (default 1,000,000).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        max_steps: Option<usize>,
    },
}

fn default_rtol() -> f64 {
    1e-9
}

fn default_atol() -> f64 {
    1e-12
}

/// Standard deviations of the seeded Gaussian noise (all default to zero).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// On the reference `(a1_ref, a2_ref)` the controller receives (rad).
    #[serde(default)]
    pub reference_std: [f64; 2],
    /// On the measured `(a1, a2)` (rad).
    #[serde(default)]
    pub sensor_a_std: [f64; 2],
    /// On the measured `(a1_dot, a2_dot)` (rad/s).
    #[serde(default)]
    pub sensor_a_dot_std: [f64; 2],
}

/// The runaway bound and optional joint torque limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// The run stops when `|a_i - a_i_ref|` exceeds this (rad, default pi).
    #[serde(default = "default_max_modal_error")]
    pub max_modal_error: f64,
    /// Joint torque limits (N m): one for all joints or one per joint; exceeding is reported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_torque_nm: Option<TorqueLimit>,
}

fn default_max_modal_error() -> f64 {
    std::f64::consts::PI
}

impl Default for LimitsSpec {
    fn default() -> Self {
        Self {
            max_modal_error: default_max_modal_error(),
            joint_torque_nm: None,
        }
    }
}

/// A torque limit for every joint, or one per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum TorqueLimit {
    /// The same limit for every joint (N m).
    All(f64),
    /// One limit per joint, base first (N m).
    PerJoint(Vec<f64>),
}

impl Scenario {
    /// Parses a scenario from TOML text.
    ///
    /// ```
    /// let scenario = sim_core::Scenario::from_toml(r#"
    ///     name = "hold"
    ///     duration = 0.1
    ///     alpha0 = 1.0
    ///     reference = { kind = "constant", a = [0.3, -0.2] }
    ///     integrator = { method = "rk4", dt = 1e-3 }
    /// "#)?;
    /// let run = scenario.build()?.run()?;
    /// assert_eq!(run.summary.controller_samples, 101);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_toml(text: &str) -> Result<Self, ScenarioError> {
        parse(text, "text")
    }

    /// Reads a scenario file; a relative `controller.fis` path is taken relative to the file.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = crate::read_text_file(path, crate::MAX_INPUT_FILE_BYTES).map_err(|e| {
            ScenarioError::Io {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })?;
        let mut scenario = parse(&text, &path.display().to_string())?;
        if let (Some(fis), Some(dir)) = (&scenario.controller.fis, path.parent())
            && fis.is_relative()
        {
            scenario.controller.fis = Some(dir.join(fis));
        }
        Ok(scenario)
    }

    /// A scenario shipped with the crate, by name (see [`Scenario::builtin_names`]).
    ///
    /// ```
    /// let scenario = sim_core::Scenario::builtin("paper-tracking")?;
    /// assert_eq!(scenario.duration, 5.5);
    /// # Ok::<(), sim_core::ScenarioError>(())
    /// ```
    pub fn builtin(name: &str) -> Result<Self, ScenarioError> {
        match BUILTIN.iter().find(|(n, _)| *n == name) {
            Some((name, text)) => parse(text, name),
            None => Err(unknown(name)),
        }
    }

    /// The names of the shipped scenarios: `paper-tracking` (Figures 10-11) and the
    /// `paper-responses-*` step, sine and noise responses (Figure 9).
    pub fn builtin_names() -> impl Iterator<Item = &'static str> {
        BUILTIN.iter().map(|(name, _)| *name)
    }

    /// The TOML text of a shipped scenario.
    pub fn builtin_text(name: &str) -> Option<&'static str> {
        BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }

    /// A built-in scenario by name, or else a scenario file at that path.
    pub fn resolve(name_or_path: &str) -> Result<Self, ScenarioError> {
        if Self::builtin_text(name_or_path).is_some() {
            return Self::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        if path.is_file() {
            Self::load(path)
        } else {
            Err(unknown(name_or_path))
        }
    }

    /// The scenario as TOML (it parses back to an equal scenario).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a scenario serialises to TOML")
    }

    /// The reduced model of the arm with `alpha0` fixed: coordinates `(a1, a2)`.
    pub fn model(&self) -> Result<ReducedModel, SimError> {
        let chain = self.arm.to_chain()?;
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let map = ModalMap::new(&lengths, 1, BaseAngle::Fixed(self.alpha0))?;
        ReducedModel::new(chain, map).map_err(SimError::Model)
    }

    /// Builds the simulation: checks every setting and the whole reference path, loads the
    /// `.fis` file if any. Errors name the setting that failed; the loop's own limits are
    /// [`Simulation::new`]'s.
    pub fn build(&self) -> Result<Simulation, SimError> {
        let model = self.model()?;
        let reference = self
            .reference
            .build(model.chain().total_length(), self.alpha0)?;
        let controller = self.controller.build(&model)?;
        let period = match (self.controller.period, self.integrator) {
            (Some(period), _) => period,
            (None, IntegratorSpec::Rk4 { dt }) => dt,
            (None, IntegratorSpec::Dopri5 { .. }) => {
                return Err(SimError::setting(
                    "controller.period",
                    "is required with the dopri5 integrator",
                ));
            }
        };
        let mut settings = LoopSettings::new(self.integrator.build(), period, self.duration);
        settings.record_period = self.record_period.unwrap_or(period);
        settings.seed = self.seed;
        settings.reference_noise_std = self.noise.reference_std;
        let [a1, a2] = self.noise.sensor_a_std;
        let [v1, v2] = self.noise.sensor_a_dot_std;
        settings.sensor_noise_std = [a1, a2, v1, v2];
        settings.max_modal_error = self.limits.max_modal_error;
        settings.joint_torque_limits = self.limits.joint_torque_nm.as_ref().map(|l| match l {
            TorqueLimit::All(limit) => vec![*limit; model.n_links()],
            TorqueLimit::PerJoint(limits) => limits.clone(),
        });
        let initial = self.initial.map(|i| ModalState {
            a: i.a,
            a_dot: i.a_dot,
        });
        Simulation::new(model, reference, controller, settings, initial)
    }
}

impl ArmSpec {
    /// The chain: `links` uniform beams of `link_length` and `link_mass` (the paper's by
    /// default), with per-link `lengths`, `masses` and `inertias` overriding; all given sizes must
    /// agree, and the arm has between 1 and [`manip_dyn::MAX_LINKS`] links, checked before any
    /// per-link array is allocated.
    pub fn to_chain(&self) -> Result<ChainModel, SimError> {
        let mut n = self.links;
        for (name, array) in [
            ("arm.lengths", &self.lengths),
            ("arm.masses", &self.masses),
            ("arm.inertias", &self.inertias),
        ] {
            if let Some(values) = array {
                match n {
                    Some(k) if k != values.len() => {
                        return Err(SimError::setting(
                            name,
                            format!("has {} entries but the arm has {k} links", values.len()),
                        ));
                    }
                    _ => n = Some(values.len()),
                }
            }
        }
        let n = n.unwrap_or(10);
        if n == 0 {
            return Err(SimError::setting("arm.links", "must be at least 1"));
        }
        if n > manip_dyn::MAX_LINKS {
            return Err(SimError::setting(
                "arm.links",
                format!("must be at most {}, got {n}", manip_dyn::MAX_LINKS),
            ));
        }
        let per_link = |array: &Option<Vec<f64>>, scalar: f64| match array {
            Some(values) => values.clone(),
            None => vec![scalar; n],
        };
        let lengths = per_link(&self.lengths, self.link_length.unwrap_or(0.1));
        let masses = per_link(&self.masses, self.link_mass.unwrap_or(0.1));
        // A lone link has no index: name the link's real one.
        let arm_error = |i: usize, e: manip_dyn::DynError| {
            SimError::setting("arm", format!("is invalid: {}", e.at_link(i)))
        };
        let mut links = Vec::with_capacity(n);
        for i in 0..n {
            let beam = Link::uniform_beam(lengths[i], masses[i]).map_err(|e| arm_error(i, e))?;
            let link = match &self.inertias {
                Some(inertias) => Link::new(beam.length, beam.mass, beam.com, inertias[i])
                    .map_err(|e| arm_error(i, e))?,
                None => beam,
            };
            links.push(link);
        }
        ChainModel::new(links, self.gravity.unwrap_or(9.81))
            .map_err(|e| SimError::setting("arm", format!("is invalid: {e}")))
    }
}

impl ReferenceSpec {
    /// The reference for a curve of length `length` with base angle `alpha0`.
    fn build(&self, length: f64, alpha0: f64) -> Result<Box<dyn Reference>, SimError> {
        Ok(match self {
            ReferenceSpec::Constant { a } => Box::new(Step::constant(*a)?),
            ReferenceSpec::Step {
                initial,
                target,
                time,
            } => Box::new(Step::new(*initial, *target, *time)?),
            ReferenceSpec::Sinusoid {
                offset,
                amplitude,
                frequency_hz,
                phase,
            } => Box::new(Sinusoid::new(*offset, *amplitude, *frequency_hz, *phase)?),
            ReferenceSpec::Path {
                travel_time,
                branch,
                sine,
                points,
            } => {
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
                Box::new(CartesianPath::new(
                    shape,
                    *travel_time,
                    length,
                    alpha0,
                    branch,
                )?)
            }
        })
    }
}

impl ControllerSpec {
    /// The fuzzy system: the `.fis` file if given, else the paper's.
    fn fuzzy_system(&self) -> Result<FuzzySystem, SimError> {
        match &self.fis {
            None => Ok(fuzzy_sugeno::paper_controller()),
            Some(path) => {
                let text =
                    crate::read_text_file(path, crate::MAX_INPUT_FILE_BYTES).map_err(|e| {
                        SimError::setting(
                            "controller.fis",
                            format!("cannot be read from {}: {e}", path.display()),
                        )
                    })?;
                Ok(FuzzySystem::from_fis(&text)?)
            }
        }
    }

    /// The controller for `model`.
    fn build(&self, model: &ReducedModel) -> Result<Box<dyn Controller>, SimError> {
        Ok(match self.kind {
            ControllerKind::Fuzzy => Box::new(FuzzyController::new(self.fuzzy_system()?)?),
            ControllerKind::Pd => Box::new(PdController::from_fuzzy_slope(&self.fuzzy_system()?)?),
            ControllerKind::ComputedTorque => {
                Box::new(ComputedTorque::new(model.clone(), self.kp, self.kd)?)
            }
            ControllerKind::FuzzyGc => Box::new(
                FuzzyController::new(self.fuzzy_system()?)?
                    .with_gravity_compensation(model.clone())?,
            ),
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

/// A `u64` seed as a TOML integer when it fits one (`i64`), else as a decimal string.
mod seed_text {
    use serde::de::{Error, Visitor};
    use serde::{Deserializer, Serializer};
    use std::fmt;

    pub fn serialize<S: Serializer>(seed: &u64, serializer: S) -> Result<S::Ok, S::Error> {
        match i64::try_from(*seed) {
            Ok(seed) => serializer.serialize_i64(seed),
            Err(_) => serializer.serialize_str(&seed.to_string()),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<u64, D::Error> {
        deserializer.deserialize_any(SeedVisitor)
    }

    struct SeedVisitor;

    impl Visitor<'_> for SeedVisitor {
        type Value = u64;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str(
                "a seed: an integer from 0 to 18446744073709551615 (as a string above 2^63 - 1)",
            )
        }

        fn visit_u64<E: Error>(self, seed: u64) -> Result<u64, E> {
            Ok(seed)
        }

        fn visit_i64<E: Error>(self, seed: i64) -> Result<u64, E> {
            u64::try_from(seed)
                .map_err(|_| E::custom(format!("seed must not be negative, got {seed}")))
        }

        fn visit_str<E: Error>(self, seed: &str) -> Result<u64, E> {
            seed.parse().map_err(|_| {
                E::custom(format!(
                    "seed must be an integer from 0 to {}, got \"{seed}\"",
                    u64::MAX
                ))
            })
        }
    }
}

/// Parses scenario text; a refusal is one line: `line L, column C (`<that line>`): <what is
/// wrong>` (toml's own message spans several lines around the quoted text).
fn parse(text: &str, origin: &str) -> Result<Scenario, ScenarioError> {
    toml::from_str(text).map_err(|e| {
        let what = e.message().trim_end().replace('\n', "; ");
        let message = match e.span() {
            Some(span) => {
                let mut end = span.start.min(text.len());
                while !text.is_char_boundary(end) {
                    end -= 1;
                }
                let before = &text[..end];
                let line = before.matches('\n').count() + 1;
                let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
                let quoted: String = text
                    .lines()
                    .nth(line - 1)
                    .unwrap_or_default()
                    .trim()
                    .chars()
                    .take(80)
                    .collect();
                format!("line {line}, column {column} (`{quoted}`): {what}")
            }
            None => what,
        };
        ScenarioError::Parse {
            origin: origin.to_string(),
            message,
        }
    })
}

fn unknown(name: &str) -> ScenarioError {
    ScenarioError::Unknown {
        name: name.to_string(),
        available: BUILTIN
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(", "),
    }
}
