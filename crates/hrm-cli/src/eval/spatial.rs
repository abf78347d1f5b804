//! The ops of `hrm eval` on spatial modal arms (`"arm": {"kind": "spatial", ...}`):
//! `joints`, `fk`, `ik`, `reduced`, `reduced_derivatives` and `export`
//! (`docs/eval-protocol.md`, "Spatial arms").

use super::request::{EvalError, EvalResult, arm_object, curve_error, finite, json_fields};
use backbone_kin::{SpatialIk, spatial_tip_position};
use modal_reduce::spatial::{
    SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel, spatial_forward_dynamics,
    spatial_joint_torques, spatial_reduced_derivatives,
};
use serde::Deserialize;
use serde_json::{Map, Value, json};
use sim_study::{ArmSpec, Inertias};

/// Most links of a spatial arm in a request (`2n` joints).
const MAX_SPATIAL_LINKS: usize = 100_000;

/// Most harmonics per plane in a request (`m = 4K` coordinates).
const MAX_SPATIAL_HARMONICS: usize = 16;

/// Most entries of an answer's Jacobian or of the work of `reduced` (`2n x 4K`, and `n m^2`):
/// about 0.1 s of work and 64 MB of JSON at most.
const MAX_SPATIAL_WORK: usize = 1 << 22;

/// Whether a request's `"arm"` is a spatial arm (`"kind": "spatial"`).
pub(super) fn is_spatial(request: &Map<String, Value>) -> bool {
    request
        .get("arm")
        .and_then(|arm| arm.get("kind"))
        .is_some_and(|kind| kind == "spatial")
}

/// Answers `op` on a spatial arm.
pub(super) fn dispatch(op: &str, request: Map<String, Value>) -> EvalResult {
    match op {
        "joints" => joints(super::request::parse(request)?),
        "fk" => fk(super::request::parse(request)?),
        "ik" => ik(super::request::parse(request)?),
        "reduced" => reduced(super::request::parse(request)?),
        "reduced_derivatives" => reduced_derivatives(super::request::parse(request)?),
        "export" => export(super::request::parse(request)?),
        other => Err(EvalError::input(format!(
            "op {other:?} does not take a spatial arm; spatial arms take joints, fk, ik, reduced, \
             reduced_derivatives and export"
        ))),
    }
}

