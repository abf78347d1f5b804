#![doc = include_str!("../README.md")]

mod closest;
mod cores;
mod data;
mod distances;
mod error;
mod joint_gradient;
mod modal_gradient;
mod model;
mod obstacle;
mod place;
mod point_lanes;
mod vector;

pub use closest::{Closest, segment_box, segment_point, segment_segment};
pub use data::{ClearanceData, MAX_GRADIENT_ENTRIES};
pub use distances::distances;
pub use error::ClearanceError;
pub use joint_gradient::joint_gradient;
pub use modal_gradient::modal_gradients;
pub use model::{ClearanceModel, MAX_OBSTACLES, MAX_PAIRS, Pair};
pub use obstacle::{MAX_OBSTACLE_EXTENT, Obstacle};
pub use place::{place, place_planar};
