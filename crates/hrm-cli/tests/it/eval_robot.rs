//! The robot-description ops of `hrm eval`: the paper's arm exported as URDF gives through the
//! spatial chain what the planar ops give, frames in closed form, exports that read back, and
//! one clear error per bad request. (Pinocchio and MuJoCo check the same ops in
//! crates/hrm-py/tests/test_robot_engines.py.)

use crate::eval_derivatives::eval;
use serde_json::{Value, json};

fn arm() -> Value {
    json!({"links": 6, "link_length": 0.15, "link_mass": 0.2, "gravity": 9.81})
}

fn numbers(value: &Value) -> Vec<f64> {
    let mut out = Vec::new();
    match value {
        Value::Array(items) => items.iter().for_each(|v| out.extend(numbers(v))),
        Value::Number(n) => out.push(n.as_f64().unwrap()),
        other => panic!("not numbers: {other}"),
    }
    out
}

fn assert_close(a: &Value, b: &Value, tol: f64) {
    let (a, b) = (numbers(a), numbers(b));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= tol * (1.0 + y.abs()), "{x} vs {y}");
    }
}

fn exported_urdf() -> String {
    let answer = &eval(&[json!({"op": "export", "arm": arm(), "format": "urdf"})])[0];
    assert_eq!(answer["ok"], true, "{answer}");
    answer["text"].as_str().unwrap().to_string()
}

#[test]
fn the_planar_arm_as_urdf_gives_the_planar_dynamics_and_derivatives() {
    let urdf = exported_urdf();
    let theta = json!([0.3, -0.5, 0.8, 0.1, -1.2, 0.4]);
    let rate = json!([0.5, 0.2, -0.7, 1.1, 0.0, -0.3]);
    let g = json!([0.0, -9.81, 0.0]);
    let answers = eval(&[
        json!({"op": "dynamics", "arm": arm(), "theta": theta, "theta_dot": rate}),
        json!({"op": "dynamics", "urdf": urdf, "gravity": g, "theta": theta, "theta_dot": rate}),
        json!({"op": "aba_derivatives", "arm": arm(), "theta": theta, "theta_dot": rate, "tau": rate}),
        json!({"op": "aba_derivatives", "urdf": urdf, "gravity": g, "theta": theta, "theta_dot": rate, "tau": rate}),
        json!({"op": "rnea_derivatives", "arm": arm(), "theta": theta, "theta_dot": rate, "theta_ddot": rate}),
        json!({"op": "rnea_derivatives", "urdf": urdf, "gravity": g, "theta": theta, "theta_dot": rate, "theta_ddot": rate}),
    ]);
    for pair in answers.chunks(2) {
        assert_eq!(pair[0]["ok"], true, "{}", pair[0]);
        assert_eq!(pair[1]["ok"], true, "{}", pair[1]);
        for (key, value) in pair[0].as_object().unwrap() {
            if !matches!(key.as_str(), "id" | "ok") {
                assert_close(&pair[1][key], value, 1e-12);
            }
        }
    }
}

#[test]
fn frames_of_the_planar_arm_are_its_joint_positions() {
    let theta = [0.3, -0.5, 0.8, 0.1, -1.2, 0.4];
    let answer = &eval(&[json!({"op": "frames", "urdf": exported_urdf(), "theta": theta})])[0];
    assert_eq!(answer["ok"], true, "{answer}");
    // Link i's frame sits at joint i: the sum of the earlier links, rotated by phi_i.
    let (mut x, mut y, mut phi) = (0.0f64, 0.0f64, 0.0f64);
    for (i, t) in theta.iter().enumerate() {
        phi += t;
        assert_close(&answer["positions"][i], &json!([x, y, 0.0]), 1e-14);
        assert_close(
            &answer["rotations"][i],
            &json!([
                [phi.cos(), -phi.sin(), 0.0],
                [phi.sin(), phi.cos(), 0.0],
                [0.0, 0.0, 1.0]
            ]),
            1e-14,
        );
        x += 0.15 * phi.cos();
        y += 0.15 * phi.sin();
    }
}

