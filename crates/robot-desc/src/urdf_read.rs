//! Reading URDF serial chains, with every size bounded before it reaches an allocation.

use crate::error::DescError;
use crate::model::{
    Body, Geometry, Inertial, Joint, JointDynamics, JointKind, Limits, Robot, Shape,
};
use crate::pose::Pose;
use roxmltree::{Document, Node, ParsingOptions};
use std::collections::{BTreeMap, HashMap};

/// Longest URDF text read (bytes). A chain of 1000 links with geometry takes about 1 MB, and
/// what [`write_urdf`](crate::write_urdf) writes of a chain read within this bound (about 400
/// bytes a joint) fits in it up to some 80,000 joints.
pub const MAX_URDF_BYTES: usize = 32 << 20;

/// Deepest element nesting read. URDF needs five levels (`robot > link > visual > geometry >
/// box`); a document nesting deeper is refused before anything is built from it.
pub const MAX_XML_DEPTH: usize = 32;

/// Most XML nodes (elements, text, comments) a document may have.
pub const MAX_XML_NODES: u32 = 1_000_000;

/// Longest attribute value (bytes): a mesh file name is the longest legitimate one.
pub const MAX_ATTRIBUTE_BYTES: usize = 4096;

/// Most attributes an element may have (URDF's `<inertia>` has six): the XML parser's check
/// for duplicated attributes takes time quadratic in their number.
pub const MAX_ATTRIBUTES: usize = 64;

/// Most namespace declarations (`xmlns`) a text may have (a xacro file has a few): the XML
/// parser's namespace resolution takes time proportional to their number for every element.
pub const MAX_NAMESPACES: usize = 64;

/// Largest magnitude of any number read (lengths in m, masses in kg, inertias in kg m^2,
/// limits): far beyond any robot, small enough that products of a few never overflow.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// A link merged into another by a fixed joint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Merged {
    /// The fixed joint.
    pub joint: String,
    /// The link merged away.
    pub link: String,
    /// The body it joined.
    pub into: String,
}

/// What [`read_urdf`] read, merged and ignored (for `hrm arm check`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadReport {
    /// `<link>` elements read.
    pub links: usize,
    /// `<joint>` elements read (fixed ones included).
    pub joints: usize,
    /// Links merged into their parent through fixed joints, in chain order.
    pub merged: Vec<Merged>,
    /// Elements skipped because they do not change the chain's kinematics or dynamics
    /// (`transmission`, `gazebo`, `material`, a joint's `mimic` or `safety_controller`...), by
    /// path, with how many times each occurred.
    pub ignored: BTreeMap<String, usize>,
}

/// A description read from URDF and the report of how.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The chain.
    pub robot: Robot,
    /// What was read, merged and ignored.
    pub report: ReadReport,
}

/// Reads a URDF serial chain.
///
/// Bounds first: at most [`MAX_URDF_BYTES`], at most [`MAX_NAMESPACES`] namespace declarations
/// and [`MAX_ATTRIBUTES`] attributes an element (counted on the text in one pass, before the
/// XML parser, whose time grows faster than the text with either), no DTD (so no entity is ever
/// expanded), at most [`MAX_XML_NODES`] nodes nested at most [`MAX_XML_DEPTH`] deep, attribute
/// values of at most [`MAX_ATTRIBUTE_BYTES`]. Then the chain: `revolute`, `continuous` and `prismatic` joints are
/// its degrees of freedom; links behind `fixed` joints are merged into their parent body (mass
/// properties by the parallel-axis theorem, geometry moved into the parent's frame, the next
/// joint's origin composed). Axes are normalised. Trees, closed loops, `floating` and `planar`
/// joints, links without a path to the root and duplicated names are refused, naming the element.
pub fn read_urdf(text: &str) -> Result<Reading, DescError> {
    if text.len() > MAX_URDF_BYTES {
        return Err(DescError::TooLarge {
            got: text.len(),
            max: MAX_URDF_BYTES,
        });
    }
    check_markup(text)?;
    let options = ParsingOptions {
        allow_dtd: false,
        nodes_limit: MAX_XML_NODES,
        ..ParsingOptions::default()
    };
    let doc = Document::parse_with_options(text, options).map_err(|e| match e {
        roxmltree::Error::NodesLimitReached => DescError::TooManyNodes { max: MAX_XML_NODES },
        other => DescError::Xml(other),
    })?;
    check_shape(&doc)?;
    let root = doc.root_element();
    // A prefixed `<x:robot>` is another vocabulary's element, as `<xacro:link>` is no link.
    if root.tag_name().name() != "robot" || root.tag_name().namespace().is_some() {
        let problem = match root.tag_name().namespace() {
            Some(namespace) => format!(
                "the document's element must be <robot> in no namespace, not in namespace \
                 {namespace:?}"
            ),
            None => "the document's element must be <robot>".to_string(),
        };
        return Err(DescError::invalid(
            format!("<{}>", root.tag_name().name()),
            problem,
        ));
    }
    let name = required(root, "name", || "<robot>".to_string())?.to_string();
    let mut report = ReadReport::default();
    let mut links: Vec<UrdfLink> = Vec::new();
    let mut joints: Vec<UrdfJoint> = Vec::new();
    for child in root.children().filter(Node::is_element) {
        let tag = child.tag_name();
        // An element of another namespace (`xacro:property`) is not URDF's, whatever its name.
        if tag.namespace() != root.tag_name().namespace() {
            let prefix = tag.namespace().and_then(|uri| child.lookup_prefix(uri));
            ignore(
                &mut report,
                &format!("{}:{}", prefix.unwrap_or_default(), tag.name()),
            );
            continue;
        }
        match tag.name() {
            "link" => links.push(read_link(child, &mut report)?),
            "joint" => joints.push(read_joint(child, &mut report)?),
            other => ignore(&mut report, other),
        }
    }
    report.links = links.len();
    report.joints = joints.len();
    ignore_unknown_attributes(root, &mut report);
    let robot = assemble(name, links, joints, &mut report)?;
    Ok(Reading { robot, report })
}

