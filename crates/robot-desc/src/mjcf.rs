//! Writing a chain as MJCF for MuJoCo.
//!
//! MuJoCo refuses a moving body without mass or inertia, so a link without `<inertial>`
//! (the middle link of a universal joint written as two revolute joints) is not a body of its
//! own: its joint joins those of the next body that has mass, MuJoCo applying a body's joints
//! in order, each about its own anchor and axis in the body frame. Every body frame is the URDF
//! frame of its (last) link, so inertias and geometry keep their placements.
//!
//! MuJoCo 4.0.1 parses XML with tinyxml2, which refuses elements nested deeper than
//! [`MJCF_MAX_XML_DEPTH`]; a single document holds at most [`MJCF_MAX_BODIES_ONE_FILE`] moving
//! bodies. Past that, [`write_mjcf_files`] splits the chain into files joined by `<include>`
//! (each parsed as a document of its own), up to the [`MJCF_MAX_BODIES`] nested bodies
//! MuJoCo's compiler accepts.

use crate::error::DescError;
use crate::model::{Body, Inertial, Joint, JointKind, Robot, Shape};
use crate::pose::{Mat3, Pose, mat_vec, matrix_quaternion, transpose};
use crate::urdf_write::{escape, numbers};
use std::fmt::Write;

/// The deepest element nesting MuJoCo's XML parser reads (measured with MuJoCo 4.0.1:
/// `<mujoco><worldbody>` and 496 nested `<body>`s, each with a `<joint>`, load; 497 do not).
pub const MJCF_MAX_XML_DEPTH: usize = 499;

/// The most moving bodies one MJCF document of this writer holds: `<mujoco>`, `<worldbody>`,
/// the base `<body>` and the bodies' own children take four of [`MJCF_MAX_XML_DEPTH`] levels.
pub const MJCF_MAX_BODIES_ONE_FILE: usize = MJCF_MAX_XML_DEPTH - 4;

/// The most nested bodies below the world MuJoCo compiles, whatever the XML ("depth limit
/// exceeded in signature computation" at 1024, measured with MuJoCo 4.0.1, through included
/// files and `MjSpec` alike): the base and 1022 moving bodies.
pub const MJCF_MAX_BODIES: usize = 1022;

/// Moving bodies per included file in [`write_mjcf_files`] (well inside the parser's depth).
pub const MJCF_BODIES_PER_FILE: usize = 400;

/// The chain as one MJCF document, gravity `[gx, gy, gz]` (m/s^2) in `<option>`. Refused past
/// [`MJCF_MAX_BODIES_ONE_FILE`] moving bodies (use [`write_mjcf_files`]).
pub fn write_mjcf(robot: &Robot, gravity: [f64; 3]) -> Result<String, DescError> {
    let bodies = bodies(robot)?;
    if bodies.len() > MJCF_MAX_BODIES_ONE_FILE {
        return Err(DescError::export(
            format!("robot '{}' as one MJCF document", robot.name),
            format!(
                "{} nested bodies exceed the {MJCF_MAX_BODIES_ONE_FILE} MuJoCo's XML parser \
                 reads in one document; write it as several files (`hrm arm export`)",
                bodies.len()
            ),
        ));
    }
    let mut files = assemble(robot, &bodies, gravity, "", usize::MAX);
    Ok(files.remove(0).1)
}

/// The chain as MJCF files: `{stem}.xml`, and past [`MJCF_BODIES_PER_FILE`] moving bodies
/// `{stem}-part1.xml`, `{stem}-part2.xml`... each included by the one before (MuJoCo resolves
/// them relative to the first). Returns `(file name, text)` pairs, the main file first.
/// Refused past [`MJCF_MAX_BODIES`].
pub fn write_mjcf_files(
    robot: &Robot,
    gravity: [f64; 3],
    stem: &str,
) -> Result<Vec<(String, String)>, DescError> {
    let bodies = bodies(robot)?;
    Ok(assemble(
        robot,
        &bodies,
        gravity,
        stem,
        MJCF_BODIES_PER_FILE,
    ))
}

