//! `hrm arm`: robot descriptions. `check` reads a URDF chain and says what was read, merged and
//! ignored; `export` writes a URDF chain, or the planar arm of a scenario, as URDF or MJCF into
//! an output folder written whole (`output_dir`), never over files hrm did not write.

use crate::console;
use crate::output_dir::OutputDir;
use clap::{Args, Subcommand, ValueEnum};
use robot_desc::{Robot, read_urdf, write_mjcf_files, write_urdf};
use sim_study::{ArmKind, ArmSpec, Scenario};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The arguments of `hrm arm`.
#[derive(Debug, Args)]
pub struct ArmArgs {
    #[command(subcommand)]
    command: ArmCommand,
}

#[derive(Debug, Subcommand)]
enum ArmCommand {
    /// Read a URDF serial chain and list its joints, the links merged through fixed joints and the elements ignored.
    Check {
        /// The `.urdf` file.
        file: PathBuf,
    },
    /// Write a URDF chain, or a scenario's planar arm (shipped name or TOML file), as URDF or MJCF.
    Export {
        /// A `.urdf` file, or a scenario (its planar `[arm]` in the base's x-y plane, a spatial one
        /// as its chain of universal joints).
        file: String,
        /// What to write.
        #[arg(long, value_enum)]
        format: Format,
        /// The folder to write into (replaced whole; refused if it holds files hrm did not write).
        #[arg(long)]
        out: PathBuf,
        /// MJCF gravity "gx gy gz" (m/s^2); default "0 0 -9.81" for a URDF, "0 -g 0" for a planar arm.
        #[arg(long, allow_hyphen_values = true)]
        gravity: Option<String>,
    },
}

/// The export formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// URDF (no gravity: set it in the simulator).
    Urdf,
    /// MJCF for MuJoCo (gravity in `<option>`).
    Mjcf,
}

/// ROS's gravity, the default of a URDF chain.
pub const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// Runs `hrm arm`.
pub fn run(args: ArmArgs) -> Result<(), String> {
    match args.command {
        ArmCommand::Check { file } => check(&file),
        ArmCommand::Export {
            file,
            format,
            out,
            gravity,
        } => export(&file, format, &out, gravity.as_deref()),
    }
}

/// The text of a URDF file, read up to [`robot_desc::MAX_URDF_BYTES`].
fn read_urdf_file(path: &Path) -> Result<String, String> {
    sim_study::read_text_file(path, robot_desc::MAX_URDF_BYTES as u64)
        .map_err(|e| format!("{}: {e}", path.display()))
}

fn check(path: &Path) -> Result<(), String> {
    let text = read_urdf_file(path)?;
    let reading = read_urdf(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let (robot, report) = (&reading.robot, &reading.report);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "robot '{}': {} links and {} joints read; a serial chain of {} movable joints on base '{}'",
        name(&robot.name),
        report.links,
        report.joints,
        robot.n_joints(),
        name(&robot.base.name)
    );
    for (i, joint) in robot.joints.iter().enumerate() {
        let _ = writeln!(
            out,
            "  {:>3} {} '{}' axis {:?} -> link '{}' (mass {} kg){}",
            i + 1,
            joint.kind.urdf_name(),
            name(&joint.name),
            joint.axis,
            name(&joint.child.name),
            lane_math::Compact(joint.child.inertial.mass),
            if joint.child.inertial.is_massless() {
                ", massless"
            } else {
                ""
            }
        );
    }
    for joint in unlimited(robot) {
        let _ = writeln!(out, "note: {}", unlimited_note(joint));
    }
    for note in robot.joints.iter().filter_map(partial_limit_note) {
        let _ = writeln!(out, "note: {note}");
    }
    if let Some(note) = singular_note(robot) {
        let _ = writeln!(out, "note: {note}");
    }
    if report.merged.is_empty() {
        out.push_str("merged: none\n");
    }
    for merged in &report.merged {
        let _ = writeln!(
            out,
            "merged: link '{}' into '{}' (fixed joint '{}')",
            name(&merged.link),
            name(&merged.into),
            name(&merged.joint)
        );
    }
    if report.ignored.is_empty() {
        out.push_str("ignored: none\n");
    }
    for (path, count) in &report.ignored {
        let _ = writeln!(out, "ignored: <{}> x{count}", name(path));
    }
    console::print(&out)
}

/// The revolute and prismatic joints without `<limit>`, which the URDF specification requires
/// of them (urdfdom, and with it ROS and Pinocchio, refuses such a file); hrm reads them as
/// unlimited.
fn unlimited(robot: &Robot) -> impl Iterator<Item = &robot_desc::Joint> {
    robot.joints.iter().filter(|joint| {
        matches!(
            joint.kind,
            robot_desc::JointKind::Revolute | robot_desc::JointKind::Prismatic
        ) && joint.limits.is_none()
    })
}