/// The attributes URDF gives each element this reader reads (the elements it skips are listed
/// whole).
const ATTRIBUTES: &[(&str, &[&str])] = &[
    ("robot", &["name"]),
    ("link", &["name"]),
    ("joint", &["name", "type"]),
    ("inertial", &[]),
    ("origin", &["xyz", "rpy"]),
    ("mass", &["value"]),
    ("inertia", &["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]),
    ("visual", &["name"]),
    ("collision", &["name"]),
    ("geometry", &[]),
    ("box", &["size"]),
    ("cylinder", &["radius", "length"]),
    ("sphere", &["radius"]),
    ("mesh", &["filename", "scale"]),
    ("parent", &["link"]),
    ("child", &["link"]),
    ("axis", &["xyz"]),
    ("limit", &["lower", "upper", "effort", "velocity"]),
    ("dynamics", &["damping", "friction"]),
];

/// Lists, as `<origin rpy_>`, every attribute URDF does not give an element this reader reads (a
/// misspelt one reads as absent: its default), walking down from `root` through those elements
/// only (at most [`MAX_XML_DEPTH`] deep, checked before).
fn ignore_unknown_attributes(root: Node<'_, '_>, report: &mut ReadReport) {
    let namespace = root.tag_name().namespace();
    let mut pending = vec![root];
    while let Some(node) = pending.pop() {
        let tag = node.tag_name();
        let Some((_, known)) = ATTRIBUTES.iter().find(|(name, _)| *name == tag.name()) else {
            continue;
        };
        if tag.namespace() != namespace {
            continue;
        }
        for attribute in node.attributes() {
            if attribute.namespace().is_none() && !known.contains(&attribute.name()) {
                ignore(report, &format!("{} {}", tag.name(), attribute.name()));
            }
        }
        pending.extend(node.children().filter(Node::is_element));
    }
}

/// Namespace declarations and attributes an element, counted on the text in one pass: every
/// `xmlns` (in markup or not: a description has a few), and in every tag the `=` outside quoted
/// values (comments, CDATA sections and processing instructions skipped).
fn check_markup(text: &str) -> Result<(), DescError> {
    let namespaces = text.matches("xmlns").count();
    if namespaces > MAX_NAMESPACES {
        return Err(DescError::TooManyNamespaces {
            got: namespaces,
            max: MAX_NAMESPACES,
        });
    }
    let bytes = text.as_bytes();
    let mut line = 1u32;
    let mut i = 0;
    // Skips past `end` from `from`, counting lines; `None` when `end` never comes (the parser
    // then refuses the text).
    let skip = |from: usize, end: &str, line: &mut u32| {
        let rest = &text[from..];
        let at = rest.find(end)?;
        *line += rest[..at].matches('\n').count() as u32;
        Some(from + at + end.len())
    };
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => {
                line += 1;
                i += 1;
            }
            b'<' => {
                let rest = &text[i..];
                let skipped = if rest.starts_with("<!--") {
                    skip(i + 4, "-->", &mut line)
                } else if rest.starts_with("<![CDATA[") {
                    skip(i + 9, "]]>", &mut line)
                } else if rest.starts_with("<?") {
                    skip(i + 2, "?>", &mut line)
                } else {
                    let start = line;
                    let (mut quote, mut attributes) = (None, 0);
                    let mut j = i + 1;
                    while j < bytes.len() {
                        match (bytes[j], quote) {
                            (b'\n', _) => line += 1,
                            (b'"' | b'\'', None) => quote = Some(bytes[j]),
                            (c, Some(q)) if c == q => quote = None,
                            (b'=', None) => attributes += 1,
                            (b'>', None) => break,
                            _ => {}
                        }
                        j += 1;
                    }
                    if attributes > MAX_ATTRIBUTES {
                        return Err(DescError::TooManyAttributes {
                            line: start,
                            max: MAX_ATTRIBUTES,
                        });
                    }
                    Some(j + 1)
                };
                match skipped {
                    Some(next) => i = next,
                    None => return Ok(()),
                }
            }
            _ => i += 1,
        }
    }
    Ok(())
}

