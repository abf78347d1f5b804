//! `hrm arm check` and `hrm arm export --format urdf|mjcf --out DIR`: the check lists what the
//! URDF reader read, merged and ignored; an exported URDF reads back to the same chain bit for
//! bit; the MJCF carries the gravity and every joint, and splits a chain past MuJoCo's nesting
//! limit into included files; bad command lines and files get one line naming what is wrong.

use crate::common::{hrm, scratch};
use robot_desc::{MJCF_BODIES_PER_FILE, MJCF_MAX_BODIES_ONE_FILE, Robot, read_urdf};
use std::path::{Path, PathBuf};

fn example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/urdf-arm/arm7.urdf")
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The standard output of a run that must succeed.
fn succeeds(args: &[&str]) -> String {
    let out = hrm(args);
    assert!(
        out.status.success(),
        "hrm {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The one-line error of a run that must fail.
fn fails(args: &[&str]) -> String {
    let out = hrm(args);
    assert!(!out.status.success(), "hrm {args:?} succeeded");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// `hrm arm export SOURCE --format mjcf --out OUT` with the `extra` flags, then the text of the
/// file `OUT/FILE` it wrote.
fn export_mjcf(source: &str, out: &Path, extra: &[&str], file: &str) -> String {
    let args = [
        "arm",
        "export",
        source,
        "--format",
        "mjcf",
        "--out",
        path(out),
    ];
    succeeds(&[&args[..], extra].concat());
    std::fs::read_to_string(out.join(file)).unwrap()
}

/// The chain a URDF file holds.
fn robot(file: &Path) -> Robot {
    read_urdf(&std::fs::read_to_string(file).unwrap())
        .unwrap()
        .robot
}

/// A serial chain of `n` revolute joints alternating about z and y, unit rods along z.
fn long_chain(n: usize) -> String {
    let mut text = String::from("<robot name=\"long\"><link name=\"l0\"/>\n");
    for i in 1..=n {
        let axis = if i % 2 == 0 { "0 1 0" } else { "0 0 1" };
        text += &format!(
            "<joint name=\"j{i}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{i}\"/>\
             <origin xyz=\"0 0 0.1\"/><axis xyz=\"{axis}\"/></joint>\n<link name=\"l{i}\">\
             <inertial><origin xyz=\"0 0 0.05\"/><mass value=\"0.1\"/>\
             <inertia ixx=\"1e-4\" iyy=\"1e-4\" izz=\"1e-5\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>\
             </inertial></link>\n",
            i - 1
        );
    }
    text + "</robot>\n"
}

#[test]
fn check_lists_the_chain_and_what_was_merged_and_ignored() {
    let reading = read_urdf(&std::fs::read_to_string(example()).unwrap()).unwrap();
    let text = succeeds(&["arm", "check", path(&example())]);
    let first = text.lines().next().unwrap();
    assert!(
        first.contains("robot 'arm7'") && first.contains("7 movable joints on base 'base'"),
        "{first}"
    );
    for joint in &reading.robot.joints {
        let line = text
            .lines()
            .find(|l| l.contains(&format!("'{}'", joint.name)))
            .unwrap_or_else(|| panic!("joint '{}' is not listed:\n{text}", joint.name));
        assert!(
            line.contains(&format!("link '{}'", joint.child.name)),
            "{line}"
        );
    }
    // The fixed tool link is merged into the last link, as the reader reports.
    assert!(!reading.report.merged.is_empty());
    for merged in &reading.report.merged {
        let line = format!(
            "merged: link '{}' into '{}' (fixed joint '{}')",
            merged.link, merged.into, merged.joint
        );
        assert!(text.contains(&line), "{line:?} missing:\n{text}");
    }
}

#[test]
fn an_exported_urdf_reads_back_to_the_same_chain_bit_for_bit() {
    let dir = scratch("arm-export-urdf");
    let out = dir.join("out");
    let said = succeeds(&[
        "arm",
        "export",
        path(&example()),
        "--format",
        "urdf",
        "--out",
        path(&out),
    ]);
    let file = out.join("arm7.urdf");
    assert!(said.contains(path(&file)), "{said}");
    let (read, original) = (robot(&file), robot(&example()));
    assert_eq!(format!("{read:?}"), format!("{original:?}"));
    // Exporting the export writes the same text again.
    let again = dir.join("again");
    succeeds(&[
        "arm",
        "export",
        path(&file),
        "--format",
        "urdf",
        "--out",
        path(&again),
    ]);
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        std::fs::read_to_string(again.join("arm7.urdf")).unwrap()
    );
}

#[test]
fn check_quotes_names_with_line_breaks_on_one_line() {
    let dir = scratch("arm-check-names");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("names.urdf");
    std::fs::write(
        &file,
        "<robot name=\"r\"><link name=\"a&#10;hrm: fake\"/><joint name=\"j&#10;x\" \
         type=\"continuous\"><parent link=\"a&#10;hrm: fake\"/><child link=\"b\"/></joint>\
         <link name=\"b\"/></robot>",
    )
    .unwrap();
    let said = succeeds(&["arm", "check", path(&file)]);
    assert!(
        said.contains("base 'a\\nhrm: fake'") && said.contains("'j\\nx'"),
        "{said}"
    );
    assert!(!said.lines().any(|l| l.starts_with("hrm: fake")), "{said}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_spatial_scenarios_arm_exports_and_a_urdf_arm_is_its_file() {
    let dir = scratch("arm-export-spatial");
    let out = dir.join("out");
    succeeds(&[
        "arm",
        "export",
        "spatial-tracking",
        "--format",
        "urdf",
        "--out",
        path(&out),
    ]);
    // Ten universal joints: twenty movable joints, theta's order.
    let robot = robot(&out.join("hrm_spatial_arm.urdf"));
    assert_eq!(robot.n_joints(), 20);
    let said = fails(&[
        "arm",
        "export",
        path(&example().with_file_name("step.toml")),
        "--format",
        "urdf",
        "--out",
        path(&dir.join("urdf-arm")),
    ]);
    assert!(
        said.contains("its arm is the URDF file arm.urdf") && said.contains("arm7.urdf"),
        "{said}"
    );
    // URDF carries no gravity: --gravity with it is refused, not dropped.
    let said = fails(&[
        "arm",
        "export",
        "spatial-tracking",
        "--format",
        "urdf",
        "--gravity",
        "0 0 -1",
        "--out",
        path(&dir.join("gravity")),
    ]);
    assert!(said.contains("--gravity is written only to MJCF"), "{said}");
    // An arm beyond what the format is written with: the format's own limit, at once.
    for (links, base, format, expected) in [
        (
            1_000_000,
            "paper-responses-step",
            "mjcf",
            "arm.links must be at most 1022 for export (MJCF: the nested bodies MuJoCo \
             compiles), got 1000000",
        ),
        (
            50_000,
            "paper-responses-step",
            "urdf",
            "arm.links must be at most 40000 for export (URDF: the joints a description is \
             written with and read back), got 50000",
        ),
        (
            10_001,
            "spatial-tracking",
            "urdf",
            "arm.links must be at most 10000 for export (URDF: two joints a link of a spatial \
             arm), got 10001",
        ),
    ] {
        let mut arm = sim_study::Scenario::builtin(base).unwrap();
        arm.arm.links = Some(links);
        arm.arm.link_length = Some(1e-3);
        let scenario = dir.join(format!("arm{links}.toml"));
        std::fs::write(&scenario, arm.to_toml()).unwrap();
        let said = fails(&[
            "arm",
            "export",
            path(&scenario),
            "--format",
            format,
            "--out",
            path(&dir.join("many")),
        ]);
        assert!(said.trim_end().ends_with(expected), "{said}");
    }
    assert!(!dir.join("many").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_mjcf_export_carries_gravity_and_every_joint() {
    let dir = scratch("arm-export-mjcf");
    let out = dir.join("urdf");
    let mjcf = export_mjcf(path(&example()), &out, &[], "arm7.xml");
    assert!(
        mjcf.contains("<option gravity=\"0.0 0.0 -9.81\"/>"),
        "{mjcf}"
    );
    assert_eq!(mjcf.matches("<joint ").count(), 7, "{mjcf}");
    // A given gravity replaces ROS's default.
    let tilted = dir.join("tilted");
    let mjcf = export_mjcf(
        path(&example()),
        &tilted,
        &["--gravity", "1,0,-9"],
        "arm7.xml",
    );
    assert!(
        mjcf.contains("<option gravity=\"1.0 0.0 -9.0\"/>"),
        "{mjcf}"
    );
    // The paper's planar arm: in the base's x-y plane, joints about z, gravity along -y.
    let planar = dir.join("planar");
    let mjcf = export_mjcf("paper-tracking", &planar, &[], "hrm_planar_arm.xml");
    assert!(
        mjcf.contains("<option gravity=\"0.0 -9.81 0.0\"/>"),
        "{mjcf}"
    );
    assert_eq!(mjcf.matches("<joint ").count(), 10, "{mjcf}");
    assert_eq!(mjcf.matches("axis=\"0.0 0.0 1.0\"").count(), 10, "{mjcf}");
}

#[test]
fn a_chain_past_the_nesting_limit_is_split_into_included_files() {
    let n = MJCF_MAX_BODIES_ONE_FILE + 5;
    let dir = scratch("arm-export-long");
    let urdf = dir.join("long.urdf");
    std::fs::write(&urdf, long_chain(n)).unwrap();
    let out = dir.join("out");
    let main = export_mjcf(path(&urdf), &out, &[], "long.xml");
    assert!(
        main.contains("<include file=\"long-part1.xml\"/>"),
        "{main}"
    );
    let mut joints = main.matches("<joint ").count();
    let mut parts = 0;
    while let Ok(part) = std::fs::read_to_string(out.join(format!("long-part{}.xml", parts + 1))) {
        joints += part.matches("<joint ").count();
        parts += 1;
    }
    // No file holds more than its share of the chain.
    assert!(
        parts + 1 >= n.div_ceil(MJCF_BODIES_PER_FILE),
        "{parts} parts"
    );
    assert_eq!(joints, n);
}

/// A revolute or prismatic joint without `<limit>` (which URDF requires: urdfdom refuses it) is
/// read as unlimited, and said so by `check` and, when it is written back, by `export`.
#[test]
fn joints_without_the_limits_urdf_requires_are_noted() {
    let dir = scratch("arm-unlimited");
    let file = dir.join("r.urdf");
    std::fs::write(&file, one_joint("revolute", "", HEAVY)).unwrap();
    let note = "joint 'j1' is revolute without <limit>, which URDF requires (urdfdom, ROS and \
                Pinocchio refuse it): hrm reads it as unlimited (type=\"continuous\" says so)";
    let report = succeeds(&["arm", "check", path(&file)]);
    assert!(report.contains(&format!("note: {note}\n")), "{report}");
    let run = hrm(&[
        "arm",
        "export",
        path(&file),
        "--format",
        "urdf",
        "--out",
        path(&dir.join("out")),
    ]);
    assert!(run.status.success());
    let said = String::from_utf8_lossy(&run.stderr);
    assert_eq!(
        said.trim_end(),
        format!("hrm: warning: written as read: {note}")
    );
    // The paper's arm (continuous joints) has nothing to note.
    let report = succeeds(&["arm", "check", path(&example())]);
    assert!(!report.contains("note:"), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_arm_commands_get_one_line_naming_the_problem() {
    let dir = scratch("arm-errors");
    let missing = dir.join("missing.urdf");
    assert!(fails(&["arm", "check", path(&missing)]).contains("missing.urdf"));
    let hostile = dir.join("hostile.urdf");
    std::fs::write(
        &hostile,
        "<robot name=\"r\"><link name=\"a\"/><joint name=\"j\" type=\"revolute\">\
         <parent link=\"a\"/><child link=\"b\"/></joint><link name=\"b\"><inertial>\
         <mass value=\"NaN\"/></inertial></link></robot>",
    )
    .unwrap();
    let err = fails(&["arm", "check", path(&hostile)]);
    assert!(
        err.contains("hostile.urdf") && err.contains("<mass> of link 'b'"),
        "{err}"
    );
    let out = dir.join("out");
    // The format is checked by the argument parser (its usage message follows).
    let run = hrm(&[
        "arm",
        "export",
        path(&example()),
        "--format",
        "sdf",
        "--out",
        path(&out),
    ]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("'sdf'"));
    let err = fails(&[
        "arm",
        "export",
        path(&example()),
        "--format",
        "mjcf",
        "--out",
        path(&out),
        "--gravity",
        "0 nan",
    ]);
    assert!(err.contains("--gravity"), "{err}");
    assert!(!out.exists(), "nothing is written on an error");
}

/// A link of 1 kg with its inertia, as `one_joint`'s link.
const HEAVY: &str = "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" \
                     iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial>";

/// A robot of one joint `j1` of `kind` (its `<limit>` or other elements `joint_extra`) moving
/// link `l1` (holding `link`).
fn one_joint(kind: &str, joint_extra: &str, link: &str) -> String {
    format!(
        "<robot name=\"r\"><link name=\"base\"/><joint name=\"j1\" type=\"{kind}\">\
         <parent link=\"base\"/><child link=\"l1\"/><axis xyz=\"0 0 1\"/>{joint_extra}</joint>\
         <link name=\"l1\">{link}</link></robot>"
    )
}

/// `hrm arm check`'s report of the URDF `text`, written in a scratch folder `label`.
fn check_report(label: &str, text: &str) -> String {
    let dir = scratch(label);
    let file = dir.join("r.urdf");
    std::fs::write(&file, text).unwrap();
    let report = succeeds(&["arm", "check", path(&file)]);
    std::fs::remove_dir_all(&dir).unwrap();
    report
}

/// A `<limit>` without `lower` or `upper` reads them as 0 (as urdfdom does), one without
/// `effort` or `velocity` is one urdfdom refuses: `check` says both.
#[test]
fn partial_limits_are_noted_with_the_range_they_give() {
    let report = check_report(
        "arm-partial-limits",
        &one_joint("revolute", "<limit lower=\"-1\"/>", HEAVY),
    );
    let note = "note: joint 'j1' has <limit> without upper, effort, velocity: URDF reads a \
                missing bound as 0, so it moves within [-1, 0]; urdfdom (ROS, Pinocchio) \
                refuses a <limit> without effort or velocity\n";
    assert!(report.contains(note), "{report}");
}

/// A chain whose links are all massless reads (a kinematic chain), and `check` says that its
/// dynamics refuse it, naming the joint that moves nothing.
#[test]
fn a_chain_that_moves_no_mass_is_noted() {
    let report = check_report("arm-massless", &one_joint("continuous", "", ""));
    assert!(
        report.contains("note: joint 'j1' moves no mass or inertia at the zero positions"),
        "{report}"
    );
}
