//! Scenarios: a closed-loop experiment described in a TOML file (arm, `alpha0`, reference,
//! controller, integrator, step sizes, duration, noise, seed), and the paper's experiments
//! shipped with the crate.
//!
//! Required keys: `name`, `duration`, `alpha0` (for a planar arm), `reference` (with its `kind`
//! and that kind's required keys) and `integrator` (with its `method`); everything else has a
//! default. Every per-coordinate array (`initial`, `reference`, `noise`, the controller gains) has
//! exactly `m` entries, the number of modal coordinates: `2K` with `alpha0` fixed, `2K + 1` with
//! `alpha0` free (its last entry is then `alpha0`'s), `4K` on a spatial arm
//! (`[az1..az2K, ay1..ay2K]`, in-plane then out-of-plane bending).
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
//! radius = 0.01           # m, each link's collision capsule around its segment, default 0
//! # urdf = "arm.urdf"     a URDF chain instead (relative to the file), run in joint space by
//! #                       Scenario::run_chain: computed torque only, one entry per joint
//!
//! # A spatial modal arm instead (docs/theory.md, section 8): universal joints, m = 4K, no alpha0
//! # kind = "spatial"      # default "planar"
//! # joints = "universal"  # the one layout: about the parent's z, then the resulting y
//! # gravity = [0.0, 0.0, -9.81]   # m/s^2, world frame; a number g is [0, 0, -g] (the default)
//! # inertias = [[0.0, 8.3e-5, 8.3e-5], ...]  # [Ixx, Iyy, Izz] per link (kg m^2) about the
//! #                       centre of mass in the link frame; default: slender rods
//! # base = { xyz = [0.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.0] }  # m, rad (URDF's roll-pitch-yaw)
//!
//! [[obstacles]]           # kind = "circle" | "capsule" | "box" (spatial arms: "sphere")
//! kind = "circle"         # planar points are [x, y], spatial ones [x, y, z]
//! center = [0.3, 0.6]     # m
//! radius = 0.05           # m
//! # kind = "capsule": from = [x, y], to = [x, y], radius
//! # kind = "box": center = [x, y], half_extents = [hx, hy], rpy = [0.0, 0.0, yaw]
//!
//! [task]                  # optional: planned before the controller runs (shape-plan)
//! kind = "reach"          # the chain's tip on target, every link clearance from obstacles
//! target = [0.35, 0.55]   # m                                      and from itself
//! clearance = 0.01        # m, on the goal shape and all along the motion to it
//! # check_slack = 1e-3    m, samples = 64, max_iterations = 200: the planner's bounds
//! # with a task, [reference] kind = "planned", travel_time = 3.0 (s): the plan's motion
//!
//! [reference]             # kind = "constant" | "step" | "sinusoid" | "path" | "planned"
//! kind = "step"
//! initial = [0.0, 0.0]
//! target = [0.2, -0.2]
//! time = 0.1
//!
//! # a spatial arm's path: a helix (a circle at pitch 0) instead of `sine` or `points`
//! # [reference.helix]     # from start, about the line through center along axis, right-handed
//! # center = [0.8, 0.0, 0.0]   # m
//! # axis = [1.0, 0.0, 0.0]
//! # start = [0.8, 0.15, 0.0]   # m, off the axis; the radius is its distance from the axis
//! # pitch = 0.0           # m per turn along the axis (default 0: a circle)
//! # turns = 1.0           # default 1, at constant speed over travel_time
//!
//! [controller]            # kind = "fuzzy" | "pd" | "computed-torque" | "fuzzy-gc" | "lqr"
//! kind = "fuzzy"
//! period = 0.0001         # s, default: the RK4 step
//! # kp = [2500.0, 2500.0]   computed torque (1/s^2), kd = [100.0, 100.0] (1/s)
//! # pd_kp = [600.0, 300.0]  PD (N m/rad), pd_kd = [20.0, 10.0] (N m s/rad); default: fuzzy slope
//! # lqr_frequency = 50.0    LQR design frequency (rad/s), lqr_relinearise = 0.01 (s, or the period)
//! # out_of_range = "as-given"  fuzzy inputs outside their ranges: "as-given" (MATLAB) | "clamp"
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
//! joint_torque_nm = 5.0   # or one limit per joint; enforced by projecting tau* each sample
//! joint_angle_rad = 2.0   # |theta_j| <= 2 rad, or one limit per joint; enforced likewise
//! tau_star = [2.0, 0.5]   # N m, or one limit for all: the loop clamps tau* to +-limit
//! ```

mod arm;
mod builtin;
mod chain;
mod controllers;
mod deploy;
mod exact;
mod factory;
mod file;
mod obstacles;
mod schema;
mod spatial;
mod tagged;
mod task;

pub use arm::{ArmKind, BaseSpec, Gravity, Inertias, JointLayout, MAX_GRAVITY};
pub use controllers::{
    CONTROLLERS, ControllerEntry, ControllerKind, ControllerSetup, ControllerSpec, FuzzyInputRange,
};
pub use deploy::{DEPLOY_PLAN_STEPS, DeployFailure, DeployRun, MAX_DEPLOY_RECORDED_SAMPLES};
pub use file::ScenarioError;
pub use obstacles::{MAX_SCENARIO_EXTENT, MAX_SCENARIO_OBSTACLES, Workspace};
pub use schema::{
    Alpha0, AngleLimit, ArmSpec, BranchSpec, DEFAULT_ATOL, DEFAULT_RTOL, DeploySpec, HelixSpec,
    InitialSpec, IntegratorSpec, LimitsSpec, MAX_DEPLOY_CENTERLINE_POINTS, ModalSpec,
    ModalTorqueLimit, NoiseSpec, ObstacleSpec, ReferenceSpec, Scenario, SineSpec, TaskSpec,
    TorqueLimit,
};