/// Depth and attribute lengths, checked on the parsed document in one pass in document order
/// (a node's depth is its parent's plus one; no recursion, no walk up the ancestors).
fn check_shape(doc: &Document<'_>) -> Result<(), DescError> {
    let mut depths: Vec<u32> = Vec::new();
    for node in doc.descendants() {
        let depth = node.parent().map_or(0, |p| depths[p.id().get_usize()] + 1);
        let index = node.id().get_usize();
        if depths.len() <= index {
            depths.resize(index + 1, 0);
        }
        depths[index] = depth;
        if !node.is_element() {
            continue;
        }
        if depth as usize > MAX_XML_DEPTH {
            return Err(DescError::TooDeep {
                max: MAX_XML_DEPTH,
                line: line_of(node),
            });
        }
        for attribute in node.attributes() {
            if attribute.value().len() > MAX_ATTRIBUTE_BYTES {
                return Err(DescError::AttributeTooLong {
                    element: node.tag_name().name().to_string(),
                    attribute: attribute.name().to_string(),
                    line: line_of(node),
                    got: attribute.value().len(),
                    max: MAX_ATTRIBUTE_BYTES,
                });
            }
        }
    }
    Ok(())
}

fn line_of(node: Node<'_, '_>) -> u32 {
    node.document().text_pos_at(node.range().start).row
}

fn ignore(report: &mut ReadReport, path: &str) {
    *report.ignored.entry(path.to_string()).or_insert(0) += 1;
}

/// A `<link>` as written.
struct UrdfLink {
    name: String,
    body: Body,
}

/// A `<joint>` as written.
struct UrdfJoint {
    name: String,
    /// `None` for `fixed`.
    kind: Option<JointKind>,
    parent: String,
    child: String,
    origin: Pose,
    axis: [f64; 3],
    limits: Option<Limits>,
    dynamics: Option<JointDynamics>,
}

fn required<'a>(
    node: Node<'a, '_>,
    attribute: &str,
    element: impl FnOnce() -> String,
) -> Result<&'a str, DescError> {
    node.attribute(attribute)
        .ok_or_else(|| DescError::invalid(element(), format!("missing attribute {attribute:?}")))
}

/// A name (of a link or joint, or the link a joint names): [`required`], and not empty, which
/// urdfdom refuses and no joint could name.
fn required_name<'a>(
    node: Node<'a, '_>,
    attribute: &str,
    element: impl Fn() -> String,
) -> Result<&'a str, DescError> {
    let name = required(node, attribute, &element)?;
    if name.is_empty() {
        return Err(DescError::invalid(
            element(),
            format!("attribute {attribute:?} must not be empty"),
        ));
    }
    Ok(name)
}

/// One number, finite and at most [`MAX_MAGNITUDE`] in magnitude.
fn number(text: &str, what: &str, element: &dyn Fn() -> String) -> Result<f64, DescError> {
    let value: f64 = text.trim().parse().map_err(|_| {
        DescError::invalid(element(), format!("{what} must be a number, got {text:?}"))
    })?;
    if !value.is_finite() || value.abs() > MAX_MAGNITUDE {
        return Err(DescError::invalid(
            element(),
            format!(
                "{what} must be finite and at most {MAX_MAGNITUDE:e} in magnitude, got {value}"
            ),
        ));
    }
    Ok(value)
}

