//! Writing a chain as MJCF for MuJoCo.
//!
//! MuJoCo refuses a moving body without mass or inertia, so a link without `<inertial>`
//! (the middle link of a universal joint written as two revolute joints) is not a body of its
//! own: its joint joins those of the next body that has mass, MuJoCo applying a body's joints
//! in order, each about its own anchor and axis in the body frame. Every body frame is the URDF
//! frame of its (last) link, so inertias and geometry keep their placements. The geometry of
//! such a massless link is not written: as a geom of the body it joins it would also move with
//! that body's later joints; a comment in its place names it and says so.
//!
//! A body's inertia is written in its principal frame (`quat` and `diaginertia`, from
//! [`Inertial::principal`](crate::Inertial::principal)), so that the numbers MuJoCo checks are
//! the ones written: mass and moments at least [`MJ_MINVAL`], `A + B >= C` exactly. A root link
//! named `world` (ROS's convention) is MuJoCo's `<worldbody>` itself, its children attached
//! there.
//!
//! MuJoCo 4.0.1 parses XML with tinyxml2, which refuses elements nested deeper than
//! [`MJCF_MAX_XML_DEPTH`]; a single document holds at most [`MJCF_MAX_BODIES_ONE_FILE`] moving
//! bodies. Past that, [`write_mjcf_files`] splits the chain into files joined by `<include>`
//! (each parsed as a document of its own), up to the [`MJCF_MAX_BODIES`] nested bodies
//! MuJoCo's compiler accepts.

use crate::error::DescError;
use crate::model::{Body, Joint, Robot, Shape};
use crate::pose::{Mat3, Pose, mat_vec, matrix_quaternion, transpose};
use crate::urdf_read::MAX_MAGNITUDE;
use crate::urdf_write::{escape, numbers, write_urdf};
use std::fmt::Write;

/// MuJoCo's `mjMINVAL`: the least mass and principal moment of inertia of a moving body it
/// compiles ("mass and inertia of moving bodies must be larger than mjMINVAL"; measured with
/// MuJoCo 4.0.1, `1e-15` loads and anything smaller, zero included, does not).
pub const MJ_MINVAL: f64 = 1e-15;

/// The name MuJoCo gives its world body (`<worldbody>`); no other body may have it.
const WORLD: &str = "world";

/// The deepest element nesting MuJoCo's XML parser reads (measured with MuJoCo 4.0.1:
/// `<mujoco><worldbody>` and 496 nested `<body>`s, each with a `<joint>`, load; 497 do not).
pub const MJCF_MAX_XML_DEPTH: usize = 499;

/// The most moving bodies one MJCF document of this writer holds: `<mujoco>`, `<worldbody>`,
/// the base `<body>` and the bodies' own children take four of [`MJCF_MAX_XML_DEPTH`] levels
/// (a base named `world` is the `<worldbody>`, which leaves one level unused).
pub const MJCF_MAX_BODIES_ONE_FILE: usize = MJCF_MAX_XML_DEPTH - 4;

/// The most nested bodies below the world MuJoCo compiles, whatever the XML ("depth limit
/// exceeded in signature computation" at 1024, measured with MuJoCo 4.0.1, through included
/// files and `MjSpec` alike): the base and 1022 moving bodies.
pub const MJCF_MAX_BODIES: usize = 1022;

/// Moving bodies per included file in [`write_mjcf_files`] (well inside the parser's depth).
pub const MJCF_BODIES_PER_FILE: usize = 400;

