//! `hrm eval`: a JSON-lines request/answer protocol for scripts in other languages.
//!
//! One JSON object per input line (blank lines skipped), one JSON object per output line, in
//! order, flushed after each. A request may carry `"id"`, echoed in its answer (`null` if absent);
//! every answer has `"ok": true` or `"ok": false`. A bad request gets
//! `{"id": ..., "ok": false, "error": {"kind": "...", "message": "..."}}` and the stream goes on. The protocol
//! is documented in `docs/eval-protocol.md`.

use backbone_kin::{
    BackboneCurve, BaseAngle, Branch, ChainIk, HarmonicIk, KinError, MAX_IK_GUESS, end_point,
    inverse_kinematics, reduce_angle, tip_position,
};
use fuzzy_sugeno::FuzzySystem;
use lane_math::{Classify, ErrorClass};
use manip_dyn::ChainData;
use manip_dyn::faer::Mat;
use modal_reduce::{ReducedData, ReducedModel};
use serde::{Deserialize, Deserializer};
use serde_json::{Map, Value, json};
use sim_study::ArmSpec;
use std::io::{BufRead, Write};

mod derivatives;
mod request;
mod robot;
mod spatial;

use request::{
    EvalError, EvalResult, Kind, arm_object, curve_error, finite, harmonics, json_fields,
    modal_map, parse,
};

/// Longest request line accepted (bytes); longer lines are skipped with a `line_too_long` error.
pub const MAX_LINE_BYTES: usize = 16 << 20;

/// Serves stdin to stdout until end of input.
pub fn run_stdio() -> Result<(), String> {
    // A reader that went away (`hrm eval | head -1`) ends the stream quietly.
    match serve(std::io::stdin().lock(), std::io::stdout().lock()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(format!("eval: {e}")),
        _ => Ok(()),
    }
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
            // The blank lines' whitespace (form feed included, which JSON's is not) may also
            // surround a request.
            answer(line.trim_ascii())
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

fn error_answer(id: Value, error: &EvalError) -> Value {
    let message = lane_math::one_line(&error.message);
    json!({"id": id, "ok": false, "error": {"kind": error.kind.as_str(), "message": message}})
}

/// A JSON value read with every object's keys distinct: `{"op": "fk", "op": "ik"}` is refused
/// ("duplicate key"), as TOML refuses it, rather than the last one silently winning.
struct UniqueKeys(Value);

impl<'de> Deserialize<'de> for UniqueKeys {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer
            .deserialize_any(UniqueKeysVisitor)
            .map(UniqueKeys)
    }
}