/// Exactly three numbers separated by white space.
fn triple(text: &str, what: &str, element: &dyn Fn() -> String) -> Result<[f64; 3], DescError> {
    let mut values = [0.0; 3];
    let mut tokens = text.split_ascii_whitespace();
    for value in &mut values {
        let token = tokens.next().ok_or_else(|| {
            DescError::invalid(
                element(),
                format!("{what} must have 3 numbers, got {text:?}"),
            )
        })?;
        *value = number(token, what, element)?;
    }
    if tokens.next().is_some() {
        return Err(DescError::invalid(
            element(),
            format!("{what} must have 3 numbers, got more"),
        ));
    }
    Ok(values)
}

/// An optional numeric attribute.
fn optional_number(
    node: Node<'_, '_>,
    attribute: &str,
    element: &dyn Fn() -> String,
) -> Result<Option<f64>, DescError> {
    node.attribute(attribute)
        .map(|text| number(text, attribute, element))
        .transpose()
}

/// A required numeric attribute.
fn required_number(
    node: Node<'_, '_>,
    attribute: &str,
    element: &dyn Fn() -> String,
) -> Result<f64, DescError> {
    number(required(node, attribute, element)?, attribute, element)
}

/// The `<origin>` child, identity when absent.
fn origin(node: Node<'_, '_>, element: &dyn Fn() -> String) -> Result<Pose, DescError> {
    let mut origins = node.children().filter(|c| c.has_tag_name("origin"));
    let Some(origin) = origins.next() else {
        return Ok(Pose::IDENTITY);
    };
    if origins.next().is_some() {
        return Err(DescError::invalid(element(), "more than one <origin>"));
    }
    let element = || format!("<origin> of {}", element());
    Ok(Pose {
        xyz: origin
            .attribute("xyz")
            .map(|t| triple(t, "xyz", &element))
            .transpose()?
            .unwrap_or_default(),
        rpy: origin
            .attribute("rpy")
            .map(|t| triple(t, "rpy", &element))
            .transpose()?
            .unwrap_or_default(),
    })
}

/// A single child element, or `None`; two are refused.
fn single<'a, 'i>(
    node: Node<'a, 'i>,
    tag: &str,
    element: &dyn Fn() -> String,
) -> Result<Option<Node<'a, 'i>>, DescError> {
    let mut found = node.children().filter(|c| c.has_tag_name(tag));
    let first = found.next();
    if first.is_some() && found.next().is_some() {
        return Err(DescError::invalid(
            element(),
            format!("more than one <{tag}>"),
        ));
    }
    Ok(first)
}

fn read_link(node: Node<'_, '_>, report: &mut ReadReport) -> Result<UrdfLink, DescError> {
    let name =
        required_name(node, "name", || format!("<link> at line {}", line_of(node)))?.to_string();
    let element = || format!("link '{name}'");
    let mut body = Body {
        name: name.clone(),
        ..Body::default()
    };
    if let Some(inertial) = single(node, "inertial", &element)? {
        body.inertial = read_inertial(inertial, &name)?;
    }
    for child in node.children().filter(Node::is_element) {
        match child.tag_name().name() {
            "inertial" => {}
            "visual" => body
                .visuals
                .push(read_geometry(child, &name, "visual", report)?),
            "collision" => body
                .collisions
                .push(read_geometry(child, &name, "collision", report)?),
            other => ignore(report, &format!("link/{other}")),
        }
    }
    Ok(UrdfLink { name, body })
}

fn read_inertial(node: Node<'_, '_>, link: &str) -> Result<Inertial, DescError> {
    let element = || format!("<inertial> of link '{link}'");
    let origin = origin(node, &element)?;
    // As urdfdom (ROS, Pinocchio) reads it: <mass> and <inertia> with its six attributes are
    // required, nothing defaults to zero.
    let mass = single(node, "mass", &element)?
        .ok_or_else(|| DescError::invalid(element(), "missing <mass>"))?;
    let mass = required_number(mass, "value", &|| format!("<mass> of link '{link}'"))?;
    if mass < 0.0 {
        return Err(DescError::invalid(
            element(),
            format!("mass must be non-negative, got {mass}"),
        ));
    }
    let tensor = single(node, "inertia", &element)?
        .ok_or_else(|| DescError::invalid(element(), "missing <inertia>"))?;
    let mut inertia = [0.0; 6];
    let tensor_element = || format!("<inertia> of link '{link}'");
    for (value, attribute) in inertia
        .iter_mut()
        .zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"])
    {
        *value = required_number(tensor, attribute, &tensor_element)?;
    }
    let inertial = Inertial {
        origin,
        mass,
        inertia,
    };
    inertial.physical(|problem| DescError::invalid(element(), problem))?;
    Ok(inertial)
}

