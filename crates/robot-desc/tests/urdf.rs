//! Reading and writing URDF: what is kept, merged and refused, and the bit-for-bit round trip.

use proptest::prelude::*;
use robot_desc::pose::{Mat3, rpy_matrix};
use robot_desc::{DescError, JointKind, Robot, Shape, read_urdf, to_spatial, write_urdf};
use std::time::{Duration, Instant};

/// A 3-joint chain: a prismatic base axis, a revolute with limits, a continuous joint, a fixed
/// tool link, a visual box, collision cylinder and sphere, a mesh, and elements to ignore.
const ARM: &str = r#"<?xml version="1.0"?>
<robot name="arm">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="carriage"/>
    <axis xyz="0 0 2"/>
    <limit lower="0" upper="0.5" effort="100" velocity="0.2"/>
  </joint>
  <link name="carriage">
    <inertial><origin xyz="0 0 0.05" rpy="0.1 0.2 0.3"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.05" length="0.1"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="carriage"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0.5 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="10" velocity="3"/>
    <dynamics damping="0.1"/>
    <safety_controller k_velocity="1"/>
  </joint>
  <link name="upper">
    <inertial><origin xyz="0.2 0 0"/><mass value="1.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>
    <visual name="tube"><origin xyz="0.2 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><mesh filename="package://arm/upper.stl" scale="1 1 1"/></geometry>
      <material name="blue"/></visual>
  </link>
  <joint name="elbow" type="continuous">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="fore">
    <inertial><origin xyz="0.15 0 0"/><mass value="1"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="tool_mount" type="fixed">
    <parent link="fore"/><child link="tool"/>
    <origin xyz="0.3 0 0" rpy="0 0 0.5"/>
  </joint>
  <link name="tool">
    <inertial><mass value="0.5"/><inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0001" iyz="0" izz="0.0001"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <transmission name="t1"><type>x</type></transmission>
  <gazebo reference="tool"/>
</robot>
"#;

#[test]
fn reads_joints_bodies_limits_geometry_and_reports_what_it_merged_and_ignored() {
    let reading = read_urdf(ARM).unwrap();
    let robot = &reading.robot;
    assert_eq!(robot.name, "arm");
    assert_eq!(robot.base.name, "base");
    let kinds: Vec<JointKind> = robot.joints.iter().map(|j| j.kind).collect();
    assert_eq!(
        kinds,
        [
            JointKind::Prismatic,
            JointKind::Revolute,
            JointKind::Continuous
        ]
    );
    // The axis is normalised, the default origin is the identity.
    assert_eq!(robot.joints[0].axis, [0.0, 0.0, 1.0]);
    let limits = robot.joints[0].limits.unwrap();
    assert_eq!(
        (limits.lower, limits.upper, limits.effort, limits.velocity),
        (Some(0.0), Some(0.5), Some(100.0), Some(0.2))
    );
    assert_eq!(robot.joints[1].dynamics.unwrap().damping, Some(0.1));
    assert_eq!(robot.joints[1].origin.rpy, [0.0, 0.5, 0.0]);
    assert_eq!(robot.joints[0].child.inertial.origin.rpy, [0.1, 0.2, 0.3]);
    assert!(matches!(robot.base.visuals[0].shape, Shape::Box(_)));
    assert!(matches!(
        &robot.joints[1].child.visuals[0].shape,
        Shape::Mesh { filename, .. } if filename == "package://arm/upper.stl"
    ));
    // The tool is merged into the forearm, its sphere moved into the forearm's frame.
    let fore = &robot.joints[2].child;
    assert_eq!(fore.name, "fore");
    assert_eq!(fore.inertial.mass, 1.5);
    assert_eq!(fore.collisions.len(), 1);
    assert_eq!(fore.collisions[0].origin.xyz, [0.3, 0.0, 0.0]);
    assert_eq!(reading.report.merged.len(), 1);
    assert_eq!(reading.report.merged[0].link, "tool");
    assert_eq!(reading.report.merged[0].into, "fore");
    assert_eq!((reading.report.links, reading.report.joints), (5, 4));
    for ignored in [
        "material",
        "transmission",
        "gazebo",
        "joint/safety_controller",
    ] {
        assert!(reading.report.ignored.contains_key(ignored), "{ignored}");
    }
    // An element of another namespace is not URDF's, whatever its local name: listed with its
    // prefix, never read as a link.
    let xacro = ARM
        .replace(
            "<robot name=\"arm\">",
            "<robot name=\"arm\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">",
        )
        .replace(
            "<gazebo reference=\"tool\"/>",
            "<xacro:link name=\"zz\"/><xacro:property name=\"p\" value=\"1\"/>",
        );
    let reading = read_urdf(&xacro).unwrap();
    assert_eq!(reading.robot, *robot);
    for ignored in ["xacro:link", "xacro:property"] {
        assert!(reading.report.ignored.contains_key(ignored), "{ignored}");
    }
    // The file's attributes are all URDF's; a misspelt one reads as absent and is listed.
    assert!(
        !reading.report.ignored.keys().any(|k| k.contains(' ')),
        "{:?}",
        reading.report.ignored
    );
    let typo = ARM.replace(
        "<origin xyz=\"0.4 0 0\"/>",
        "<origin xyz=\"0.4 0 0\" rpy_=\"0 0 1\"/>",
    );
    let reading = read_urdf(&typo).unwrap();
    assert_eq!(reading.robot, *robot);
    assert_eq!(reading.report.ignored.get("origin rpy_"), Some(&1));
}

