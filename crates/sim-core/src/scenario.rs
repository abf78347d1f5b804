//! Scenarios: a closed-loop experiment described in a TOML file (arm, `alpha0`, reference,
//! controller, integrator, step sizes, duration, noise, seed), and the paper's experiments
//! shipped with the crate.
//!
//! Required keys: `name`, `duration`, `alpha0`, `reference` (with its `kind` and that kind's
//! required keys) and `integrator` (with its `method`); everything else has a default. Every
//! per-coordinate array (`initial`, `reference`, `noise`, the controller gains) has exactly `m`
//! entries, the number of modal coordinates: `2K` with `alpha0` fixed, `2K + 1` with `alpha0`
//! free (its last entry is then `alpha0`'s).
//!
//! ```toml
//! name = "step"
//! duration = 2.0          # s
//! alpha0 = 1.5707963267948966   # rad, or "free": alpha0 is the last modal coordinate
//! seed = 1
//! record_period = 0.001   # s, default: the controller period
//!
//! [modal]                 # the modal family, default: the paper's K = 1
//! harmonics = 1
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
//! # kp = [2500.0, 2500.0]   computed torque (1/s^2), kd = [100.0, 100.0] (1/s)
//! # pd_kp = [600.0, 300.0]  PD (N m/rad), pd_kd = [20.0, 10.0] (N m s/rad); default: fuzzy slope
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

/// The scenarios shipped with the crate, by name: the paper's experiments (section 5), then the
/// paper's tracking task with two harmonics and with `alpha0` free.
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
    (
        "harmonic-tracking",
        include_str!("../scenarios/harmonic-tracking.toml"),
    ),
    (
        "free-base-tracking",
        include_str!("../scenarios/free-base-tracking.toml"),
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
    /// The base inclination `alpha0`: fixed (rad) or free (the last modal coordinate).
    pub alpha0: Alpha0,
    /// Seed of the noise sources. TOML integers stop at `2^63 - 1`: larger seeds are written
    /// (and may be given) as a decimal string, `seed = "18446744073709551615"`.
    #[serde(default, with = "seed_text")]
    pub seed: u64,
    /// Recording period (s); default: the controller period.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record_period: Option<f64>,
    /// The modal family (default: the paper's `K = 1`).
    #[serde(default)]
    pub modal: ModalSpec,
    /// The arm.
    #[serde(default)]
    pub arm: ArmSpec,
    /// The initial state; default: at rest at the reference's value at `t = 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<InitialSpec>,
    /// The reference for the modal coordinates.
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

/// The base inclination `alpha0` of a scenario: a number (fixed, in rad) or `"free"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Alpha0 {
    /// Held at this angle (rad); not a coordinate.
    Fixed(f64),
    /// A modal coordinate, the last one.
    Free,
}

impl Alpha0 {
    /// As a [`BaseAngle`] of the modal map.
    pub fn base_angle(self) -> BaseAngle {
        match self {
            Alpha0::Fixed(alpha0) => BaseAngle::Fixed(alpha0),
            Alpha0::Free => BaseAngle::Free,
        }
    }
}

impl Serialize for Alpha0 {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Alpha0::Fixed(alpha0) => serializer.serialize_f64(*alpha0),
            Alpha0::Free => serializer.serialize_str("free"),
        }
    }
}

