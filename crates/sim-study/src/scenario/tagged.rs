//! The tables tagged by a `kind` (or `method`) key, `[reference]`, `[[obstacles]]`, `[task]` and
//! `[integrator]`, read key by key: serde's internally tagged enums buffer a table before they
//! know its variant, and a wrongly typed value then lost its position (`line 31, column 1
//! (`[task]`): invalid type: string "0.01", expected f64`). Each table is read here as a struct
//! of every key any variant takes, so that toml names the key's own line, then given to the
//! variant its tag names, which refuses the keys of other variants and asks for its own as
//! serde's derive does ("unknown field `half_extents`, expected `center` or `radius`", "missing
//! field `radius`").

use super::schema::{
    BranchSpec, HelixSpec, IntegratorSpec, ObstacleSpec, ReferenceSpec, SineSpec, TaskSpec,
};
use serde::Deserialize;
use serde::de::Error as _;
use serde::de::value::Error;

/// Refuses a key of `given` (name, whether the table has it) that the variant does not take,
/// `allowed`, with serde's message for an unknown field.
fn only(given: &[(&'static str, bool)], allowed: &'static [&'static str]) -> Result<(), Error> {
    match given
        .iter()
        .find(|(name, has)| *has && !allowed.contains(name))
    {
        Some((name, _)) => Err(Error::unknown_field(name, allowed)),
        None => Ok(()),
    }
}

/// The value of a key the variant requires, or serde's message for a missing field.
fn required<T>(value: Option<T>, name: &'static str) -> Result<T, Error> {
    value.ok_or_else(|| Error::missing_field(name))
}

/// The kinds of `[[obstacles]]`.
#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ObstacleKind {
    Circle,
    Sphere,
    Capsule,
    Box,
}

/// An `[[obstacles]]` table, every key of every kind.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObstacleTable {
    kind: ObstacleKind,
    center: Option<Vec<f64>>,
    radius: Option<f64>,
    from: Option<Vec<f64>>,
    to: Option<Vec<f64>>,
    half_extents: Option<Vec<f64>>,
    rpy: Option<Vec<f64>>,
}

impl TryFrom<ObstacleTable> for ObstacleSpec {
    type Error = Error;

    fn try_from(table: ObstacleTable) -> Result<Self, Error> {
        let given = [
            ("center", table.center.is_some()),
            ("radius", table.radius.is_some()),
            ("from", table.from.is_some()),
            ("to", table.to.is_some()),
            ("half_extents", table.half_extents.is_some()),
            ("rpy", table.rpy.is_some()),
        ];
        Ok(match table.kind {
            ObstacleKind::Circle => {
                only(&given, &["center", "radius"])?;
                ObstacleSpec::Circle {
                    center: required(table.center, "center")?,
                    radius: required(table.radius, "radius")?,
                }
            }
            ObstacleKind::Sphere => {
                only(&given, &["center", "radius"])?;
                ObstacleSpec::Sphere {
                    center: required(table.center, "center")?,
                    radius: required(table.radius, "radius")?,
                }
            }
            ObstacleKind::Capsule => {
                only(&given, &["from", "to", "radius"])?;
                ObstacleSpec::Capsule {
                    from: required(table.from, "from")?,
                    to: required(table.to, "to")?,
                    radius: required(table.radius, "radius")?,
                }
            }
            ObstacleKind::Box => {
                only(&given, &["center", "half_extents", "rpy"])?;
                ObstacleSpec::Box {
                    center: required(table.center, "center")?,
                    half_extents: required(table.half_extents, "half_extents")?,
                    rpy: table.rpy,
                }
            }
        })
    }
}

/// The kinds of `[task]`.
#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum TaskKind {
    Reach,
}

/// A `[task]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TaskTable {
    kind: TaskKind,
    target: Option<Vec<f64>>,
    clearance: Option<f64>,
    check_slack: Option<f64>,
    samples: Option<usize>,
    max_iterations: Option<usize>,
}

impl TryFrom<TaskTable> for TaskSpec {
    type Error = Error;

    fn try_from(table: TaskTable) -> Result<Self, Error> {
        Ok(match table.kind {
            TaskKind::Reach => TaskSpec::Reach {
                target: required(table.target, "target")?,
                clearance: required(table.clearance, "clearance")?,
                check_slack: table.check_slack,
                samples: table.samples,
                max_iterations: table.max_iterations,
            },
        })
    }
}

/// The kinds of `[reference]`.
#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ReferenceKind {
    Constant,
    Step,
    Sinusoid,
    Path,
    Planned,
}