/// The forearm (1 kg, centre at x = 0.15) and tool (0.5 kg at x = 0.3): centre of mass and
/// inertia by hand, from the parallel-axis theorem.
#[test]
fn a_fixed_link_merges_by_the_parallel_axis_theorem() {
    let fore = &read_urdf(ARM).unwrap().robot.joints[2].child.inertial;
    let com = (1.0 * 0.15 + 0.5 * 0.3) / 1.5;
    assert!((fore.origin.xyz[0] - com).abs() < 1e-15);
    let (d1, d2) = (0.15 - com, 0.3 - com);
    let iyy = 0.01 + 1.0 * d1 * d1 + 0.0001 + 0.5 * d2 * d2;
    let ixx = 0.001 + 0.0001;
    // The tool's yaw of 0.5 rad leaves its isotropic inertia unchanged.
    let [xx, xy, xz, yy, yz, zz] = fore.inertia;
    assert!((xx - ixx).abs() < 1e-15 && (yy - iyy).abs() < 1e-15 && (zz - iyy).abs() < 1e-15);
    assert!(xy.abs() < 1e-18 && xz.abs() < 1e-18 && yz.abs() < 1e-18);
}

/// Two cubes of side `s` and mass `m` side by side weigh and turn as one `2s x s x s` box.
#[test]
fn two_welded_cubes_are_one_box() {
    let (s, m) = (0.1, 2.0);
    let cube = m * s * s / 6.0;
    let text = format!(
        r#"<robot name="boxes">
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <link name="a"><inertial><origin xyz="{h} 0 0" rpy="0.3 0.2 0.1"/><mass value="{m}"/>
    <inertia ixx="{cube}" ixy="0" ixz="0" iyy="{cube}" iyz="0" izz="{cube}"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="a"/><child link="b"/><origin xyz="{s} 0 0" rpy="1 2 3"/></joint>
  <link name="b"><inertial><origin xyz="0 0 0"/><mass value="{m}"/>
    <inertia ixx="{cube}" ixy="0" ixz="0" iyy="{cube}" iyz="0" izz="{cube}"/></inertial></link>
</robot>"#,
        h = s / 2.0,
    );
    let body = &read_urdf(&text).unwrap().robot.joints[0].child.inertial;
    let (mass, long, short) = (2.0 * m, 2.0 * s, s);
    assert_eq!(body.mass, mass);
    assert!((body.origin.xyz[0] - 0.75 * s).abs() < 1e-15);
    // The union of a cube centred at s/2 and one centred at s is not a box: check the
    // parallel-axis sum directly, d = +-s/4.
    let d = s / 4.0;
    let iyy = 2.0 * (cube + m * d * d);
    assert!((body.inertia[0] - 2.0 * cube).abs() < 1e-15);
    assert!((body.inertia[3] - iyy).abs() < 1e-15 && (body.inertia[5] - iyy).abs() < 1e-15);
    // Centred at s/2 and 3s/2 instead, they are the 2s x s x s box.
    let text = text
        .replace(
            &format!("<origin xyz=\"{s} 0 0\" rpy=\"1 2 3\"/>"),
            &format!("<origin xyz=\"{} 0 0\"/>", s),
        )
        .replace(
            "<origin xyz=\"0 0 0\"/>",
            &format!("<origin xyz=\"{h} 0 0\"/>", h = s / 2.0),
        );
    let body = &read_urdf(&text).unwrap().robot.joints[0].child.inertial;
    let box_ixx = mass * (short * short + short * short) / 12.0;
    let box_iyy = mass * (long * long + short * short) / 12.0;
    assert!((body.inertia[0] - box_ixx).abs() < 1e-15, "{body:?}");
    assert!((body.inertia[3] - box_iyy).abs() < 1e-15, "{body:?}");
}