fn read_geometry(
    node: Node<'_, '_>,
    link: &str,
    kind: &str,
    report: &mut ReadReport,
) -> Result<Geometry, DescError> {
    let element = || format!("<{kind}> of link '{link}'");
    let origin = origin(node, &element)?;
    let geometry = single(node, "geometry", &element)?
        .ok_or_else(|| DescError::invalid(element(), "missing <geometry>"))?;
    let mut shapes = geometry.children().filter(Node::is_element);
    let shape_node = shapes
        .next()
        .ok_or_else(|| DescError::invalid(element(), "<geometry> has no shape"))?;
    if shapes.next().is_some() {
        return Err(DescError::invalid(
            element(),
            "<geometry> has more than one shape",
        ));
    }
    let shape_element = || format!("<{}> of {}", shape_node.tag_name().name(), element());
    let positive = |value: f64, what: &str| {
        if value > 0.0 {
            Ok(value)
        } else {
            Err(DescError::invalid(
                shape_element(),
                format!("{what} must be positive, got {value}"),
            ))
        }
    };
    let shape = match shape_node.tag_name().name() {
        "box" => {
            let size = triple(
                required(shape_node, "size", shape_element)?,
                "size",
                &shape_element,
            )?;
            for side in size {
                positive(side, "size")?;
            }
            Shape::Box(size)
        }
        "cylinder" => Shape::Cylinder {
            radius: positive(
                required_number(shape_node, "radius", &shape_element)?,
                "radius",
            )?,
            length: positive(
                required_number(shape_node, "length", &shape_element)?,
                "length",
            )?,
        },
        "sphere" => Shape::Sphere(positive(
            required_number(shape_node, "radius", &shape_element)?,
            "radius",
        )?),
        "mesh" => Shape::Mesh {
            filename: required(shape_node, "filename", shape_element)?.to_string(),
            scale: shape_node
                .attribute("scale")
                .map(|t| triple(t, "scale", &shape_element))
                .transpose()?,
        },
        other => {
            return Err(DescError::invalid(
                element(),
                format!("unknown shape <{other}> (box, cylinder, sphere and mesh are read)"),
            ));
        }
    };
    for child in node.children().filter(Node::is_element) {
        let tag = child.tag_name().name();
        if !matches!(tag, "origin" | "geometry") {
            ignore(report, &format!("link/{kind}/{tag}"));
        }
    }
    Ok(Geometry {
        name: node.attribute("name").map(str::to_string),
        origin,
        shape,
    })
}

fn read_joint(node: Node<'_, '_>, report: &mut ReadReport) -> Result<UrdfJoint, DescError> {
    let name = required_name(node, "name", || {
        format!("<joint> at line {}", line_of(node))
    })?
    .to_string();
    let element = || format!("joint '{name}'");
    let kind = match required(node, "type", element)? {
        "revolute" => Some(JointKind::Revolute),
        "continuous" => Some(JointKind::Continuous),
        "prismatic" => Some(JointKind::Prismatic),
        "fixed" => None,
        kind @ ("floating" | "planar") => {
            return Err(DescError::not_a_chain(
                element(),
                format!("{kind} joints are not read (a fixed base, one degree of freedom a joint)"),
            ));
        }
        other => {
            return Err(DescError::invalid(
                element(),
                format!("unknown joint type {other:?}"),
            ));
        }
    };
    let link_of = |tag: &str| -> Result<String, DescError> {
        let child = single(node, tag, &element)?
            .ok_or_else(|| DescError::invalid(element(), format!("missing <{tag}>")))?;
        Ok(required_name(child, "link", || format!("<{tag}> of joint '{name}'"))?.to_string())
    };
    let (parent, child) = (link_of("parent")?, link_of("child")?);
    let origin = origin(node, &element)?;
    // A fixed joint has no axis, limits or dynamics (urdfdom reads none of them there, so an
    // exporter's `<axis xyz="0 0 0"/>` on one is no error): listed as ignored.
    let (axis, limits, dynamics) = if let Some(kind) = kind {
        movable_parts(node, &name, kind)?
    } else {
        for tag in ["axis", "limit", "dynamics"] {
            if single(node, tag, &element)?.is_some() {
                ignore(report, &format!("fixed joint/{tag}"));
            }
        }
        ([1.0, 0.0, 0.0], None, None)
    };
    for child in node.children().filter(Node::is_element) {
        let tag = child.tag_name().name();
        if !matches!(
            tag,
            "parent" | "child" | "origin" | "axis" | "limit" | "dynamics"
        ) {
            ignore(report, &format!("joint/{tag}"));
        }
    }
    Ok(UrdfJoint {
        name,
        kind,
        parent,
        child,
        origin,
        axis,
        limits,
        dynamics,
    })
}