/// The chain as one MJCF document, gravity `[gx, gy, gz]` (m/s^2) in `<option>`. Refused past
/// [`MJCF_MAX_BODIES_ONE_FILE`] moving bodies (use [`write_mjcf_files`]), and, naming the link,
/// what MuJoCo would refuse: a massless last link, a moving body's mass or principal moment
/// below [`MJ_MINVAL`], an inertia [`read_urdf`](crate::read_urdf) refuses, a moving link named
/// `world`; and what [`write_urdf`](crate::write_urdf) refuses (a number `read_urdf` would not
/// read), or a gravity component beyond [`MAX_MAGNITUDE`](crate::MAX_MAGNITUDE).
pub fn write_mjcf(robot: &Robot, gravity: [f64; 3]) -> Result<String, DescError> {
    let bodies = bodies(robot, gravity)?;
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
/// Refused past [`MJCF_MAX_BODIES`], as [`write_mjcf`] for what MuJoCo would refuse, and for a
/// `stem` that is not a plain file name (empty, `.` or `..`, a path separator or a control
/// character: the names are the files' and the `<include>`s').
pub fn write_mjcf_files(
    robot: &Robot,
    gravity: [f64; 3],
    stem: &str,
) -> Result<Vec<(String, String)>, DescError> {
    if stem.is_empty()
        || stem == "."
        || stem == ".."
        || stem
            .chars()
            .any(|c| c == '/' || c == '\\' || c.is_control())
    {
        return Err(DescError::export(
            "MJCF file stem",
            format!("{stem:?} is not a plain file name (no path separators or control characters)"),
        ));
    }
    let bodies = bodies(robot, gravity)?;
    Ok(assemble(
        robot,
        &bodies,
        gravity,
        stem,
        MJCF_BODIES_PER_FILE,
    ))
}

/// One moving MuJoCo body: its pose in the previous body's frame, its joints (anchor and axis
/// in its own frame; the massless links before it are their children), the URDF body whose
/// frame it has and its inertia as written.
struct MjBody<'a> {
    pose: Pose,
    joints: Vec<(&'a Joint, [f64; 3], [f64; 3])>,
    body: &'a Body,
    inertia: MjInertia,
}

/// A body's `<inertial>`: the principal frame's orientation in the body frame (`quat`,
/// `[w, x, y, z]`) and the principal moments (`diaginertia`).
struct MjInertia {
    quat: [f64; 4],
    diagonal: [f64; 3],
}

/// Checks `gravity` and that the robot reads back as URDF, then groups the joints into bodies
/// that have mass and checks what MuJoCo checks.
fn bodies(robot: &Robot, gravity: [f64; 3]) -> Result<Vec<MjBody<'_>>, DescError> {
    if let Some(g) = gravity
        .iter()
        .find(|g| !(g.is_finite() && g.abs() <= MAX_MAGNITUDE))
    {
        return Err(DescError::export(
            "gravity to MJCF",
            format!("each component must be finite and at most {MAX_MAGNITUDE:e} m/s^2, got {g}"),
        ));
    }
    // Counted before the URDF is written: a chain of 50,000 links is refused as MJCF, not as
    // a URDF too large to read back.
    let massive = robot
        .joints
        .iter()
        .filter(|joint| !joint.child.inertial.is_massless())
        .count();
    if massive > MJCF_MAX_BODIES {
        return Err(too_many_bodies(robot, massive));
    }
    // What the URDF reader refuses, MuJoCo's loader would refuse or misread too.
    write_urdf(robot)?;
    let mut bodies = Vec::new();
    let mut group: Vec<&Joint> = Vec::new();
    for joint in &robot.joints {
        let [lower, upper] = joint.position_range();
        if lower == upper {
            return Err(DescError::export(
                format!("joint '{}' to MJCF", joint.name),
                format!(
                    "its <limit> holds it at {lower} (a missing lower or upper reads as 0), \
                     which MJCF cannot say: MuJoCo needs range[0] < range[1] (give the joint \
                     its lower and upper, or make it fixed)"
                ),
            ));
        }
        group.push(joint);
        if joint.child.inertial.is_massless() {
            continue;
        }
        if joint.child.name == WORLD {
            return Err(DescError::export(
                format!("link '{WORLD}' to MJCF"),
                "MuJoCo reserves the name for its world body: only the root link may have it",
            ));
        }
        let inertia = mj_inertia(&joint.child)?;
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
            inertia,
        });
        group.clear();
    }
    if let Some(last) = group.last() {
        return Err(DescError::export(
            format!("link '{}' to MJCF", last.child.name),
            "it has no mass and no heavier link follows it: MuJoCo refuses massless moving bodies",
        ));
    }
    Ok(bodies)
}

/// The error of `bodies` moving bodies, more than [`MJCF_MAX_BODIES`].
fn too_many_bodies(robot: &Robot, bodies: usize) -> DescError {
    DescError::export(
        format!("robot '{}' to MJCF", robot.name),
        format!("{bodies} nested bodies exceed the {MJCF_MAX_BODIES} MuJoCo compiles"),
    )
}

