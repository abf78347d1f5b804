//! The `hrm eval` ops of the analytic derivatives: `rnea_derivatives`, `aba_derivatives` and
//! `reduced_derivatives` (`docs/eval-protocol.md`). Matrices are lists of rows with entry
//! `[i][j] = d out_i / d in_j`.

use manip_dyn::faer::MatRef;
use manip_dyn::{ChainData, ChainModel, DerivativeData};
use modal_reduce::{ReducedData, ReducedDerivatives, ReducedModel};
use serde::Deserialize;
use serde_json::{Value, json};
use sim_study::ArmSpec;

use super::request::{EvalError, EvalResult, finite, json_fields, modal_map};

/// The most links the joint-space derivative ops accept: their answer holds `2 n^2` or `3 n^2`
/// numbers (3 million, some 60 MB of JSON, at this limit) and their workspace `24 n^2` bytes.
pub(super) const MAX_DERIVATIVE_LINKS: usize = 1024;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RneaDerivativesRequest {
    #[serde(default)]
    arm: ArmSpec,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    theta_ddot: Vec<f64>,
}

/// `rnea_derivatives`: `tau` of eq 12 and its Jacobians with respect to `theta` and `theta_dot`.
pub(super) fn rnea_derivatives(request: RneaDerivativesRequest) -> EvalResult {
    let chain = chain(&request.arm)?;
    joint_vectors(
        chain.n_links(),
        "link",
        &[
            ("theta", &request.theta),
            ("theta_dot", &request.theta_dot),
            ("theta_ddot", &request.theta_ddot),
        ],
    )?;
    let mut derivatives = DerivativeData::new(&chain);
    manip_dyn::rnea_derivatives(
        &chain,
        &mut ChainData::new(&chain),
        &mut derivatives,
        &request.theta,
        &request.theta_dot,
        &request.theta_ddot,
    )?;
    rnea_answer(derivatives.value(), derivatives.d_q(), derivatives.d_v())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AbaDerivativesRequest {
    #[serde(default)]
    arm: ArmSpec,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    tau: Vec<f64>,
}

/// `aba_derivatives`: `theta_ddot` of eq 12 and its Jacobians with respect to `theta`,
/// `theta_dot` and `tau` (`M^-1`).
pub(super) fn aba_derivatives(request: AbaDerivativesRequest) -> EvalResult {
    let chain = chain(&request.arm)?;
    joint_vectors(
        chain.n_links(),
        "link",
        &[
            ("theta", &request.theta),
            ("theta_dot", &request.theta_dot),
            ("tau", &request.tau),
        ],
    )?;
    let mut derivatives = DerivativeData::new(&chain);
    manip_dyn::aba_derivatives(
        &chain,
        &mut ChainData::new(&chain),
        &mut derivatives,
        &request.theta,
        &request.theta_dot,
        &request.tau,
    )
    .map_err(accelerations_named)?;
    aba_answer(
        derivatives.value(),
        derivatives.d_q(),
        derivatives.d_v(),
        derivatives.d_input(),
    )
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ReducedDerivativesRequest {
    #[serde(default)]
    arm: ArmSpec,
    a: Vec<f64>,
    a_dot: Vec<f64>,
    tau_star: Vec<f64>,
    alpha0: Option<f64>,
    harmonics: Option<usize>,
}

/// `reduced_derivatives`: `a_ddot` of eq 15 and its Jacobians with respect to `a`, `a_dot` and
/// `tau*` (`M*^-1`), for `K` harmonics (default 1) with `alpha0` free or fixed.
pub(super) fn reduced_derivatives(mut request: ReducedDerivativesRequest) -> EvalResult {
    let chain = request.arm.to_chain()?;
    let map = modal_map(&chain, &mut request.a, request.alpha0, request.harmonics)?;
    let model = ReducedModel::new(chain, map)?;
    let mut derivatives = ReducedDerivatives::new(&model);
    modal_reduce::reduced_derivatives(
        &model,
        &mut ReducedData::new(&model),
        &mut derivatives,
        &request.a,
        &request.a_dot,
        &request.tau_star,
    )?;
    finite("a_ddot", derivatives.a_ddot())?;
    Ok(json_fields([
        ("a_ddot", json!(derivatives.a_ddot())),
        ("d_a", rows("d_a", derivatives.d_a())?),
        ("d_a_dot", rows("d_a_dot", derivatives.d_a_dot())?),
        ("d_tau_star", rows("d_tau_star", derivatives.d_tau_star())?),
    ]))
}

/// The arm, refused beyond [`MAX_DERIVATIVE_LINKS`] before the `n x n` workspaces exist.
fn chain(arm: &ArmSpec) -> Result<ChainModel, EvalError> {
    let chain = arm.to_chain()?;
    if chain.n_links() > MAX_DERIVATIVE_LINKS {
        return Err(EvalError::input(format!(
            "arm.links must be at most {MAX_DERIVATIVE_LINKS} for the derivative ops, got {}",
            chain.n_links()
        )));
    }
    Ok(chain)
}

/// Each joint-space vector (named by its request field) has `n` entries, one per `unit` (a link
/// of an arm, a movable joint of a URDF chain).
pub(super) fn joint_vectors(
    n: usize,
    unit: &str,
    vectors: &[(&str, &[f64])],
) -> Result<(), EvalError> {
    for (name, values) in vectors {
        if values.len() != n {
            return Err(EvalError::input(format!(
                "{name} has {} entries, expected {n} (one per {unit})",
                values.len()
            )));
        }
    }
    Ok(())
}

/// A library error of `aba_derivatives` as an answer, the accelerations by the request's name
/// (`theta_ddot`, the library's `qdd`).
pub(super) fn accelerations_named(error: manip_dyn::DynError) -> EvalError {
    match error {
        manip_dyn::DynError::NonFiniteResult { name: "qdd" } => {
            let class = lane_math::Classify::class(&error);
            EvalError::new(
                super::request::Kind::Library(class),
                error.to_string().replacen("qdd", "theta_ddot", 1),
            )
        }
        other => other.into(),
    }
}

/// The answer of `rnea_derivatives` (of an arm or a URDF chain): `tau` and its Jacobians in
/// `theta` and `theta_dot`, refused if an entry is not finite.
pub(super) fn rnea_answer(tau: &[f64], d_q: MatRef<'_, f64>, d_v: MatRef<'_, f64>) -> EvalResult {
    finite("tau", tau)?;
    Ok(json_fields([
        ("tau", json!(tau)),
        ("d_theta", rows("d_theta", d_q)?),
        ("d_theta_dot", rows("d_theta_dot", d_v)?),
    ]))
}

/// The answer of `aba_derivatives` (of an arm or a URDF chain): `theta_ddot` and its Jacobians
/// in `theta`, `theta_dot` and `tau`, refused if an entry is not finite.
pub(super) fn aba_answer(
    theta_ddot: &[f64],
    d_q: MatRef<'_, f64>,
    d_v: MatRef<'_, f64>,
    d_tau: MatRef<'_, f64>,
) -> EvalResult {
    finite("theta_ddot", theta_ddot)?;
    Ok(json_fields([
        ("theta_ddot", json!(theta_ddot)),
        ("d_theta", rows("d_theta", d_q)?),
        ("d_theta_dot", rows("d_theta_dot", d_v)?),
        ("d_tau", rows("d_tau", d_tau)?),
    ]))
}

/// A matrix as JSON rows, refused if an entry is not finite.
pub(super) fn rows(name: &str, m: MatRef<'_, f64>) -> Result<Value, EvalError> {
    let rows: Vec<Vec<f64>> = (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect();
    finite(name, &rows.concat())?;
    Ok(json!(rows))
}
