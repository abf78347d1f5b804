#![doc = include_str!("../README.md")]

mod lanes;
mod trig;

pub use lanes::{Lane, Pack};
pub use trig::{REDUCTION_LIMIT, sin_cos, sin_cos_in_range, sin_cos_lanes};