/// Bit-for-bit identity of two models (`PartialEq` would take `-0.0` for `0.0`).
fn same_bits(a: &Robot, b: &Robot) -> bool {
    format!("{a:?}") == format!("{b:?}") && a == b
}

/// A pseudo-random chain as URDF text: random axes, origins, inertias (from random principal
/// moments satisfying the triangle inequality, rotated), some prismatic joints, massless
/// universal-joint middles, and a fixed tool link.
fn random_urdf(seed: u64, n: usize) -> String {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("<robot name=\"random\">\n<link name=\"l0\"/>\n");
    for i in 1..=n {
        let kind = match (next() * 4.0) as u32 {
            0 => "prismatic",
            1 => "continuous",
            _ => "revolute",
        };
        let v = |next: &mut dyn FnMut() -> f64| next() * 2.0 - 1.0;
        text += &format!(
            "<joint name=\"j{i}\" type=\"{kind}\"><parent link=\"l{}\"/><child link=\"l{i}\"/>\
             <origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/><axis xyz=\"{} {} {}\"/>\
             <limit lower=\"-1\" upper=\"1\" effort=\"5\" velocity=\"2\"/></joint>\n",
            i - 1,
            v(&mut next) * 0.3,
            v(&mut next) * 0.3,
            v(&mut next) * 0.3,
            v(&mut next) * 3.0,
            v(&mut next) * 1.5,
            v(&mut next) * 3.0,
            v(&mut next),
            v(&mut next),
            v(&mut next) + 0.01,
        );
        if next() < 0.2 {
            text += &format!("<link name=\"l{i}\"/>\n");
            continue;
        }
        let (a, b) = (0.01 + next() * 0.1, 0.01 + next() * 0.1);
        let c = a.max(b) - a.min(b) + next() * (a + b - (a.max(b) - a.min(b)));
        text += &format!(
            "<link name=\"l{i}\"><inertial><origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>\
             <mass value=\"{}\"/><inertia ixx=\"{a}\" ixy=\"0\" ixz=\"0\" iyy=\"{b}\" iyz=\"0\" izz=\"{c}\"/>\
             </inertial></link>\n",
            v(&mut next) * 0.2,
            v(&mut next) * 0.2,
            v(&mut next) * 0.2,
            v(&mut next),
            v(&mut next),
            v(&mut next),
            0.1 + next() * 2.0,
        );
    }
    text += &format!(
        "<joint name=\"tool_mount\" type=\"fixed\"><parent link=\"l{n}\"/><child link=\"tool\"/>\
         <origin xyz=\"0.1 0.02 0\" rpy=\"0.3 0 0.2\"/></joint>\n\
         <link name=\"tool\"><inertial><origin xyz=\"0.01 0 0\"/><mass value=\"0.3\"/>\
         <inertia ixx=\"0.001\" iyy=\"0.002\" izz=\"0.002\" ixy=\"0.0001\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n</robot>\n"
    );
    text
}

#[test]
fn read_write_read_is_the_same_model_bit_for_bit() {
    for seed in 0..40 {
        let n = 1 + (seed as usize * 7) % 30;
        let first = read_urdf(&random_urdf(seed, n)).unwrap().robot;
        assert_eq!(first.n_joints(), n);
        let written = write_urdf(&first).unwrap();
        let second = read_urdf(&written).unwrap().robot;
        assert!(same_bits(&first, &second), "seed {seed}");
        assert_eq!(write_urdf(&second).unwrap(), written, "seed {seed}");
    }
    let arm = read_urdf(ARM).unwrap().robot;
    assert!(same_bits(
        &arm,
        &read_urdf(&write_urdf(&arm).unwrap()).unwrap().robot
    ));
    // Names with a line break, a tab and markup characters, told apart from their spaced
    // versions: written as character references, they read back as they were.
    let names = chain_with("", "")
        .replace("name=\"a\"", "name=\"p&#10;q\"")
        .replace("link=\"a\"", "link=\"p&#10;q\"")
        .replace("name=\"j\"", "name=\"j&#9;&lt;&amp;&quot;\"");
    let robot = read_urdf(&names).unwrap().robot;
    assert_eq!(robot.joints[0].name, "j\t<&\"");
    assert_eq!(
        read_urdf(&write_urdf(&robot).unwrap()).unwrap().robot,
        robot
    );
}

