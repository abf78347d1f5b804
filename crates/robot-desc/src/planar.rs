//! The planar arms of `manip-dyn` as spatial chains.

use crate::error::DescError;
use crate::model::{Body, Inertial, Joint, JointKind, Robot};
use crate::pose::Pose;
use crate::urdf_write::MAX_EXPORT_JOINTS;
use manip_dyn::ChainModel;

/// The planar chain as a spatial one in the base's `x-y` plane: joint `i` about `z` at the end
/// of link `i - 1` (`continuous`, the planar model has no limits), link `i` along its `x` axis
/// with its centre of mass at `(com, 0, 0)`. The planar model knows only the moment about `z`;
/// the two other principal moments do not enter motion in the plane, and are set equal to it
/// (MuJoCo refuses a singular inertia, so a zero-thickness rod's `ixx = 0` would not export).
/// Gravity is not part of a URDF: the chain's gravity acts along `-y`, which MJCF writes in
/// `<option>` and URDF users set themselves.
///
/// # Errors
/// [`DescError::Export`] for more than [`MAX_EXPORT_JOINTS`] links, before any is built.
pub fn from_planar(chain: &ChainModel, name: &str) -> Result<Robot, DescError> {
    if chain.n_links() > MAX_EXPORT_JOINTS {
        return Err(DescError::export(
            format!("robot '{name}'"),
            format!(
                "{} links exceed the {MAX_EXPORT_JOINTS} a description is written with",
                chain.n_links()
            ),
        ));
    }
    let mut joints = Vec::with_capacity(chain.n_links());
    let mut offset = 0.0;
    for (i, link) in chain.links().iter().enumerate() {
        joints.push(Joint {
            name: format!("joint_{}", i + 1),
            kind: JointKind::Continuous,
            origin: Pose {
                xyz: [offset, 0.0, 0.0],
                rpy: [0.0; 3],
            },
            axis: [0.0, 0.0, 1.0],
            limits: None,
            dynamics: None,
            child: Body {
                name: format!("link_{}", i + 1),
                inertial: Inertial {
                    origin: Pose {
                        xyz: [link.com, 0.0, 0.0],
                        rpy: [0.0; 3],
                    },
                    mass: link.mass,
                    inertia: [link.inertia, 0.0, 0.0, link.inertia, 0.0, link.inertia],
                },
                visuals: Vec::new(),
                collisions: Vec::new(),
            },
        });
        offset = link.length;
    }
    Ok(Robot {
        name: name.to_string(),
        base: Body {
            name: "base".to_string(),
            ..Body::default()
        },
        joints,
    })
}