/// What [`unlimited`] says of `joint`.
fn unlimited_note(joint: &robot_desc::Joint) -> String {
    format!(
        "joint '{}' is {} without <limit>, which URDF requires (urdfdom, ROS and Pinocchio refuse \
         it): hrm reads it as unlimited{}",
        name(&joint.name),
        joint.kind.urdf_name(),
        if joint.kind == robot_desc::JointKind::Revolute {
            " (type=\"continuous\" says so)"
        } else {
            ""
        }
    )
}

/// What `check` says of a `<limit>` that lacks attributes: a missing `lower` or `upper` of a
/// revolute or prismatic joint reads as 0 (the joint's range is then `[lower, 0]`, `[0, upper]`
/// or the single position 0), and urdfdom refuses a `<limit>` without `effort` or `velocity`.
fn partial_limit_note(joint: &robot_desc::Joint) -> Option<String> {
    let limits = joint.limits?;
    let mut missing: Vec<&str> = Vec::new();
    if joint.kind != robot_desc::JointKind::Continuous {
        missing.extend(limits.lower.is_none().then_some("lower"));
        missing.extend(limits.upper.is_none().then_some("upper"));
    }
    let bounds = missing.len();
    missing.extend(limits.effort.is_none().then_some("effort"));
    missing.extend(limits.velocity.is_none().then_some("velocity"));
    if missing.is_empty() {
        return None;
    }
    let [lower, upper] = joint.position_range();
    let mut note = format!(
        "joint '{}' has <limit> without {}",
        name(&joint.name),
        missing.join(", ")
    );
    if bounds > 0 {
        let _ = write!(
            note,
            ": URDF reads a missing bound as 0, so it moves within [{lower}, {upper}]"
        );
    }
    if missing.len() > bounds {
        note.push_str(if bounds > 0 { "; " } else { ": " });
        note.push_str("urdfdom (ROS, Pinocchio) refuses a <limit> without effort or velocity");
    }
    Some(note)
}

/// What `check` says of a chain whose mass matrix is singular at the zero positions (a joint
/// that moves no mass or inertia there, such as a chain of massless links), which the forward
/// dynamics, and so `hrm simulate` and the dynamics ops, refuse.
fn singular_note(robot: &Robot) -> Option<String> {
    let model = robot_desc::to_spatial(robot, [0.0; 3]).ok()?;
    let index = manip_dyn::spatial::singular_joint(&model, &vec![0.0; model.n_links()])?;
    Some(format!(
        "joint '{}' moves no mass or inertia at the zero positions (its link '{}' and every link \
         beyond massless, or their masses on its axis): the chain's mass matrix is singular \
         there, and its forward dynamics (hrm simulate, the dynamics ops) refuse it",
        name(&robot.joints[index].name),
        name(&robot.joints[index].child.name),
    ))
}

/// A name from the file as one line of the report: a line break or tab in it escaped (`\n`),
/// as the error messages quote names.
fn name(text: &str) -> String {
    console::escape_field(text)
}

/// The most links of a scenario's modal arm written as `format`, and why: MJCF's nested bodies
/// (one a link) or the joints a URDF is written with (two a link of a spatial arm, whose links
/// [`robot_desc::MAX_SPATIAL_EXPORT_LINKS`] bounds).
fn max_export_links(format: Format, kind: ArmKind) -> (usize, &'static str) {
    match (format, kind) {
        (Format::Mjcf, _) => (
            robot_desc::MJCF_MAX_BODIES,
            "MJCF: the nested bodies MuJoCo compiles",
        ),
        (Format::Urdf, ArmKind::Spatial) => (
            robot_desc::MAX_SPATIAL_EXPORT_LINKS,
            "URDF: two joints a link of a spatial arm",
        ),
        (Format::Urdf, _) => (
            robot_desc::MAX_EXPORT_JOINTS,
            "URDF: the joints a description is written with and read back",
        ),
    }
}

/// The robot of a `.urdf` file (default gravity [`DEFAULT_GRAVITY`]) or of a scenario's modal
/// arm, planar or spatial (a scenario's URDF arm is its file), whose links are refused beyond
/// what `format` is written with ([`max_export_links`]) before the robot is built.
fn robot_of(source: &str, format: Format) -> Result<(Robot, [f64; 3]), String> {
    let path = Path::new(source);
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
    {
        let text = read_urdf_file(path)?;
        let robot = read_urdf(&text)
            .map_err(|e| format!("{source}: {e}"))?
            .robot;
        return Ok((robot, DEFAULT_GRAVITY));
    }
    let scenario = Scenario::resolve(source).map_err(|e| e.to_string())?;
    if let Some(urdf) = &scenario.arm.urdf {
        return Err(format!(
            "{source}: its arm is the URDF file arm.urdf = {:?}: export that file \
             (hrm arm export FILE.urdf)",
            urdf.display()
        ));
    }
    let links = scenario
        .arm
        .link_count(scenario.arm.inertias.as_ref().map(sim_study::Inertias::len))
        .map_err(|e| format!("{source}: {e}"))?;
    let (max, why) = max_export_links(format, scenario.arm.kind);
    if links > max {
        return Err(format!(
            "{source}: arm.links must be at most {max} for export ({why}), got {links}"
        ));
    }
    if scenario.arm.kind == ArmKind::Spatial {
        // The universal-joint snake, its movable joints in the order of theta.
        let model = scenario
            .spatial_model()
            .map_err(|e| format!("{source}: {e}"))?;
        let robot = robot_desc::from_spatial_arm(&model, "hrm_spatial_arm")
            .map_err(|e| format!("{source}: {e}"))?;
        return Ok((robot, model.gravity()));
    }
    planar_robot(&scenario.arm, "hrm_planar_arm")
}

