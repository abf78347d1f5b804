#![doc = include_str!("../README.md")]

pub mod error;
mod mjcf;
pub mod model;
mod planar;
pub mod pose;
mod spatial;
mod universal;
mod urdf_read;
mod urdf_write;

pub use error::DescError;
pub use mjcf::{
    MJ_MINVAL, MJCF_BODIES_PER_FILE, MJCF_MAX_BODIES, MJCF_MAX_BODIES_ONE_FILE, MJCF_MAX_XML_DEPTH,
    write_mjcf, write_mjcf_files,
};
pub use model::{Body, Geometry, Inertial, Joint, JointDynamics, JointKind, Limits, Robot, Shape};
pub use planar::from_planar;
pub use spatial::{check_gravity, to_spatial};
pub use universal::{MAX_SPATIAL_EXPORT_LINKS, from_spatial_arm};
pub use urdf_read::{
    MAX_ATTRIBUTE_BYTES, MAX_ATTRIBUTES, MAX_MAGNITUDE, MAX_NAMESPACES, MAX_URDF_BYTES,
    MAX_XML_DEPTH, MAX_XML_NODES, Merged, ReadReport, Reading, read_urdf,
};
pub use urdf_write::{MAX_EXPORT_JOINTS, write_urdf};
