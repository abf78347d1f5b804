//! The paper's split `M* = M0* + M1*` (eq 16) and its fixed-point form (eqs 17-18),
//! `a_ddot <- M0*^-1 (tau* - M1* a_ddot - C* - G*)`, with `M0*` the diagonal of `M*` and `M1*`
//! the rest: a Jacobi iteration for `M* a_ddot = tau* - C* - G*`.
//!
//! It converges for every starting point exactly when the spectral radius `rho` of
//! `M0*^-1 M1*` is below 1. That matrix is similar to `N - I` with
//! `N = M0*^-1/2 M* M0*^-1/2` (unit diagonal, symmetric positive definite), so its eigenvalues are
//! real and `rho = max |lambda(N) - 1|`. With two coordinates `rho = |M*_12| / sqrt(M*_11 M*_22)`,
//! always below 1; with the three coordinates `(a1, a2, alpha0)` `rho` is 1.0-1.6 at ordinary
//! poses of the paper's arm, and the iteration diverges. Note also that, contrary to the paper,
//! `M0*` is not constant: it depends on `a`.
//!
//! [`jacobi_forward_dynamics`] computes `rho` first and refuses to iterate when `rho >= 1`, so it
//! never returns garbage; [`forward_dynamics`](crate::forward_dynamics) is the method to use.

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::forward::{check_forces, right_hand_side};
use crate::model::ReducedModel;
use crate::terms::reduced_terms;
use lane_math::dense::symmetric_eigen_extremes;

/// When the eq-18 iteration stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobiSettings {
    /// Stop when `|x_{k+1} - x_k|_inf <= tolerance * |x_{k+1}|_inf`. Positive and finite.
    pub tolerance: f64,
    /// Give up after this many iterations. At least 1.
    pub max_iterations: usize,
}

impl Default for JacobiSettings {
    /// `tolerance = 1e-13`, `max_iterations = 1000`.
    fn default() -> Self {
        Self {
            tolerance: 1e-13,
            max_iterations: 1000,
        }
    }
}

/// How a converged eq-18 iteration went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JacobiReport {
    /// Iterations performed, starting from `a_ddot = 0`.
    pub iterations: usize,
    /// Spectral radius of `M0*^-1 M1*` at this state (below 1).
    pub spectral_radius: f64,
}

/// The modal accelerations of eq 15 by the paper's eq-18 iteration, written into `a_ddot`, with
/// `M*`, `C*` and `G*` from the default path. Allocation-free.
///
/// # Errors
/// [`ReduceError::JacobiDiverged`] (with the spectral radius) when the iteration cannot converge at
/// this state, [`ReduceError::JacobiNotConverged`] when it converges too slowly for
/// `settings.max_iterations`, [`ReduceError::InvalidSetting`] for bad settings, and the input
/// errors of [`forward_dynamics`](crate::forward_dynamics).
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{JacobiSettings, ReduceError, ReducedData, ReducedModel, jacobi_forward_dynamics};
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let settings = JacobiSettings::default();
/// let mut a_ddot = [0.0; 3];
/// // Three coordinates (a1, a2, alpha0): diverges at an ordinary pose.
/// let model = ReducedModel::new(arm.clone(), ModalMap::paper(10)?)?;
/// let mut data = ReducedData::new(&model);
/// let result = jacobi_forward_dynamics(
///     &model, &mut data, &[0.5, 0.3, 1.0], &[0.0; 3], &[0.0; 3], &settings, &mut a_ddot,
/// );
/// assert!(matches!(result, Err(ReduceError::JacobiDiverged { .. })));
/// // Two coordinates (alpha0 held fixed): always converges.
/// let model = ReducedModel::new(arm, ModalMap::paper_fixed_alpha0(10, 1.0)?)?;
/// let mut data = ReducedData::new(&model);
/// let report = jacobi_forward_dynamics(
///     &model, &mut data, &[0.5, 0.3], &[0.0; 2], &[0.0; 2], &settings, &mut a_ddot[..2],
/// )?;
/// assert!(report.spectral_radius < 1.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn jacobi_forward_dynamics(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    settings: &JacobiSettings,
    a_ddot: &mut [f64],
) -> Result<JacobiReport, ReduceError> {
    check_settings(settings)?;
    check_forces(model, tau_star, a_ddot)?;
    reduced_terms(model, data, a, a_dot)?;
    let spectral_radius = spectral_radius(data);
    if spectral_radius.is_nan() || spectral_radius >= 1.0 {
        return Err(ReduceError::JacobiDiverged { spectral_radius });
    }
    let m = data.n_coords;
    right_hand_side(tau_star, &data.coriolis, &data.gravity, &mut data.rhs);
    let (mass, rhs, previous) = (&data.mass, &data.rhs, &mut data.iterate);
    a_ddot.fill(0.0);
    let mut relative_update = f64::INFINITY;
    for iteration in 1..=settings.max_iterations {
        previous.copy_from_slice(a_ddot);
        // Eq 18: x_{k+1} = M0*^-1 (rhs - M1* x_k).
        let mut update: f64 = 0.0;
        let mut size: f64 = 0.0;
        for j in 0..m {
            let off_diagonal: f64 = (0..m)
                .filter(|&k| k != j)
                .map(|k| mass[j * m + k] * previous[k])
                .sum();
            let next = (rhs[j] - off_diagonal) / mass[j * m + j];
            update = update.max((next - previous[j]).abs());
            size = size.max(next.abs());
            a_ddot[j] = next;
        }
        relative_update = if size > 0.0 { update / size } else { 0.0 };
        if relative_update <= settings.tolerance {
            check_finite_result("a_ddot", a_ddot)?;
            return Ok(JacobiReport {
                iterations: iteration,
                spectral_radius,
            });
        }
    }
    Err(ReduceError::JacobiNotConverged {
        iterations: settings.max_iterations,
        spectral_radius,
        relative_update,
    })
}

/// The spectral radius of `M0*^-1 M1*` for the `M*` in `data`: `max |lambda(N) - 1|` with
/// `N = M0*^-1/2 M* M0*^-1/2` (see the module documentation).
fn spectral_radius(data: &mut ReducedData) -> f64 {
    let m = data.n_coords;
    for j in 0..m {
        for k in 0..m {
            let scale = (data.mass[j * m + j] * data.mass[k * m + k]).sqrt();
            data.factor[j * m + k] = data.mass[j * m + k] / scale;
        }
    }
    let (lowest, highest) = symmetric_eigen_extremes(&mut data.factor, m);
    (highest - 1.0).max(1.0 - lowest)
}

fn check_settings(settings: &JacobiSettings) -> Result<(), ReduceError> {
    if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
        return Err(ReduceError::InvalidSetting {
            name: "tolerance",
            requirement: "positive and finite",
            value: settings.tolerance,
        });
    }
    if settings.max_iterations == 0 {
        return Err(ReduceError::InvalidSetting {
            name: "max_iterations",
            requirement: "at least 1",
            value: 0.0,
        });
    }
    Ok(())
}
