//! What every op of `hrm eval` shares: the kind and message of a failed request, a request's
//! fields read with the JSON path of the one at fault, `"arm"` objects, the modal map of a
//! request's coordinates, and the checks and layout of an answer.

use backbone_kin::{BaseAngle, KinError, ModalMap, reduce_angle};
use lane_math::{Classify, ErrorClass};
use manip_dyn::ChainModel;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer};
use serde_json::{Map, Value};
use sim_study::ArmSpec;

/// The category of a failed request, the `kind` field of an error answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
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
    /// A library's refusal, in the library's own class (`docs/eval-protocol.md`: well-formed but
    /// outside the model's domain, a target the curve cannot reach, a computation that failed
    /// numerically).
    Library(ErrorClass),
}

impl Kind {
    pub(super) fn as_str(self) -> &'static str {
        match self {
            Kind::InvalidUtf8 => "invalid_utf8",
            Kind::Parse => "parse",
            Kind::LineTooLong => "line_too_long",
            Kind::InvalidRequest => "invalid_request",
            Kind::UnknownOp => "unknown_op",
            Kind::Library(class) => class.name(),
        }
    }
}

/// A failed request: its kind and a readable message.
#[derive(Debug)]
pub(super) struct EvalError {
    pub(super) kind: Kind,
    pub(super) message: String,
}

impl EvalError {
    pub(super) fn new(kind: Kind, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
        }
    }

    pub(super) fn input(message: impl ToString) -> Self {
        Self::new(Kind::Library(ErrorClass::InvalidInput), message.to_string())
    }
}

/// A library error as an answer: its kind the error's [`ErrorClass`], its message the error's
/// text.
impl<E: Classify + std::fmt::Display> From<E> for EvalError {
    fn from(error: E) -> Self {
        Self::new(Kind::Library(error.class()), error.to_string())
    }
}

pub(super) type EvalResult = Result<Map<String, Value>, EvalError>;

/// Deserialises the request's remaining fields into the op's typed request; serde's own type
/// errors name the JSON path of the field they are about (`arm.links: invalid type: ...`).
pub(super) fn parse<T: DeserializeOwned>(request: Map<String, Value>) -> Result<T, EvalError> {
    from_object(request).map_err(|e| EvalError::new(Kind::InvalidRequest, e))
}

/// Deserialises an object; an error's message gets the path of the field it is about in front
/// when [`located`] finds one.
pub(super) fn from_object<T: DeserializeOwned>(object: Map<String, Value>) -> Result<T, String> {
    located(object).map_err(|(path, message)| match path {
        Some(path) => format!("{path}: {message}"),
        None => message,
    })
}

/// Deserialises an object, answering an error as the dotted JSON path of the offending field
/// (`theta[1]`, `arm.links`) and the message. Serde's own messages ([`SERDE_MESSAGES`]) name no
/// field and get the path; the project's own messages name their field already and get none. A
/// nested object's error (see [`arm_object`]) carries its inner path behind [`NESTED_PATH`],
/// joined here to the outer one.
pub(super) fn located<T: DeserializeOwned>(
    object: Map<String, Value>,
) -> Result<T, (Option<String>, String)> {
    serde_path_to_error::deserialize(Value::Object(object)).map_err(|e| {
        let path = e.path().to_string();
        let message = e.into_inner().to_string();
        if let Some((inner, message)) = message
            .strip_prefix(NESTED_PATH)
            .and_then(|nested| nested.split_once('\u{1}'))
        {
            let separator = if inner.starts_with('[') { "" } else { "." };
            (
                Some(format!("{path}{separator}{inner}")),
                message.to_string(),
            )
        } else if path != "." && SERDE_MESSAGES.iter().any(|p| message.starts_with(p)) {
            (Some(path), message)
        } else {
            (None, message)
        }
    })
}

/// How serde's default `de::Error` messages start: the errors that say what is wrong but not where.
pub(super) const SERDE_MESSAGES: [&str; 7] = [
    "invalid type:",
    "invalid value:",
    "invalid length ",
    "unknown variant ",
    "unknown field ",
    "missing field ",
    "duplicate field ",
];

/// Starts a nested object's error message as `NESTED_PATH path \u{1} message`, so that the
/// enclosing [`located`] joins the field's path to the inner one (`arm` and `links` give
/// `arm.links`). Every nested object is read inside an enclosing [`located`], which removes the
/// mark.
pub(super) const NESTED_PATH: &str = "\u{1}nested:";