/// Refused, with a message containing every one of `needles`, in well under a second.
fn refused(text: &str, needles: &[&str]) -> DescError {
    let start = Instant::now();
    let error = read_urdf(text).expect_err("must be refused");
    let elapsed = start.elapsed();
    let message = error.to_string();
    assert!(!message.contains('\n'), "{message}");
    for needle in needles {
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
    assert!(
        elapsed < Duration::from_millis(500),
        "{message}: took {elapsed:?}"
    );
    error
}

fn chain_with(joint_extra: &str, link_extra: &str) -> String {
    format!(
        r#"<robot name="r"><link name="a"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>{joint_extra}</joint>
  <link name="b">{link_extra}</link></robot>"#
    )
}

#[test]
fn hostile_files_are_refused_in_milliseconds() {
    // Entity expansion ("billion laughs"): no DTD is read.
    let mut laughs =
        String::from("<?xml version=\"1.0\"?>\n<!DOCTYPE robot [\n<!ENTITY l0 \"lol\">\n");
    for i in 1..10 {
        let prev = format!("&l{};", i - 1);
        laughs += &format!("<!ENTITY l{i} \"{}\">\n", prev.repeat(10));
    }
    laughs += "]>\n<robot name=\"&l9;\"><link name=\"a\"/></robot>";
    refused(&laughs, &["XML", "DTD"]);
    // 100,000 nested elements.
    let deep = format!(
        "<robot name=\"r\">{}{}</robot>",
        "<link>".repeat(100_000),
        "</link>".repeat(100_000)
    );
    refused(&deep, &["nest deeper than 32"]);
    // A 3 MB attribute.
    let long = format!(
        "<robot name=\"r\"><link name=\"{}\"/></robot>",
        "x".repeat(3 << 20)
    );
    refused(&long, &["attribute \"name\" of <link>", "3145728 bytes"]);
    // More than the size limit.
    let huge = " ".repeat(robot_desc::MAX_URDF_BYTES + 1);
    refused(&huge, &["at most 33554432 bytes"]);
    let mass = |m: &str| chain_with("", &format!("<inertial><mass value=\"{m}\"/></inertial>"));
    refused(&mass("NaN"), &["<mass> of link 'b'", "finite"]);
    refused(&mass("inf"), &["<mass> of link 'b'", "finite"]);
    refused(&mass("-1"), &["<inertial> of link 'b'", "non-negative"]);
    refused(&mass("1e300"), &["<mass> of link 'b'", "at most"]);
    refused(&mass("heavy"), &["<mass> of link 'b'", "must be a number"]);
    let inertia = |i: &str| {
        chain_with(
            "",
            &format!("<inertial><mass value=\"1\"/><inertia {i}/></inertial>"),
        )
    };
    refused(
        &inertia("ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"3\""),
        &["<inertial> of link 'b'", "triangle inequality"],
    );
    refused(
        &inertia("ixx=\"-1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\""),
        &["<inertial> of link 'b'", "positive semi-definite"],
    );
    // Off-diagonal terms that break positivity with a positive diagonal.
    refused(
        &inertia("ixx=\"1\" ixy=\"2\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\""),
        &["<inertial> of link 'b'", "positive semi-definite"],
    );
    // As urdfdom: <mass>, <inertia> and its six attributes are required (nothing defaults to 0,
    // a misspelt attribute is a missing one).
    refused(
        &inertia("ixx=\"1\" iyy=\"1\" izz=\"1\""),
        &["<inertia> of link 'b'", "ixy"],
    );
    refused(
        &inertia("Ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\""),
        &["<inertia> of link 'b'", "ixx"],
    );
    refused(
        &chain_with("", "<inertial><mass value=\"1\"/></inertial>"),
        &["<inertial> of link 'b'", "missing <inertia>"],
    );
    refused(
        &chain_with(
            "",
            "<inertial><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>",
        ),
        &["<inertial> of link 'b'", "missing <mass>"],
    );
    // Attributes by the thousand, namespace declarations by the thousand: the XML parser's
    // time grows faster than the text with either, so they are counted first.
    let attributes: String = (0..80_000).map(|k| format!(" a{k}=\"\"")).collect();
    refused(
        &format!("<robot name=\"r\"><link name=\"b\"{attributes}/></robot>"),
        &["line 1 has more than 64 attributes"],
    );
    let declarations: String = (0..2000).map(|k| format!(" xmlns:n{k}=\"u{k}\"")).collect();
    refused(
        &format!(
            "<robot name=\"r\"{declarations}>{}</robot>",
            "<x xmlns:z=\"v\"/>".repeat(2000)
        ),
        &["4000 namespace declarations", "at most 64"],
    );
}

/// A one-joint chain whose link 'b' has mass 1 and the inertia tensor `i` written as decimals
/// in an `<inertial>` frame turned by `rpy`.
fn inertia_chain(i: &Mat3, rpy: [f64; 3]) -> String {
    chain_with(
        "",
        &format!(
            "<inertial><origin xyz=\"0.1 0 0\" rpy=\"{:?} {:?} {:?}\"/><mass value=\"1\"/>\
             <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>\
             </inertial>",
            rpy[0], rpy[1], rpy[2], i[0][0], i[0][1], i[0][2], i[1][1], i[1][2], i[2][2]
        ),
    )
}

/// `R diag(d) R^T`, exactly symmetric.
fn turned(r: &Mat3, d: [f64; 3]) -> Mat3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| d[k] * (r[i][k] * r[j][k])).sum()))
}