#[test]
fn an_exported_urdf_exports_again_to_the_same_text() {
    let urdf = exported_urdf();
    let again = &eval(&[json!({"op": "export", "urdf": urdf, "format": "urdf"})])[0];
    assert_eq!(again["text"].as_str().unwrap(), urdf);
    let mjcf = &eval(&[json!({"op": "export", "arm": arm(), "format": "mjcf"})])[0];
    let text = mjcf["text"].as_str().unwrap();
    assert!(
        text.contains("<option gravity=\"0.0 -9.81 0.0\"/>"),
        "{text}"
    );
}

#[test]
fn bad_robot_requests_get_one_clear_error() {
    let urdf = exported_urdf();
    let massless = r#"<robot name="r"><link name="a"/><link name="b"/>
        <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint></robot>"#;
    let slide = r#"<robot name="r"><link name="a"/><link name="b"><inertial><mass value="1"/>
        <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="s" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
    let cases = [
        (
            json!({"op": "frames", "urdf": "<!DOCTYPE r [<!ENTITY a \"b\">]><robot name=\"&a;\"/>", "theta": []}),
            "DTD",
        ),
        (
            json!({"op": "frames", "urdf": urdf, "theta": [0.0]}),
            "theta has 1 entries, expected 6",
        ),
        (
            json!({"op": "aba_derivatives", "urdf": massless, "theta": [0.0], "theta_dot": [0.0], "tau": [0.0]}),
            "urdf: joint 'j': joint 0: the articulated inertia about its axis is not positive",
        ),
        (
            json!({"op": "frames", "urdf": slide, "theta": [-2e9]}),
            "theta[0]: joint 's': joint 0: position q must be at most 1e9 m in magnitude (a prismatic joint), got -2000000000",
        ),
        (
            json!({"op": "dynamics", "urdf": slide, "theta": [1e160], "theta_dot": [0.0]}),
            "theta[0]: joint 's': joint 0: position q must be at most 1e9 m",
        ),
        (
            json!({"op": "rnea_derivatives", "urdf": slide, "theta": [1e160], "theta_dot": [0.0], "theta_ddot": [0.0]}),
            "theta[0]: joint 's': joint 0: position q must be at most 1e9 m",
        ),
        (
            json!({"op": "export", "urdf": urdf, "arm": arm(), "format": "urdf"}),
            "exactly one",
        ),
        (
            json!({"op": "export", "urdf": urdf, "format": "sdf"}),
            "format must be",
        ),
        (
            json!({"op": "dynamics", "urdf": urdf, "gravity": [0.0, 1.0], "theta": [], "theta_dot": []}),
            "gravity",
        ),
        (
            json!({"op": "export", "urdf": massless, "format": "mjcf"}),
            "MuJoCo refuses massless moving bodies",
        ),
        (
            json!({"op": "export", "urdf": urdf, "format": "urdf", "gravity": [0.0, 0.0, -1.0]}),
            "gravity is written only to MJCF",
        ),
        (
            json!({"op": "export", "urdf": urdf, "format": "mjcf", "gravity": [0.0, 0.0, 1e308]}),
            "at most 1e9 in magnitude",
        ),
    ];
    let requests: Vec<Value> = cases.iter().map(|(r, _)| r.clone()).collect();
    for (answer, (_, needle)) in eval(&requests).iter().zip(&cases) {
        assert_eq!(answer["ok"], false, "{answer}");
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

/// A joint that moves no mass has a singular mass matrix: `dynamics` and `rnea_derivatives`
/// answer (zeros: nothing to accelerate or hold), `aba_derivatives` refuses it (above).
#[test]
fn a_massless_chain_has_zero_dynamics() {
    let massless = r#"<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
        <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
        <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint></robot>"#;
    let answers = eval(&[
        json!({"op": "dynamics", "urdf": massless, "theta": [0.3, -0.2], "theta_dot": [1.0, 2.0]}),
        json!({"op": "rnea_derivatives", "urdf": massless, "theta": [0.3, -0.2], "theta_dot": [1.0, 2.0], "theta_ddot": [0.5, 0.5]}),
    ]);
    for answer in &answers {
        assert_eq!(answer["ok"], true, "{answer}");
        let values: Vec<f64> = answer
            .as_object()
            .unwrap()
            .iter()
            .filter(|(key, _)| !["ok", "id"].contains(&key.as_str()))
            .flat_map(|(_, value)| numbers(value))
            .collect();
        assert!(
            !values.is_empty() && values.iter().all(|&v| v == 0.0),
            "{answer}"
        );
    }
}