/// Builds a [`UniqueKeys`] value.
struct UniqueKeysVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueKeysVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        UniqueKeys::deserialize(d).map(|v| v.0)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(UniqueKeys(item)) = seq.next_element()? {
            items.push(item);
        }
        Ok(Value::Array(items))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut object = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(serde::de::Error::custom(format!(
                    "duplicate key {}",
                    Value::String(key)
                )));
            }
            let UniqueKeys(value) = map.next_value()?;
            object.insert(key, value);
        }
        Ok(Value::Object(object))
    }
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
    let mut request = match serde_json::from_str::<UniqueKeys>(text) {
        Ok(UniqueKeys(Value::Object(map))) => map,
        Ok(_) => {
            return error_answer(
                Value::Null,
                &EvalError::new(Kind::InvalidRequest, "a request must be a JSON object"),
            );
        }
        Err(_) if text.starts_with('\u{feff}') => {
            return error_answer(
                Value::Null,
                &EvalError::new(
                    Kind::Parse,
                    "malformed JSON: the line starts with a byte-order mark (U+FEFF), which a \
                     JSON-lines request does not hold: write UTF-8 without a BOM",
                ),
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
    // The fields the user gave, for a computation that failed numerically (a result that
    // overflowed, a matrix singular in double precision): no one of them alone is at fault, so
    // the message names them all.
    let given: Vec<String> = request.keys().filter(|k| *k != "op").cloned().collect();
    let result = match request.remove("op") {
        Some(Value::String(op)) => dispatch(&op, request).map_err(|mut error| {
            if error.kind == Kind::Library(ErrorClass::Numerical) {
                error.message = format!(
                    "{} (computed from the request's {})",
                    error.message,
                    given.join(", ")
                );
            }
            error
        }),
        Some(_) => Err(EvalError::new(
            Kind::InvalidRequest,
            "\"op\" must be a string",
        )),
        None => Err(EvalError::new(Kind::InvalidRequest, "missing \"op\"")),
    };
    match result {
        Ok(mut fields) => {
            fields.insert("id".to_string(), id.unwrap_or(Value::Null));
            fields.insert("ok".to_string(), Value::Bool(true));
            Value::Object(fields)
        }
        Err(error) => error_answer(id.unwrap_or(Value::Null), &error),
    }
}

const OPS: &str = "fk, ik, joints, dynamics, reduced, fuzzy, rnea_derivatives, aba_derivatives, reduced_derivatives, frames, export";

fn dispatch(op: &str, request: Map<String, Value>) -> EvalResult {
    request::check_rates(&request)?;
    request::check_arm_kind(&request)?;
    // `"urdf"` in place of `"arm"`: the spatial chain of a robot description.
    let urdf = request.contains_key("urdf");
    if spatial::is_spatial(&request) {
        request::check_angles(&request, "a")?;
        return spatial::dispatch(op, request);
    }
    if !urdf {
        request::check_angles(&request, "theta")?;
    }
    match op {
        "dynamics" if urdf => robot::dynamics(parse(request)?),
        "rnea_derivatives" if urdf => robot::rnea_derivatives(parse(request)?),
        "aba_derivatives" if urdf => robot::aba_derivatives(parse(request)?),
        "frames" => robot::frames(parse(request)?),
        "export" => robot::export(parse(request)?),
        "fk" => fk(parse(request)?),
        "ik" => ik(parse(request)?),
        "joints" => joints(parse(request)?),
        "dynamics" => dynamics(parse(request)?),
        "reduced" => reduced(parse(request)?),
        "fuzzy" => fuzzy(parse(request)?),
        "rnea_derivatives" => derivatives::rnea_derivatives(parse(request)?),
        "aba_derivatives" => derivatives::aba_derivatives(parse(request)?),
        "reduced_derivatives" => derivatives::reduced_derivatives(parse(request)?),
        other => Err(EvalError::new(
            Kind::UnknownOp,
            format!("unknown op {other:?}; known ops: {OPS}"),
        )),
    }
}

/// Most harmonics an `ik` request may ask for: its solvers evaluate the end point and its
/// Jacobian up to 100 times, for the curve and for the chain.
const MAX_IK_HARMONICS: usize = 8;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FkRequest {
    #[serde(default, deserialize_with = "arm_object")]
    arm: ArmSpec,
    a: Vec<f64>,
    alpha0: Option<f64>,
    harmonics: Option<usize>,
}

/// `fk`: the end point of the backbone curve (closed form, eqs 3-4, for `K = 1`; quadrature for
/// `K > 1`) and the tip of the discrete chain whose joint angles follow the curve (eq 7).
fn fk(mut request: FkRequest) -> EvalResult {
    let chain = request.arm.to_chain()?;
    let map = modal_map(&chain, &mut request.a, request.alpha0, request.harmonics)?;
    let modes = &request.a[..2 * map.harmonics()];
    let alpha0 = match map.base_angle() {
        BaseAngle::Fixed(alpha0) => alpha0,
        BaseAngle::Free => request.a[2 * map.harmonics()],
    };
    let length = chain.total_length();
    // The closed form takes any amplitude; quadrature refuses amplitudes it cannot resolve.
    let tip = match *modes {
        [a1, a2] => end_point(length, [a1, a2], alpha0).map_err(EvalError::from),
        _ => BackboneCurve::new(length, modes, alpha0)
            .map(|curve| curve.end_point())
            .map_err(curve_error),
    }?;
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&request.a, &mut theta)?;
    finite("theta", &theta)?;
    let lengths: Vec<f64> = chain.link_lengths().collect();
    // Finite joint angles can still sum past double precision: the chain's absolute angles.
    let tip_chain =
        tip_position(&lengths, &theta).map_err(|e| EvalError::input(format!("a: {e}")))?;
    finite("tip", &[tip[0], tip[1], tip_chain[0], tip_chain[1]])?;
    Ok(json_fields([
        ("tip", json!(tip)),
        ("tip_chain", json!(tip_chain)),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IkRequest {
    #[serde(default, deserialize_with = "arm_object")]
    arm: ArmSpec,
    /// Read whole: serde's `[f64; 2]` says "expected fewer elements in array" of three.
    target: Vec<f64>,
    alpha0: f64,
    harmonics: Option<usize>,
    guess: Option<Vec<f64>>,
}

/// `ik`: modal coordinates whose curve ends on the target (`a`) and whose discrete chain does
/// (`a_chain`). Without a guess both start from the closed form (eqs 5-6, branch `a1 >= 0`,
/// higher harmonics zero): `a` is the closed form itself for `K = 1` and its refinement by
/// [`HarmonicIk`] for `K > 1`; `a_chain` is [`ChainIk`]'s refinement. With `"guess"` (`2K`
/// entries) both solvers start there instead, which reaches targets off the closed form's first
/// branch of `J0`.
fn ik(request: IkRequest) -> EvalResult {
    let target: [f64; 2] = request.target.as_slice().try_into().map_err(|_| {
        EvalError::new(
            Kind::InvalidRequest,
            format!(
                "target must have 2 entries [x, y] (a planar arm), got {}",
                request.target.len()
            ),
        )
    })?;
    let chain = request.arm.to_chain()?;
    let k = harmonics(request.harmonics, MAX_IK_HARMONICS)?;
    let (length, alpha0) = (chain.total_length(), reduce_angle(request.alpha0));
    let lengths: Vec<f64> = chain.link_lengths().collect();
    let guessed = request.guess.is_some();
    // Where both solvers start: the guess, or the closed form padded with zeros (`None` when
    // the closed form's branch misses a target a K-harmonic curve may still reach).
    let start = match request.guess {
        Some(guess) if guess.len() == 2 * k => {
            if let Some(x) = guess.iter().find(|x| x.abs() > MAX_IK_GUESS) {
                return Err(EvalError::input(format!(
                    "guess entries must lie within [-{MAX_IK_GUESS}, {MAX_IK_GUESS}] rad, got {x:e}"
                )));
            }
            Some(guess)
        }
        Some(guess) => {
            return Err(EvalError::input(format!(
                "guess has {} entries, expected 2K = {} (K = {k} harmonics)",
                guess.len(),
                2 * k
            )));
        }
        None => match inverse_kinematics(length, target, alpha0, Branch::Positive) {
            Ok(closed) => {
                let mut start = vec![0.0; 2 * k];
                start[..2].copy_from_slice(&closed);
                Some(start)
            }
            Err(error)
                if k > 1
                    && error.is_unreachable()
                    && !matches!(error, KinError::OutOfReach { .. }) =>
            {
                None
            }
            Err(error) => return Err(error.into()),
        },
    };
    let mut a = start.clone().unwrap_or_else(|| vec![0.0; 2 * k]);
    if guessed {
        HarmonicIk::new(length, k, alpha0).and_then(|mut solver| solver.solve(target, &mut a))?;
    } else if k > 1 {
        // From the closed form, then (if it misses or does not converge) the other branch and a
        // list of moderate curves: the answer of Python's `ReducedModel.ik`.
        HarmonicIk::new(length, k, alpha0)
            .and_then(|mut solver| solver.solve_unguided(target, Branch::Positive, &mut a))?;
    }
    // The chain starts where the curve did, or on the curve's solution when the closed form
    // had no answer.
    let start = start.unwrap_or_else(|| a.clone());
    finite("a", &a)?;
    let mut a_chain = start;
    match ChainIk::new(&lengths, k, alpha0)
        .and_then(|mut solver| solver.solve(target, &mut a_chain))
    {
        Ok(_) => {
            finite("a_chain", &a_chain)?;
            Ok(json_fields([("a", json!(a)), ("a_chain", json!(a_chain))]))
        }
        // The curve's answer stands on its own: a chain that cannot reach the target on this
        // family (or a polish that stalls) loses only `a_chain`, with the reason.
        Err(error) if error.is_numerical() => Ok(json_fields([
            ("a", json!(a)),
            ("a_chain", Value::Null),
            ("a_chain_error", json!(error.to_string())),
        ])),
        Err(error) => Err(error.into()),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointsRequest {
    #[serde(default, deserialize_with = "arm_object")]
    arm: ArmSpec,
    a: Vec<f64>,
    alpha0: Option<f64>,
    harmonics: Option<usize>,
}

/// `joints`: joint angles `theta = J a (+ alpha0 e_1)` and the `n x m` modal Jacobian (eqs 7-9).
fn joints(mut request: JointsRequest) -> EvalResult {
    let chain = request.arm.to_chain()?;
    let map = modal_map(&chain, &mut request.a, request.alpha0, request.harmonics)?;
    let mut theta = vec![0.0; map.n_joints()];
    map.joint_angles(&request.a, &mut theta)?;
    finite("theta", &theta)?;
    let jacobian: Vec<&[f64]> = (0..map.n_joints()).map(|i| map.row(i)).collect();
    Ok(json_fields([
        ("theta", json!(theta)),
        ("jacobian", json!(jacobian)),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DynamicsRequest {
    #[serde(default, deserialize_with = "arm_object")]
    arm: ArmSpec,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
}

/// `dynamics`: `M(theta)`, the Coriolis/centrifugal vector `C(theta, theta_dot)` and `G(theta)` of eq 12.
fn dynamics(request: DynamicsRequest) -> EvalResult {
    let chain = request.arm.to_chain()?;
    let n = chain.n_links();
    if n > manip_dyn::MAX_DENSE_LINKS {
        return Err(EvalError::input(format!(
            "arm.links must be at most {} for the dynamics op (an n x n mass matrix), got {n}",
            manip_dyn::MAX_DENSE_LINKS
        )));
    }
    derivatives::joint_vectors(
        n,
        "link",
        &[("theta", &request.theta), ("theta_dot", &request.theta_dot)],
    )?;
    let mut data = ChainData::new(&chain);
    let mut mass = Mat::<f64>::zeros(n, n);
    let (mut coriolis, mut gravity) = (vec![0.0; n], vec![0.0; n]);
    manip_dyn::mass_matrix(&chain, &mut data, &request.theta, mass.as_mut())?;
    manip_dyn::coriolis(
        &chain,
        &mut data,
        &request.theta,
        &request.theta_dot,
        &mut coriolis,
    )?;
    manip_dyn::gravity(&chain, &mut data, &request.theta, &mut gravity)?;
    finite("coriolis", &coriolis)?;
    finite("gravity", &gravity)?;
    Ok(json_fields([
        (
            "mass_matrix",
            derivatives::rows("mass_matrix", mass.as_ref())?,
        ),
        ("coriolis", json!(coriolis)),
        ("gravity", json!(gravity)),
    ]))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ReducedRequest {
    #[serde(default, deserialize_with = "arm_object")]
    arm: ArmSpec,
    a: Vec<f64>,
    a_dot: Vec<f64>,
    tau_star: Vec<f64>,
    alpha0: Option<f64>,
    harmonics: Option<usize>,
}

/// `reduced`: the reduced model `M*`, `C*`, `G*` (eqs 13-15), the modal accelerations for the
/// given `tau*`, and the joint torques `tau = M J a_ddot + C + G` that realise them.
fn reduced(mut request: ReducedRequest) -> EvalResult {
    let chain = request.arm.to_chain()?;
    let map = modal_map(&chain, &mut request.a, request.alpha0, request.harmonics)?;
    let (n, m) = (map.n_joints(), map.n_coords());
    let model = ReducedModel::new(chain, map)?;
    let mut data = ReducedData::new(&model);
    let (mut a_ddot, mut torques) = (vec![0.0; m], vec![0.0; n]);
    modal_reduce::forward_dynamics(
        &model,
        &mut data,
        &request.a,
        &request.a_dot,
        &request.tau_star,
        &mut a_ddot,
    )?;
    let mass = derivatives::rows("mass_matrix", data.mass_matrix())?;
    let (coriolis, gravity) = (data.coriolis().to_vec(), data.gravity().to_vec());
    modal_reduce::joint_torques(
        &model,
        &mut data,
        &request.a,
        &request.a_dot,
        &a_ddot,
        &mut torques,
    )?;
    for (name, values) in [
        ("coriolis", &coriolis),
        ("gravity", &gravity),
        ("a_ddot", &a_ddot),
        ("joint_torques", &torques),
    ] {
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FuzzyRequest {
    controller: Option<String>,
    fis: Option<String>,
    inputs: Vec<f64>,
    /// `"as-given"` (the default, MATLAB's evalfis), `"clamp"` or `"error"`.
    #[serde(default)]
    out_of_range: Option<String>,
}

/// `fuzzy`: the outputs of the paper's controller (eqs 19-24), or of a system given as `.fis` text.
fn fuzzy(request: FuzzyRequest) -> EvalResult {
    let system = match (request.controller.as_deref(), request.fis) {
        (Some("paper"), None) => fuzzy_sugeno::paper_controller(),
        (Some(other), None) => {
            return Err(EvalError::input(format!(
                "unknown controller {other:?}; known: \"paper\""
            )));
        }
        (None, Some(text)) => FuzzySystem::from_fis(&text)?,
        _ => {
            return Err(EvalError::new(
                Kind::InvalidRequest,
                "give exactly one of \"controller\" and \"fis\"",
            ));
        }
    };
    let out_of_range = match request.out_of_range.as_deref() {
        None | Some("as-given") => fuzzy_sugeno::OutOfRange::AsGiven,
        Some("clamp") => fuzzy_sugeno::OutOfRange::Clamp,
        Some("error") => fuzzy_sugeno::OutOfRange::Error,
        Some(other) => {
            return Err(EvalError::input(format!(
                "out_of_range {other:?}: expected \"as-given\", \"clamp\" or \"error\""
            )));
        }
    };
    let options = fuzzy_sugeno::EvalOptions {
        out_of_range,
        ..fuzzy_sugeno::EvalOptions::default()
    };
    let mut evaluator = fuzzy_sugeno::Evaluator::with_options(system, options)?;
    let expected = evaluator.system().inputs().len();
    if request.inputs.len() != expected {
        return Err(EvalError::input(format!(
            "inputs has {} entries, expected {expected} (one per input of the system)",
            request.inputs.len()
        )));
    }
    let mut outputs = vec![0.0; evaluator.system().outputs().len()];
    evaluator.eval(&request.inputs, &mut outputs)?;
    crate::fis_cmd::warn_outside_range(&evaluator, &request.inputs, "\"out_of_range\": \"clamp\"");
    finite("outputs", &outputs)?;
    Ok(json_fields([("outputs", json!(outputs))]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use backbone_kin::ModalMap;

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
        // An id is echoed as read: a number as the double it is (docs/eval-protocol.md).
        let ids = run(
            b"{\"id\":12345678901234567890123,\"op\":\"x\"}\n{\"id\":1.0e2,\"op\":\"x\"}\n\
            {\"id\":\"run 7\",\"op\":\"x\"}\n",
        );
        assert_eq!(ids[0]["id"].as_f64(), Some(1.2345678901234568e22));
        assert_eq!(ids[1]["id"].to_string(), "100.0");
        assert_eq!(ids[2]["id"], "run 7");
        // The blank lines' whitespace around a request, form feed included (not JSON's).
        let fed = run(b"\x0c {\"id\":10,\"op\":\"joints\",\"a\":[0.1,0.2,0.3]}\x0c\t\n\x0c\n");
        assert_eq!(fed.len(), 1);
        assert_eq!(fed[0]["ok"], true, "{}", fed[0]);
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
    fn fk_and_ik_invert_each_other_and_report_unreachable_targets() {
        let answers = run(
            b"{\"id\":1,\"op\":\"ik\",\"target\":[0.3,0.5],\"alpha0\":1.5707963267948966}\n\
            {\"id\":2,\"op\":\"ik\",\"target\":[1.2,0.5],\"alpha0\":0}\n\
            {\"id\":3,\"op\":\"fk\",\"a\":[0.0,0.0],\"alpha0\":0.5}\n",
        );
        let a: [f64; 2] = serde_json::from_value(answers[0]["a"].clone()).unwrap();
        assert!(a[0] >= 0.0);
        let fk = format!(
            "{{\"op\":\"fk\",\"a\":[{},{}],\"alpha0\":1.5707963267948966}}\n",
            a[0], a[1]
        );
        let tip: [f64; 2] = serde_json::from_value(run(fk.as_bytes())[0]["tip"].clone()).unwrap();
        approx::assert_abs_diff_eq!(tip[0], 0.3, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(tip[1], 0.5, epsilon = 1e-12);
        assert_eq!(answers[1]["error"]["kind"], "unreachable");
        // A straight arm: both tips at distance l = 1 along alpha0.
        for key in ["tip", "tip_chain"] {
            let tip: [f64; 2] = serde_json::from_value(answers[2][key].clone()).unwrap();
            approx::assert_abs_diff_eq!(tip[0], 0.5f64.cos(), epsilon = 1e-14);
            approx::assert_abs_diff_eq!(tip[1], 0.5f64.sin(), epsilon = 1e-14);
        }
    }

    fn vector(value: &Value) -> Vec<f64> {
        serde_json::from_value(value.clone()).unwrap()
    }

    #[test]
    fn dynamics_of_one_link_is_a_pendulum() {
        // One uniform beam of 0.1 m, 0.1 kg: M = m L^2 / 3, C = 0, G = m g (L/2) cos(theta).
        let answers = run(
            b"{\"op\":\"dynamics\",\"arm\":{\"links\":1},\"theta\":[0.3],\"theta_dot\":[2.0]}\n",
        );
        approx::assert_relative_eq!(
            answers[0]["mass_matrix"][0][0].as_f64().unwrap(),
            0.1 * 0.01 / 3.0,
            max_relative = 1e-14
        );
        approx::assert_abs_diff_eq!(
            answers[0]["coriolis"][0].as_f64().unwrap(),
            0.0,
            epsilon = 1e-15
        );
        approx::assert_relative_eq!(
            answers[0]["gravity"][0].as_f64().unwrap(),
            0.1 * 9.81 * 0.05 * 0.3f64.cos(),
            max_relative = 1e-14
        );
    }

    #[test]
    fn reduced_torques_project_back_to_tau_star() {
        let request = b"{\"op\":\"reduced\",\"a\":[0.4,-0.3,1.2],\"a_dot\":[0.5,1.0,-0.2],\"tau_star\":[0.3,-0.1,0.2]}\n";
        let answer = &run(request)[0];
        let torques = vector(&answer["joint_torques"]);
        let map = ModalMap::paper(10).unwrap();
        for (j, expected) in [0.3, -0.1, 0.2].into_iter().enumerate() {
            let projected: f64 = (0..10).map(|i| map.entry(i, j) * torques[i]).sum();
            approx::assert_abs_diff_eq!(projected, expected, epsilon = 1e-12);
        }
        assert_eq!(answer["mass_matrix"].as_array().unwrap().len(), 3);
        // Two coordinates with alpha0 fixed, and the refusal of a mismatched tau_star.
        let two = b"{\"op\":\"reduced\",\"a\":[0.4,-0.3],\"alpha0\":1.2,\"a_dot\":[0,0],\"tau_star\":[0,0]}\n\
            {\"op\":\"reduced\",\"a\":[0.4,-0.3],\"alpha0\":1.2,\"a_dot\":[0,0],\"tau_star\":[0]}\n";
        let answers = run(two);
        assert_eq!(vector(&answers[0]["a_ddot"]).len(), 2);
        assert_eq!(answers[1]["error"]["kind"], "invalid_input");
    }

    /// An input outside its range is evaluated as given by default (MATLAB's evalfis: 75.93
    /// for tau1 at the paper's point, by the formula of eq 21), clamped on request (71.32).
    #[test]
    fn fuzzy_inputs_outside_their_ranges_as_given_unless_clamped() {
        let point = "[-0.414,-0.263,0.904,0.246]";
        let input = format!(
            "{{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":{point}}}\n\
            {{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":{point},\"out_of_range\":\"clamp\"}}\n\
            {{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":{point},\"out_of_range\":\"error\"}}\n\
            {{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":{point},\"out_of_range\":\"wrap\"}}\n"
        );
        let answers = run(input.as_bytes());
        approx::assert_abs_diff_eq!(vector(&answers[0]["outputs"])[0], 75.933, epsilon = 1e-3);
        approx::assert_abs_diff_eq!(vector(&answers[1]["outputs"])[0], 71.321, epsilon = 1e-3);
        assert_eq!(answers[2]["error"]["kind"], "invalid_input");
        assert_eq!(answers[3]["error"]["kind"], "invalid_input");
    }

    #[test]
    fn fuzzy_paper_controller_and_fis_text_agree() {
        let fis = include_str!("../../fuzzy-sugeno/data/paper.fis");
        let request = json!({"op": "fuzzy", "fis": fis, "inputs": [0.1, -0.2, 0.3, 0.5]});
        let input = format!(
            "{{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":[0.1,-0.2,0.3,0.5]}}\n{request}\n\
            {{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":[0,0,0,0]}}\n\
            {{\"op\":\"fuzzy\",\"controller\":\"paper\",\"inputs\":[0,0]}}\n"
        );
        let answers = run(input.as_bytes());
        let (preset, loaded) = (
            vector(&answers[0]["outputs"]),
            vector(&answers[1]["outputs"]),
        );
        assert_eq!(preset.len(), 2);
        for (p, l) in preset.iter().zip(&loaded) {
            approx::assert_abs_diff_eq!(p, l, epsilon = 1e-12);
        }
        // da1 > 0 with a1 rising: the controller pushes a1 back (measured minus desired, notes).
        assert!(preset[0] < 0.0);
        for out in vector(&answers[2]["outputs"]) {
            approx::assert_abs_diff_eq!(out, 0.0, epsilon = 1e-12);
        }
        assert_eq!(answers[3]["error"]["kind"], "invalid_input");
    }

    #[test]
    fn arm_errors_name_the_offending_link() {
        let answers = run(b"{\"id\":\"x\",\"op\":\"joints\",\"arm\":{\"masses\":[0.1,-1]},\"a\":[0,0],\"alpha0\":1}\n");
        assert_eq!(answers[0]["error"]["kind"], "invalid_input");
        assert_eq!(
            answers[0]["error"]["message"],
            "arm.masses[1] is invalid: link 1: mass must be positive and finite, got -1"
        );
        assert_eq!(answers[0]["id"], "x");
    }

    #[test]
    fn refusals_name_the_request_field() {
        let ten = [0.1; 10];
        for (request, message) in [
            (
                json!({"op": "dynamics", "theta": &ten[..9], "theta_dot": ten}),
                "theta has 9 entries, expected 10 (one per link)",
            ),
            (
                json!({"op": "dynamics", "theta": ten, "theta_dot": [0.1]}),
                "theta_dot has 1 entries, expected 10 (one per link)",
            ),
            (
                json!({"op": "dynamics", "arm": {"links": 2, "inertias": [-1, 0]},
                    "theta": [0.1, 0.1], "theta_dot": [0.1, 0.1]}),
                "arm.inertias[0] is invalid: link 0: inertia must be non-negative and finite, \
                 got -1",
            ),
            // A mode beyond the scale a run resolves (in `J a` it rounds the others away);
            // the base angle is reduced instead (`a_huge_alpha0_gives_the_answer_of_its_angle`).
            (
                json!({"op": "fk", "a": [0, 1e308], "alpha0": 0}),
                "a[1] must be at most 1000000 in magnitude (rad), got 1e308",
            ),
            (
                json!({"op": "joints", "a": [0.1, -1e17, 0.2], "harmonics": 1}),
                "a[1] must be at most 1000000 in magnitude (rad), got -1e17",
            ),
            (
                json!({"op": "fuzzy", "controller": "paper", "inputs": [0.1, 0.1, 0.1]}),
                "inputs has 3 entries, expected 4 (one per input of the system)",
            ),
        ] {
            let answer = self::request(request);
            assert_eq!(answer["error"]["kind"], "invalid_input", "{answer}");
            assert_eq!(answer["error"]["message"], message);
        }
        // A first harmonic at the bound: no quadrature resolves it.
        let answer = request(json!({"op": "fk", "a": [1e6, 2, 3, 4, 5], "harmonics": 2}));
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(
            message.starts_with("a: the curve oscillates too fast")
                && message.contains("an overflowing number of nodes"),
            "{message}"
        );
    }

    #[test]
    fn modal_requests_are_bounded_in_answer_size_and_work() {
        // 130 bytes that used to answer 767 MB (joints) or work seconds (reduced): refused.
        let a = vec![0.0; 128];
        let answer = request(json!({"op": "joints", "arm": {"links": 260_000}, "a": a,
            "alpha0": 1, "harmonics": 64}));
        assert_eq!(answer["error"]["kind"], "invalid_input", "{answer}");
        assert!(
            answer["error"]["message"]
                .as_str()
                .unwrap()
                .contains("at most 4194304 (the n x m modal Jacobian"),
            "{answer}"
        );
        let a = vec![0.0; 32];
        let answer = request(json!({"op": "reduced", "arm": {"links": 100_000}, "a": a,
            "a_dot": a, "tau_star": a, "alpha0": 1, "harmonics": 16}));
        assert!(
            answer["error"]["message"]
                .as_str()
                .unwrap()
                .contains("100000 x 32^2 = 102400000"),
            "{answer}"
        );
        let answer = request(
            json!({"op": "reduced_derivatives", "arm": {"links": 100_000},
            "a": a, "a_dot": a, "tau_star": a, "alpha0": 1, "harmonics": 16}),
        );
        assert_eq!(answer["error"]["kind"], "invalid_input", "{answer}");
    }

    #[test]
    fn duplicate_keys_are_refused_at_any_depth() {
        let answers = run(
            b"{\"op\": \"fk\", \"op\": \"ik\", \"a\": [0, 0], \"alpha0\": 1}\n\
            {\"op\": \"fk\", \"arm\": {\"links\": 3, \"links\": 4}, \"a\": [0, 0], \"alpha0\": 1}\n\
            {\"op\": \"fk\", \"arm\": {\"links\": 3}, \"a\": [0, 0], \"alpha0\": 1}\n",
        );
        for answer in &answers[..2] {
            assert_eq!(answer["error"]["kind"], "parse", "{answer}");
            let message = answer["error"]["message"].as_str().unwrap();
            assert!(message.contains("duplicate key"), "{message}");
        }
        assert!(
            answers[0]["error"]["message"]
                .as_str()
                .unwrap()
                .contains("\"op\"")
        );
        assert!(answers[2].get("error").is_none(), "{}", answers[2]);
    }

    fn request(line: Value) -> Value {
        run(format!("{line}\n").as_bytes()).remove(0)
    }

    fn distance(p: &[f64], q: &[f64]) -> f64 {
        (p[0] - q[0]).hypot(p[1] - q[1])
    }

    #[test]
    fn harmonics_set_the_number_of_coordinates() {
        // K = 2: 4 coordinates with alpha0 given, 5 with alpha0 last; the Jacobian is n x m.
        for (a, alpha0, m) in [
            (json!([0.3, 0.2, 0.1, -0.1]), json!(0.5), 4),
            (json!([0.3, 0.2, 0.1, -0.1, 0.5]), Value::Null, 5),
        ] {
            let mut line = json!({"op": "joints", "a": a, "harmonics": 2});
            if !alpha0.is_null() {
                line["alpha0"] = alpha0;
            }
            let answer = request(line);
            let jacobian = answer["jacobian"].as_array().unwrap();
            assert_eq!(jacobian.len(), 10);
            assert!(
                jacobian
                    .iter()
                    .all(|row| row.as_array().unwrap().len() == m)
            );
            // The tip link's inclination alpha(l - L/2) is the sum of the joint angles.
            let s = 0.95 * std::f64::consts::TAU;
            let alpha = 0.5 + 0.3 * s.sin() + 0.2 * (1.0 - s.cos()) + 0.1 * (2.0 * s).sin()
                - 0.1 * (1.0 - (2.0 * s).cos());
            approx::assert_abs_diff_eq!(
                vector(&answer["theta"]).iter().sum::<f64>(),
                alpha,
                epsilon = 1e-14
            );
        }
        // Wrong counts name both forms; K = 0 and K beyond the limit are refused.
        for line in [
            json!({"op": "joints", "a": [0.1, 0.2, 0.3], "alpha0": 1, "harmonics": 2}),
            json!({"op": "joints", "a": [0.1, 0.2], "alpha0": 1, "harmonics": 0}),
            json!({"op": "joints", "a": [0.1, 0.2], "alpha0": 1, "harmonics": 100_000}),
            json!({"op": "joints", "a": [0.1, 0.2], "alpha0": 1, "harmonics": 65}),
            json!({"op": "ik", "target": [0.3, 0.5], "alpha0": 1, "harmonics": 9}),
            json!({"op": "ik", "target": [0.3, 0.5], "alpha0": 1, "guess": [11.0, 0.0]}),
            json!({"op": "ik", "target": [0.3, 0.5], "alpha0": 1, "guess": [0.0, -1e300]}),
            json!({"op": "fk", "a": [0.1, 0.2, 0.3, 0.4], "harmonics": 2}),
        ] {
            let answer = request(line);
            assert_eq!(answer["error"]["kind"], "invalid_input", "{answer}");
        }
    }

    #[test]
    fn fk_with_more_harmonics_is_the_quadrature_end_point() {
        // Zero higher harmonics: the K = 2 quadrature equals the K = 1 closed form.
        let one = request(json!({"op": "fk", "a": [0.8, -0.4], "alpha0": 0.3}));
        let two = request(json!({"op": "fk", "a": [0.8, -0.4, 0.0, 0.0, 0.3], "harmonics": 2}));
        for key in ["tip", "tip_chain"] {
            let (p, q) = (vector(&one[key]), vector(&two[key]));
            assert!(distance(&p, &q) < 1e-14, "{key}: {p:?} {q:?}");
        }
        // A true second harmonic: the chain follows the curve to the aliasing error.
        let two =
            request(json!({"op": "fk", "a": [0.3, 0.2, 0.1, -0.1], "alpha0": 0.5, "harmonics": 2}));
        let (tip, chain) = (vector(&two["tip"]), vector(&two["tip_chain"]));
        assert!(distance(&tip, &chain) < 1e-6 && distance(&tip, &chain) > 0.0);
    }

    #[test]
    fn ik_from_the_straight_arm_says_no_step_is_defined_there() {
        // The paper's modes move the tip by nothing to first order at a = 0: the answer said
        // "did not converge ... after 0 iterations".
        let answer = request(
            json!({"op": "ik", "arm": {"links": 3}, "target": [0.1, 0.1],
            "alpha0": 0.7, "guess": [0, 0]}),
        );
        assert_eq!(answer["error"]["kind"], "numerical", "{answer}");
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(
            message.starts_with("numerical inverse kinematics cannot move from the guess: ")
                && message.contains("start from another guess"),
            "{message}"
        );
        let moved = request(
            json!({"op": "ik", "arm": {"links": 3}, "target": [0.1, 0.1],
            "alpha0": 0.7, "guess": [0.01, 0]}),
        );
        assert!(moved.get("error").is_none(), "{moved}");
    }

    #[test]
    fn ik_keeps_the_curves_answer_when_the_chain_cannot_follow() {
        // The closed form (eqs 5-6) reaches this target with the curve; the 3-link chain on
        // the K = 1 family misses it by 3e-5 m, which must not take `a` with it.
        let arm = json!({"links": 3, "link_length": 0.0728739, "link_mass": 1.1});
        let target = [-0.063044, -0.107254];
        let answer = request(json!({"op": "ik", "arm": arm, "target": target,
            "alpha0": -0.871704}));
        assert!(answer.get("error").is_none(), "{answer}");
        assert!(answer["a_chain"].is_null(), "{answer}");
        assert!(
            answer["a_chain_error"]
                .as_str()
                .is_some_and(|m| m.contains("did not converge")),
            "{answer}"
        );
        let curve = request(json!({"op": "fk", "arm": arm, "a": answer["a"],
            "alpha0": -0.871704}));
        assert!(distance(&vector(&curve["tip"]), &target) < 1e-15, "{curve}");
    }

    #[test]
    fn ik_puts_the_curve_and_the_chain_on_the_target() {
        let alpha0 = std::f64::consts::FRAC_PI_2;
        let target = [0.3, 0.5];
        let tapered: Vec<f64> = (0..20)
            .map(|i| 0.075 - 0.05 * f64::from(i) / 19.0)
            .collect();
        for (arm, harmonics) in [
            (json!({}), 1),
            (json!({}), 2),
            (json!({"lengths": tapered}), 1),
            (json!({"lengths": tapered}), 2),
        ] {
            let answer = request(json!({"op": "ik", "arm": arm, "target": target,
                "alpha0": alpha0, "harmonics": harmonics}));
            let (a, a_chain) = (answer["a"].clone(), answer["a_chain"].clone());
            assert_eq!(vector(&a).len(), 2 * harmonics, "{answer}");
            let fk = |a: Value| {
                request(json!({"op": "fk", "arm": arm, "a": a, "alpha0": alpha0,
                    "harmonics": harmonics}))
            };
            let curve = fk(a);
            assert!(distance(&vector(&curve["tip"]), &target) < 1e-13, "{curve}");
            let chain = fk(a_chain);
            assert!(
                distance(&vector(&chain["tip_chain"]), &target) < 1e-13,
                "{chain}"
            );
            // With tapered links the curve's solution leaves the chain off the target.
            if arm.get("lengths").is_some() {
                assert!(distance(&vector(&curve["tip_chain"]), &target) > 1e-4);
            }
        }
        // Beyond the first branch of J0: refused by name without a guess, solved with one.
        let target = [0.0, -0.3];
        let refused = request(json!({"op": "ik", "target": target, "alpha0": alpha0}));
        assert_eq!(refused["error"]["kind"], "unreachable");
        assert!(
            refused["error"]["message"]
                .as_str()
                .unwrap()
                .contains("first branch")
        );
        let solved = request(json!({"op": "ik", "target": target, "alpha0": alpha0,
            "guess": [3.0, 0.2]}));
        let fk = request(json!({"op": "fk", "a": solved["a"], "alpha0": alpha0}));
        assert!(distance(&vector(&fk["tip"]), &target) < 1e-13, "{fk}");
        let wrong = request(json!({"op": "ik", "target": target, "alpha0": alpha0,
            "guess": [3.0]}));
        assert_eq!(wrong["error"]["kind"], "invalid_input");
        // A two-harmonic curve's tip that the closed form's branch misses (|a2| > A): found
        // without a guess by the unguided solver's other starts, as Python's `ik` finds it.
        let alpha0 = 1.9686465720275468;
        let tip = request(
            json!({"op": "fk", "a": [0.1, -0.45, -0.2, -0.9], "alpha0": alpha0,
            "harmonics": 2}),
        )["tip"]
            .clone();
        let solved = request(json!({"op": "ik", "target": tip, "alpha0": alpha0, "harmonics": 2}));
        assert_eq!(solved["ok"], true, "{solved}");
        let fk = request(json!({"op": "fk", "a": solved["a"], "alpha0": alpha0, "harmonics": 2}));
        assert!(distance(&vector(&fk["tip"]), &vector(&tip)) < 1e-13, "{fk}");
        let fk = request(json!({"op": "fk", "a": solved["a_chain"], "alpha0": alpha0,
            "harmonics": 2}));
        assert!(
            distance(&vector(&fk["tip_chain"]), &vector(&tip)) < 1e-13,
            "{fk}"
        );
    }

    #[test]
    fn reduced_works_for_any_number_of_coordinates() {
        let line = json!({"op": "reduced", "harmonics": 2, "a": [0.1, 0.2, 0.1, 0.1, 0.3],
            "a_dot": [0.2, -0.1, 0.3, 0.0, 0.5], "tau_star": [0.3, -0.1, 0.2, 0.05, -0.2]});
        let answer = request(line);
        assert_eq!(answer["mass_matrix"].as_array().unwrap().len(), 5);
        let torques = vector(&answer["joint_torques"]);
        let map = ModalMap::uniform(10, 2, BaseAngle::Free).unwrap();
        for (j, expected) in [0.3, -0.1, 0.2, 0.05, -0.2].into_iter().enumerate() {
            let projected: f64 = (0..10).map(|i| map.entry(i, j) * torques[i]).sum();
            approx::assert_abs_diff_eq!(projected, expected, epsilon = 1e-12);
        }
    }

    #[test]
    fn overflow_is_numerical_and_a_non_object_arm_is_refused() {
        let answer = request(
            json!({"op": "dynamics", "arm": {"links": 2, "link_mass": 1e300}, "theta": [0.1, 0.2],
            "theta_dot": [1e6, 1e6]}),
        );
        assert_eq!(answer["error"]["kind"], "numerical", "{answer}");
        for arm in [json!([10]), json!(5), json!("paper"), json!(null)] {
            let answer = request(json!({"op": "joints", "arm": arm, "a": [0, 0, 0]}));
            assert_eq!(answer["error"]["kind"], "invalid_request", "{answer}");
            assert!(
                answer["error"]["message"]
                    .as_str()
                    .unwrap()
                    .contains("\"arm\" must be an object"),
                "{answer}"
            );
        }
    }

    #[test]
    fn type_errors_name_the_json_path_of_the_field() {
        for (line, message) in [
            (
                json!({"op": "joints", "arm": {"links": -1}, "a": [0, 0, 0]}),
                "arm.links: invalid value: integer `-1`, expected usize",
            ),
            (
                json!({"op": "fk", "arm": {"link_length": "x"}, "a": [0, 0], "alpha0": 0}),
                "arm.link_length: invalid type: string \"x\", expected f64",
            ),
            (
                json!({"op": "dynamics", "theta": [1, "a"], "theta_dot": [0, 0]}),
                "theta[1]: invalid type: string \"a\", expected f64",
            ),
            (
                json!({"op": "fk", "a": ["NaN", 0], "alpha0": 0}),
                "a[0]: invalid type: string \"NaN\", expected f64",
            ),
            (
                json!({"op": "fk", "arm": {"kind": "spatial", "links": "3"}, "a": [0, 0]}),
                "arm.links: invalid type: string \"3\", expected usize",
            ),
            (
                json!({"op": "joints", "arm": {"links": 3, "colour": 1}, "a": [0, 0, 0]}),
                "arm.colour: unknown field `colour`",
            ),
            // Messages that name their field already, or are about the request as a whole,
            // pass unchanged.
            (
                json!({"op": "joints", "arm": [10], "a": [0, 0, 0]}),
                "\"arm\" must be an object of arm fields, got an array",
            ),
            (json!({"op": "fk", "alpha0": 0}), "missing field `a`"),
            (
                json!({"op": "ik", "target": [0.3, 0.5, 0.0], "alpha0": 1.57}),
                "target must have 2 entries [x, y] (a planar arm), got 3",
            ),
        ] {
            let answer = request(line.clone());
            assert_eq!(
                answer["error"]["kind"], "invalid_request",
                "{line} -> {answer}"
            );
            let got = answer["error"]["message"].as_str().unwrap();
            assert!(got.starts_with(message), "{line} -> {got}");
            assert!(!got.contains('\u{1}'), "{line} -> {got:?}");
        }
    }

    #[test]
    fn an_overflowing_result_is_numerical_in_every_dynamics_op() {
        // Finite inputs whose result overflows: the library's NonFiniteResult, classified by
        // its is_numerical(), for the full chain and for the reduced model alike.
        // The message names the request's fields it was computed from.
        for (line, fields) in [
            (
                json!({"op": "aba_derivatives", "arm": {"link_mass": 1e200},
                    "theta": vec![0.1; 10], "theta_dot": vec![0.1; 10], "tau": vec![0.1; 10]}),
                "(computed from the request's arm, tau, theta, theta_dot)",
            ),
            (
                json!({"op": "reduced", "a": [0.1, 0.2, 0.3], "a_dot": [0.0, 0.0, 0.0],
                    "tau_star": [1e308, 0.0, 0.0]}),
                "(computed from the request's a, a_dot, tau_star)",
            ),
        ] {
            let answer = request(line);
            assert_eq!(answer["error"]["kind"], "numerical", "{answer}");
            let message = answer["error"]["message"].as_str().unwrap();
            assert!(message.contains("finite"), "{answer}");
            assert!(message.ends_with(fields), "{answer}");
        }
        // The accelerations by the request's name, not the library's `qdd`.
        let answer = request(json!({"op": "aba_derivatives", "arm": {"links": 3},
            "theta": [0, 1, 0.5], "theta_dot": [0, 0, 0], "tau": [1e308, -1e308, 1e308]}));
        let message = answer["error"]["message"].as_str().unwrap();
        assert!(message.starts_with("theta_ddot is not finite"), "{answer}");
    }

    #[test]
    fn rates_beyond_what_a_run_resolves_are_refused_by_name() {
        // 1e300 rad/s overflowed the Coriolis terms and was reported by their internal names.
        for (line, message) in [
            (
                json!({"op": "dynamics", "theta": vec![0.1; 10], "theta_dot": [0, 1e300, 0, 0, 0, 0, 0, 0, 0, 0]}),
                "theta_dot[1] must be at most 1000000 in magnitude (rad/s, m/s for a prismatic joint), got 1e300",
            ),
            (
                json!({"op": "dynamics", "arm": {"links": 3}, "theta": [1e17, 1.0, 0.5],
                    "theta_dot": [0, 0, 0]}),
                "theta[0] must be at most 1000000 in magnitude (rad), got 1e17",
            ),
            (
                json!({"op": "reduced_derivatives", "a": [0.1, 0.2, 0.3], "a_dot": [-2e6, 0, 0],
                    "tau_star": [0, 0, 0]}),
                "a_dot[0] must be at most 1000000 in magnitude",
            ),
            (
                json!({"op": "reduced", "arm": {"kind": "spatial"}, "a": [0.1, 0.2, 0.1, 0.2],
                    "a_dot": [1e154, 0, 0, 0], "tau_star": [0, 0, 0, 0]}),
                "a_dot[0] must be at most 1000000 in magnitude",
            ),
        ] {
            let answer = request(line);
            assert_eq!(answer["error"]["kind"], "invalid_input", "{answer}");
            assert!(
                answer["error"]["message"]
                    .as_str()
                    .unwrap()
                    .starts_with(message),
                "{answer}"
            );
        }
        // A planar arm's angles at the bound: the mass matrix depends on the relative angles
        // alone, as the straight-started one says.
        let mass = |theta: [f64; 3]| {
            request(
                json!({"op": "dynamics", "arm": {"links": 3}, "theta": theta,
                "theta_dot": [0, 0, 0]}),
            )["mass_matrix"]
                .clone()
        };
        let (far, near) = (mass([1e6, 1.0, 0.5]), mass([0.0, 1.0, 0.5]));
        for (row_far, row_near) in far.as_array().unwrap().iter().zip(near.as_array().unwrap()) {
            for (x, y) in row_far
                .as_array()
                .unwrap()
                .iter()
                .zip(row_near.as_array().unwrap())
            {
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                assert!((x - y).abs() < 1e-9 * y.abs().max(1e-3), "{far} {near}");
            }
        }
        // At the bound the answer is finite.
        let answer = request(json!({"op": "aba_derivatives", "theta": vec![0.1; 10],
            "theta_dot": vec![1e6; 10], "tau": vec![0.0; 10]}));
        assert_eq!(answer["ok"], true, "{answer}");
    }

    #[test]
    fn a_huge_alpha0_gives_the_answer_of_its_angle() {
        // alpha0 only turns the whole arm: every tip is the alpha0 = 0 tip rotated by
        // (cos alpha0, sin alpha0), whose argument reduction libm does exactly.
        let huge = 1e20f64;
        let (sin, cos) = huge.sin_cos();
        let base = request(json!({"op": "fk", "a": [0.7, 0.2], "alpha0": 0.0}));
        for line in [
            json!({"op": "fk", "a": [0.7, 0.2], "alpha0": huge}),
            json!({"op": "fk", "a": [0.7, 0.2, huge]}),
        ] {
            let turned = request(line);
            for key in ["tip", "tip_chain"] {
                let (p, q) = (vector(&base[key]), vector(&turned[key]));
                let rotated = [cos * p[0] - sin * p[1], sin * p[0] + cos * p[1]];
                assert!(distance(&rotated, &q) < 1e-15, "{key}: {rotated:?} {q:?}");
            }
        }
        // The joint angles keep their modal part: theta_1 - alpha0 is the same.
        let base = request(json!({"op": "joints", "a": [0.7, 0.2], "alpha0": 0.0}));
        let turned = request(json!({"op": "joints", "a": [0.7, 0.2], "alpha0": huge}));
        let (p, q) = (vector(&base["theta"]), vector(&turned["theta"]));
        assert_eq!(p[1..], q[1..]);
        let offset = q[0] - p[0];
        assert!((offset.cos() - cos).abs() < 1e-15 && (offset.sin() - sin).abs() < 1e-15);
        // And ik answers as for the reduced angle.
        let target = [cos * 0.5 - sin * 0.3, sin * 0.5 + cos * 0.3];
        let ik = request(json!({"op": "ik", "target": target, "alpha0": huge}));
        let fk = request(json!({"op": "fk", "a": ik["a"], "alpha0": huge}));
        assert!(distance(&vector(&fk["tip"]), &target) < 1e-13, "{ik} {fk}");
    }
}
