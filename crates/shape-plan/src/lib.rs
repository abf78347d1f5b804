#![doc = include_str!("../README.md")]

mod arm;
mod channel;
mod data;
mod deploy;
mod deploy_metrics;
mod error;
mod farthest;
mod generator;
mod motion;
mod options;
mod planar;
mod planner;
mod polyline;
mod shape;
mod spatial;

pub use arm::{Arm, ArmScratch};
pub use channel::{Channel, MAX_CENTERLINE_EXTENT, MAX_CENTERLINE_POINTS, MIN_CENTERLINE_SCALE};
pub use data::PlanData;
pub use deploy::{DeployFrame, Deployment, MAX_DEPLOY_STEPS, MAX_LENGTH_RATIO, follow_the_leader};
pub use deploy_metrics::{
    DeployMetrics, DeploySample, DeployTracker, MAX_DEPLOY_METRIC_WORK, SAMPLES_PER_LINK,
    deploy_metric_work,
};
pub use error::PlanError;
pub use farthest::{
    FALLBACK_SAMPLES, FARTHEST_ALLOWANCE, FarthestScratch, MAX_FARTHEST_INTERVALS,
    MAX_NEAR_FEATURES,
};
pub use generator::{
    MAX_PASSAGE_OBSTACLES, NarrowPassage, PassageSpec, narrow_passage, spatial_narrow_passage,
};
pub use motion::{SegmentCheck, check_segment};
pub use options::{MAX_CHECKS, MAX_ITERATIONS, MAX_LENGTH_M, MAX_SAMPLES, PlanOptions};
pub use planar::PlanarArm;
pub use planner::{MAX_PLAN_WORK, Plan, Planner};
pub use shape::{ShapeOutcome, solve_shape};
pub use spatial::SpatialArm;
