//! `hrm eval`: a JSON-lines request/answer protocol for scripts in other languages.
//!
//! One JSON object per input line, one JSON object per output line, in order, flushed after each.
//! A request may carry `"id"`, echoed in its answer. A bad request gets
//! `{"id": ..., "error": {"kind": "...", "message": "..."}}` and the stream goes on. The protocol
//! is documented in `docs/eval-protocol.md`.

use crate::arm::ArmSpec;
use backbone_kin::{BaseAngle, ModalMap};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value, json};
use std::io::{BufRead, Write};

/// Longest request line accepted (bytes); longer lines are skipped with a `line_too_long` error.
pub const MAX_LINE_BYTES: usize = 16 << 20;

/// Serves stdin to stdout until end of input.
pub fn run_stdio() -> Result<(), String> {
    serve(std::io::stdin().lock(), std::io::stdout().lock()).map_err(|e| format!("eval: {e}"))
}

/// Answers every line of `input` on `output`. Only I/O failures end the stream.
pub fn serve(mut input: impl BufRead, mut output: impl Write) -> std::io::Result<()> {
    let mut line = Vec::new();
    loop {
        let Some(complete) = read_line(&mut input, &mut line, MAX_LINE_BYTES)? else {
            return Ok(());
        };
        if complete && line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let answer = if complete {
            answer(&line)
        } else {
            error_answer(
                Value::Null,
                &EvalError::new(
                    Kind::LineTooLong,
                    format!("request line longer than {MAX_LINE_BYTES} bytes"),
                ),
            )
        };
        serde_json::to_writer(&mut output, &answer)?;
        output.write_all(b"\n")?;
        output.flush()?;
    }
}

/// Reads one line (without its newline) into `line`, keeping at most `limit` bytes. Returns
/// `None` at end of input, `Some(false)` when the line was longer than `limit` (the rest of it is
/// consumed and dropped).
fn read_line(
    input: &mut impl BufRead,
    line: &mut Vec<u8>,
    limit: usize,
) -> std::io::Result<Option<bool>> {
    line.clear();
    let mut total = 0usize;
    loop {
        let buffer = input.fill_buf()?;
        if buffer.is_empty() {
            return Ok((total > 0).then_some(total <= limit));
        }
        let (chunk, found_newline) = match buffer.iter().position(|&b| b == b'\n') {
            Some(i) => (&buffer[..i], true),
            None => (buffer, false),
        };
        if total + chunk.len() <= limit {
            line.extend_from_slice(chunk);
        }
        total = total.saturating_add(chunk.len());
        let consumed = chunk.len() + usize::from(found_newline);
        input.consume(consumed);
        if found_newline {
            return Ok(Some(total <= limit));
        }
    }
}

/// The category of a failed request, the `kind` field of an error answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Not valid UTF-8.
    InvalidUtf8,
    /// Not valid JSON.
    Parse,
    /// A line over [`MAX_LINE_BYTES`].
    LineTooLong,
    /// Valid JSON, but not a request of the documented shape (missing or mistyped field).
    InvalidRequest,
    /// An `op` this version does not know.
    UnknownOp,
    /// Well-formed, but outside the model's domain (non-finite, wrong size, non-positive mass).
    InvalidInput,
    /// An inverse-kinematics target the backbone curve cannot reach.
    Unreachable,
    /// A computation that failed numerically.
    Numerical,
}

impl Kind {
    fn as_str(self) -> &'static str {
        match self {
            Kind::InvalidUtf8 => "invalid_utf8",
            Kind::Parse => "parse",
            Kind::LineTooLong => "line_too_long",
            Kind::InvalidRequest => "invalid_request",
            Kind::UnknownOp => "unknown_op",
            Kind::InvalidInput => "invalid_input",
            Kind::Unreachable => "unreachable",
            Kind::Numerical => "numerical",
        }
    }
}

/// A failed request: its kind and a readable message.
#[derive(Debug)]
struct EvalError {
    kind: Kind,
    message: String,
}

