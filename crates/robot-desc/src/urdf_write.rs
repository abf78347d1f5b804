//! Writing a chain as URDF, numbers in Rust's shortest round-trip form so that reading the text
//! back gives the same model bit for bit.

use crate::error::DescError;
use crate::model::{Body, Geometry, Inertial, Robot, Shape};
use crate::pose::Pose;
use crate::urdf_read::read_urdf;
use std::fmt::Write;

/// The most movable joints a description is written with, checked before any text is: what
/// [`read_urdf`] reads back (its [`MAX_XML_NODES`](crate::MAX_XML_NODES), about 23 a joint of a
/// planar chain: 43,478 joints are the most it reads), so that every planar arm within it is
/// written; a chain of heavier links may still be refused by the read-back.
pub const MAX_EXPORT_JOINTS: usize = 40_000;

/// The chain as a URDF document: the base link, then each movable joint and its child link.
/// Fixed links were merged when the model was read, so none is written; reading the result
/// gives back `robot` exactly (every `f64` is printed in its shortest form that parses back to
/// the same bits).
///
/// # Errors
/// [`DescError::Export`] for more than [`MAX_EXPORT_JOINTS`] joints (checked before anything is
/// written) and for a robot whose document [`read_urdf`] would refuse (a number beyond
/// [`MAX_MAGNITUDE`](crate::MAX_MAGNITUDE), an inertia that is not physical, ...): the text is
/// read back before it is returned, so what this writes, this crate reads.
pub fn write_urdf(robot: &Robot) -> Result<String, DescError> {
    if robot.joints.len() > MAX_EXPORT_JOINTS {
        return Err(DescError::export(
            format!("robot '{}'", robot.name),
            format!(
                "{} movable joints exceed the {MAX_EXPORT_JOINTS} a description is written with",
                robot.joints.len()
            ),
        ));
    }
    let text = urdf_text(robot);
    read_urdf(&text).map_err(|e| {
        DescError::export(
            format!("robot '{}'", robot.name),
            match e {
                // Too large a document: say so with the joints, not only as the XML limit.
                DescError::Xml(_) => format!(
                    "its URDF would not read back (a name or path holding a character XML cannot \
                     carry, such as a control character): {e}"
                ),
                DescError::TooLarge { .. } | DescError::TooManyNodes { .. } => {
                    format!(
                        "its URDF of {} movable joints is larger than a URDF is read back (at most \
                         {} XML nodes, about 25 a joint, and {} MiB): {e}",
                        robot.joints.len(),
                        crate::MAX_XML_NODES,
                        crate::MAX_URDF_BYTES >> 20
                    )
                }
                e => format!("its URDF would not read back: {e}"),
            },
        )
    })?;
    Ok(text)
}

/// [`write_urdf`]'s text, unchecked.
fn urdf_text(robot: &Robot) -> String {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(out, "<robot name=\"{}\">", escape(&robot.name));
    write_link(&mut out, &robot.base);
    let mut parent = &robot.base.name;
    for joint in &robot.joints {
        let _ = writeln!(
            out,
            "  <joint name=\"{}\" type=\"{}\">",
            escape(&joint.name),
            joint.kind.urdf_name()
        );
        let _ = writeln!(out, "    <parent link=\"{}\"/>", escape(parent));
        let _ = writeln!(out, "    <child link=\"{}\"/>", escape(&joint.child.name));
        write_origin(&mut out, "    ", &joint.origin);
        let _ = writeln!(out, "    <axis xyz=\"{}\"/>", numbers(&joint.axis));
        if let Some(limits) = &joint.limits {
            out.push_str("    <limit");
            for (name, value) in [
                ("lower", limits.lower),
                ("upper", limits.upper),
                ("effort", limits.effort),
                ("velocity", limits.velocity),
            ] {
                if let Some(value) = value {
                    let _ = write!(out, " {name}=\"{value:?}\"");
                }
            }
            out.push_str("/>\n");
        }
        if let Some(dynamics) = &joint.dynamics {
            out.push_str("    <dynamics");
            for (name, value) in [
                ("damping", dynamics.damping),
                ("friction", dynamics.friction),
            ] {
                if let Some(value) = value {
                    let _ = write!(out, " {name}=\"{value:?}\"");
                }
            }
            out.push_str("/>\n");
        }
        out.push_str("  </joint>\n");
        write_link(&mut out, &joint.child);
        parent = &joint.child.name;
    }
    out.push_str("</robot>\n");
    out
}

