//! Reduced forward dynamics: solve `M* a_ddot = tau* - C* - G*` (eq 15) directly by a Cholesky
//! factorisation (in its square-root-free `L D L^T` form) of the small `m x m` matrix `M*`.

use pulp::{Simd, WithSimd};

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::model::ReducedModel;
use crate::projection::reduced_terms_by_projection;
use crate::terms::{StackTerms, accumulate_in_data, check_state, check_terms};
use lane_math::all_finite;
use lane_math::dense::{ldlt_in_place, ldlt_solve_in_place};
use lane_math::{check_len, check_values};

/// The modal accelerations `a_ddot` under generalised forces `tau*` (eq 15), written into
/// `a_ddot` (length `m`), with `M*`, `C*` and `G*` from the default `O(n m^2)` path
/// ([`reduced_terms`](crate::reduced_terms)). `data` holds those terms afterwards. Allocation-free.
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
    check_state(model, data, a, a_dot)?;
    let arch = data.arch;
    arch.dispatch(ForwardOfOneState {
        model,
        data,
        a,
        a_dot,
        tau_star,
        a_ddot,
    })
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
    check_values("tau_star", tau_star, model.n_coords())?;
    check_len("a_ddot", a_ddot.len(), model.n_coords())?;
    Ok(())
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

/// [`forward_dynamics`] after its input checks, run by [`pulp::Arch::dispatch`] so that the
/// kernel is compiled for the processor's instruction set (see [`crate::terms`]).
struct ForwardOfOneState<'a> {
    model: &'a ReducedModel,
    data: &'a mut ReducedData,
    a: &'a [f64],
    a_dot: &'a [f64],
    tau_star: &'a [f64],
    a_ddot: &'a mut [f64],
}

impl WithSimd for ForwardOfOneState<'_> {
    type Output = Result<(), ReduceError>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Self::Output {
        // The sizes evaluated SIMD across states in a batch run on stack arrays here too.
        match self.model.n_coords() {
            2 => self.on_stack::<S, 2>(simd),
            3 => self.on_stack::<S, 3>(simd),
            4 => self.on_stack::<S, 4>(simd),
            5 => self.on_stack::<S, 5>(simd),
            _ => {
                let Self {
                    model,
                    data,
                    a,
                    a_dot,
                    tau_star,
                    a_ddot,
                } = self;
                accumulate_in_data(simd, model, data, a, a_dot);
                check_terms(data)?;
                solve(data, tau_star, a_ddot)
            }
        }
    }
}

impl ForwardOfOneState<'_> {
    /// The terms, the right-hand side and the solve on stack arrays for a compile-time `M`, with
    /// one finiteness test of all results; the checks of the general path name a failure.
    #[inline(always)]
    fn on_stack<S: Simd, const M: usize>(self, simd: S) -> Result<(), ReduceError> {
        let Self {
            model,
            data,
            a,
            a_dot,
            tau_star,
            a_ddot,
        } = self;
        let terms = StackTerms::<M>::compute(simd, model, data, a, a_dot);
        terms.store(data);
        let mut x = [0.0; M];
        right_hand_side(tau_star, &terms.coriolis, &terms.gravity, &mut x);
        let mut factor = terms.mass;
        let positive_definite = factor_and_solve(factor.as_flattened_mut(), &mut x, M);
        if terms.all_finite() & positive_definite & all_finite(&x) {
            a_ddot.copy_from_slice(&x);
            return Ok(());
        }
        check_terms(data)?;
        if !positive_definite {
            return Err(ReduceError::NotPositiveDefinite);
        }
        a_ddot.copy_from_slice(&x);
        check_finite_result("a_ddot", a_ddot)
    }
}

/// Solves `M* a_ddot = tau* - C* - G*` with the terms in `data` (sizes already checked).
fn solve(data: &mut ReducedData, tau_star: &[f64], a_ddot: &mut [f64]) -> Result<(), ReduceError> {
    right_hand_side(tau_star, &data.coriolis, &data.gravity, a_ddot);
    let m = data.n_coords;
    data.factor.copy_from_slice(&data.mass);
    if !factor_and_solve(&mut data.factor, a_ddot, m) {
        return Err(ReduceError::NotPositiveDefinite);
    }
    check_finite_result("a_ddot", a_ddot)
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
