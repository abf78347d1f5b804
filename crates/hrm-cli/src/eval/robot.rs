//! The `hrm eval` ops on robot descriptions (`docs/eval-protocol.md`): `dynamics`,
//! `rnea_derivatives` and `aba_derivatives` of a URDF chain (`"urdf"` in place of `"arm"`),
//! `frames` (every link's pose) and `export` (URDF or MJCF text).

use manip_dyn::faer::Mat;
use manip_dyn::spatial::{self, SpatialData, SpatialDerivativeData, SpatialModel};
use robot_desc::{Robot, read_urdf};
use serde::Deserialize;
use serde_json::json;
use sim_study::ArmSpec;

use super::derivatives::{MAX_DERIVATIVE_LINKS, aba_answer, joint_vectors, rnea_answer, rows};
use super::request::{EvalError, EvalResult, Kind, finite, json_fields};
use lane_math::Classify;
use manip_dyn::DynError;

/// ROS's gravity, the default of a URDF chain (URDF carries none).
const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// A URDF chain read, refused past [`MAX_DERIVATIVE_LINKS`] joints (the answers of these ops
/// are `n x n` matrices).
fn robot(urdf: &str) -> Result<Robot, EvalError> {
    let robot = read_urdf(urdf)
        .map_err(|e| EvalError::input(format!("urdf: {e}")))?
        .robot;
    if robot.n_joints() > MAX_DERIVATIVE_LINKS {
        return Err(EvalError::input(format!(
            "urdf: at most {MAX_DERIVATIVE_LINKS} movable joints for this op, got {}",
            robot.n_joints()
        )));
    }
    Ok(robot)
}

/// `"gravity"`: three finite numbers of at most [`robot_desc::MAX_MAGNITUDE`] (the bound of a
/// URDF's numbers, [`robot_desc::check_gravity`]), or `default` when absent.
fn gravity(requested: Option<Vec<f64>>, default: [f64; 3]) -> Result<[f64; 3], EvalError> {
    match requested.as_deref() {
        None => Ok(default),
        Some(&[x, y, z]) => {
            robot_desc::check_gravity([x, y, z])?;
            Ok([x, y, z])
        }
        Some(values) => Err(EvalError::input(format!(
            "gravity must be three finite numbers [gx, gy, gz], got {} entries",
            values.len()
        ))),
    }
}

/// The dynamics model of a URDF chain under `gravity` (default [`DEFAULT_GRAVITY`]).
fn model(urdf: &str, requested: Option<Vec<f64>>) -> Result<SpatialModel, EvalError> {
    let gravity = gravity(requested, DEFAULT_GRAVITY)?;
    let robot = robot(urdf)?;
    if robot.n_joints() == 0 {
        return Err(EvalError::input("urdf: the chain has no movable joint"));
    }
    robot_desc::to_spatial(&robot, gravity).map_err(|e| EvalError::input(format!("urdf: {e}")))
}

/// A library error as an answer, a [`DynError::SingularJoint`] with the URDF name of its joint
/// ("urdf: joint 'yaw3': joint 4: the articulated inertia ..."), a prismatic position out of
/// range with the request's entry too ("theta[1]: joint 'slide': joint 1: position q ...").
fn joint_named(urdf: &str, error: DynError) -> EvalError {
    let (field, index) = match error {
        DynError::SingularJoint { index } => ("urdf".to_string(), index),
        DynError::InvalidJoint {
            index,
            quantity: "position q",
            ..
        } => (format!("theta[{index}]"), index),
        _ => return error.into(),
    };
    let name = robot(urdf)
        .ok()
        .and_then(|robot| robot.joints.get(index).map(|joint| joint.name.clone()));
    match name {
        Some(name) => EvalError::new(
            Kind::Library(error.class()),
            format!("{field}: joint '{name}': {error}"),
        ),
        None => error.into(),
    }
}

/// `dynamics` of a URDF chain.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DynamicsRequest {
    urdf: String,
    gravity: Option<Vec<f64>>,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
}

/// `dynamics` with `"urdf"`: `M(q)`, `C(q, qd) qd` and `G(q)` of the spatial chain.
pub(super) fn dynamics(request: DynamicsRequest) -> EvalResult {
    let model = model(&request.urdf, request.gravity)?;
    let n = model.n_links();
    joint_vectors(
        n,
        "movable joint",
        &[("theta", &request.theta), ("theta_dot", &request.theta_dot)],
    )?;
    let mut data = SpatialData::new(&model);
    let mut mass = Mat::<f64>::zeros(n, n);
    let (mut coriolis, mut gravity) = (vec![0.0; n], vec![0.0; n]);
    spatial::mass_matrix(&model, &mut data, &request.theta, mass.as_mut())
        .map_err(|error| joint_named(&request.urdf, error))?;
    spatial::coriolis(
        &model,
        &mut data,
        &request.theta,
        &request.theta_dot,
        &mut coriolis,
    )
    .map_err(|error| joint_named(&request.urdf, error))?;
    spatial::gravity(&model, &mut data, &request.theta, &mut gravity)
        .map_err(|error| joint_named(&request.urdf, error))?;
    finite("coriolis", &coriolis)?;
    finite("gravity", &gravity)?;
    Ok(json_fields([
        ("mass_matrix", rows("mass_matrix", mass.as_ref())?),
        ("coriolis", json!(coriolis)),
        ("gravity", json!(gravity)),
    ]))
}