impl EvalError {
    fn new(kind: Kind, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
        }
    }

    fn input(message: impl ToString) -> Self {
        Self::new(Kind::InvalidInput, message.to_string())
    }
}

type EvalResult = Result<Map<String, Value>, EvalError>;

fn error_answer(id: Value, error: &EvalError) -> Value {
    json!({"id": id, "error": {"kind": error.kind.as_str(), "message": error.message}})
}

/// Answers one request line.
fn answer(line: &[u8]) -> Value {
    let text = match std::str::from_utf8(line) {
        Ok(text) => text,
        Err(e) => {
            return error_answer(
                Value::Null,
                &EvalError::new(Kind::InvalidUtf8, format!("request is not UTF-8: {e}")),
            );
        }
    };
    let mut request = match serde_json::from_str::<Value>(text) {
        Ok(Value::Object(map)) => map,
        Ok(_) => {
            return error_answer(
                Value::Null,
                &EvalError::new(Kind::InvalidRequest, "a request must be a JSON object"),
            );
        }
        Err(e) => {
            return error_answer(
                Value::Null,
                &EvalError::new(Kind::Parse, format!("malformed JSON: {e}")),
            );
        }
    };
    let id = request.remove("id");
    let result = match request.remove("op") {
        Some(Value::String(op)) => dispatch(&op, request),
        Some(_) => Err(EvalError::new(
            Kind::InvalidRequest,
            "\"op\" must be a string",
        )),
        None => Err(EvalError::new(Kind::InvalidRequest, "missing \"op\"")),
    };
    match result {
        Ok(mut fields) => {
            if let Some(id) = id {
                fields.insert("id".to_string(), id);
            }
            Value::Object(fields)
        }
        Err(error) => error_answer(id.unwrap_or(Value::Null), &error),
    }
}

const OPS: &str = "joints";

fn dispatch(op: &str, request: Map<String, Value>) -> EvalResult {
    match op {
        "joints" => joints(parse(request)?),
        other => Err(EvalError::new(
            Kind::UnknownOp,
            format!("unknown op {other:?}; known ops: {OPS}"),
        )),
    }
}

/// Deserialises the request's remaining fields into the op's typed request.
fn parse<T: DeserializeOwned>(request: Map<String, Value>) -> Result<T, EvalError> {
    serde_json::from_value(Value::Object(request))
        .map_err(|e| EvalError::new(Kind::InvalidRequest, e.to_string()))
}

/// Modal coordinates as requests give them: `[a1, a2, alpha0]`, or `[a1, a2]` with `"alpha0"`.
fn modal_map(arm: &ArmSpec, a: &[f64], alpha0: Option<f64>) -> Result<ModalMap, EvalError> {
    let chain = arm.to_chain().map_err(EvalError::input)?;
    let lengths: Vec<f64> = chain.link_lengths().collect();
    let base = match (a.len(), alpha0) {
        (3, None) => BaseAngle::Free,
        (2, Some(alpha0)) => BaseAngle::Fixed(alpha0),
        (3, Some(_)) => {
            return Err(EvalError::input(
                "give alpha0 either as a[2] or as \"alpha0\", not both",
            ));
        }
        (2, None) => {
            return Err(EvalError::input(
                "with two coordinates [a1, a2], \"alpha0\" is required",
            ));
        }
        (k, _) => {
            return Err(EvalError::input(format!(
                "a has {k} entries, expected [a1, a2, alpha0] or [a1, a2]"
            )));
        }
    };
    ModalMap::new(&lengths, 1, base).map_err(EvalError::input)
}

/// Refuses to answer with a non-finite number (JSON has none).
fn finite(name: &str, values: &[f64]) -> Result<(), EvalError> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(EvalError::new(
            Kind::Numerical,
            format!("{name} came out non-finite ({v})"),
        )),
        None => Ok(()),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointsRequest {
    #[serde(default)]
    arm: ArmSpec,
    a: Vec<f64>,
    alpha0: Option<f64>,
}

