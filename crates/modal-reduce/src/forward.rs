//! Reduced forward dynamics: solve `M* a_ddot = tau* - C* - G*` (eq 15) directly by a Cholesky
//! factorisation (in its square-root-free `L D L^T` form) of the small `m x m` matrix `M*`.

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result, check_input, check_len};
use crate::model::ReducedModel;
use crate::projection::reduced_terms_by_projection;
use crate::small_linalg::{ldlt_in_place, ldlt_solve_in_place};
use crate::terms::reduced_terms;

/// The modal accelerations `a_ddot` under generalised forces `tau*` (eq 15), written into
/// `a_ddot` (length `m`), with `M*`, `C*` and `G*` from the default `O(n m^2)` path
/// ([`reduced_terms`]). `data` holds those terms afterwards. Allocation-free.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedData, ReducedModel, forward_dynamics};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let mut data = ReducedData::new(&model);
/// let mut a_ddot = [0.0; 3];
/// // Holding the arm still against gravity takes tau* = G*: zero acceleration.
/// forward_dynamics(&model, &mut data, &[0.4, 0.1, 1.2], &[0.0; 3], &[0.0; 3], &mut a_ddot)?;
/// let g_star = data.gravity().to_vec();
/// forward_dynamics(&model, &mut data, &[0.4, 0.1, 1.2], &[0.0; 3], &g_star, &mut a_ddot)?;
/// assert!(a_ddot.iter().all(|x| x.abs() < 1e-12));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn forward_dynamics(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), ReduceError> {
    check_forces(model, tau_star, a_ddot)?;
    reduced_terms(model, data, a, a_dot)?;
    solve(data, tau_star, a_ddot)
}

/// [`forward_dynamics`] with `M*`, `C*` and `G*` from the projection path
/// ([`reduced_terms_by_projection`], `O(n^2 m)`): the paper's method, kept as a reference and a benchmark.
pub fn forward_dynamics_by_projection(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), ReduceError> {
    check_forces(model, tau_star, a_ddot)?;
    reduced_terms_by_projection(model, data, a, a_dot)?;
    solve(data, tau_star, a_ddot)
}

/// Checks the generalised forces and the output of a forward-dynamics call.
pub(crate) fn check_forces(
    model: &ReducedModel,
    tau_star: &[f64],
    a_ddot: &[f64],
) -> Result<(), ReduceError> {
    check_input("tau_star", tau_star, model.n_coords())?;
    check_len("a_ddot", a_ddot.len(), model.n_coords())
}

/// `out = tau* - C* - G*` (sizes already checked).
pub(crate) fn right_hand_side(
    tau_star: &[f64],
    coriolis: &[f64],
    gravity: &[f64],
    out: &mut [f64],
) {
    for (((o, &tau), &c), &g) in out.iter_mut().zip(tau_star).zip(coriolis).zip(gravity) {
        *o = tau - c - g;
    }
}

/// Solves `M* a_ddot = tau* - C* - G*` with the terms in `data` (sizes already checked).
fn solve(data: &mut ReducedData, tau_star: &[f64], a_ddot: &mut [f64]) -> Result<(), ReduceError> {
    right_hand_side(tau_star, &data.coriolis, &data.gravity, a_ddot);
    let m = data.n_coords;
    // The paper's sizes and two harmonics (m = 2 to 5) factorise a copy on the stack, with
    // fully unrolled loops.
    let positive_definite = match m {
        2 => solve_on_stack::<2>(&data.mass, a_ddot),
        3 => solve_on_stack::<3>(&data.mass, a_ddot),
        4 => solve_on_stack::<4>(&data.mass, a_ddot),
        5 => solve_on_stack::<5>(&data.mass, a_ddot),
        _ => {
            data.factor.copy_from_slice(&data.mass);
            factor_and_solve(&mut data.factor, a_ddot, m)
        }
    };
    if !positive_definite {
        return Err(ReduceError::NotPositiveDefinite);
    }
    check_finite_result("a_ddot", a_ddot)
}

#[inline(always)]
fn solve_on_stack<const M: usize>(mass: &[f64], x: &mut [f64]) -> bool {
    let mut factor = [[0.0; M]; M];
    factor.as_flattened_mut().copy_from_slice(&mass[..M * M]);
    factor_and_solve(factor.as_flattened_mut(), x, M)
}

/// `x <- M^-1 x` by an `L D L^T` factorisation of `factor` (holding `M`) in place; `false` if `M`
/// is not numerically positive definite.
#[inline(always)]
fn factor_and_solve(factor: &mut [f64], x: &mut [f64], m: usize) -> bool {
    if !ldlt_in_place((), factor, m) {
        return false;
    }
    ldlt_solve_in_place(factor, m, x);
    true
}
