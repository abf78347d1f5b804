//! The scenario schema: what a scenario file may say, with its defaults.

use super::arm::{ArmKind, BaseSpec, Gravity, Inertias, JointLayout};
use super::controllers::ControllerSpec;
use backbone_kin::BaseAngle;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::PathBuf;

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
    /// The base inclination `alpha0` of a planar arm: fixed (rad) or free (the last modal
    /// coordinate). Required for a planar arm, refused for a spatial one (whose base angles are
    /// `arm.base`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha0: Option<Alpha0>,
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
    /// Obstacles (`[[obstacles]]` tables): the loop takes the arm's clearance to them, and to
    /// itself, at every controller sample.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub obstacles: Vec<ObstacleSpec>,
    /// What the arm must achieve, planned before the controller runs (`[task]`, with the
    /// reference of kind `"planned"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub task: Option<TaskSpec>,
    /// A follow-the-leader deployment into a channel (`[deploy]`, with the reference of kind
    /// `"planned"`): the arm gets a base insertion axis and runs in joint space
    /// ([`Scenario::run_deploy`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deploy: Option<DeploySpec>,
}

/// A channel the arm deploys into by follow-the-leader (`docs/theory.md`, "Follow-the-leader
/// deployment"): the arm gets a prismatic insertion axis before its first joint, along the
/// centreline's first segment, and its tip advances to the centreline's end along the
/// centreline while its body follows the path the tip traced.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeploySpec {
    /// The centreline `[[x, y], ...]` (m): at least two points, consecutive points distinct, at
    /// most [`MAX_DEPLOY_CENTERLINE_POINTS`]. The entry is the first point; the arm starts fully
    /// retracted, its tip at the entry and its body on the guide behind it. Spatial points
    /// `[x, y, z]` are refused by name (planar channels only).
    pub centerline: Vec<Vec<f64>>,
    /// The channel's radius (m, positive): the walls are at this distance from the centreline.
    pub radius: f64,
}

/// The most centreline points a scenario's `[deploy]` accepts.
pub const MAX_DEPLOY_CENTERLINE_POINTS: usize = 10_000;

/// An obstacle, tagged by `kind`. A planar arm moves in the plane `z = 0`: its obstacles are
/// circles, capsules and boxes given by `[x, y]` points; a spatial arm's are spheres, capsules
/// and boxes given by `[x, y, z]` points ([`Scenario::obstacles`] checks them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "super::tagged::ObstacleTable"
)]
pub enum ObstacleSpec {
    /// A disc of the arm's plane (planar arms).
    Circle {
        /// The centre `[x, y]` (m).
        center: Vec<f64>,
        /// The radius (m, non-negative).
        radius: f64,
    },
    /// A ball (spatial arms).
    Sphere {
        /// The centre `[x, y, z]` (m).
        center: Vec<f64>,
        /// The radius (m, non-negative).
        radius: f64,
    },
    /// The points within `radius` of the segment `from`-`to`.
    Capsule {
        /// One end of the axis (m).
        from: Vec<f64>,
        /// The other end (m).
        to: Vec<f64>,
        /// The radius (m, non-negative).
        radius: f64,
    },
    /// A box, axis-aligned unless turned by `rpy`.
    Box {
        /// The centre (m).
        center: Vec<f64>,
        /// Half the side lengths along the box's own axes (m, positive): `[hx, hy]` in the
        /// plane (the box is then a rectangle), `[hx, hy, hz]` in space.
        half_extents: Vec<f64>,
        /// Roll, pitch and yaw (rad, URDF's `R = Rz(yaw) Ry(pitch) Rx(roll)`, default zero); a
        /// planar arm's box turns about `z` only (`[0, 0, yaw]`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rpy: Option<Vec<f64>>,
    },
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
    /// `"planar"` (default, the paper's arm) or `"spatial"` (universal joints, `m = 4K`).
    #[serde(default, skip_serializing_if = "ArmKind::is_planar")]
    pub kind: ArmKind,
    /// The joints of a spatial arm (default and only layout `"universal"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints: Option<JointLayout>,
    /// The base pose of a spatial arm (default: at the origin, along `x`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<BaseSpec>,
    /// Number of links (default 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub links: Option<usize>,
    /// Length of every link (m, default 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link_length: Option<f64>,
    /// Mass of every link (kg, default 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link_mass: Option<f64>,
    /// Gravity (m/s^2): a magnitude along `-y` (planar) or `-z` (spatial), default 9.81, or a
    /// vector `[gx, gy, gz]` (spatial arms).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<Gravity>,
    /// Per-link lengths (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lengths: Option<Vec<f64>>,
    /// Per-link masses (kg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub masses: Option<Vec<f64>>,
    /// Per-link inertias about the centre of mass (kg m^2; default: uniform beams, slender rods
    /// for a spatial arm): one number per link (planar) or `[Ixx, Iyy, Izz]` per link (spatial).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertias: Option<Inertias>,
    /// A URDF serial chain (a path, relative to the scenario file) in place of the planar arm:
    /// run in joint space by [`Scenario::run_chain`], with only `gravity` of the other keys.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub urdf: Option<PathBuf>,
    /// The radius of every link's collision capsule around its segment (m, non-negative, default
    /// 0): the clearance to obstacles and between links is measured from these capsules.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
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
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "super::tagged::ReferenceTable"
)]
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
    /// [`CartesianPath`](sim_core::reference::CartesianPath)): exactly one of `sine` or `points`.
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
        /// A helix or circle in space (spatial arms), at constant speed along it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        helix: Option<HelixSpec>,
    },
    /// The motion of the `[task]`'s plan from the initial shape, its straight segments in modal
    /// space timed by the minimum-jerk profile
    /// ([`Waypoints`](sim_core::reference::Waypoints)); the goal is held afterwards.
    Planned {
        /// Time of the motion (s, positive).
        travel_time: f64,
    },
}