fn diagonal(d: [f64; 3]) -> Mat3 {
    turned(&rpy_matrix([0.0; 3]), d)
}

/// Read, accepted as a dynamics model, its principal moments `expected` (ascending) to 1e-14 of
/// the largest.
fn read_with_moments(text: &str, expected: [f64; 3]) {
    let robot = read_urdf(text).unwrap().robot;
    to_spatial(&robot, [0.0, 0.0, -9.81]).unwrap();
    let moments = robot.joints[0].child.inertial.principal().values;
    for (got, want) in moments.iter().zip(expected) {
        assert!(
            (got - want).abs() <= 1e-14 * expected[2],
            "{moments:?} vs {expected:?}"
        );
    }
}

/// Principal moments satisfying the triangle inequalities, of order one: general ones (from
/// non-negative second moments), rods `(0, I, I)`, spheres `(I, I, I)`, plates `(a, b, a + b)`.
fn moments() -> impl Strategy<Value = [f64; 3]> {
    prop_oneof![
        [0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64]
            .prop_filter("not all small", |s| s.iter().sum::<f64>() > 0.01)
            .prop_map(|[a, b, c]| [b + c, a + c, a + b]),
        (0.01..1.0f64).prop_map(|i| [0.0, i, i]),
        (0.01..1.0f64).prop_map(|i| [i, i, i]),
        (0.01..1.0f64, 0.01..1.0f64).prop_map(|(a, b)| [a, b, a + b]),
    ]
}