/// A moving body's inertia as MuJoCo checks it: the principal moments of a physical inertia
/// (within [`INERTIA_TOLERANCE`](crate::model::INERTIA_TOLERANCE), as
/// [`read_urdf`](crate::read_urdf) checks), the largest lowered to the sum of the other two
/// where it exceeds it by rounding (MuJoCo checks `A + B >= C` without a tolerance), then mass
/// and moments at least [`MJ_MINVAL`].
fn mj_inertia(body: &Body) -> Result<MjInertia, DescError> {
    let element = || format!("link '{}' to MJCF", body.name);
    let principal = body
        .inertial
        .physical(|problem| DescError::export(element(), problem))?;
    let [a, b, c] = principal.values;
    let diagonal = [a, b, c.min(a + b)];
    let mass = body.inertial.mass;
    if mass >= MJ_MINVAL && diagonal[0] >= MJ_MINVAL {
        return Ok(MjInertia {
            quat: matrix_quaternion(&principal.vectors),
            diagonal,
        });
    }
    Err(DescError::export(
        element(),
        format!(
            "MuJoCo needs a mass and principal moments of inertia of at least {MJ_MINVAL:e} \
             (mjMINVAL; a slender rod's zero moment about its axis too), got mass {mass:?} and \
             moments {diagonal:?}"
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
    // The base is a body of its own, or, named `world`, MuJoCo's world body.
    let world = robot.base.name == WORLD;
    let base_depth = if world { 1 } else { 2 };
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
            if world {
                write_geoms(&mut out, "    ", &robot.base);
            } else {
                let _ = writeln!(out, "    <body name=\"{}\">", escape(&robot.base.name));
                write_geoms(&mut out, "      ", &robot.base);
            }
            depth = base_depth;
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
            write_inertial(&mut out, &inner, body);
            write_geoms(&mut out, &inner, body.body);
            if let Some((_, massless)) = body.joints.split_last() {
                for (joint, _, _) in massless {
                    write_dropped_geometry(&mut out, &inner, &joint.child, body.body);
                }
            }
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
        let first = if k == 0 { base_depth } else { 1 };
        while depth > first {
            let _ = writeln!(out, "{}</body>", "  ".repeat(depth));
            depth -= 1;
        }
        if k == 0 {
            if !world {
                out.push_str("    </body>\n");
            }
            out.push_str("  </worldbody>\n");
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
    let [lower, upper] = joint.position_range();
    if lower.is_finite() && upper.is_finite() && lower < upper {
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

/// The inertia in its principal frame: `quat` the principal axes in the body frame, `diaginertia`
/// the moments of [`mj_inertia`].
fn write_inertial(out: &mut String, indent: &str, body: &MjBody<'_>) {
    let _ = writeln!(
        out,
        "{indent}<inertial pos=\"{}\" quat=\"{}\" mass=\"{:?}\" diaginertia=\"{}\"/>",
        numbers(&body.body.inertial.origin.xyz),
        numbers(&body.inertia.quat),
        body.body.inertial.mass,
        numbers(&body.inertia.diagonal)
    );
}

/// A comment in place of the geometry of the massless link `link`, whose joint moves `body`:
/// as geoms of `body` its shapes would also move with the joints after its own.
fn write_dropped_geometry(out: &mut String, indent: &str, link: &Body, body: &Body) {
    let (visuals, collisions) = (link.visuals.len(), link.collisions.len());
    if visuals + collisions == 0 {
        return;
    }
    let _ = writeln!(
        out,
        "{indent}<!-- link '{}' (massless, its joint moves this body) has {visuals} visual and \
         {collisions} collision shapes, not exported: as geoms of '{}' they would also move with \
         its later joints -->",
        comment_text(&link.name),
        comment_text(&body.name),
    );
}

/// `text` for the inside of an XML comment: escaped, and a space between consecutive dashes
/// (a comment may not hold `--`).
fn comment_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in escape(text).chars() {
        if ch == '-' && out.ends_with('-') {
            out.push(' ');
        }
        out.push(ch);
    }
    out
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
                        comment_text(filename)
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