/// A movable joint's unit axis, `<limit>` and `<dynamics>`.
type MovableParts = ([f64; 3], Option<Limits>, Option<JointDynamics>);

/// The `<axis>` (default `x`), `<limit>` and `<dynamics>` of the movable joint `name`.
fn movable_parts(
    node: Node<'_, '_>,
    name: &str,
    kind: JointKind,
) -> Result<MovableParts, DescError> {
    let element = || format!("joint '{name}'");
    let axis = match single(node, "axis", &element)? {
        Some(axis) => {
            let element = || format!("<axis> of joint '{name}'");
            normalised(triple(required(axis, "xyz", element)?, "xyz", &element)?)
                .ok_or_else(|| DescError::invalid(element(), "the axis must not be zero"))?
        }
        None => [1.0, 0.0, 0.0],
    };
    let limits = single(node, "limit", &element)?
        .map(|limit| {
            let element = || format!("<limit> of joint '{name}'");
            let limits = Limits {
                lower: optional_number(limit, "lower", &element)?,
                upper: optional_number(limit, "upper", &element)?,
                effort: optional_number(limit, "effort", &element)?,
                velocity: optional_number(limit, "velocity", &element)?,
            };
            check_limits(&limits, kind, &element)?;
            Ok::<_, DescError>(limits)
        })
        .transpose()?;
    let dynamics = single(node, "dynamics", &element)?
        .map(|dynamics| {
            let element = || format!("<dynamics> of joint '{name}'");
            let values = JointDynamics {
                damping: optional_number(dynamics, "damping", &element)?,
                friction: optional_number(dynamics, "friction", &element)?,
            };
            for (what, value) in [("damping", values.damping), ("friction", values.friction)] {
                if let Some(value) = value.filter(|v| *v < 0.0) {
                    return Err(DescError::invalid(
                        element(),
                        format!("{what} must be non-negative, got {value}"),
                    ));
                }
            }
            Ok(values)
        })
        .transpose()?;
    Ok((axis, limits, dynamics))
}

/// The `<limit>` of a joint of `kind` ordered (a missing bound read as 0, as
/// [`Joint::position_range`](crate::Joint::position_range) reads it; a continuous joint's bounds
/// are not read) and non-negative; `element` names it in the error.
fn check_limits(
    limits: &Limits,
    kind: JointKind,
    element: &dyn Fn() -> String,
) -> Result<(), DescError> {
    let (lower, upper) = (limits.lower.unwrap_or(0.0), limits.upper.unwrap_or(0.0));
    if kind != JointKind::Continuous && lower > upper {
        let shown = |value: Option<f64>| {
            value.map_or("0, the default of a missing bound".to_string(), |v| {
                v.to_string()
            })
        };
        return Err(DescError::invalid(
            element(),
            format!(
                "lower ({}) must not exceed upper ({})",
                shown(limits.lower),
                shown(limits.upper)
            ),
        ));
    }
    for (what, value) in [("effort", limits.effort), ("velocity", limits.velocity)] {
        if let Some(value) = value.filter(|v| *v < 0.0) {
            return Err(DescError::invalid(
                element(),
                format!("{what} must be non-negative, got {value}"),
            ));
        }
    }
    Ok(())
}

/// `v / |v|`, or `None` for a zero vector. A vector already of unit length within four units
/// in the last place is kept as it is, so that normalising is idempotent and a written model
/// reads back bit for bit.
pub(crate) fn normalised(v: [f64; 3]) -> Option<[f64; 3]> {
    // Scale first so that tiny and huge axes neither underflow nor overflow the norm.
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale == 0.0 {
        return None;
    }
    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if (norm - 1.0).abs() <= 4.0 * f64::EPSILON {
        return Some(v);
    }
    let s = v.map(|x| x / scale);
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some(s.map(|x| x / n))
}