/// One moving MuJoCo body: its pose in the previous body's frame, its joints (anchor and axis
/// in its own frame) and the URDF body whose frame it has.
struct MjBody<'a> {
    pose: Pose,
    joints: Vec<(&'a Joint, [f64; 3], [f64; 3])>,
    body: &'a Body,
}

/// Groups the joints into bodies that have mass and checks what MuJoCo checks.
fn bodies(robot: &Robot) -> Result<Vec<MjBody<'_>>, DescError> {
    let mut bodies = Vec::new();
    let mut group: Vec<&Joint> = Vec::new();
    for joint in &robot.joints {
        group.push(joint);
        if joint.child.inertial.is_massless() {
            continue;
        }
        check_mass(&joint.child)?;
        // Body frame B = T_1 ... T_k at rest; joint i's anchor and axis in B are those of the
        // joint frame moved by S_i^-1, S_i = T_{i+1} ... T_k.
        let mut pose = Pose::IDENTITY;
        let mut after: Vec<Pose> = vec![Pose::IDENTITY; group.len()];
        for i in (0..group.len()).rev() {
            after[i] = pose;
            pose = group[i].origin.compose(&pose);
        }
        let joints = group
            .iter()
            .zip(&after)
            .map(|(joint, s)| {
                let rt: Mat3 = transpose(&s.rotation());
                let p = mat_vec(&rt, s.xyz);
                (*joint, [-p[0], -p[1], -p[2]], mat_vec(&rt, joint.axis))
            })
            .collect();
        bodies.push(MjBody {
            pose,
            joints,
            body: &joint.child,
        });
        group.clear();
    }
    if let Some(last) = group.last() {
        return Err(DescError::export(
            format!("link '{}' to MJCF", last.child.name),
            "it has no mass and no heavier link follows it: MuJoCo refuses massless moving bodies",
        ));
    }
    if bodies.len() > MJCF_MAX_BODIES {
        return Err(DescError::export(
            format!("robot '{}' to MJCF", robot.name),
            format!(
                "{} nested bodies exceed the {MJCF_MAX_BODIES} MuJoCo compiles",
                bodies.len()
            ),
        ));
    }
    Ok(bodies)
}

/// MuJoCo's own requirement of a moving body: positive mass and a positive definite inertia.
fn check_mass(body: &Body) -> Result<(), DescError> {
    let moments = body.inertial.principal().values;
    if body.inertial.mass > 0.0 && moments[0] > 0.0 {
        return Ok(());
    }
    Err(DescError::export(
        format!("link '{}' to MJCF", body.name),
        format!(
            "MuJoCo needs a positive mass and positive principal moments of inertia, got mass {} \
             and moments {moments:?}",
            body.inertial.mass
        ),
    ))
}

