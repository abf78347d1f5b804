//! The joint-space mass matrix `M(q)` by the composite-rigid-body algorithm (CRBA), `O(n^2)`,
//! into a faer matrix (Featherstone 2008, table 6.2; Pinocchio's `crba`).
//!
//! Tip to base, the composite inertia of links `i..n` in link `i`'s frame:
//! `Ic_i = I_i + X_{i+1}^-T Ic_{i+1} X_{i+1}^-1`. Column `i`: `F = Ic_i S_i`, `M_ii = S_i^T F`,
//! then for each ancestor `j`, `F <- X_{j+1}^-T F` and `M_ji = M_ij = S_j^T F`.

use faer::MatMut;

use super::data::SpatialData;
use super::kinematics::update_placements;
use super::model::SpatialModel;
use crate::check;
use crate::error::DynError;

/// The mass matrix `M(q)`, symmetric positive definite, written in full into `out` (`n x n`).
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, mass_matrix};
/// let arm = SpatialModel::from_planar(&ChainModel::uniform(3, 0.5, 1.0, 9.81)?);
/// let mut m = manip_dyn::faer::Mat::<f64>::zeros(3, 3);
/// mass_matrix(&arm, &mut SpatialData::new(&arm), &[0.1, 0.2, 0.3], m.as_mut())?;
/// assert_eq!(m[(0, 2)], m[(2, 0)]);
/// // The last joint moves only the last link: I + m c^2 = m L^2 / 3.
/// assert!((m[(2, 2)] - 0.25 / 3.0).abs() < 1e-15);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links; [`DynError::Dimension`] if `q` does not have `n` entries, `out` is not `n x n`, or
/// `data` was built for another chain; [`DynError::NonFinite`] for a NaN or infinite `q`;
/// [`DynError::NonFiniteResult`] if an entry overflows.
pub fn mass_matrix(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    mut out: MatMut<'_, f64>,
) -> Result<(), DynError> {
    check::dense_count("the mass matrix", model.n_links())?;
    let n = super::check_inputs(model, data, &[("q", q)])?;
    check::square_output(&out, n)?;
    update_placements(model, data, q);
    composite_inertias(model, data);
    for i in 0..n {
        let mut force = data.composites[i].apply(&model.axes[i]);
        out[(i, i)] = model.axes[i].dot(&force);
        for j in (0..i).rev() {
            force = data.placements[j + 1].act_force(&force);
            let entry = model.axes[j].dot(&force);
            out[(j, i)] = entry;
            out[(i, j)] = entry;
        }
    }
    check::finite_matrix("mass matrix", &out)
}

/// `Ic_i` for every link, from the tip, on the placements already in `data`.
pub(crate) fn composite_inertias(model: &SpatialModel, data: &mut SpatialData) {
    let n = model.n_links();
    for i in (0..n).rev() {
        data.composites[i] = if i + 1 < n {
            model.matrices[i].plus(&data.placements[i + 1].act_inertia(&data.composites[i + 1]))
        } else {
            model.matrices[i]
        };
    }
}
