#![doc = include_str!("../README.md")]

mod lanes;
mod trig;

pub use lanes::{Lane, Pack};
pub use trig::{sin_cos, sin_cos_simd};