/// `"arm"`: an object of [`ArmSpec`] fields but `radius` (a scenario's clearance, which no op
/// uses: refused rather than ignored). Serde would also read a struct from an array of its
/// fields in order, which no user means; anything but an object is refused.
pub(super) fn arm_object<'de, D: Deserializer<'de>>(deserializer: D) -> Result<ArmSpec, D::Error> {
    match Value::deserialize(deserializer)? {
        Value::Object(fields) => match located::<ArmSpec>(fields) {
            Ok(arm) if arm.radius.is_some() => Err(serde::de::Error::custom(format!(
                "{NESTED_PATH}radius\u{1}not used by any op of hrm eval (it is a scenario's \
                 clearance): remove it"
            ))),
            Ok(arm) => Ok(arm),
            Err((path, message)) => Err(serde::de::Error::custom(match path {
                Some(path) => format!("{NESTED_PATH}{path}\u{1}{message}"),
                None => message,
            })),
        },
        other => Err(serde::de::Error::custom(format!(
            "\"arm\" must be an object of arm fields, got {}",
            json_type(&other)
        ))),
    }
}

/// An optional `"arm"` object, read as [`arm_object`] reads one.
pub(super) fn optional_arm_object<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<Option<ArmSpec>, D::Error> {
    arm_object(deserializer).map(Some)
}

