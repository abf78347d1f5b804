#![doc = include_str!("../README.md")]

pub mod imitation;
mod input_file;
mod scenario;
pub mod study;
pub mod summary_json;

pub use input_file::{MAX_INPUT_FILE_BYTES, open_regular_file, read_text_file};
pub use scenario::{
    Alpha0, AngleLimit, ArmKind, ArmSpec, BaseSpec, BranchSpec, CONTROLLERS, ControllerEntry,
    ControllerKind, ControllerSetup, ControllerSpec, DEFAULT_ATOL, DEFAULT_RTOL, DEPLOY_PLAN_STEPS,
    DeployFailure, DeployRun, DeploySpec, FuzzyInputRange, Gravity, HelixSpec, Inertias,
    InitialSpec, IntegratorSpec, JointLayout, LimitsSpec, MAX_DEPLOY_CENTERLINE_POINTS,
    MAX_DEPLOY_RECORDED_SAMPLES, MAX_GRAVITY, MAX_SCENARIO_EXTENT, MAX_SCENARIO_OBSTACLES,
    ModalSpec, ModalTorqueLimit, NoiseSpec, ObstacleSpec, ReferenceSpec, Scenario, ScenarioError,
    SineSpec, TaskSpec, TorqueLimit, Workspace,
};
pub use shape_plan::{Channel, DeployMetrics, DeploySample};