/// `joints`: joint angles `theta = J a (+ alpha0 e_1)` and the modal Jacobian (eqs 7-9).
fn joints(request: JointsRequest) -> EvalResult {
    let map = modal_map(&request.arm, &request.a, request.alpha0)?;
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&request.a, &mut theta)
        .map_err(EvalError::input)?;
    finite("theta", &theta)?;
    let jacobian: Vec<&[f64]> = (0..map.n_joints()).map(|i| map.row(i)).collect();
    Ok(json_fields([
        ("theta", json!(theta)),
        ("jacobian", json!(jacobian)),
    ]))
}

fn json_fields<const N: usize>(fields: [(&str, Value); N]) -> Map<String, Value> {
    fields
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(input: &[u8]) -> Vec<Value> {
        let mut out = Vec::new();
        serve(input, &mut out).unwrap();
        String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }

    #[test]
    fn bad_lines_get_errors_and_the_stream_goes_on() {
        let input = b"{not json\n\xff\xfe\n[1,2]\n{\"id\":7}\n{\"id\":8,\"op\":\"nope\"}\n\n{\"id\":9,\"op\":\"joints\",\"a\":[0.1,0.2,0.3]}\n";
        let answers = run(input);
        let kinds: Vec<&str> = answers
            .iter()
            .map(|a| a["error"]["kind"].as_str().unwrap_or("ok"))
            .collect();
        assert_eq!(
            kinds,
            [
                "parse",
                "invalid_utf8",
                "invalid_request",
                "invalid_request",
                "unknown_op",
                "ok"
            ]
        );
        assert_eq!(answers[3]["id"], 7);
        assert_eq!(answers[4]["id"], 8);
        assert_eq!(answers[5]["id"], 9);
    }

    #[test]
    fn overlong_line_is_refused_and_the_next_line_answered() {
        let mut input = vec![b' '; MAX_LINE_BYTES + 10];
        input.extend_from_slice(b"\n{\"id\":1,\"op\":\"joints\",\"a\":[0,0,0]}\n");
        let answers = run(&input);
        assert_eq!(answers[0]["error"]["kind"], "line_too_long");
        assert_eq!(answers[1]["id"], 1);
        assert_eq!(answers[1]["theta"].as_array().unwrap().len(), 10);
    }

    #[test]
    fn joints_follow_eq_7_for_the_paper_arm() {
        let answers = run(b"{\"op\":\"joints\",\"a\":[0.3,-0.2,0.5]}\n");
        let theta: Vec<f64> = serde_json::from_value(answers[0]["theta"].clone()).unwrap();
        // theta_1 = alpha(L/2) = alpha0 + a1 sin(pi/n) + a2 (1 - cos(pi/n)) (eq 7).
        let pi_n = std::f64::consts::PI / 10.0;
        approx::assert_abs_diff_eq!(
            theta[0],
            0.5 + 0.3 * pi_n.sin() - 0.2 * (1.0 - pi_n.cos()),
            epsilon = 1e-15
        );
        // The joint angles sum to the tip link's inclination alpha(l - L/2).
        let s = 9.5 / 10.0 * std::f64::consts::TAU;
        let alpha = 0.5 + 0.3 * s.sin() - 0.2 * (1.0 - s.cos());
        approx::assert_abs_diff_eq!(theta.iter().sum::<f64>(), alpha, epsilon = 1e-14);
        assert_eq!(answers[0]["jacobian"].as_array().unwrap().len(), 10);
    }

    #[test]
    fn arm_errors_name_the_offending_link() {
        let answers = run(b"{\"id\":\"x\",\"op\":\"joints\",\"arm\":{\"masses\":[0.1,-1]},\"a\":[0,0],\"alpha0\":1}\n");
        assert_eq!(answers[0]["error"]["kind"], "invalid_input");
        assert_eq!(
            answers[0]["error"]["message"],
            "link 1: mass must be positive and finite, got -1"
        );
        assert_eq!(answers[0]["id"], "x");
    }
}