/// The documents: bodies nested in order, a new file every `per_file` bodies.
fn assemble(
    robot: &Robot,
    bodies: &[MjBody<'_>],
    gravity: [f64; 3],
    stem: &str,
    per_file: usize,
) -> Vec<(String, String)> {
    let chunks: Vec<&[MjBody<'_>]> = if bodies.is_empty() {
        vec![&[]]
    } else {
        bodies.chunks(per_file).collect()
    };
    let mut files = Vec::with_capacity(chunks.len());
    for (k, chunk) in chunks.iter().enumerate() {
        let mut out = String::new();
        let mut depth = 1;
        if k == 0 {
            let _ = writeln!(out, "<mujoco model=\"{}\">", escape(&robot.name));
            out.push_str(
                "  <compiler angle=\"radian\" inertiafromgeom=\"false\" autolimits=\"true\"/>\n",
            );
            let _ = writeln!(out, "  <option gravity=\"{}\"/>", numbers(&gravity));
            out.push_str("  <worldbody>\n");
            let _ = writeln!(out, "    <body name=\"{}\">", escape(&robot.base.name));
            write_geoms(&mut out, "      ", &robot.base);
            depth = 3;
        } else {
            out.push_str("<mujoco>\n");
        }
        for body in *chunk {
            depth += 1;
            let indent = "  ".repeat(depth);
            let _ = writeln!(
                out,
                "{indent}<body name=\"{}\" pos=\"{}\" quat=\"{}\">",
                escape(&body.body.name),
                numbers(&body.pose.xyz),
                numbers(&matrix_quaternion(&body.pose.rotation()))
            );
            let inner = "  ".repeat(depth + 1);
            for (joint, anchor, axis) in &body.joints {
                write_joint(&mut out, &inner, joint, anchor, axis);
            }
            write_inertial(&mut out, &inner, &body.body.inertial);
            write_geoms(&mut out, &inner, body.body);
        }
        if k + 1 < chunks.len() {
            let _ = writeln!(
                out,
                "{}<include file=\"{}-part{}.xml\"/>",
                "  ".repeat(depth + 1),
                escape(stem),
                k + 1
            );
        }
        let first = if k == 0 { 3 } else { 1 };
        while depth > first {
            let _ = writeln!(out, "{}</body>", "  ".repeat(depth));
            depth -= 1;
        }
        if k == 0 {
            out.push_str("    </body>\n  </worldbody>\n");
        }
        out.push_str("</mujoco>\n");
        let name = if k == 0 {
            format!("{stem}.xml")
        } else {
            format!("{stem}-part{k}.xml")
        };
        files.push((name, out));
    }
    files
}

fn write_joint(out: &mut String, indent: &str, joint: &Joint, anchor: &[f64; 3], axis: &[f64; 3]) {
    let kind = if joint.kind.is_rotation() {
        "hinge"
    } else {
        "slide"
    };
    let _ = write!(
        out,
        "{indent}<joint name=\"{}\" type=\"{kind}\" pos=\"{}\" axis=\"{}\"",
        escape(&joint.name),
        numbers(anchor),
        numbers(axis)
    );
    if joint.kind != JointKind::Continuous
        && let Some(limits) = &joint.limits
        && let (Some(lower), Some(upper)) = (limits.lower, limits.upper)
        && lower < upper
    {
        let _ = write!(out, " range=\"{}\"", numbers(&[lower, upper]));
    }
    if let Some(dynamics) = &joint.dynamics {
        if let Some(damping) = dynamics.damping.filter(|d| *d > 0.0) {
            let _ = write!(out, " damping=\"{damping:?}\"");
        }
        if let Some(friction) = dynamics.friction.filter(|f| *f > 0.0) {
            let _ = write!(out, " frictionloss=\"{friction:?}\"");
        }
    }
    out.push_str("/>\n");
}

/// MuJoCo takes `fullinertia` in the body frame only (not with `quat`): the tensor is rotated
/// from the `<inertial>` frame into the link frame, `R I R^T`.
fn write_inertial(out: &mut String, indent: &str, inertial: &Inertial) {
    let (com, i) = inertial.in_link_frame();
    let _ = writeln!(
        out,
        "{indent}<inertial pos=\"{}\" mass=\"{:?}\" fullinertia=\"{}\"/>",
        numbers(&com),
        inertial.mass,
        numbers(&[i[0][0], i[1][1], i[2][2], i[0][1], i[0][2], i[1][2]])
    );
}

/// Visual shapes as geoms that never collide (group 1), collision shapes as colliding geoms
/// (group 3). Meshes are named in a comment only: their files are not part of the model.
fn write_geoms(out: &mut String, indent: &str, body: &Body) {
    for (geometries, class) in [
        (&body.visuals, "contype=\"0\" conaffinity=\"0\" group=\"1\""),
        (&body.collisions, "group=\"3\""),
    ] {
        for geometry in geometries {
            let (kind, size) = match &geometry.shape {
                Shape::Box(size) => ("box", size.map(|s| 0.5 * s).to_vec()),
                Shape::Cylinder { radius, length } => ("cylinder", vec![*radius, 0.5 * length]),
                Shape::Sphere(radius) => ("sphere", vec![*radius]),
                Shape::Mesh { filename, .. } => {
                    let _ = writeln!(
                        out,
                        "{indent}<!-- mesh {} not exported -->",
                        escape(filename).replace("--", "- -")
                    );
                    continue;
                }
            };
            let _ = writeln!(
                out,
                "{indent}<geom type=\"{kind}\" size=\"{}\" pos=\"{}\" quat=\"{}\" {class}/>",
                numbers(&size),
                numbers(&geometry.origin.xyz),
                numbers(&matrix_quaternion(&geometry.origin.rotation()))
            );
        }
    }
}