/// A task planned before the controller runs, tagged by `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "kebab-case",
    try_from = "super::tagged::TaskTable"
)]
pub enum TaskSpec {
    /// Reach `target` with the chain's tip, every link at least `clearance` from every obstacle
    /// and from the other links, on the goal shape and all along the motion to it
    /// ([`Scenario::plan`]).
    Reach {
        /// The target (m): `[x, y]` in a planar arm's plane, `[x, y, z]` for a spatial arm.
        target: Vec<f64>,
        /// The margin (m, non-negative).
        clearance: f64,
        /// The slack of the motion's checks (m, positive, default 1e-3): check points keep
        /// `clearance + check_slack`, so every shape in between keeps `clearance`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        check_slack: Option<f64>,
        /// Random starts and via points after the deterministic starts (default 64, at most
        /// 100000).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        samples: Option<usize>,
        /// Iterations of one shape solve (default 200, at most 100000).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        max_iterations: Option<usize>,
    },
}

/// A helix in space for a spatial arm's tip: from `start`, turning right-handedly about the
/// line through `center` along `axis` for `turns` turns and rising `pitch` metres per turn along
/// `axis`, at constant speed; `pitch = 0` (the default) is a circle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HelixSpec {
    /// A point on the axis (m).
    #[serde(deserialize_with = "super::exact::numbers")]
    pub center: [f64; 3],
    /// The axis direction (any length but zero).
    #[serde(deserialize_with = "super::exact::numbers")]
    pub axis: [f64; 3],
    /// The first point (m), off the axis.
    #[serde(deserialize_with = "super::exact::numbers")]
    pub start: [f64; 3],
    /// Rise per turn along the axis (m, default 0: a circle).
    #[serde(default)]
    pub pitch: f64,
    /// Number of turns (default 1), positive.
    #[serde(default = "default_turns")]
    pub turns: f64,
}

fn default_turns() -> f64 {
    1.0
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

/// The integrator between controller samples, tagged by `method`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "method",
    rename_all = "kebab-case",
    try_from = "super::tagged::IntegratorTable"
)]
pub enum IntegratorSpec {
    /// Fixed-step RK4.
    Rk4 {
        /// The step (s).
        dt: f64,
    },
    /// Adaptive Dormand-Prince 5(4).
    Dopri5 {
        /// Relative tolerance (default [`DEFAULT_RTOL`]).
        rtol: f64,
        /// Absolute tolerance (default [`DEFAULT_ATOL`]).
        atol: f64,
        /// Largest step (s, default unbounded).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        h_max: Option<f64>,
        /// Most steps per controller period (default 1,000,000).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        max_steps: Option<usize>,
    },
}

/// The default relative tolerance of `dopri5`.
pub const DEFAULT_RTOL: f64 = 1e-9;

/// The default absolute tolerance of `dopri5`.
pub const DEFAULT_ATOL: f64 = 1e-12;

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