/// Builds the chain from the links and joints as written.
fn assemble(
    name: String,
    links: Vec<UrdfLink>,
    joints: Vec<UrdfJoint>,
    report: &mut ReadReport,
) -> Result<Robot, DescError> {
    if links.is_empty() {
        return Err(DescError::invalid(
            format!("robot '{name}'"),
            "has no <link>",
        ));
    }
    let mut link_index: HashMap<&str, usize> = HashMap::with_capacity(links.len());
    for (i, link) in links.iter().enumerate() {
        if link_index.insert(&link.name, i).is_some() {
            return Err(DescError::invalid(
                format!("link '{}'", link.name),
                "the name is used twice",
            ));
        }
    }
    let mut joint_names: HashMap<&str, ()> = HashMap::with_capacity(joints.len());
    // The joint of which each link is the child, and the joints leaving each link.
    let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); links.len()];
    let mut child_of = Vec::with_capacity(joints.len());
    for (j, joint) in joints.iter().enumerate() {
        let element = || format!("joint '{}'", joint.name);
        if joint_names.insert(&joint.name, ()).is_some() {
            return Err(DescError::invalid(element(), "the name is used twice"));
        }
        let find = |link: &str, role: &str| {
            link_index.get(link).copied().ok_or_else(|| {
                DescError::invalid(
                    element(),
                    format!("its {role} link '{link}' does not exist"),
                )
            })
        };
        let (parent, child) = (find(&joint.parent, "parent")?, find(&joint.child, "child")?);
        if parent == child {
            return Err(DescError::not_a_chain(
                element(),
                "joins link to itself (a closed loop)",
            ));
        }
        if let Some(other) = parent_joint[child] {
            return Err(DescError::not_a_chain(
                format!("link '{}'", joint.child),
                format!(
                    "is the child of two joints, '{}' and '{}' (a closed loop)",
                    joints[other].name, joint.name
                ),
            ));
        }
        parent_joint[child] = Some(j);
        children[parent].push(j);
        child_of.push(child);
    }
    let mut roots = (0..links.len()).filter(|&i| parent_joint[i].is_none());
    let root = roots.next().ok_or_else(|| {
        DescError::not_a_chain(
            format!("robot '{name}'"),
            "every link is the child of a joint, there is no root (a closed loop)",
        )
    })?;
    if let Some(other) = roots.next() {
        return Err(DescError::not_a_chain(
            format!("link '{}'", links[other].name),
            format!(
                "has no path to the root link '{}' (both are children of no joint)",
                links[root].name
            ),
        ));
    }
    let mut visited = vec![false; links.len()];
    let mut chain = Chain {
        links: links.into_iter().map(Some).collect(),
        joints: joints.into_iter().map(Some).collect(),
        children,
        child_of,
    };
    let (base, mut next) = weld(root, &mut chain, &mut visited, report)?;
    let mut movable = Vec::new();
    while let Some((j, placement)) = next {
        let joint = chain.joints[j].take().expect("a joint has one parent link");
        let (body, after) = weld(chain.child_of[j], &mut chain, &mut visited, report)?;
        let origin = within_bounds(placement.compose(&joint.origin), &joint.name)?;
        movable.push(Joint {
            name: joint.name,
            kind: joint.kind.expect("weld hands on movable joints only"),
            origin,
            axis: joint.axis,
            limits: joint.limits,
            dynamics: joint.dynamics,
            child: body,
        });
        next = after;
    }
    if let Some(lost) = visited.iter().position(|v| !v) {
        let lost_name = &chain.links[lost]
            .as_ref()
            .expect("unvisited links are there")
            .name;
        return Err(DescError::not_a_chain(
            format!("link '{lost_name}'"),
            format!(
                "has no path to the root link '{}' (a closed loop)",
                base.name
            ),
        ));
    }
    Ok(Robot {
        name,
        base,
        joints: movable,
    })
}

