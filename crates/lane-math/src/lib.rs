#![doc = include_str!("../README.md")]

mod alloc;
mod checks;
mod compact;
pub mod dense;
mod error_class;
mod instruction_sets;
mod lanes;
mod message;
mod trig;

pub use alloc::{OutOfMemory, try_copied, try_filled, try_reserve, try_with_capacity};
pub use checks::{
    EntryIndex, ShapeError, ShapeProblem, all_finite, check_all_finite, check_finite, check_len,
    check_values, first_non_finite,
};
pub use compact::{Compact, compact_numbers};
pub use error_class::{Classify, ErrorClass};
pub use instruction_sets::instruction_sets;
pub use lanes::{Lane, Pack};
pub use message::{escape_controls, is_one_line, one_line};
pub use trig::{REDUCTION_LIMIT, sin_cos, sin_cos_in_range, sin_cos_lanes};
