#![doc = include_str!("../README.md")]

mod decimate;
mod error;
mod from_record;
mod gif;
mod page;
mod view;

pub use decimate::{round_decimal, strided};
pub use error::{FieldProblem, ViewError};
pub use from_record::from_record;
pub use gif::{
    Camera, GifOptions, MAX_FRAMES, MAX_PIXELS, MAX_SIDE, draw_frame, torque_colour, write_gif,
};
pub use page::{
    PAGE_SAMPLES, REPORT_SAMPLES, SCRIPT, SIGNATURE, SIGNATURE_WITHIN, STYLE, escape, head, iframe,
    page, scene_html, tail, written_by_hrm,
};
pub use view::{
    Channel, MAX_ITEMS, MAX_MAGNITUDE, MAX_POINTS, MAX_RUNS, MAX_SAMPLES, MAX_VALUE, Obstacle,
    RunView, Scene, Series,
};
