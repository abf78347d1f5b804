//! Forward dynamics through the mass matrix: `qdd = M^-1 (tau - C - G)` with an in-place faer
//! Cholesky factorisation, O(n^3). The O(n) alternative is [`aba`](crate::aba()).

use faer::dyn_stack::MemStack;
use faer::linalg::cholesky::llt;
use faer::{MatMut, Par};

use crate::check;
use crate::crba;
use crate::data::{ChainData, Factorisation};
use crate::error::DynError;
use crate::model::ChainModel;
use crate::rnea::newton_euler;

/// Forward dynamics by solving eq 12, `M(q) qdd = tau - C(q, v) - G(q)`: `M` from the
/// composite-rigid-body algorithm, the right-hand side from one Newton-Euler pass, then a
/// Cholesky factorisation and solve in the workspace.
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, aba, forward_dynamics};
/// let arm = ChainModel::uniform(4, 0.25, 0.5, 9.81)?;
/// let mut data = ChainData::new(&arm);
/// let (q, v, tau) = ([0.1, -0.2, 0.3, 0.4], [1.0, 0.0, -1.0, 0.5], [0.2, 0.1, 0.0, -0.1]);
/// let (mut by_cholesky, mut by_aba) = ([0.0; 4], [0.0; 4]);
/// forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut by_cholesky)?;
/// aba(&arm, &mut data, &q, &v, &tau, &mut by_aba)?;
/// for (x, y) in by_cholesky.iter().zip(&by_aba) {
///     assert!((x - y).abs() < 1e-9 * x.abs().max(1.0));
/// }
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input,
/// [`DynError::NotPositiveDefinite`] if a Cholesky pivot is not positive beyond rounding (link
/// parameters too disparate for double precision), [`DynError::NonFiniteResult`] if a result overflows.
pub fn forward_dynamics(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    check::dense("Cholesky forward dynamics", model)?;
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::output("qdd", qdd, n)?;

    newton_euler(model, data, q, Some(v), None, model.gravity(), qdd);
    check::finite_result("nonlinear effects", qdd)?;
    for (rhs, t) in qdd.iter_mut().zip(tau) {
        *rhs = t - *rhs;
    }

    // The Newton-Euler pass left the link directions of `q` in `data.frames`.
    let ChainData {
        frames,
        subtrees,
        mass_row,
        factorisation,
        ..
    } = data;
    let n_links = frames.len();
    let Factorisation { mass_factor, stack } =
        factorisation.get_or_insert_with(|| Factorisation::new(n_links));
    crba::assemble(model, frames, subtrees, mass_row, mass_factor.as_mut());
    check::finite_matrix("mass matrix", &mass_factor.as_mut())?;
    let stack = MemStack::new(stack);
    llt::factor::cholesky_in_place(
        mass_factor.as_mut(),
        Default::default(),
        Par::Seq,
        stack,
        Default::default(),
    )
    .map_err(|_| DynError::NotPositiveDefinite)?;
    // The assembly left M_ii in the composite bodies; the pivots are L_ii^2.
    for (i, subtree) in subtrees.iter().enumerate() {
        check::pivot(
            "mass matrix",
            mass_factor[(i, i)].powi(2),
            subtree.second_moment,
        )?;
    }
    llt::solve::solve_in_place(
        mass_factor.as_ref(),
        MatMut::from_column_major_slice_mut(qdd, n, 1),
        Par::Seq,
        stack,
    );
    check::finite_result("qdd", qdd)
}