/// The runaway bound, optional joint torque and joint angle limits (enforced) and optional
/// limits on the modal forces `tau*` (enforced).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSpec {
    /// The run stops when `|a_i - a_i_ref|` exceeds this (rad, default pi).
    #[serde(default = "default_max_modal_error")]
    pub max_modal_error: f64,
    /// Joint torque limits (N m): one for all joints or one per joint, enforced: at every
    /// controller sample the loop projects `tau*` onto the modal torques whose joint torques
    /// at that state are within them, and reports how often it acted
    /// ([`LoopSettings::joint_torque_limits`](sim_core::LoopSettings::joint_torque_limits)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_torque_nm: Option<TorqueLimit>,
    /// Joint angle limits `|theta_j| <= limit` (rad): one for all joints or one per joint,
    /// enforced in the same projection by bounding each joint's rate towards its limit
    /// ([`LoopSettings::joint_angle_limits`](sim_core::LoopSettings::joint_angle_limits)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_angle_rad: Option<AngleLimit>,
    /// Saturation of the modal forces `tau* = J^T tau` (N m): one limit for every coordinate or
    /// one per coordinate (`m` entries), each finite and positive. They bound the modal
    /// coordinates' generalised forces, not any joint torque (see `joint_torque_nm`). The loop
    /// clamps every controller's output to `[-limit_i, limit_i]` before applying it and records
    /// when it did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tau_star: Option<ModalTorqueLimit>,
}

fn default_max_modal_error() -> f64 {
    std::f64::consts::PI
}

impl Default for LimitsSpec {
    fn default() -> Self {
        Self {
            max_modal_error: default_max_modal_error(),
            joint_torque_nm: None,
            joint_angle_rad: None,
            tau_star: None,
        }
    }
}

/// A limit on the modal torques `tau*`: the same for every coordinate, or one per coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number (N m) or a list of numbers, one per modal coordinate"
)]
pub enum ModalTorqueLimit {
    /// The same limit for every coordinate (N m).
    All(f64),
    /// One limit per coordinate, in coordinate order (N m).
    PerCoordinate(Vec<f64>),
}

/// An angle limit for every joint, or one per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number (rad) or a list of numbers, one per joint"
)]
pub enum AngleLimit {
    /// The same limit for every joint (rad).
    All(f64),
    /// One limit per joint, base first (rad).
    PerJoint(Vec<f64>),
}

/// A torque limit for every joint, or one per joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number (N m) or a list of numbers, one per joint"
)]
pub enum TorqueLimit {
    /// The same limit for every joint (N m).
    All(f64),
    /// One limit per joint, base first (N m).
    PerJoint(Vec<f64>),
}

impl Scenario {
    /// The number of modal coordinates `m`: `2K` with `alpha0` fixed, `2K + 1` with it free
    /// (saturating, for a scenario read from a file whose `harmonics` is not yet validated).
    pub fn n_coords(&self) -> usize {
        match self.arm.kind {
            ArmKind::Planar => self
                .modal
                .harmonics
                .saturating_mul(2)
                .saturating_add(usize::from(self.alpha0 == Some(Alpha0::Free))),
            ArmKind::Spatial => self.modal.harmonics.saturating_mul(4),
        }
    }

    /// The names of the modal coordinates, in order (the column names of the outputs): for a
    /// planar arm `a1, ..., a{2K}`, then `alpha0` when it is free; for a spatial arm
    /// `az1, ..., az{2K}` (in-plane bending), then `ay1, ..., ay{2K}` (out-of-plane).
    ///
    /// ```
    /// let mut scenario = sim_study::Scenario::builtin("paper-tracking")?;
    /// assert_eq!(scenario.coordinate_names(), ["a1", "a2"]);
    /// scenario.alpha0 = Some(sim_study::Alpha0::Free);
    /// assert_eq!(scenario.coordinate_names(), ["a1", "a2", "alpha0"]);
    /// let spatial = sim_study::Scenario::builtin("spatial-tracking")?;
    /// assert_eq!(spatial.coordinate_names(), ["az1", "az2", "ay1", "ay2"]);
    /// # Ok::<(), sim_study::ScenarioError>(())
    /// ```
    pub fn coordinate_names(&self) -> Vec<String> {
        let modes = 2 * self.modal.harmonics;
        if self.arm.kind == ArmKind::Spatial {
            return ["az", "ay"]
                .iter()
                .flat_map(|plane| (1..=modes).map(move |i| format!("{plane}{i}")))
                .collect();
        }
        let mut names: Vec<String> = (1..=modes).map(|i| format!("a{i}")).collect();
        if self.alpha0 == Some(Alpha0::Free) {
            names.push("alpha0".into());
        }
        names
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
