//! The MJCF text: inertias in their principal frames (the written `quat` and `diaginertia` give
//! the link's tensor back and satisfy MuJoCo's `A + B >= C` exactly), the refusal of what MuJoCo
//! refuses naming the link, a root link named `world` as MuJoCo's world body, and the comment in
//! place of a massless link's geometry. `crates/hrm-py/tests/test_robot_engines.py` loads the
//! same exports in MuJoCo.

use manip_dyn::{ChainModel, Link};
use proptest::prelude::*;
use robot_desc::pose::{Mat3, matrix_quaternion, rpy_matrix};
use robot_desc::{MAX_EXPORT_JOINTS, MJ_MINVAL, from_planar, read_urdf, write_mjcf, write_urdf};
use test_support::numeric::quaternion_matrix;

/// A one-joint chain: base 'b', link 'a' with the `<inertial>` content `inertial`.
fn one_link(inertial: &str) -> String {
    format!(
        r#"<robot name="r"><link name="b"/><link name="a"><inertial>{inertial}</inertial></link>
<joint name="j" type="continuous"><parent link="b"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#
    )
}

/// The `<inertial>` of mass 1 at `(0.1, 0, 0)`, its frame turned by `rpy`, the tensor `i`.
fn inertial(i: &Mat3, rpy: [f64; 3]) -> String {
    format!(
        "<origin xyz=\"0.1 0 0\" rpy=\"{:?} {:?} {:?}\"/><mass value=\"1\"/>\
         <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>",
        rpy[0], rpy[1], rpy[2], i[0][0], i[0][1], i[0][2], i[1][1], i[1][2], i[2][2]
    )
}

/// The MJCF of a URDF text.
fn mjcf(urdf: &str) -> Result<String, String> {
    let robot = read_urdf(urdf).map_err(|e| e.to_string())?.robot;
    write_mjcf(&robot, [0.0, 0.0, -9.81]).map_err(|e| e.to_string())
}

/// The numbers of attribute `name` of the first element of `text` holding it.
fn attribute(text: &str, name: &str) -> Vec<f64> {
    let start = text.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
    let end = start + text[start..].find('"').unwrap();
    text[start..end]
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect()
}

/// `R diag(d) R^T`, exactly symmetric.
fn turned(r: &Mat3, d: [f64; 3]) -> Mat3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| d[k] * (r[i][k] * r[j][k])).sum()))
}

/// The exported `<inertial>` of link 'a': `quat` and `diaginertia`, checked as MuJoCo checks
/// them (moments at least `MJ_MINVAL`, `A + B >= C` in floating point), give back its tensor in
/// the link frame to `tolerance` of the largest moment. Returns the diagonal.
fn principal_frame_gives_the_tensor(urdf: &str, tolerance: f64) -> Vec<f64> {
    let robot = read_urdf(urdf).unwrap().robot;
    let text = write_mjcf(&robot, [0.0, 0.0, -9.81]).unwrap();
    let line = text.lines().find(|l| l.contains("<inertial ")).unwrap();
    let (quat, diagonal) = (attribute(line, "quat"), attribute(line, "diaginertia"));
    assert!(diagonal.iter().all(|&m| m >= MJ_MINVAL), "{line}");
    let [a, b, c] = [diagonal[0], diagonal[1], diagonal[2]];
    assert!(a + b >= c && a + c >= b && b + c >= a, "{line}");
    let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() <= 1e-14, "{line}");
    let back = turned(
        &quaternion_matrix([quat[0], quat[1], quat[2], quat[3]]),
        [a, b, c],
    );
    let (_, tensor) = robot.joints[0].child.inertial.in_link_frame();
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (back[i][j] - tensor[i][j]).abs() <= tolerance * c,
                "{line}: {back:?} vs {tensor:?}"
            );
        }
    }
    diagonal
}

/// Principal moments of order one whose smallest is well above `MJ_MINVAL`: general ones,
/// near-rods `(I / 1000, I, I)`, spheres, plates `(a, b, a + b)`.
fn moments() -> impl Strategy<Value = [f64; 3]> {
    prop_oneof![
        [0.01..1.0f64, 0.01..1.0f64, 0.01..1.0f64].prop_map(|[a, b, c]| [b + c, a + c, a + b]),
        (0.01..1.0f64).prop_map(|i| [1e-3 * i, i, i]),
        (0.01..1.0f64).prop_map(|i| [i, i, i]),
        (0.01..1.0f64, 0.01..1.0f64).prop_map(|(a, b)| [a, b, a + b]),
    ]
}

