//! The derivative ops of `hrm eval` through the built binary: closed forms, consistency with the
//! `dynamics` and `reduced` ops (inverse mass matrices, finite differences of `a_ddot`), and one
//! clear error per bad request.

use serde_json::{Value, json};
use std::io::Write;
use std::process::{Command, Stdio};

/// Sends `requests` to one `hrm eval` and returns the answers, in order.
pub(crate) fn eval(requests: &[Value]) -> Vec<Value> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .arg("eval")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("hrm starts");
    let mut input = String::new();
    for request in requests {
        input.push_str(&request.to_string());
        input.push('\n');
    }
    let mut stdin = child.stdin.take().expect("piped stdin");
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let output = child.wait_with_output().expect("hrm runs");
    writer.join().unwrap().unwrap();
    assert!(output.status.success());
    String::from_utf8(output.stdout)
        .unwrap()
        .lines()
        .map(|line| serde_json::from_str(line).unwrap())
        .collect()
}

fn ok(answer: &Value) -> &Value {
    assert_eq!(answer["ok"], json!(true), "{answer}");
    answer
}

fn vector(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn matrix(value: &Value) -> Vec<Vec<f64>> {
    value.as_array().unwrap().iter().map(vector).collect()
}

fn product(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
    (0..a.len())
        .map(|i| {
            (0..b[0].len())
                .map(|j| (0..b.len()).map(|k| a[i][k] * b[k][j]).sum())
                .collect()
        })
        .collect()
}

fn assert_identity(m: &[Vec<f64>], tolerance: f64) {
    for (i, row) in m.iter().enumerate() {
        for (j, &x) in row.iter().enumerate() {
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!((x - expected).abs() < tolerance, "[{i}][{j}] = {x}");
        }
    }
}

#[test]
fn a_pendulum_has_the_closed_form_derivatives() {
    // tau = (m L^2 / 3) qdd + m g (L / 2) cos q: d tau / d q = -m g (L / 2) sin q, d / d qdd = 0.
    let (m, l, g, q) = (2.0, 0.5, 9.81, 0.4f64);
    let arm = json!({"links": 1, "link_length": l, "link_mass": m, "gravity": g});
    let answers = eval(&[
        json!({"op": "rnea_derivatives", "arm": arm, "theta": [q], "theta_dot": [1.0], "theta_ddot": [0.5]}),
        json!({"op": "aba_derivatives", "arm": arm, "theta": [q], "theta_dot": [1.0], "tau": [0.5]}),
    ]);
    let inertia = m * l * l / 3.0;
    let rnea = ok(&answers[0]);
    assert!((vector(&rnea["tau"])[0] - (inertia * 0.5 + m * g * l / 2.0 * q.cos())).abs() < 1e-12);
    assert!((matrix(&rnea["d_theta"])[0][0] + m * g * l / 2.0 * q.sin()).abs() < 1e-12);
    assert_eq!(matrix(&rnea["d_theta_dot"]), vec![vec![0.0]]);
    let aba = ok(&answers[1]);
    assert!((matrix(&aba["d_theta"])[0][0] - m * g * l / 2.0 * q.sin() / inertia).abs() < 1e-12);
    assert!((matrix(&aba["d_tau"])[0][0] - 1.0 / inertia).abs() < 1e-12);
}

#[test]
fn aba_derivatives_invert_the_mass_matrix_and_chain_with_rnea_derivatives() {
    let arm =
        json!({"lengths": [0.3, 0.2, 0.25, 0.1], "masses": [1.0, 0.7, 0.5, 0.2], "gravity": 9.81});
    let (theta, theta_dot, tau) = (
        json!([0.3, -0.5, 0.8, 0.1]),
        json!([1.0, -0.4, 0.3, 2.0]),
        json!([0.5, -0.2, 0.1, 0.05]),
    );
    let first = eval(&[
        json!({"op": "aba_derivatives", "arm": arm, "theta": theta, "theta_dot": theta_dot, "tau": tau}),
        json!({"op": "dynamics", "arm": arm, "theta": theta, "theta_dot": theta_dot}),
    ]);
    let aba = ok(&first[0]);
    let mass = matrix(&ok(&first[1])["mass_matrix"]);
    let inverse = matrix(&aba["d_tau"]);
    assert_identity(&product(&mass, &inverse), 1e-12);
    // d qdd / d q = -M^-1 d tau / d q at the solution.
    let second = eval(
        &[json!({"op": "rnea_derivatives", "arm": arm, "theta": theta,
        "theta_dot": theta_dot, "theta_ddot": aba["theta_ddot"]})],
    );
    let rnea = ok(&second[0]);
    assert_eq!(vector(&rnea["tau"]).len(), 4);
    for (forward, inverse_partial) in [("d_theta", "d_theta"), ("d_theta_dot", "d_theta_dot")] {
        let expected = product(&inverse, &matrix(&rnea[inverse_partial]));
        for (row, expected_row) in matrix(&aba[forward]).iter().zip(&expected) {
            for (x, y) in row.iter().zip(expected_row) {
                assert!((x + y).abs() < 1e-10, "{forward}: {x} vs {}", -y);
            }
        }
    }
}

#[test]
fn reduced_derivatives_match_differences_of_the_reduced_op() {
    let (a, a_dot, tau_star) = ([0.4, -0.3, 1.2], [0.5, 0.2, -0.1], [0.2, -0.1, 0.05]);
    let request = |a: [f64; 3], a_dot: [f64; 3]| json!({"op": "reduced", "a": a, "a_dot": a_dot, "tau_star": tau_star});
    let h = 1e-6;
    let mut requests = vec![
        json!({"op": "reduced_derivatives", "a": a, "a_dot": a_dot, "tau_star": tau_star}),
        request(a, a_dot),
    ];
    for k in 0..3 {
        for sign in [1.0, -1.0] {
            let mut moved = a;
            moved[k] += sign * h;
            requests.push(request(moved, a_dot));
        }
    }
    let answers = eval(&requests);
    let derivatives = ok(&answers[0]);
    let reduced = ok(&answers[1]);
    assert_eq!(derivatives["a_ddot"], reduced["a_ddot"]);
    assert_identity(
        &product(
            &matrix(&reduced["mass_matrix"]),
            &matrix(&derivatives["d_tau_star"]),
        ),
        1e-12,
    );
    let d_a = matrix(&derivatives["d_a"]);
    for k in 0..3 {
        let plus = vector(&ok(&answers[2 + 2 * k])["a_ddot"]);
        let minus = vector(&ok(&answers[3 + 2 * k])["a_ddot"]);
        for i in 0..3 {
            let difference = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (d_a[i][k] - difference).abs() < 1e-5 * (1.0 + difference.abs()),
                "d_a[{i}][{k}] = {} vs {difference}",
                d_a[i][k]
            );
        }
    }
}