impl<'de> Deserialize<'de> for Alpha0 {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = Alpha0;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("alpha0: a number (rad) or \"free\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Alpha0, E> {
                Ok(Alpha0::Fixed(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Alpha0, E> {
                Ok(Alpha0::Fixed(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Alpha0, E> {
                Ok(Alpha0::Fixed(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Alpha0, E> {
                if v == "free" {
                    Ok(Alpha0::Free)
                } else {
                    Err(E::custom(format!(
                        "alpha0 must be a number (rad) or \"free\", got \"{v}\""
                    )))
                }
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

/// The modal family: `K` harmonics (`m = 2K` coordinates with `alpha0` fixed, `2K + 1` free).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModalSpec {
    /// The number of harmonics `K` (default 1, the paper's).
    #[serde(default = "default_harmonics")]
    pub harmonics: usize,
}

fn default_harmonics() -> usize {
    1
}

impl Default for ModalSpec {
    fn default() -> Self {
        Self {
            harmonics: default_harmonics(),
        }
    }
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

/// The initial modal state (`m` entries each).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// The coordinates (rad).
    pub a: Vec<f64>,
    /// Their rates (rad/s), default zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a_dot: Option<Vec<f64>>,
}

/// The reference for the `m` modal coordinates, tagged by `kind`; every array has `m` entries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ReferenceSpec {
    /// A constant `a` (rad).
    Constant {
        /// The value.
        a: Vec<f64>,
    },
    /// `initial` until `time` (s), then `target` (rad).
    Step {
        /// Before the step (default zero).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        initial: Option<Vec<f64>>,
        /// After the step.
        target: Vec<f64>,
        /// When (s, default 0).
        #[serde(default)]
        time: f64,
    },
    /// `offset + amplitude sin(2 pi frequency_hz t + phase)` per coordinate.
    Sinusoid {
        /// Offsets (rad, default zero).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        offset: Option<Vec<f64>>,
        /// Amplitudes (rad).
        amplitude: Vec<f64>,
        /// Frequencies (Hz).
        frequency_hz: Vec<f64>,
        /// Phases (rad, default zero).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        phase: Option<Vec<f64>>,
    },
    /// A tip path followed through the inverse kinematics of the modal family (closed form for
    /// `K = 1` with `alpha0` fixed, numerical continuation otherwise, see
    /// [`CartesianPath`]): exactly one of `sine` or `points`.
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
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
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
    /// Computed-torque stiffness per coordinate (1/s^2, default 2500 each: 50 rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kp: Option<Vec<f64>>,
    /// Computed-torque damping per coordinate (1/s, default 100 each: critically damped).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kd: Option<Vec<f64>>,
    /// PD stiffness per coordinate (N m/rad); default: the fuzzy system's slope at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_kp: Option<Vec<f64>>,
    /// PD damping per coordinate (N m s/rad); default: the fuzzy system's slope at the origin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_kd: Option<Vec<f64>>,
}

/// The default computed-torque stiffness (1/s^2): 50 rad/s.
const DEFAULT_KP: f64 = 2500.0;
/// The default computed-torque damping (1/s): critically damped with [`DEFAULT_KP`].
const DEFAULT_KD: f64 = 100.0;

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

/// Standard deviations of the seeded Gaussian noise, `m` entries each (all default to zero).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// On the reference `a_ref` the controller receives (rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_std: Option<Vec<f64>>,
    /// On the measured coordinates `a` (rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_a_std: Option<Vec<f64>>,
    /// On the measured rates `a_dot` (rad/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor_a_dot_std: Option<Vec<f64>>,
}

impl NoiseSpec {
    /// The same noise level on every one of `m` coordinates: `sensor` rad on `a`, `rate` rad/s
    /// on `a_dot`, `reference` rad on `a_ref`.
    pub fn uniform(m: usize, sensor: f64, rate: f64, reference: f64) -> Self {
        Self {
            reference_std: Some(vec![reference; m]),
            sensor_a_std: Some(vec![sensor; m]),
            sensor_a_dot_std: Some(vec![rate; m]),
        }
    }
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

    /// The names of the shipped scenarios: `paper-tracking` (Figures 10-11), the
    /// `paper-responses-*` step, sine and noise responses (Figure 9), and the tracking task for
    /// other modal families: `harmonic-tracking` (`K = 2`, `m = 4`) and `free-base-tracking`
    /// (`alpha0` free, `m = 3`).
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

    /// The number of modal coordinates `m`: `2K` with `alpha0` fixed, `2K + 1` with it free
    /// (saturating, for a scenario read from a file whose `harmonics` is not yet validated).
    pub fn n_coords(&self) -> usize {
        self.modal
            .harmonics
            .saturating_mul(2)
            .saturating_add(usize::from(self.alpha0 == Alpha0::Free))
    }

    /// The names of the modal coordinates, in order: `a1, ..., a{2K}`, then `alpha0` when it is
    /// free (the column names of the outputs).
    ///
    /// ```
    /// let mut scenario = sim_core::Scenario::builtin("paper-tracking")?;
    /// assert_eq!(scenario.coordinate_names(), ["a1", "a2"]);
    /// scenario.alpha0 = sim_core::Alpha0::Free;
    /// assert_eq!(scenario.coordinate_names(), ["a1", "a2", "alpha0"]);
    /// # Ok::<(), sim_core::ScenarioError>(())
    /// ```
    pub fn coordinate_names(&self) -> Vec<String> {
        let mut names: Vec<String> = (1..=2 * self.modal.harmonics)
            .map(|i| format!("a{i}"))
            .collect();
        if self.alpha0 == Alpha0::Free {
            names.push("alpha0".into());
        }
        names
    }

    /// The reduced model of the arm with the scenario's modal family. Refuses a family with no
    /// harmonic or more coordinates than the arm has links (its reduced mass matrix would be
    /// singular).
    pub fn model(&self) -> Result<ReducedModel, SimError> {
        let chain = self.arm.to_chain()?;
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
        let lengths: Vec<f64> = chain.link_lengths().collect();
        let map = ModalMap::new(&lengths, k, self.alpha0.base_angle())?;
        ReducedModel::new(chain, map).map_err(SimError::Model)
    }

    /// Builds the simulation: checks every setting and the whole reference path, loads the
    /// `.fis` file if any. Errors name the setting that failed; the loop's own limits are
    /// [`Simulation::new`]'s.
    pub fn build(&self) -> Result<Simulation, SimError> {
        let model = self.model()?;
        let m = model.n_coords();
        let reference = self.reference.build(
            model.chain().total_length(),
            self.modal.harmonics,
            self.alpha0,
            m,
        )?;
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
        let noise = |name: &str, values: &Option<Vec<f64>>| {
            per_coordinate(name, values.as_deref(), m).map(|v| v.unwrap_or_else(|| vec![0.0; m]))
        };
        settings.reference_noise_std = noise("noise.reference_std", &self.noise.reference_std)?;
        settings.sensor_noise_std = noise("noise.sensor_a_std", &self.noise.sensor_a_std)?;
        settings.sensor_noise_std.extend(noise(
            "noise.sensor_a_dot_std",
            &self.noise.sensor_a_dot_std,
        )?);
        settings.max_modal_error = self.limits.max_modal_error;
        settings.joint_torque_limits = self.limits.joint_torque_nm.as_ref().map(|l| match l {
            TorqueLimit::All(limit) => vec![*limit; model.n_links()],
            TorqueLimit::PerJoint(limits) => limits.clone(),
        });
        let initial = match &self.initial {
            None => None,
            Some(i) => {
                let a = per_coordinate("initial.a", Some(&i.a), m)?.unwrap_or_default();
                let a_dot = per_coordinate("initial.a_dot", i.a_dot.as_deref(), m)?
                    .unwrap_or_else(|| vec![0.0; m]);
                Some(ModalState { a, a_dot })
            }
        };
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

/// `values` if given, checked to have exactly `m` entries (one per modal coordinate); the
/// error names the field.
fn per_coordinate(
    name: &str,
    values: Option<&[f64]>,
    m: usize,
) -> Result<Option<Vec<f64>>, SimError> {
    match values {
        None => Ok(None),
        Some(values) if values.len() == m => Ok(Some(values.to_vec())),
        Some(values) => Err(SimError::setting(
            name,
            format!(
                "has {} entries, the modal family has {m} coordinates (one entry each)",
                values.len()
            ),
        )),
    }
}

impl ReferenceSpec {
    /// The reference of `m` coordinates for a curve of length `length` with `harmonics`
    /// harmonics and base angle `alpha0`.
    fn build(
        &self,
        length: f64,
        harmonics: usize,
        alpha0: Alpha0,
        m: usize,
    ) -> Result<Box<dyn Reference>, SimError> {
        let given = |name: &str, values: &[f64]| {
            per_coordinate(name, Some(values), m).map(Option::unwrap_or_default)
        };
        let or_zero = |name: &str, values: &Option<Vec<f64>>| {
            per_coordinate(name, values.as_deref(), m).map(|v| v.unwrap_or_else(|| vec![0.0; m]))
        };
        Ok(match self {
            ReferenceSpec::Constant { a } => Box::new(Step::constant(&given("reference.a", a)?)?),
            ReferenceSpec::Step {
                initial,
                target,
                time,
            } => Box::new(Step::new(
                &or_zero("reference.initial", initial)?,
                &given("reference.target", target)?,
                *time,
            )?),
            ReferenceSpec::Sinusoid {
                offset,
                amplitude,
                frequency_hz,
                phase,
            } => Box::new(Sinusoid::new(
                &or_zero("reference.offset", offset)?,
                &given("reference.amplitude", amplitude)?,
                &given("reference.frequency_hz", frequency_hz)?,
                &or_zero("reference.phase", phase)?,
            )?),
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
                    harmonics,
                    alpha0.base_angle(),
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

    /// The controller for `model`'s `m` coordinates; every gain array must have `m` entries.
    fn build(&self, model: &ReducedModel) -> Result<Box<dyn Controller>, SimError> {
        let m = model.n_coords();
        let gains = |name: &str, values: &Option<Vec<f64>>, default: f64| {
            per_coordinate(name, values.as_deref(), m)
                .map(|v| v.unwrap_or_else(|| vec![default; m]))
        };
        let kp = gains("controller.kp", &self.kp, DEFAULT_KP)?;
        let kd = gains("controller.kd", &self.kd, DEFAULT_KD)?;
        let pd_kp = per_coordinate("controller.pd_kp", self.pd_kp.as_deref(), m)?;
        let pd_kd = per_coordinate("controller.pd_kd", self.pd_kd.as_deref(), m)?;
        Ok(match self.kind {
            ControllerKind::Fuzzy => Box::new(FuzzyController::new(self.fuzzy_system()?, m)?),
            ControllerKind::Pd => {
                let slope = PdController::from_fuzzy_slope(&self.fuzzy_system()?, m)?;
                let kp = pd_kp.unwrap_or_else(|| slope.kp().to_vec());
                let kd = pd_kd.unwrap_or_else(|| slope.kd().to_vec());
                Box::new(PdController::new(slope.offset(), &kp, &kd)?)
            }
            ControllerKind::ComputedTorque => Box::new(ComputedTorque::new(model, &kp, &kd)?),
            ControllerKind::FuzzyGc => Box::new(
                FuzzyController::new(self.fuzzy_system()?, m)?.with_gravity_compensation(model)?,
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
