#![doc = include_str!("../README.md")]
#![deny(missing_docs)]

pub mod alloc;
pub mod config;
pub mod engine;
pub mod numeric;
pub mod refusal;
pub mod sample;