/// The JSON type of a value, for messages.
pub(super) fn json_type(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Most harmonics a request may ask for. A `K`-harmonic end point by quadrature costs up to
/// `K` times [`backbone_kin::MAX_QUADRATURE_NODES`] basis evaluations, so this keeps one `fk`
/// under about a second; the library's own limit ([`backbone_kin::MAX_HARMONICS`]) is far larger.
pub(super) const MAX_REQUEST_HARMONICS: usize = 64;

/// `"harmonics"`: `K >= 1` (default 1), at most `max`.
pub(super) fn harmonics(requested: Option<usize>, max: usize) -> Result<usize, EvalError> {
    match requested.unwrap_or(1) {
        0 => Err(EvalError::input("harmonics must be at least 1, got 0")),
        k if k > max => Err(EvalError::input(format!(
            "harmonics must be at most {max}, got {k}"
        ))),
        k => Ok(k),
    }
}

/// Modal coordinates as requests give them: with `"alpha0"`, `a` has `2K` entries and `alpha0` is
/// fixed; without it, `2K + 1` entries with `alpha0` last. Reduces `alpha0` (in `a` or the field)
/// to `(-pi, pi]` and returns the modal map of the chain's own links.
pub(super) fn modal_map(
    chain: &ChainModel,
    a: &mut [f64],
    alpha0: Option<f64>,
    requested: Option<usize>,
) -> Result<ModalMap, EvalError> {
    let k = harmonics(requested, MAX_REQUEST_HARMONICS)?;
    let base = match (a.len(), alpha0) {
        (len, Some(alpha0)) if len == 2 * k => BaseAngle::Fixed(reduce_angle(alpha0)),
        (len, None) if len == 2 * k + 1 => {
            a[2 * k] = reduce_angle(a[2 * k]);
            BaseAngle::Free
        }
        (len, Some(_)) if len == 2 * k + 1 => {
            return Err(EvalError::input(
                "give alpha0 either as the last entry of a or as \"alpha0\", not both",
            ));
        }
        (len, None) if len == 2 * k => {
            return Err(EvalError::input(format!(
                "with {len} coordinates (2K, K = {k}), \"alpha0\" is required"
            )));
        }
        (len, _) => {
            return Err(EvalError::input(format!(
                "a has {len} entries, expected 2K = {} with \"alpha0\" given, or 2K + 1 = {} \
                 with alpha0 last (K = {k} harmonics)",
                2 * k,
                2 * k + 1
            )));
        }
    };
    // The base angle is reduced above; the modes are not, and one of 1e17 would round the
    // others away in `J a`.
    sim_core::check_coordinates("a", &a[..2 * k], 2 * k)
        .map_err(|e| EvalError::input(e.to_string()))?;
    let (n, m) = (chain.n_links(), a.len());
    let entries = n.saturating_mul(m);
    if entries > MAX_MAP_ANSWER {
        return Err(EvalError::input(format!(
            "arm.links times the modal coordinates must be at most {MAX_MAP_ANSWER} (the n x m \
             modal Jacobian a request may build and answer), got {n} x {m} = {entries}"
        )));
    }
    let work = entries.saturating_mul(m);
    if work > MAX_MAP_WORK {
        return Err(EvalError::input(format!(
            "arm.links times the square of the modal coordinates must be at most \
             {MAX_MAP_WORK} (the work of M* = J^T M J), got {n} x {m}^2 = {work}"
        )));
    }
    let lengths: Vec<f64> = chain.link_lengths().collect();
    ModalMap::new(&lengths, k, base).map_err(EvalError::from)
}

/// Most entries `n m` of the modal Jacobian a request may build (`joints` answers all of them,
/// about 100 MB of JSON at the limit): every one-link-per-coordinate arm up to
/// [`backbone_kin::MAX_LINKS`] with 4 coordinates fits.
pub(super) const MAX_MAP_ANSWER: usize = 1 << 22;

/// Most work `n m^2` of a modal request (`M* = J^T M J` of `reduced` and its derivatives), about
/// a tenth of a second.
pub(super) const MAX_MAP_WORK: usize = 1 << 25;

/// A backbone curve's error as an answer: one that quadrature refuses for its amplitudes names
/// the request's `a`.
pub(super) fn curve_error(error: KinError) -> EvalError {
    match error {
        KinError::TooOscillatory { .. } => EvalError::input(format!("a: {error}")),
        other => other.into(),
    }
}

/// Refuses rates (`theta_dot`, `a_dot`, in every op that takes them) beyond the scale a run
/// resolves ([`sim_core::check_rates`]); an entry that is not a number is left to the op's own
/// parsing.
pub(super) fn check_rates(request: &Map<String, Value>) -> Result<(), EvalError> {
    for name in sim_core::RATE_NAMES {
        if let Some(rates) = numbers(request, name) {
            sim_core::check_rates(name, &rates, rates.len())
                .map_err(|e| EvalError::input(e.to_string()))?;
        }
    }
    Ok(())
}

/// Refuses the angles of array field `name` beyond the scale a run resolves
/// ([`sim_core::check_coordinates`]), as [`check_rates`] refuses rates: a spatial request's
/// modal coordinates `a` (a planar request's are checked by [`modal_map`], which knows whether
/// the last entry is the base angle), and a planar arm's joint angles `theta`, which its
/// dynamics sum into absolute link angles, where `1e17` rounds the others away (the mass matrix
/// came out as the straight arm's).
pub(super) fn check_angles(request: &Map<String, Value>, name: &str) -> Result<(), EvalError> {
    match numbers(request, name) {
        Some(values) => sim_core::check_coordinates(name, &values, values.len())
            .map_err(|e| EvalError::input(e.to_string())),
        None => Ok(()),
    }
}

/// Refuses an `arm.kind` that is not a string: serde would also read a unit variant from the
/// map `{"spatial": null}`, which [`is_spatial`](super::spatial::is_spatial) does not see.
pub(super) fn check_arm_kind(request: &Map<String, Value>) -> Result<(), EvalError> {
    match request.get("arm").and_then(|arm| arm.get("kind")) {
        Some(kind) if !kind.is_string() => Err(EvalError::new(
            Kind::InvalidRequest,
            format!("arm.kind must be \"planar\" or \"spatial\", got {kind}"),
        )),
        _ => Ok(()),
    }
}

/// The array field `name` of a request as numbers, an entry that is not one read as zero (left
/// to the op's own parsing); `None` when the field is not an array.
fn numbers(request: &Map<String, Value>, name: &str) -> Option<Vec<f64>> {
    match request.get(name) {
        Some(Value::Array(values)) => {
            Some(values.iter().map(|v| v.as_f64().unwrap_or(0.0)).collect())
        }
        _ => None,
    }
}

/// Refuses to answer with a non-finite number (JSON has none).
pub(super) fn finite(name: &str, values: &[f64]) -> Result<(), EvalError> {
    match lane_math::first_non_finite(values) {
        Some((_, v)) => Err(EvalError::new(
            Kind::Library(ErrorClass::Numerical),
            format!("{name} came out non-finite ({v})"),
        )),
        None => Ok(()),
    }
}

/// An answer's fields, in order.
pub(super) fn json_fields<const N: usize>(fields: [(&str, Value); N]) -> Map<String, Value> {
    fields
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}