#[test]
fn reduced_derivatives_take_harmonics_and_a_fixed_alpha0() {
    let answers = eval(&[
        json!({"op": "reduced_derivatives", "harmonics": 2, "a": [0.3, -0.2, 0.1, 0.05, 1.5],
            "a_dot": (vec![0.1; 5]), "tau_star": (vec![0.0; 5])}),
        json!({"op": "reduced_derivatives", "harmonics": 2, "alpha0": 1.5, "a": [0.3, -0.2, 0.1, 0.05],
            "a_dot": (vec![0.1; 4]), "tau_star": (vec![0.0; 4])}),
        json!({"op": "reduced_derivatives", "alpha0": 1.5, "a": [0.3, -0.2], "a_dot": [0.1, 0.2],
            "tau_star": [0.0, 0.0]}),
    ]);
    for (answer, m) in answers.iter().zip([5, 4, 2]) {
        let answer = ok(answer);
        for field in ["d_a", "d_a_dot", "d_tau_star"] {
            let rows = matrix(&answer[field]);
            assert_eq!((rows.len(), rows[0].len()), (m, m), "{field}");
        }
    }
}

#[test]
fn bad_requests_get_one_clear_error_each() {
    let cases = [
        (
            json!({"op": "rnea_derivatives", "theta": (vec![0.0; 3]), "theta_dot": (vec![0.0; 10]), "theta_ddot": (vec![0.0; 10])}),
            "invalid_input",
            "theta has 3 entries, expected 10",
        ),
        (
            json!({"op": "aba_derivatives", "theta": (vec![0.0; 10]), "theta_dot": (vec![0.0; 10])}),
            "invalid_request",
            "missing field `tau`",
        ),
        (
            json!({"op": "aba_derivatives", "arm": {"links": 2000}, "theta": [], "theta_dot": [], "tau": []}),
            "invalid_input",
            "at most 1024",
        ),
        (
            json!({"op": "reduced_derivatives", "harmonics": 0, "a": (vec![0.0; 3]), "a_dot": (vec![0.0; 3]), "tau_star": (vec![0.0; 3])}),
            "invalid_input",
            "harmonics must be at least 1",
        ),
        (
            json!({"op": "reduced_derivatives", "harmonics": 2, "a": (vec![0.0; 3]), "a_dot": (vec![0.0; 3]), "tau_star": (vec![0.0; 3])}),
            "invalid_input",
            "2K + 1 = 5",
        ),
        (
            json!({"op": "reduced_derivatives", "harmonics": 6, "a": (vec![0.0; 13]), "a_dot": (vec![0.0; 13]), "tau_star": (vec![0.0; 13])}),
            "invalid_input",
            "column-rank-deficient",
        ),
        (
            json!({"op": "reduced_derivatives", "a": (vec![0.0; 3]), "a_dot": (vec![0.0; 2]), "tau_star": (vec![0.0; 3])}),
            "invalid_input",
            "a_dot",
        ),
    ];
    let requests: Vec<Value> = cases.iter().map(|(r, _, _)| r.clone()).collect();
    let answers = eval(&requests);
    assert_eq!(answers.len(), cases.len());
    for (answer, (request, kind, message)) in answers.iter().zip(&cases) {
        assert_eq!(answer["ok"], json!(false), "{request} -> {answer}");
        assert_eq!(
            answer["error"]["kind"],
            json!(kind),
            "{request} -> {answer}"
        );
        let text = answer["error"]["message"].as_str().unwrap();
        assert!(
            text.contains(message) && !text.contains('\n'),
            "{request} -> {text}"
        );
    }
}