fn rpy() -> impl Strategy<Value = [f64; 3]> {
    [-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Any physical inertia, turned by its `<inertial>` frame and as a full tensor, is written
    /// in a principal frame that gives it back, with moments MuJoCo accepts.
    #[test]
    fn principal_frames_give_the_tensor_back(d in moments(), a in rpy(), b in rpy()) {
        principal_frame_gives_the_tensor(&one_link(&inertial(&turned(&rpy_matrix(b), d), a)), 1e-14);
    }
}

/// The thin plate whose rotated `fullinertia` MuJoCo refused: written in its own principal
/// frame, the inertial frame's quaternion and its exact moments.
#[test]
fn a_turned_thin_plate_keeps_its_moments_exactly() {
    let rpy = [0.3, 0.4, 0.5];
    let plate = one_link(&inertial(
        &turned(&rpy_matrix([0.0; 3]), [0.01, 0.01, 0.02]),
        rpy,
    ));
    assert_eq!(
        principal_frame_gives_the_tensor(&plate, 1e-15),
        [0.01, 0.01, 0.02]
    );
    let text = mjcf(&plate).unwrap();
    assert_eq!(
        attribute(&text[text.find("<inertial").unwrap()..], "quat"),
        matrix_quaternion(&rpy_matrix(rpy))
    );
}

/// A largest moment over the sum of the other two by less than the reader's tolerance (1e-9 of
/// the trace) is written as that sum, which MuJoCo's `A + B >= C` accepts.
#[test]
fn a_largest_moment_over_the_sum_by_rounding_is_lowered_to_it() {
    let over = one_link(&inertial(
        &turned(&rpy_matrix([0.0; 3]), [0.01, 0.01, 0.020000000001]),
        [0.0; 3],
    ));
    assert_eq!(
        principal_frame_gives_the_tensor(&over, 1e-10),
        [0.01, 0.01, 0.02]
    );
}

/// What MuJoCo refuses ("mass and inertia of moving bodies must be larger than mjMINVAL",
/// "inertia must satisfy A + B >= C") is refused in one line naming the link.
#[test]
fn masses_and_moments_below_mjminval_are_refused_naming_the_link() {
    let diagonal = |d: [f64; 3]| turned(&rpy_matrix([0.0; 3]), d);
    let tiny_mass = one_link(
        "<mass value=\"1e-16\"/><inertia ixx=\"1e-16\" iyy=\"1e-16\" izz=\"1e-16\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>",
    );
    let rod = one_link(&inertial(&diagonal([0.0, 0.01, 0.01]), [0.0, 1.2, 0.0]));
    let tiny_moment = one_link(&inertial(&diagonal([1e-300, 1.0, 1.0]), [0.0; 3]));
    for urdf in [tiny_mass, rod, tiny_moment] {
        let message = mjcf(&urdf).unwrap_err();
        assert!(!message.contains('\n'), "{message}");
        for needle in [
            "cannot export link 'a' to MJCF",
            "MuJoCo needs a mass and principal moments of inertia of at least 1e-15",
        ] {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
    }
    // The bound itself is accepted.
    let least = one_link(&inertial(&diagonal([MJ_MINVAL, 1.0, 1.0]), [0.0; 3]));
    assert_eq!(
        principal_frame_gives_the_tensor(&least, 0.0),
        [MJ_MINVAL, 1.0, 1.0]
    );
    let light = one_link(
        "<mass value=\"1e-15\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>",
    );
    assert!(mjcf(&light).is_ok());
    // A planar arm of point-like links (`hrm.Arm(inertias=[1e-20, 1e-20]).to_mjcf()`).
    let link = Link::new(0.1, 0.1, 0.05, 1e-20).unwrap();
    let arm = from_planar(&ChainModel::new(vec![link; 2], 9.81).unwrap(), "arm").unwrap();
    let message = write_mjcf(&arm, [0.0, -9.81, 0.0]).unwrap_err().to_string();
    assert!(
        message.contains("link 'link_1' to MJCF") && message.contains("at least 1e-15"),
        "{message}"
    );
}

/// A description built in code is checked as `read_urdf` checks a file: an inertia breaking
/// the triangle inequality beyond the tolerance is not exported.
#[test]
fn an_unphysical_inertia_built_in_code_is_refused() {
    let mut robot = read_urdf(&one_link(
        "<mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>",
    ))
    .unwrap()
    .robot;
    robot.joints[0].child.inertial.inertia = [1.0, 0.0, 0.0, 1.0, 0.0, 2.001];
    let message = write_mjcf(&robot, [0.0; 3]).unwrap_err().to_string();
    assert!(
        message.contains("link 'a'") && message.contains("triangle inequality"),
        "{message}"
    );
}

/// ROS's root link `world` is MuJoCo's world body: no body of that name (MuJoCo refuses a second
/// one), its geometry and the first moving body directly in `<worldbody>`. A moving link of
/// that name is refused.
#[test]
fn a_root_link_named_world_is_the_world_body() {
    let urdf = r#"<robot name="r"><link name="world"><visual><geometry><box size="1 1 0.1"/></geometry></visual></link>
<link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j" type="continuous"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>"#;
    let text = mjcf(urdf).unwrap();
    assert!(!text.contains("name=\"world\""), "{text}");
    let lines: Vec<&str> = text.lines().collect();
    let world = lines.iter().position(|l| *l == "  <worldbody>").unwrap();
    assert!(
        lines[world + 1].starts_with("    <geom type=\"box\""),
        "{text}"
    );
    assert!(
        lines[world + 2]
            .trim_start()
            .starts_with("<body name=\"a\""),
        "{text}"
    );
    assert_eq!(
        lines[lines.len() - 3..],
        ["    </body>", "  </worldbody>", "</mujoco>"]
    );
    assert_eq!(
        text.matches("<body").count(),
        text.matches("</body>").count()
    );
    let moving = urdf
        .replace("link name=\"world\"", "link name=\"b\"")
        .replace("parent link=\"world\"", "parent link=\"b\"")
        .replace("\"a\"", "\"world\"");
    let message = mjcf(&moving).unwrap_err();
    assert!(
        message.contains("link 'world' to MJCF") && message.contains("reserves the name"),
        "{message}"
    );
}

/// The geometry of a massless link whose joint moves the next body is named in a comment, which
/// says why it is not a geom of that body; the comment's text never holds `--`.
#[test]
fn a_massless_links_geometry_is_named_in_a_comment() {
    let urdf = |geometry: &str, name: &str| {
        format!(
            r#"<robot name="r"><link name="b"/><link name="{name}">{geometry}</link>
<link name="a"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j1" type="continuous"><parent link="b"/><child link="{name}"/><axis xyz="0 0 1"/></joint>
<joint name="j2" type="continuous"><parent link="{name}"/><child link="a"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/></joint></robot>"#
        )
    };
    let sphere = "<origin xyz=\"0.3 0 0\"/><geometry><sphere radius=\"0.05\"/></geometry>";
    let visual = mjcf(&urdf(&format!("<visual>{sphere}</visual>"), "m")).unwrap();
    assert!(
        visual.contains(
            "<!-- link 'm' (massless, its joint moves this body) has 1 visual and 0 collision \
             shapes, not exported: as geoms of 'a' they would also move with its later joints -->"
        ),
        "{visual}"
    );
    let collision = mjcf(&urdf(
        &format!("<collision>{sphere}</collision><collision>{sphere}</collision>"),
        "m---x",
    ))
    .unwrap();
    assert!(
        collision.contains(
            "<!-- link 'm- - -x' (massless, its joint moves this body) has 0 visual and 2 collision"
        ),
        "{collision}"
    );
    for text in [visual, collision] {
        assert!(!text.contains("<geom"), "{text}");
        for comment in text.split("<!--").skip(1) {
            let inside = &comment[..comment.find("-->").unwrap()];
            assert!(!inside.contains("--"), "{inside}");
        }
    }
}

/// What is written reads back: a link mass beyond what `read_urdf` reads, a gravity beyond its
/// bound and a chain beyond `MAX_EXPORT_JOINTS` are refused, naming the robot or the gravity,
/// before any text is returned.
#[test]
fn what_the_reader_would_refuse_is_not_written() {
    let heavy = from_planar(&ChainModel::uniform(3, 0.1, 1e10, 9.81).unwrap(), "heavy").unwrap();
    let error = write_urdf(&heavy).unwrap_err().to_string();
    assert!(
        error.starts_with("cannot export robot 'heavy': its URDF would not read back: ")
            && error.contains("at most 1e9"),
        "{error}"
    );
    let error = write_mjcf(&heavy, [0.0, -9.81, 0.0])
        .unwrap_err()
        .to_string();
    assert!(error.contains("its URDF would not read back"), "{error}");
    // Within MAX_EXPORT_JOINTS but more XML than the reader reads back (names of 2,000
    // characters: some 40 MB): said with the joints.
    let mut long = from_planar(
        &ChainModel::uniform(10_000, 0.1, 0.1, 9.81).unwrap(),
        "long",
    )
    .unwrap();
    for (k, joint) in long.joints.iter_mut().enumerate() {
        joint.name = format!("j{k}{}", "_".repeat(2000));
        joint.child.name = format!("l{k}{}", "_".repeat(2000));
    }
    let error = write_urdf(&long).unwrap_err().to_string();
    assert!(
        error.starts_with(
            "cannot export robot 'long': its URDF of 10000 movable joints is larger than a URDF \
             is read back (at most 1000000 XML nodes"
        ),
        "{error}"
    );
    // The most joints written: a planar arm of MAX_EXPORT_JOINTS links reads back.
    let most = from_planar(
        &ChainModel::uniform(MAX_EXPORT_JOINTS, 1e-3, 1e-3, 9.81).unwrap(),
        "most",
    )
    .unwrap();
    assert!(write_urdf(&most).is_ok());
    // MJCF: refused by its bodies before the URDF is written.
    let error = write_mjcf(&most, [0.0, -9.81, 0.0])
        .unwrap_err()
        .to_string();
    assert_eq!(
        error,
        "cannot export robot 'most' to MJCF: 40000 nested bodies exceed the 1022 MuJoCo compiles"
    );
    let arm = from_planar(&ChainModel::uniform(3, 0.1, 0.1, 9.81).unwrap(), "arm").unwrap();
    for gravity in [[0.0, -1e300, 0.0], [f64::NAN, 0.0, 0.0]] {
        let error = write_mjcf(&arm, gravity).unwrap_err().to_string();
        assert!(
            error.starts_with("cannot export gravity to MJCF"),
            "{error}"
        );
    }
    assert!(write_mjcf(&arm, [0.0, -9.81, 0.0]).is_ok());
    let long = ChainModel::uniform(MAX_EXPORT_JOINTS + 1, 1e-3, 1e-3, 9.81).unwrap();
    let error = from_planar(&long, "long").unwrap_err().to_string();
    assert!(error.contains("40001 links exceed the 40000"), "{error}");
    let mut robot =
        from_planar(&ChainModel::uniform(1, 1e-3, 1e-3, 9.81).unwrap(), "long").unwrap();
    robot.joints = vec![robot.joints[0].clone(); MAX_EXPORT_JOINTS + 1];
    let error = write_urdf(&robot).unwrap_err().to_string();
    assert!(
        error.contains("40001 movable joints exceed the 40000"),
        "{error}"
    );
}

#[test]
fn a_file_stem_that_is_not_a_plain_name_is_refused() {
    let robot = read_urdf(&one_link(&inertial(
        &[[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
        [0.0; 3],
    )))
    .unwrap()
    .robot;
    let g = [0.0, 0.0, -9.81];
    for stem in ["", ".", "..", "../../etc/x", "a\\b", "x\0", "tab\t"] {
        let error = robot_desc::write_mjcf_files(&robot, g, stem).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("cannot export MJCF file stem"),
            "{stem:?}: {error}"
        );
    }
    let files = robot_desc::write_mjcf_files(&robot, g, "snake-10").unwrap();
    assert_eq!(files[0].0, "snake-10.xml");
}

/// A joint whose `<limit>` holds it at one position (no `lower`, no `upper`: both 0) has no
/// MJCF range (MuJoCo needs `range[0] < range[1]`): refused by name rather than written
/// unlimited; a one-sided limit is written as `[lower, 0]`.
#[test]
fn a_joint_held_by_its_limit_is_refused_and_a_one_sided_one_written() {
    let urdf = |limit: &str| {
        format!(
            r#"<robot name="r"><link name="a"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>{limit}</joint>
      <link name="b"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
        <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#
        )
    };
    let held = read_urdf(&urdf("<limit effort=\"1\" velocity=\"1\"/>"))
        .unwrap()
        .robot;
    let message = write_mjcf(&held, [0.0, 0.0, -9.81])
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("joint 'j' to MJCF") && message.contains("holds it at 0"),
        "{message}"
    );
    let one_sided = read_urdf(&urdf("<limit lower=\"-1\" effort=\"1\" velocity=\"1\"/>"))
        .unwrap()
        .robot;
    let text = write_mjcf(&one_sided, [0.0, 0.0, -9.81]).unwrap();
    assert!(text.contains("range=\"-1.0 0.0\""), "{text}");
}