fn write_link(out: &mut String, body: &Body) {
    let _ = writeln!(out, "  <link name=\"{}\">", escape(&body.name));
    if !all_zero_bits(&body.inertial) {
        let Inertial {
            origin,
            mass,
            inertia: [ixx, ixy, ixz, iyy, iyz, izz],
        } = &body.inertial;
        out.push_str("    <inertial>\n");
        write_origin(out, "      ", origin);
        let _ = writeln!(out, "      <mass value=\"{mass:?}\"/>");
        let _ = writeln!(
            out,
            "      <inertia ixx=\"{ixx:?}\" ixy=\"{ixy:?}\" ixz=\"{ixz:?}\" iyy=\"{iyy:?}\" \
             iyz=\"{iyz:?}\" izz=\"{izz:?}\"/>"
        );
        out.push_str("    </inertial>\n");
    }
    for (tag, geometries) in [("visual", &body.visuals), ("collision", &body.collisions)] {
        for geometry in geometries {
            write_geometry(out, tag, geometry);
        }
    }
    out.push_str("  </link>\n");
}

/// True when every number of the inertial is `+0.0`, as for a link read without `<inertial>`.
fn all_zero_bits(inertial: &Inertial) -> bool {
    let o = &inertial.origin;
    o.xyz
        .iter()
        .chain(&o.rpy)
        .chain(std::iter::once(&inertial.mass))
        .chain(&inertial.inertia)
        .all(|v| v.to_bits() == 0)
}

fn write_geometry(out: &mut String, tag: &str, geometry: &Geometry) {
    match &geometry.name {
        Some(name) => {
            let _ = writeln!(out, "    <{tag} name=\"{}\">", escape(name));
        }
        None => {
            let _ = writeln!(out, "    <{tag}>");
        }
    }
    write_origin(out, "      ", &geometry.origin);
    out.push_str("      <geometry>\n");
    let _ = match &geometry.shape {
        Shape::Box(size) => writeln!(out, "        <box size=\"{}\"/>", numbers(size)),
        Shape::Cylinder { radius, length } => writeln!(
            out,
            "        <cylinder radius=\"{radius:?}\" length=\"{length:?}\"/>"
        ),
        Shape::Sphere(radius) => writeln!(out, "        <sphere radius=\"{radius:?}\"/>"),
        Shape::Mesh { filename, scale } => {
            let _ = write!(out, "        <mesh filename=\"{}\"", escape(filename));
            if let Some(scale) = scale {
                let _ = write!(out, " scale=\"{}\"", numbers(scale));
            }
            writeln!(out, "/>")
        }
    };
    out.push_str("      </geometry>\n");
    let _ = writeln!(out, "    </{tag}>");
}

fn write_origin(out: &mut String, indent: &str, pose: &Pose) {
    let _ = writeln!(
        out,
        "{indent}<origin xyz=\"{}\" rpy=\"{}\"/>",
        numbers(&pose.xyz),
        numbers(&pose.rpy)
    );
}

/// Numbers separated by spaces, each in Rust's shortest round-trip form (`{:?}`, which uses
/// an exponent for very small and very large magnitudes).
pub(crate) fn numbers(values: &[f64]) -> String {
    let mut text = String::new();
    for (i, value) in values.iter().enumerate() {
        if i > 0 {
            text.push(' ');
        }
        let _ = write!(text, "{value:?}");
    }
    text
}

/// Text safe inside a double-quoted XML attribute, read back unchanged: a line break or tab is
/// written as a character reference, since a reader normalises a literal one to a space.
pub(crate) fn escape(text: &str) -> String {
    let mut escaped = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => escaped.push_str("&amp;"),
            '<' => escaped.push_str("&lt;"),
            '>' => escaped.push_str("&gt;"),
            '"' => escaped.push_str("&quot;"),
            '\'' => escaped.push_str("&apos;"),
            '\n' => escaped.push_str("&#10;"),
            '\r' => escaped.push_str("&#13;"),
            '\t' => escaped.push_str("&#9;"),
            c => escaped.push(c),
        }
    }
    escaped
}