/// A `[reference]` table, every key of every kind.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ReferenceTable {
    kind: ReferenceKind,
    a: Option<Vec<f64>>,
    initial: Option<Vec<f64>>,
    target: Option<Vec<f64>>,
    time: Option<f64>,
    offset: Option<Vec<f64>>,
    amplitude: Option<Vec<f64>>,
    frequency_hz: Option<Vec<f64>>,
    phase: Option<Vec<f64>>,
    travel_time: Option<f64>,
    branch: Option<BranchSpec>,
    sine: Option<SineSpec>,
    #[serde(default, deserialize_with = "super::exact::optional_points")]
    points: Option<Vec<[f64; 2]>>,
    helix: Option<HelixSpec>,
}

impl TryFrom<ReferenceTable> for ReferenceSpec {
    type Error = Error;

    fn try_from(table: ReferenceTable) -> Result<Self, Error> {
        let given = [
            ("a", table.a.is_some()),
            ("initial", table.initial.is_some()),
            ("target", table.target.is_some()),
            ("time", table.time.is_some()),
            ("offset", table.offset.is_some()),
            ("amplitude", table.amplitude.is_some()),
            ("frequency_hz", table.frequency_hz.is_some()),
            ("phase", table.phase.is_some()),
            ("travel_time", table.travel_time.is_some()),
            ("branch", table.branch.is_some()),
            ("sine", table.sine.is_some()),
            ("points", table.points.is_some()),
            ("helix", table.helix.is_some()),
        ];
        Ok(match table.kind {
            ReferenceKind::Constant => {
                only(&given, &["a"])?;
                ReferenceSpec::Constant {
                    a: required(table.a, "a")?,
                }
            }
            ReferenceKind::Step => {
                only(&given, &["initial", "target", "time"])?;
                ReferenceSpec::Step {
                    initial: table.initial,
                    target: required(table.target, "target")?,
                    time: table.time.unwrap_or_default(),
                }
            }
            ReferenceKind::Sinusoid => {
                only(&given, &["offset", "amplitude", "frequency_hz", "phase"])?;
                ReferenceSpec::Sinusoid {
                    offset: table.offset,
                    amplitude: required(table.amplitude, "amplitude")?,
                    frequency_hz: required(table.frequency_hz, "frequency_hz")?,
                    phase: table.phase,
                }
            }
            ReferenceKind::Path => {
                only(
                    &given,
                    &["travel_time", "branch", "sine", "points", "helix"],
                )?;
                ReferenceSpec::Path {
                    travel_time: required(table.travel_time, "travel_time")?,
                    branch: table.branch.unwrap_or_default(),
                    sine: table.sine,
                    points: table.points,
                    helix: table.helix,
                }
            }
            ReferenceKind::Planned => {
                only(&given, &["travel_time"])?;
                ReferenceSpec::Planned {
                    travel_time: required(table.travel_time, "travel_time")?,
                }
            }
        })
    }
}

/// The methods of `[integrator]`.
#[derive(Deserialize)]
#[serde(rename_all = "kebab-case")]
enum IntegratorMethod {
    Rk4,
    Dopri5,
}

/// An `[integrator]` table, every key of every method.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct IntegratorTable {
    method: IntegratorMethod,
    dt: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    h_max: Option<f64>,
    max_steps: Option<usize>,
}

impl TryFrom<IntegratorTable> for IntegratorSpec {
    type Error = Error;

    fn try_from(table: IntegratorTable) -> Result<Self, Error> {
        let given = [
            ("dt", table.dt.is_some()),
            ("rtol", table.rtol.is_some()),
            ("atol", table.atol.is_some()),
            ("h_max", table.h_max.is_some()),
            ("max_steps", table.max_steps.is_some()),
        ];
        Ok(match table.method {
            IntegratorMethod::Rk4 => {
                only(&given, &["dt"])?;
                IntegratorSpec::Rk4 {
                    dt: required(table.dt, "dt")?,
                }
            }
            IntegratorMethod::Dopri5 => {
                only(&given, &["rtol", "atol", "h_max", "max_steps"])?;
                IntegratorSpec::Dopri5 {
                    rtol: table.rtol.unwrap_or(super::schema::DEFAULT_RTOL),
                    atol: table.atol.unwrap_or(super::schema::DEFAULT_ATOL),
                    h_max: table.h_max,
                    max_steps: table.max_steps,
                }
            }
        })
    }
}