fn rpy() -> impl Strategy<Value = [f64; 3]> {
    [-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    /// Physical inertias turned by any rotation, as the `<inertial>` frame's `rpy` or as the
    /// decimals of the full tensor, read and are dynamics models, their principal moments
    /// recovered to 1e-14 (about 70% of turned rods were refused when the moments came from
    /// the closed form of the cubic).
    #[test]
    fn turned_physical_inertias_are_read(d in moments(), a in rpy(), b in rpy(), exponent in -6..=6i32) {
        let d = d.map(|x| x * 10f64.powi(exponent));
        let mut expected = d;
        expected.sort_by(f64::total_cmp);
        read_with_moments(&inertia_chain(&diagonal(d), a), expected);
        read_with_moments(&inertia_chain(&turned(&rpy_matrix(b), d), [0.0; 3]), expected);
        read_with_moments(&inertia_chain(&turned(&rpy_matrix(b), d), a), expected);
    }

    /// A moment beyond the sum of the other two, or negative, by 1e-6 of the moments is refused
    /// however the tensor is turned.
    #[test]
    fn turned_unphysical_inertias_are_refused(a in 0.01..1.0f64, b in 0.01..1.0f64, r in rpy()) {
        let r = rpy_matrix(r);
        refused(
            &inertia_chain(&turned(&r, [a, b, (a + b) * (1.0 + 1e-6)]), [0.0; 3]),
            &["<inertial> of link 'b'", "triangle inequality"],
        );
        refused(
            &inertia_chain(&turned(&r, [-1e-6 * a, a, a]), [0.0; 3]),
            &["<inertial> of link 'b'", "positive semi-definite"],
        );
    }
}

/// The rods the closed form of the cubic refused: `(0, 0.01, 0.01)` turned by a quarter turn
/// of pitch, and rods along `(3, 4, 5)` and `(1, 1, 3)` as exact decimals.
#[test]
fn turned_slender_rods_are_read() {
    read_with_moments(
        &inertia_chain(
            &diagonal([0.0, 0.01, 0.01]),
            [0.0, std::f64::consts::FRAC_PI_2, 0.0],
        ),
        [0.0, 0.01, 0.01],
    );
    read_with_moments(
        &inertia_chain(
            &[[0.82, -0.24, -0.3], [-0.24, 0.68, -0.4], [-0.3, -0.4, 0.5]],
            [0.0; 3],
        ),
        [0.0, 1.0, 1.0],
    );
    let (a, b, c, d) = (
        0.9090909090909091,
        -0.09090909090909091,
        -0.27272727272727276,
        0.18181818181818177,
    );
    read_with_moments(
        &inertia_chain(&[[a, b, c], [b, a, c], [c, c, d]], [0.0; 3]),
        [0.0, 1.0, 1.0],
    );
}

#[test]
fn what_is_not_a_serial_chain_is_refused_naming_the_element() {
    refused(
        &chain_with("<axis xyz=\"0 0 0\"/>", ""),
        &["<axis> of joint 'j'", "must not be zero"],
    );
    refused(
        &chain_with("<axis xyz=\"0 1\"/>", ""),
        &["<axis> of joint 'j'", "3 numbers"],
    );
    for kind in ["floating", "planar"] {
        let text = chain_with("", "").replace("revolute", kind);
        refused(&text, &["joint 'j'", kind, "serial chains"]);
    }
    refused(
        &chain_with("", "").replace("revolute", "screw"),
        &["joint 'j'", "unknown joint type \"screw\""],
    );
    let tree = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="c"/></joint></robot>"#;
    refused(
        tree,
        &["link 'a'", "two movable joints", "'j1'", "'j2'", "tree"],
    );
    // A tree hidden behind a fixed joint: the body both hang from is named, and the link the
    // second hangs from.
    let hidden = r#"<robot name="r"><link name="a"/><link name="s"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="f" type="fixed"><parent link="a"/><child link="s"/></joint>
      <joint name="j2" type="revolute"><parent link="s"/><child link="c"/></joint></robot>"#;
    refused(
        hidden,
        &[
            "link 'a': has two movable joints",
            "through link 's'",
            "tree",
        ],
    );
    let diamond = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="c"/></joint>
      <joint name="j3" type="revolute"><parent link="a"/><child link="c"/></joint></robot>"#;
    refused(diamond, &["link 'c'", "child of two joints", "closed loop"]);
    let ring = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="revolute"><parent link="c"/><child link="c2"/></joint>
      <link name="c2"/>
      <joint name="j3" type="revolute"><parent link="c2"/><child link="c"/></joint></robot>"#;
    refused(ring, &["link 'c'", "no path to the root link 'a'"]);
    let orphan = r#"<robot name="r"><link name="a"/><link name="b"/><link name="lost"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint></robot>"#;
    refused(orphan, &["link 'lost'", "no path to the root link 'a'"]);
    let twice = r#"<robot name="r"><link name="a"/><link name="a"/></robot>"#;
    refused(twice, &["link 'a'", "used twice"]);
    let joints_twice = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j" type="revolute"><parent link="b"/><child link="c"/></joint></robot>"#;
    refused(joints_twice, &["joint 'j'", "used twice"]);
    refused(
        &chain_with("", "").replace("<child link=\"b\"/>", "<child link=\"z\"/>"),
        &["joint 'j'", "child link 'z' does not exist"],
    );
    refused(
        &chain_with("<limit lower=\"1\" upper=\"-1\"/>", ""),
        &["<limit> of joint 'j'", "must not exceed"],
    );
    // An empty name (urdfdom refuses it; no joint could name such a link).
    refused(
        &chain_with("", "")
            .replace("<link name=\"b\">", "<link name=\"\">")
            .replace("<child link=\"b\"/>", "<child link=\"\"/>"),
        &["attribute \"link\" must not be empty"],
    );
    refused(
        &chain_with("", "").replace("<link name=\"b\">", "<link name=\"\">"),
        &["<link> at line", "attribute \"name\" must not be empty"],
    );
    refused(
        "<robot><link name=\"a\"/></robot>",
        &["<robot>", "missing attribute \"name\""],
    );
    refused("<model name=\"x\"/>", &["<model>", "must be <robot>"]);
    // Past the node limit: named by its number, not in the parser's words.
    let crowded = format!("<robot name=\"r\">{}</robot>", "<a/>".repeat(1_000_000));
    refused(
        &crowded,
        &["more than the 1000000 XML nodes a robot description may have"],
    );
    refused(
        "<x:robot xmlns:x=\"urn:x\" name=\"r\"><x:link name=\"a\"/></x:robot>",
        &[
            "<robot>",
            "must be <robot> in no namespace, not in namespace \"urn:x\"",
        ],
    );
    // 2,000 fixed joints of 1e9 m each: every origin within its bound, their composition not.
    let mut deep = String::from("<robot name=\"r\"><link name=\"l0\"/>");
    for i in 0..2000 {
        deep += &format!(
            "<joint name=\"f{i}\" type=\"fixed\"><origin xyz=\"1e9 0 0\"/><parent link=\"l{i}\"/>\
             <child link=\"l{}\"/></joint><link name=\"l{}\"/>",
            i + 1,
            i + 1
        );
    }
    deep += "<joint name=\"j\" type=\"continuous\"><parent link=\"l2000\"/><child link=\"t\"/></joint>\
             <link name=\"t\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" \
             iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link></robot>";
    refused(
        &deep,
        &[
            "joint 'f1'",
            "composed through the fixed joints",
            "2e9 m",
            "more than 1e9",
        ],
    );
    refused(
        "<robot name=\"x\"><link name=\"a\">",
        &["not a readable XML document"],
    );
}

#[test]
fn a_long_chain_reads_in_linear_time() {
    // 5000 joints (about 2 MB with inertias) read well inside the time of a few milliseconds
    // a joint would take if anything were quadratic.
    let text = random_urdf(7, 5000);
    let start = Instant::now();
    let robot = read_urdf(&text).unwrap().robot;
    assert_eq!(robot.n_joints(), 5000);
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn what_is_written_of_a_long_chain_reads_back() {
    // 30,000 joints: about 12 MB read, and the written file (full inertias, every limit) is
    // longer than the text read; it reads back within the bound, the same chain.
    let text = random_urdf(3, 30_000);
    let robot = read_urdf(&text).unwrap().robot;
    let written = write_urdf(&robot).unwrap();
    assert!(written.len() > text.len() && written.len() < robot_desc::MAX_URDF_BYTES);
    assert_eq!(read_urdf(&written).unwrap().robot, robot);
}

#[test]
fn the_longest_spatial_arm_is_written_and_read_back_and_a_longer_refused() {
    use modal_reduce::spatial::SpatialReducedModel;
    use robot_desc::{MAX_SPATIAL_EXPORT_LINKS, from_spatial_arm};
    let arm = |n| SpatialReducedModel::uniform_rods(n, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    let robot = from_spatial_arm(&arm(MAX_SPATIAL_EXPORT_LINKS), "longest").unwrap();
    assert_eq!(robot.n_joints(), 2 * MAX_SPATIAL_EXPORT_LINKS);
    let written = write_urdf(&robot).unwrap();
    assert_eq!(read_urdf(&written).unwrap().robot, robot);
    let error = from_spatial_arm(&arm(MAX_SPATIAL_EXPORT_LINKS + 1), "longer").unwrap_err();
    assert_eq!(
        error.to_string(),
        "cannot export robot 'longer': 10001 links exceed the 10000 a spatial arm is written with"
    );
}

#[test]
fn a_name_xml_cannot_carry_is_named_as_such_not_as_a_size() {
    let text = r#"<robot name="r"><link name="b"/><link name="a"><inertial><mass value="1"/>
<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
<joint name="j" type="continuous"><parent link="b"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#;
    let mut robot = read_urdf(text).unwrap().robot;
    robot.joints[0].name = "j\0".into();
    let message = write_urdf(&robot).unwrap_err().to_string();
    assert!(
        message.contains("a character XML cannot carry") && !message.contains("larger than"),
        "{message}"
    );
}

/// A `<limit>` read as urdfdom (and with it ROS and Pinocchio) reads it: a missing `lower` or
/// `upper` is 0; a continuous joint and a joint without `<limit>` are unbounded.
#[test]
fn position_ranges_read_a_missing_bound_as_zero() {
    let range = |joint: &str, limit: &str| {
        let text = chain_with(limit, "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>")
            .replace("type=\"revolute\"", &format!("type=\"{joint}\""));
        read_urdf(&text).unwrap().robot.joints[0].position_range()
    };
    let free = [f64::NEG_INFINITY, f64::INFINITY];
    assert_eq!(
        range(
            "revolute",
            "<limit lower=\"-1\" upper=\"2\" effort=\"1\" velocity=\"1\"/>"
        ),
        [-1.0, 2.0]
    );
    assert_eq!(
        range("revolute", "<limit effort=\"1\" velocity=\"1\"/>"),
        [0.0, 0.0]
    );
    assert_eq!(
        range(
            "prismatic",
            "<limit lower=\"-1\" effort=\"1\" velocity=\"1\"/>"
        ),
        [-1.0, 0.0]
    );
    assert_eq!(range("revolute", "<limit upper=\"0.5\"/>"), [0.0, 0.5]);
    assert_eq!(
        range("continuous", "<limit effort=\"1\" velocity=\"1\"/>"),
        free
    );
    assert_eq!(range("revolute", ""), free);
    // A lone lower bound above the missing upper's 0 gives no range: refused, as an inverted
    // pair is; a continuous joint's bounds are not read.
    refused(
        &chain_with("<limit lower=\"1\" effort=\"1\" velocity=\"1\"/>", ""),
        &[
            "<limit> of joint 'j'",
            "lower (1) must not exceed upper (0, the default of a missing bound)",
        ],
    );
    let lone = "<limit lower=\"1\" effort=\"1\" velocity=\"1\"/>";
    assert_eq!(range("continuous", lone), free);
}

/// A fixed joint's `<axis>`, `<limit>` and `<dynamics>` mean nothing (urdfdom reads none): a
/// zero axis or an inverted limit there is listed as ignored, not refused.
#[test]
fn a_fixed_joints_axis_and_limit_are_ignored() {
    let text = r#"<robot name="r"><link name="a"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
      <link name="b"><inertial><mass value="1"/>
        <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="tool" type="fixed"><parent link="b"/><child link="c"/><axis xyz="0 0 0"/>
        <limit lower="0" upper="-1" effort="1" velocity="1"/><dynamics damping="-3"/></joint>
      <link name="c"/></robot>"#;
    let reading = read_urdf(text).unwrap();
    assert_eq!(reading.robot.joints.len(), 1);
    for tag in ["axis", "limit", "dynamics"] {
        assert_eq!(
            reading.report.ignored.get(&format!("fixed joint/{tag}")),
            Some(&1),
            "{tag}"
        );
    }
    // On a movable joint the same elements are read and refused.
    refused(
        &chain_with("<axis xyz=\"0 0 0\"/>", ""),
        &["<axis> of joint 'j'", "must not be zero"],
    );
}

/// A link merged with those fixed to it holds only numbers a URDF can hold (each within 1e9, as
/// every written one): two links of 1e9 kg, or a shape 1e9 m beyond a fixed joint 1e9 m out,
/// are refused when read, naming the link and the joint, not later by an export.
#[test]
fn merged_links_stay_within_the_bounds_of_a_urdf() {
    let inertia = "<inertia ixx=\"1e8\" ixy=\"0\" ixz=\"0\" iyy=\"1e8\" iyz=\"0\" izz=\"1e8\"/>";
    let robot = |fixed_origin: &str, tip: &str| {
        format!(
            r#"<robot name="r"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><mass value="1e9"/>{inertia}</inertial></link>
  <joint name="f" type="fixed"><parent link="a"/><child link="t"/><origin xyz="{fixed_origin}"/></joint>
  <link name="t">{tip}</link></robot>"#
        )
    };
    let heavy = format!("<inertial><mass value=\"1e9\"/>{inertia}</inertial>");
    refused(
        &robot("0 0 0", &heavy),
        &[
            "link 'a'",
            "through joint 'f'",
            "a mass of 2e9 kg",
            "more than 1e9",
        ],
    );
    let far =
        "<visual><origin xyz=\"1e9 0 0\"/><geometry><sphere radius=\"1\"/></geometry></visual>";
    refused(
        &robot("1e9 0 0", far),
        &["link 'a'", "a shape's origin at 2e9 m"],
    );
    // Within the bounds, the merged link reads and writes back.
    let reading = read_urdf(&robot("0.5 0 0", &far.replace("1e9", "0.5"))).unwrap();
    assert!(read_urdf(&write_urdf(&reading.robot).unwrap()).is_ok());
}