/// The body of link `first` and every link welded to it by fixed joints, and the one movable
/// joint leaving it (with the placement of its parent link in the body frame), if any.
fn weld(
    first: usize,
    chain: &mut Chain,
    visited: &mut [bool],
    report: &mut ReadReport,
) -> Result<(Body, Option<(usize, Pose)>), DescError> {
    visited[first] = true;
    let mut body = chain.links[first]
        .take()
        .expect("each link is visited once")
        .body;
    let mut movable: Option<(usize, Pose)> = None;
    // Links of the body still to expand, with their placement in the body frame.
    let mut stack = vec![(first, Pose::IDENTITY, body.name.clone())];
    while let Some((link, placement, link_name)) = stack.pop() {
        for &j in &chain.children[link] {
            let joint = chain.joints[j]
                .as_ref()
                .expect("joints below an unvisited link are there");
            if joint.kind.is_some() {
                if let Some((other, _)) = movable {
                    let other = chain.joints[other].as_ref().expect("still there");
                    // The body the two hang from, and the link behind a fixed joint that
                    // carries the second when it is another.
                    let welded = if link_name == body.name {
                        String::new()
                    } else {
                        format!(" (the second through link '{link_name}', fixed to it)")
                    };
                    return Err(DescError::not_a_chain(
                        format!("link '{}'", body.name),
                        format!(
                            "has two movable joints below it, '{}' and '{}'{welded} (a tree)",
                            other.name, joint.name
                        ),
                    ));
                }
                movable = Some((j, placement));
                continue;
            }
            let joint = chain.joints[j].take().expect("checked above");
            let child = chain.child_of[j];
            visited[child] = true;
            let welded = chain.links[child]
                .take()
                .expect("a link has one parent joint");
            let at = within_bounds(placement.compose(&joint.origin), &joint.name)?;
            if !welded.body.inertial.is_massless() {
                body.inertial = body.inertial.merged(&welded.body.inertial, &at);
                merged_within_bounds(&body.inertial, &body.name, &joint.name)?;
            }
            for (from, to) in [
                (welded.body.visuals, &mut body.visuals),
                (welded.body.collisions, &mut body.collisions),
            ] {
                for geometry in from {
                    let origin = at.compose(&geometry.origin);
                    if let Some(x) = origin.xyz.iter().find(|x| x.abs() > MAX_MAGNITUDE) {
                        return Err(beyond_bounds(
                            &body.name,
                            &joint.name,
                            format!("a shape's origin at {x:e} m"),
                        ));
                    }
                    to.push(Geometry { origin, ..geometry });
                }
            }
            report.merged.push(Merged {
                joint: joint.name,
                link: welded.name.clone(),
                into: body.name.clone(),
            });
            stack.push((child, at, welded.name));
        }
    }
    Ok((body, movable))
}

/// `origin`, the frame of joint `name` composed through the fixed joints before it, if its
/// translation is within [`MAX_MAGNITUDE`] as every written origin is (2,000 fixed joints of
/// `1e9` m each compose to `2e12`, which no URDF written back could hold).
fn within_bounds(origin: Pose, name: &str) -> Result<Pose, DescError> {
    match origin.xyz.iter().find(|x| x.abs() > MAX_MAGNITUDE) {
        None => Ok(origin),
        Some(x) => Err(DescError::invalid(
            format!("joint '{}'", lane_math::one_line(name)),
            format!(
                "its origin composed through the fixed joints before it is {x:e} m from the \
                 base, more than {MAX_MAGNITUDE:e}"
            ),
        )),
    }
}

/// `inertial`, link `body`'s mass properties with a link fixed to it by joint `joint` merged in,
/// if every number of it is within [`MAX_MAGNITUDE`] as every written one is (two links of
/// `1e9` kg merge to `2e9`, which no URDF written back could hold).
fn merged_within_bounds(inertial: &Inertial, body: &str, joint: &str) -> Result<(), DescError> {
    let numbers = [
        ("a mass of", "kg", inertial.mass),
        ("a centre of mass at", "m", inertial.origin.xyz[0]),
        ("a centre of mass at", "m", inertial.origin.xyz[1]),
        ("a centre of mass at", "m", inertial.origin.xyz[2]),
    ]
    .into_iter()
    .chain(
        inertial
            .inertia
            .map(|i| ("an inertia entry of", "kg m^2", i)),
    );
    for (what, unit, value) in numbers {
        if value.abs() > MAX_MAGNITUDE {
            return Err(beyond_bounds(
                body,
                joint,
                format!("{what} {value:e} {unit}"),
            ));
        }
    }
    Ok(())
}

/// The error of a link whose merge through fixed joint `joint` gives it `what`, beyond
/// [`MAX_MAGNITUDE`].
fn beyond_bounds(body: &str, joint: &str, what: String) -> DescError {
    DescError::invalid(
        format!("link '{}'", lane_math::one_line(body)),
        format!(
            "merged with the links fixed to it (through joint '{}'), it has {what}, more than \
             {MAX_MAGNITUDE:e} (the bound of every number a URDF holds)",
            lane_math::one_line(joint)
        ),
    )
}

/// The links and joints not yet taken into bodies, and the chain's connectivity.
struct Chain {
    links: Vec<Option<UrdfLink>>,
    joints: Vec<Option<UrdfJoint>>,
    /// The joints leaving each link.
    children: Vec<Vec<usize>>,
    /// Each joint's child link.
    child_of: Vec<usize>,
}