/// `rnea_derivatives` of a URDF chain.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RneaDerivativesRequest {
    urdf: String,
    gravity: Option<Vec<f64>>,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    theta_ddot: Vec<f64>,
}

/// `rnea_derivatives` with `"urdf"`: `tau` and its Jacobians in `theta` and `theta_dot`.
pub(super) fn rnea_derivatives(request: RneaDerivativesRequest) -> EvalResult {
    let model = model(&request.urdf, request.gravity)?;
    joint_vectors(
        model.n_links(),
        "movable joint",
        &[
            ("theta", &request.theta),
            ("theta_dot", &request.theta_dot),
            ("theta_ddot", &request.theta_ddot),
        ],
    )?;
    let mut derivatives = SpatialDerivativeData::new(&model);
    spatial::rnea_derivatives(
        &model,
        &mut SpatialData::new(&model),
        &mut derivatives,
        &request.theta,
        &request.theta_dot,
        &request.theta_ddot,
    )
    .map_err(|error| joint_named(&request.urdf, error))?;
    rnea_answer(derivatives.value(), derivatives.d_q(), derivatives.d_v())
}

/// `aba_derivatives` of a URDF chain.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AbaDerivativesRequest {
    urdf: String,
    gravity: Option<Vec<f64>>,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    tau: Vec<f64>,
}

/// `aba_derivatives` with `"urdf"`: `theta_ddot` and its Jacobians in `theta`, `theta_dot`
/// and `tau` (`M^-1`).
pub(super) fn aba_derivatives(request: AbaDerivativesRequest) -> EvalResult {
    let model = model(&request.urdf, request.gravity)?;
    joint_vectors(
        model.n_links(),
        "movable joint",
        &[
            ("theta", &request.theta),
            ("theta_dot", &request.theta_dot),
            ("tau", &request.tau),
        ],
    )?;
    let mut derivatives = SpatialDerivativeData::new(&model);
    spatial::aba_derivatives(
        &model,
        &mut SpatialData::new(&model),
        &mut derivatives,
        &request.theta,
        &request.theta_dot,
        &request.tau,
    )
    .map_err(|error| match error {
        DynError::NonFiniteResult { .. } => super::derivatives::accelerations_named(error),
        error => joint_named(&request.urdf, error),
    })?;
    aba_answer(
        derivatives.value(),
        derivatives.d_q(),
        derivatives.d_v(),
        derivatives.d_input(),
    )
}

/// `frames`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FramesRequest {
    urdf: String,
    theta: Vec<f64>,
}

/// `frames`: the origin and rotation (rows) of each movable joint's child link frame in the
/// base frame.
pub(super) fn frames(request: FramesRequest) -> EvalResult {
    let model = model(&request.urdf, None)?;
    joint_vectors(
        model.n_links(),
        "movable joint",
        &[("theta", &request.theta)],
    )?;
    let mut data = SpatialData::new(&model);
    spatial::forward_kinematics(&model, &mut data, &request.theta)
        .map_err(|error| joint_named(&request.urdf, error))?;
    let poses: Vec<_> = (0..model.n_links())
        .filter_map(|i| data.link_pose(i).copied())
        .collect();
    for pose in &poses {
        finite("positions", &pose.translation)?;
    }
    let positions: Vec<[f64; 3]> = poses.iter().map(|p| p.translation).collect();
    let rotations: Vec<[[f64; 3]; 3]> = poses.iter().map(|p| p.rotation).collect();
    Ok(json_fields([
        ("positions", json!(positions)),
        ("rotations", json!(rotations)),
    ]))
}

/// `export`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ExportRequest {
    urdf: Option<String>,
    #[serde(default, deserialize_with = "super::request::optional_arm_object")]
    arm: Option<ArmSpec>,
    format: String,
    gravity: Option<Vec<f64>>,
}

/// `export`: a URDF chain or a planar arm as one URDF or MJCF document.
pub(super) fn export(request: ExportRequest) -> EvalResult {
    let (robot, default_gravity) = match (request.urdf, request.arm) {
        (Some(urdf), None) => (
            read_urdf(&urdf)
                .map_err(|e| EvalError::input(format!("urdf: {e}")))?
                .robot,
            DEFAULT_GRAVITY,
        ),
        (None, Some(arm)) => {
            let chain = arm.to_chain()?;
            let gravity = [0.0, -chain.gravity(), 0.0];
            let robot = robot_desc::from_planar(&chain, "hrm_planar_arm")
                .map_err(|e| EvalError::input(format!("arm: {e}")))?;
            (robot, gravity)
        }
        _ => {
            return Err(EvalError::input(
                "export takes exactly one of \"urdf\" and \"arm\"",
            ));
        }
    };
    if request.format == "urdf" && request.gravity.is_some() {
        return Err(EvalError::input(
            "gravity is written only to MJCF (URDF carries none): leave it out with format \"urdf\"",
        ));
    }
    let gravity = gravity(request.gravity, default_gravity)?;
    let text = match request.format.as_str() {
        "urdf" => robot_desc::write_urdf(&robot).map_err(|e| EvalError::input(e.to_string()))?,
        "mjcf" => {
            robot_desc::write_mjcf(&robot, gravity).map_err(|e| EvalError::input(e.to_string()))?
        }
        other => {
            return Err(EvalError::input(format!(
                "format must be \"urdf\" or \"mjcf\", got {other:?}"
            )));
        }
    };
    Ok(json_fields([("text", json!(text))]))
}
