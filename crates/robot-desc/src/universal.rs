//! The universal-joint arms of `modal-reduce`'s spatial modal family as descriptions.

use crate::error::DescError;
use crate::model::{Body, Inertial, Joint, JointKind, Robot};
use crate::pose::Pose;
use modal_reduce::spatial::SpatialReducedModel;

/// The most links of a spatial modal arm [`from_spatial_arm`] describes: two joints a link, about
/// 0.7 MB of URDF per 1,000 links, well within [`MAX_URDF_BYTES`](crate::MAX_URDF_BYTES) and
/// [`MAX_EXPORT_JOINTS`](crate::MAX_EXPORT_JOINTS), so that what is written reads back.
pub const MAX_SPATIAL_EXPORT_LINKS: usize = 10_000;

/// The chain of the spatial modal arm `model` leaving its base pose (the first joints' frame in
/// the world: position and URDF's roll-pitch-yaw, the convention of `BasePose`), link `i` joined to link `i - 1` by a universal joint: `joint_i_z` about the
/// parent frame's `z` axis at the end of link `i - 1`, moving the massless body `link_i_z`, then
/// `joint_i_y` about its `y` axis at the same point, moving `link_i`. The movable joints come in
/// the order of the spatial family's `theta = [z_1, y_1, z_2, y_2, ...]`, all `continuous`;
/// link `i`'s mass at its midpoint with its principal moments in the link frame. Gravity is not
/// part of a URDF (MJCF writes it in `<option>`).
///
/// # Errors
/// [`DescError::Export`] for more than [`MAX_SPATIAL_EXPORT_LINKS`] links, before any is built.
pub fn from_spatial_arm(model: &SpatialReducedModel, name: &str) -> Result<Robot, DescError> {
    if model.n_links() > MAX_SPATIAL_EXPORT_LINKS {
        return Err(DescError::export(
            format!("robot '{name}'"),
            format!(
                "{} links exceed the {MAX_SPATIAL_EXPORT_LINKS} a spatial arm is written with",
                model.n_links()
            ),
        ));
    }
    let mut joints = Vec::with_capacity(2 * model.n_links());
    let base = model.base();
    let mut origin = Pose {
        xyz: base.xyz,
        rpy: base.rpy,
    };
    for (i, (&length, link)) in model
        .map()
        .link_lengths()
        .iter()
        .zip(model.links())
        .enumerate()
    {
        let number = i + 1;
        let joint = |axis: &str, origin: Pose, child: Body| Joint {
            name: format!("joint_{number}_{axis}"),
            kind: JointKind::Continuous,
            origin,
            axis: if axis == "z" {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            },
            limits: None,
            dynamics: None,
            child,
        };
        joints.push(joint(
            "z",
            origin,
            Body {
                name: format!("link_{number}_z"),
                ..Body::default()
            },
        ));
        let [xx, yy, zz] = link.principal;
        joints.push(joint(
            "y",
            Pose::default(),
            Body {
                name: format!("link_{number}"),
                inertial: Inertial {
                    origin: Pose {
                        xyz: [0.5 * length, 0.0, 0.0],
                        rpy: [0.0; 3],
                    },
                    mass: link.mass,
                    inertia: [xx, 0.0, 0.0, yy, 0.0, zz],
                },
                visuals: Vec::new(),
                collisions: Vec::new(),
            },
        ));
        origin = Pose {
            xyz: [length, 0.0, 0.0],
            rpy: [0.0; 3],
        };
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