/// A scenario's planar arm as a spatial chain in the base's x-y plane, and its gravity along
/// `-y`.
pub fn planar_robot(arm: &ArmSpec, name: &str) -> Result<(Robot, [f64; 3]), String> {
    let chain = arm.to_chain().map_err(|e| e.to_string())?;
    let gravity = [0.0, -chain.gravity(), 0.0];
    let robot = robot_desc::from_planar(&chain, name).map_err(|e| e.to_string())?;
    Ok((robot, gravity))
}

/// `"gx gy gz"` (spaces or commas), finite.
fn parse_gravity(text: &str) -> Result<[f64; 3], String> {
    let values: Vec<f64> = text
        .split(|c: char| c == ',' || c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| format!("--gravity: {t:?} is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match values[..] {
        [x, y, z] if robot_desc::check_gravity([x, y, z]).is_ok() => Ok([x, y, z]),
        _ => Err(format!(
            "--gravity must be three finite numbers \"gx gy gz\" of at most 1e9 in magnitude, \
             got {text:?}"
        )),
    }
}

/// The files of an export: `(name, text)`, the main file first.
pub fn export_files(
    robot: &Robot,
    format: Format,
    gravity: [f64; 3],
) -> Result<Vec<(String, String)>, String> {
    let stem = file_stem(&robot.name);
    match format {
        Format::Urdf => Ok(vec![(
            format!("{stem}.urdf"),
            write_urdf(robot).map_err(|e| e.to_string())?,
        )]),
        Format::Mjcf => write_mjcf_files(robot, gravity, &stem).map_err(|e| e.to_string()),
    }
}

/// The robot's name if it makes a plain file name, else `robot`.
fn file_stem(name: &str) -> String {
    let plain = !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if plain {
        name.to_string()
    } else {
        "robot".to_string()
    }
}

fn export(source: &str, format: Format, out: &Path, gravity: Option<&str>) -> Result<(), String> {
    if format == Format::Urdf && gravity.is_some() {
        return Err(
            "--gravity is written only to MJCF (URDF carries none): leave it out with --format urdf"
                .to_string(),
        );
    }
    crate::output_dir::refuse_inputs_inside(out, &[("source file", Path::new(source))])?;
    let (robot, default_gravity) = robot_of(source, format)?;
    let gravity = gravity
        .map(parse_gravity)
        .transpose()?
        .unwrap_or(default_gravity);
    let files = export_files(&robot, format, gravity)?;
    if format == Format::Urdf {
        for joint in unlimited(&robot) {
            console::to_stderr(&console::error_line(&format!(
                "warning: written as read: {}",
                unlimited_note(joint)
            )));
        }
    }
    let staging = OutputDir::create(out, "arm export")?;
    for (name, text) in &files {
        std::fs::write(staging.path().join(name), text)
            .map_err(|e| format!("cannot write {}: {e}", out.join(name).display()))?;
    }
    staging.commit()?;
    let mut message = String::new();
    for (name, _) in &files {
        let _ = writeln!(message, "wrote {}", console::shown(&out.join(name)));
    }
    console::print(&message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gravity_takes_three_finite_numbers() {
        assert_eq!(parse_gravity("0 -9.81 0"), Ok([0.0, -9.81, 0.0]));
        assert_eq!(parse_gravity("1,2,3"), Ok([1.0, 2.0, 3.0]));
        assert!(
            parse_gravity("0 0")
                .unwrap_err()
                .contains("three finite numbers")
        );
        assert!(parse_gravity("0 0 NaN").is_err());
        assert!(parse_gravity("0 0 1e308").unwrap_err().contains("1e9"));
        assert!(parse_gravity("0 0 x").unwrap_err().contains("\"x\""));
    }

    #[test]
    fn file_names_come_from_plain_robot_names_only() {
        assert_eq!(file_stem("snake_10"), "snake_10");
        assert_eq!(file_stem("../../etc/passwd"), "robot");
        assert_eq!(file_stem(""), "robot");
    }
}