/// A spatial arm as requests give it: the fields of a scenario's `[arm]` with
/// `kind = "spatial"` ([`ArmSpec::spatial_model`], whose refusals name the field), within the
/// request bounds of [`MAX_SPATIAL_LINKS`] links and [`MAX_SPATIAL_WORK`].
#[derive(Deserialize)]
#[serde(transparent)]
struct SpatialArmSpec(#[serde(deserialize_with = "arm_object")] ArmSpec);

impl SpatialArmSpec {
    /// The arm's reduced model with `harmonics` harmonics per plane; the defaults are the
    /// paper's link size (10 links of 0.1 m and 0.1 kg, slender rods) under gravity along `-z`.
    fn model(&self, harmonics: usize) -> Result<SpatialReducedModel, EvalError> {
        let arm = &self.0;
        let n = arm.link_count(arm.inertias.as_ref().map(Inertias::len))?;
        if n > MAX_SPATIAL_LINKS {
            return Err(EvalError::input(format!(
                "arm.links must be from 1 to {MAX_SPATIAL_LINKS}, got {n}"
            )));
        }
        let work = (2 * n)
            .saturating_mul(4 * harmonics)
            .saturating_mul(4 * harmonics);
        if work > MAX_SPATIAL_WORK {
            return Err(EvalError::input(format!(
                "arm.links x (4 harmonics)^2 must be at most {}, got {n} links and {harmonics} \
                 harmonics",
                MAX_SPATIAL_WORK / 2
            )));
        }
        // The scenario's `modal.harmonics` is the request's `harmonics`.
        arm.spatial_model(harmonics)
            .map_err(|e| e.renamed("modal.harmonics", "harmonics").into())
    }
}

/// `"harmonics"` of a spatial request: `1` to [`MAX_SPATIAL_HARMONICS`], default 1.
fn harmonics(requested: Option<usize>) -> Result<usize, EvalError> {
    super::request::harmonics(requested, MAX_SPATIAL_HARMONICS)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StateRequest {
    arm: SpatialArmSpec,
    a: Vec<f64>,
    harmonics: Option<usize>,
}

/// `joints`: `theta` (`2n`, `[z_1, y_1, ...]`) and the constant `2n x 4K` modal Jacobian.
fn joints(request: StateRequest) -> EvalResult {
    let model = request.arm.model(harmonics(request.harmonics)?)?;
    let map = model.map();
    lane_math::check_values("a", &request.a, map.n_coords())?;
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&request.a, &mut theta)?;
    finite("theta", &theta)?;
    let jacobian: Vec<&[f64]> = (0..map.n_joints()).map(|i| map.row(i)).collect();
    Ok(json_fields([
        ("theta", json!(theta)),
        ("jacobian", json!(jacobian)),
    ]))
}

/// `fk`: the tip of the backbone curve (`tip`, integrated to `1e-12` of the arm's length) and of
/// the universal-joint chain (`tip_chain`), both `[x, y, z]`.
fn fk(request: StateRequest) -> EvalResult {
    let model = request.arm.model(harmonics(request.harmonics)?)?;
    let map = model.map();
    lane_math::check_values("a", &request.a, map.n_coords())?;
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&request.a, &mut theta)?;
    finite("theta", &theta)?;
    let tip_chain = spatial_tip_position(map.link_lengths(), model.base(), &theta)?;
    let tip = map
        .curve_tip(&request.a, *model.base())
        .map_err(curve_error)?;
    finite("tip", &[tip, tip_chain].concat())?;
    Ok(json_fields([
        ("tip", json!(tip)),
        ("tip_chain", json!(tip_chain)),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IkRequest {
    arm: SpatialArmSpec,
    target: [f64; 3],
    harmonics: Option<usize>,
    guess: Option<Vec<f64>>,
}

/// `ik`: modal coordinates `a` (`4K`) whose chain's tip is on the target, by damped least squares
/// from `"guess"` (default: a quarter bend in each plane, away from the straight arm's
/// singularity).
fn ik(request: IkRequest) -> EvalResult {
    let model = request.arm.model(harmonics(request.harmonics)?)?;
    let mut a = vec![0.0; model.n_coords()];
    let mut solver = SpatialIk::new(model.map().clone(), *model.base())?;
    let report = solver.solve_evaluable(request.target, request.guess.as_deref(), &mut a)?;
    finite("a", &a)?;
    Ok(json_fields([
        ("a", json!(a)),
        ("iterations", json!(report.iterations)),
        ("residual", json!(report.residual)),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ReducedRequest {
    arm: SpatialArmSpec,
    a: Vec<f64>,
    a_dot: Vec<f64>,
    tau_star: Vec<f64>,
    harmonics: Option<usize>,
}

/// `reduced`: `M*`, `C*`, `G*`, the modal accelerations under `tau*` and the `2n` joint torques
/// that realise them.
fn reduced(request: ReducedRequest) -> EvalResult {
    let model = request.arm.model(harmonics(request.harmonics)?)?;
    let (n, m) = (model.n_links(), model.n_coords());
    let mut data = SpatialReducedData::new(&model);
    let (mut a_ddot, mut torques) = (vec![0.0; m], vec![0.0; 2 * n]);
    spatial_forward_dynamics(
        &model,
        &mut data,
        &request.a,
        &request.a_dot,
        &request.tau_star,
        &mut a_ddot,
    )?;
    let mass: Vec<&[f64]> = data.mass_matrix().chunks_exact(m).collect();
    let mass = json!(mass);
    let (coriolis, gravity) = (data.coriolis().to_vec(), data.gravity().to_vec());
    spatial_joint_torques(
        &model,
        &mut data,
        &request.a,
        &request.a_dot,
        &a_ddot,
        &mut torques,
    )?;
    for (name, values) in [("a_ddot", &a_ddot), ("joint_torques", &torques)] {
        finite(name, values)?;
    }
    Ok(json_fields([
        ("mass_matrix", mass),
        ("coriolis", json!(coriolis)),
        ("gravity", json!(gravity)),
        ("a_ddot", json!(a_ddot)),
        ("joint_torques", json!(torques)),
    ]))
}

/// `reduced_derivatives`: `a_ddot` and its analytic Jacobians `d_a`, `d_a_dot` and
/// `d_tau_star = M*^-1` (`m x m` each), as for planar arms.
fn reduced_derivatives(request: ReducedRequest) -> EvalResult {
    let model = request.arm.model(harmonics(request.harmonics)?)?;
    let mut derivatives = SpatialReducedDerivatives::new(&model);
    spatial_reduced_derivatives(
        &model,
        &mut SpatialReducedData::new(&model),
        &mut derivatives,
        &request.a,
        &request.a_dot,
        &request.tau_star,
    )?;
    finite("a_ddot", derivatives.a_ddot())?;
    Ok(json_fields([
        ("a_ddot", json!(derivatives.a_ddot())),
        ("d_a", super::derivatives::rows("d_a", derivatives.d_a())?),
        (
            "d_a_dot",
            super::derivatives::rows("d_a_dot", derivatives.d_a_dot())?,
        ),
        (
            "d_tau_star",
            super::derivatives::rows("d_tau_star", derivatives.d_tau_star())?,
        ),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportRequest {
    arm: SpatialArmSpec,
    format: String,
}

/// `export`: the arm as URDF or MJCF ([`robot_desc::from_spatial_arm`]: its movable joints in the
/// order of `theta`; the MJCF carries the arm's gravity, a URDF none).
fn export(request: ExportRequest) -> EvalResult {
    // The chain does not depend on the modal family: the model of one harmonic describes it.
    let model = request.arm.model(1)?;
    let robot = robot_desc::from_spatial_arm(&model, "hrm_spatial_arm")
        .map_err(|e| EvalError::input(format!("arm.links: {e}")))?;
    let text = match request.format.as_str() {
        "urdf" => robot_desc::write_urdf(&robot).map_err(|e| EvalError::input(e.to_string()))?,
        "mjcf" => robot_desc::write_mjcf(&robot, model.gravity())
            .map_err(|e| EvalError::input(e.to_string()))?,
        other => {
            return Err(EvalError::input(format!(
                "format must be \"urdf\" or \"mjcf\", got {other:?}"
            )));
        }
    };
    Ok(json_fields([("text", json!(text))]))
}

#[cfg(test)]
mod tests {
    use serde_json::{Value, json};

    fn request(line: Value) -> Value {
        super::super::answer(line.to_string().as_bytes())
    }

    fn vector(value: &Value) -> Vec<f64> {
        value
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    }

    #[test]
    fn ik_fk_and_reduced_agree_through_the_protocol() {
        let arm = json!({"kind": "spatial", "joints": "universal", "links": 10,
                         "link_length": 0.1, "link_mass": 0.1,
                         "base": {"xyz": [0.0, 0.0, 0.5], "rpy": [0.0, 0.2, 0.0]}});
        let target = [0.5, 0.3, 0.2];
        let solved = request(json!({"op": "ik", "arm": arm, "target": target}));
        assert_eq!(solved["ok"], true, "{solved}");
        let a = vector(&solved["a"]);
        let fk = request(json!({"op": "fk", "arm": arm, "a": a}));
        let tip_chain = vector(&fk["tip_chain"]);
        assert!(
            (0..3).all(|d| (tip_chain[d] - target[d]).abs() < 1e-13),
            "{fk}"
        );
        // The joint torques that realise the modal motion project back onto tau*.
        let tau_star = [0.3, -0.2, 0.1, 0.05];
        let reduced = request(json!({"op": "reduced", "arm": arm, "a": a,
                                     "a_dot": [0.5, -1.0, 0.2, 0.7], "tau_star": tau_star}));
        let joints = request(json!({"op": "joints", "arm": arm, "a": a}));
        let torques = vector(&reduced["joint_torques"]);
        let jacobian: Vec<Vec<f64>> = joints["jacobian"]
            .as_array()
            .unwrap()
            .iter()
            .map(vector)
            .collect();
        assert_eq!(
            (torques.len(), jacobian.len(), jacobian[0].len()),
            (20, 20, 4)
        );
        for (c, &tau) in tau_star.iter().enumerate() {
            let projected: f64 = (0..20).map(|j| jacobian[j][c] * torques[j]).sum();
            assert!((projected - tau).abs() < 1e-12, "{projected} vs {tau}");
        }
    }

    /// A spatial arm's gravity is bounded as a scenario's (1e308 came back as accelerations of
    /// 1e307), and a curve that oscillates too fast for `fk` is refused before it is integrated
    /// (512 links with `K = 16` and amplitudes of 30 took a minute to be refused).
    #[test]
    fn spatial_gravity_and_curve_work_are_bounded() {
        let answer = request(json!({"op": "reduced",
            "arm": {"kind": "spatial", "gravity": [1e308, 0.0, 0.0]},
            "a": [0.1, 0.1, 0.1, 0.1], "a_dot": [0.1, 0.1, 0.1, 0.1],
            "tau_star": [0.1, 0.1, 0.1, 0.1]}));
        assert_eq!(
            answer["error"]["message"],
            "arm.gravity[0] must be finite and at most 1000000 m/s^2 in magnitude, got 1e308"
        );
        let answer = request(json!({"op": "fk", "arm": {"kind": "spatial", "links": 512},
            "a": vec![30.0; 64], "harmonics": 16}));
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(
            message.starts_with("a: the curve oscillates too fast")
                && message.ends_with("at most 262144 allowed"),
            "{message}"
        );
        // An ik answer is one fk evaluates: from a guess of 10s, ik converges (residual 1e-15)
        // to coordinates whose curve needs 271,928 nodes.
        let answer = request(json!({"op": "ik",
            "arm": {"kind": "spatial", "links": 512, "link_length": 1e-3}, "harmonics": 16,
            "target": [0.1, 0.1, 0.1], "guess": vec![10.0; 64]}));
        assert_eq!(answer["error"]["kind"], "numerical");
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(
            message.starts_with("the solution's curve (")
                && message.contains("cannot be evaluated by fk: the curve oscillates too fast")
                && message.contains("start from a guess of smaller coordinates"),
            "{message}"
        );
        // Amplitudes at the bound of a run's scale: no quadrature resolves them; beyond it
        // they are refused before any quadrature.
        let answer = request(json!({"op": "fk", "arm": {"kind": "spatial"},
            "a": [1e6, 1e6, 0.0, 0.0]}));
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(
            message.starts_with("a: the curve oscillates too fast")
                && message.contains("50265484 nodes needed"),
            "{message}"
        );
        for op in ["fk", "joints", "reduced"] {
            let answer = request(json!({"op": op, "arm": {"kind": "spatial"},
                "a": [0.1, 0.2, 0.3, -1e17], "a_dot": [0, 0, 0, 0], "tau_star": [0, 0, 0, 0]}));
            assert_eq!(
                answer["error"]["message"],
                "a[3] must be at most 1000000 in magnitude (rad), got -1e17",
                "{op}"
            );
        }
    }

    #[test]
    fn in_the_plane_a_spatial_arm_answers_as_the_planar_one() {
        let spatial = json!({"kind": "spatial", "gravity": [0.0, -9.81, 0.0]});
        let (a, a_dot) = ([0.8, -0.3], [0.4, 0.9]);
        let planar = request(
            json!({"op": "reduced", "a": a, "alpha0": 0.0, "a_dot": a_dot,
                                    "tau_star": [0.0, 0.0]}),
        );
        let answer = request(
            json!({"op": "reduced", "arm": spatial, "a": [a[0], a[1], 0.0, 0.0],
                                    "a_dot": [a_dot[0], a_dot[1], 0.0, 0.0],
                                    "tau_star": [0.0, 0.0, 0.0, 0.0]}),
        );
        for r in 0..2 {
            let (p, s) = (
                vector(&planar["mass_matrix"][r]),
                vector(&answer["mass_matrix"][r]),
            );
            assert!((0..2).all(|c| (p[c] - s[c]).abs() < 1e-12), "{p:?} {s:?}");
        }
        for key in ["coriolis", "gravity"] {
            let (p, s) = (vector(&planar[key]), vector(&answer[key]));
            assert!(
                (0..2).all(|c| (p[c] - s[c]).abs() < 1e-12),
                "{key}: {p:?} {s:?}"
            );
        }
        let joints = request(json!({"op": "joints", "a": a, "alpha0": 0.0}));
        let spatial_joints =
            request(json!({"op": "joints", "arm": spatial, "a": [a[0], a[1], 0.0, 0.0]}));
        let (p, s) = (vector(&joints["theta"]), vector(&spatial_joints["theta"]));
        assert!((0..10).all(|i| p[i] == s[2 * i] && s[2 * i + 1] == 0.0));
    }

    /// The exported URDF read back: `2n` joints in the order of `theta`, whose frames composed
    /// joint by joint (`origin * Rot(axis, q)`) put the last link's end on the chain's tip;
    /// the inertias as given.
    #[test]
    fn the_exported_urdf_is_the_arm() {
        use robot_desc::pose::{mat_mul, mat_vec};
        let arm = json!({"kind": "spatial", "lengths": [0.1, 0.2, 0.15, 0.1],
                         "inertias": [[0.002, 0.001, 0.0015], [0.002, 0.001, 0.0015], [0.002, 0.001, 0.0015], [0.002, 0.001, 0.0015]],
                         "base": {"xyz": [0.1, 0.0, 0.3], "rpy": [0.3, -0.2, 0.5]}});
        let exported = request(json!({"op": "export", "arm": arm, "format": "urdf"}));
        let robot = robot_desc::read_urdf(exported["text"].as_str().unwrap())
            .unwrap()
            .robot;
        let a = [0.4, -0.3, 0.2, 0.6];
        let theta = vector(&request(json!({"op": "joints", "arm": arm, "a": a}))["theta"]);
        let tip = vector(&request(json!({"op": "fk", "arm": arm, "a": a}))["tip_chain"]);
        assert_eq!(robot.n_joints(), 8);
        let (mut rotation, mut position) = (
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            [0.0; 3],
        );
        for (joint, &q) in robot.joints.iter().zip(&theta) {
            let offset = mat_vec(&rotation, joint.origin.xyz);
            position = [0, 1, 2].map(|d| position[d] + offset[d]);
            rotation = mat_mul(&rotation, &joint.origin.rotation());
            let turn = if joint.axis == [0.0, 0.0, 1.0] {
                robot_desc::pose::rpy_matrix([0.0, 0.0, q])
            } else {
                assert_eq!(joint.axis, [0.0, 1.0, 0.0]);
                robot_desc::pose::rpy_matrix([0.0, q, 0.0])
            };
            rotation = mat_mul(&rotation, &turn);
        }
        let end = mat_vec(&rotation, [0.1, 0.0, 0.0]);
        for d in 0..3 {
            assert!(
                (position[d] + end[d] - tip[d]).abs() < 1e-14,
                "{position:?} {tip:?}"
            );
        }
        let last = &robot.joints[7].child.inertial;
        assert_eq!(
            (last.mass, last.inertia),
            (0.1, [0.002, 0.0, 0.0, 0.001, 0.0, 0.0015])
        );
        assert_eq!(last.origin.xyz, [0.05, 0.0, 0.0]);
    }

    /// `reduced_derivatives` answers what the library computes (tested there against finite
    /// differences): `d_tau_star` inverts `mass_matrix`.
    #[test]
    fn reduced_derivatives_answer_through_the_protocol() {
        let arm = json!({"kind": "spatial", "links": 6});
        let state = json!({"a": [0.4, -0.3, 0.2, 0.6], "a_dot": [0.5, -1.0, 0.2, 0.7],
                           "tau_star": [0.1, 0.0, -0.1, 0.2]});
        let mut line = json!({"op": "reduced_derivatives", "arm": arm});
        let mut reduced_line = json!({"op": "reduced", "arm": arm});
        for key in ["a", "a_dot", "tau_star"] {
            line[key] = state[key].clone();
            reduced_line[key] = state[key].clone();
        }
        let answer = request(line);
        let reduced = request(reduced_line);
        assert_eq!(answer["a_ddot"], reduced["a_ddot"]);
        for i in 0..4 {
            for j in 0..4 {
                let product: f64 = (0..4)
                    .map(|l| {
                        answer["d_tau_star"][i][l].as_f64().unwrap()
                            * reduced["mass_matrix"][l][j].as_f64().unwrap()
                    })
                    .sum();
                assert!((product - f64::from(u8::from(i == j))).abs() < 1e-10);
            }
        }
        for key in ["d_a", "d_a_dot"] {
            assert_eq!(answer[key].as_array().unwrap().len(), 4);
        }
    }

    #[test]
    fn spatial_requests_are_bounded_and_checked() {
        let cases = [
            (
                json!({"op": "dynamics", "arm": {"kind": "spatial"}, "theta": [], "theta_dot": []}),
                "does not take a spatial arm",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "joints": "alternating"}, "a": [0, 0, 0, 0]}),
                "arm.joints: unknown variant `alternating`, expected `universal`",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "links": 100_000}, "a": [], "harmonics": 16}),
                "must be at most",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "links": 0}, "a": [0, 0, 0, 0]}),
                "arm.links must be at least 1",
            ),
            (
                json!({"op": "fk", "arm": {"lengths": []}, "a": [0.1, 0.2], "alpha0": 0}),
                "arm.lengths is empty: an arm has at least 1 link",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "masses": []}, "a": [0, 0, 0, 0]}),
                "arm.masses is empty: an arm has at least 1 link",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "lengths": [0.1, 0.2], "masses": [0.1]},
                    "a": [0, 0, 0, 0]}),
                "arm.masses has 1 entries but the arm has 2 links",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "inertias": [[1.0, 0.1, 0.1], [1.0, 0.1, 0.1]]}, "a": [0, 0, 0, 0]}),
                "arm.inertias[0] is invalid: chain dynamics: link 0: principal inertia must be at \
                 most the sum of the other two (triangle",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial"}, "a": [0, 0, 0]}),
                "expected 4",
            ),
            (
                json!({"op": "export", "arm": {"kind": "spatial", "links": 20_000}, "format": "urdf"}),
                "arm.links: cannot export robot 'hrm_spatial_arm': 20000 links exceed the 10000 \
                 a spatial arm is written with",
            ),
            (
                json!({"op": "export", "arm": {"kind": "spatial"}, "format": "sdf"}),
                "format must be",
            ),
            (
                json!({"op": "export", "arm": {"kind": "spatial"}, "format": "urdf", "harmonics": 2}),
                "harmonics: unknown field `harmonics`",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "links": 1}, "a": [0, 0, 0, 0]}),
                "arm.links must be at least 2 for a spatial arm",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "gravity": [0, 0]}, "a": [0, 0, 0, 0]}),
                "arm.gravity must have 3 entries [gx, gy, gz], got 2",
            ),
            (
                json!({"op": "fk", "arm": {"kind": {"spatial": null}}, "a": [0, 0, 0, 0]}),
                "arm.kind must be \"planar\" or \"spatial\", got {\"spatial\":null}",
            ),
            (
                json!({"op": "ik", "arm": {"kind": "spatial"}, "target": [5.0, 0.0, 0.0]}),
                "out of reach",
            ),
            // The fields a scenario's spatial arm names, through the same checks.
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "link_length": -0.0}, "a": [0, 0, 0, 0]}),
                "arm.link_length is invalid: link 0: length must be positive and finite, got -0",
            ),
            // A length or mass whose rod inertia m L^2 / 12 under- or overflows, and a chain
            // whose sums overflow, are refused as a planar arm's are.
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "link_length": 1e300}, "a": [0, 0, 0, 0]}),
                "arm.link_length is invalid: link 0: length must be such that the beam's inertia",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "link_length": 5e-324}, "a": [0, 0, 0, 0]}),
                "arm.link_length is invalid: link 0: length must be such that the beam's inertia",
            ),
            (
                json!({"op": "reduced", "arm": {"kind": "spatial", "lengths": [0.1, 0.1, 0.1, 1e-300]},
                    "a": [0, 0, 0, 0], "a_dot": [0, 0, 0, 0], "tau_star": [0, 0, 0, 0]}),
                "arm.lengths[3] is invalid: link 3: length must be such that the beam's inertia",
            ),
            (
                json!({"op": "reduced", "arm": {"kind": "spatial", "link_mass": 5e-324},
                    "a": [0, 0, 0, 0], "a_dot": [0, 0, 0, 0], "tau_star": [0, 0, 0, 0]}),
                "arm.link_mass is invalid: link 0: mass must be such that the beam's inertia",
            ),
            (
                json!({"op": "reduced", "arm": {"kind": "spatial", "link_length": 1e154},
                    "a": [0, 0, 0, 0], "a_dot": [0, 0, 0, 0], "tau_star": [0, 0, 0, 0]}),
                "arm is invalid: the chain's total mass",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "base": {"xyz": [1e300, 0, 0]}},
                    "a": [0, 0, 0, 0]}),
                "arm.base.xyz is invalid",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "radius": 0.01}, "a": [0, 0, 0, 0]}),
                "arm.radius: not used by any op of hrm eval (it is a scenario's clearance): \
                 remove it",
            ),
            (
                json!({"op": "fk", "arm": {"radius": -1}, "a": [0.1, 0.2], "alpha0": 0}),
                "arm.radius: not used by any op",
            ),
            (
                json!({"op": "dynamics", "arm": {"radius": 1e308, "links": 1}, "theta": [0],
                    "theta_dot": [0]}),
                "arm.radius: not used by any op",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "lengths": [0.1, 0.1, 0.1, 0.1],
                    "link_length": 0.2}, "a": [0, 0, 0, 0]}),
                "give arm.lengths or arm.link_length, not both",
            ),
            (
                json!({"op": "dynamics", "arm": {"link_length": 7, "lengths": [0.1, 0.1]},
                    "theta": [0, 0], "theta_dot": [0, 0]}),
                "arm.link_length = 7 is not used beside arm.lengths (one per link): give \
                 arm.lengths or arm.link_length, not both",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "masses": [0.1, 0.1, 0.1, 0.1],
                    "link_mass": 0.2}, "a": [0, 0, 0, 0]}),
                "give arm.masses or arm.link_mass, not both",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial"}, "a": [0, 0, 0, 0, 0]}),
                "a has 5 entries, expected 4",
            ),
            (
                json!({"op": "ik", "arm": {"kind": "spatial"}, "target": [0.5, 0.1, 0.1],
                    "guess": [0.1, 0.1, 0.1]}),
                "guess has 3 entries, expected 4",
            ),
            (
                json!({"op": "joints", "arm": {"kind": "spatial", "colour": 1}, "a": [0, 0, 0, 0]}),
                "unknown field",
            ),
        ];
        for (line, expected) in cases {
            let answer = request(line.clone());
            assert_eq!(answer["ok"], false, "{line}");
            let message = answer["error"]["message"].as_str().unwrap();
            assert!(message.contains(expected), "{line}: {message}");
        }
    }
}
