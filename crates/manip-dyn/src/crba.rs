//! The joint-space mass matrix `M(q)` of eq 12 by the composite-rigid-body algorithm (CRBA),
//! O(n^2), assembled into a faer matrix.

use faer::MatMut;
use faer::reborrow::{Reborrow, ReborrowMut};

use crate::check;
use crate::data::{ChainData, LinkFrame, Subtree};
use crate::error::DynError;
use crate::kinematics::{dot, update_frames};
use crate::model::ChainModel;

/// The mass matrix `M(q)` (eq 12), symmetric positive definite, written in full into `out`.
///
/// Entry `(i, j)` with `i <= j` is the moment about joint `i` needed to give the composite body
/// of links `j..n` a unit angular acceleration about joint `j`:
/// `M_ij = J_j + (p_j - p_i) . h_j`, with `J_j` and `h_j` the composite body's second and first
/// moments of mass about joint `j` (`p_j`: position of joint `j`).
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, mass_matrix};
/// let arm = ChainModel::uniform(3, 0.5, 1.0, 9.81)?;
/// let mut data = ChainData::new(&arm);
/// let mut m = manip_dyn::faer::Mat::<f64>::zeros(3, 3);
/// mass_matrix(&arm, &mut data, &[0.1, 0.2, 0.3], m.as_mut())?;
/// assert_eq!(m[(0, 2)], m[(2, 0)]);
/// // The last joint moves only the last link: I + m c^2 = m L^2 / 3.
/// assert!((m[(2, 2)] - 0.25 / 3.0).abs() < 1e-15);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if `q` does not have `n` entries, `out` is not `n x n`, or `data` was
/// built for another chain; [`DynError::NonFinite`] for a NaN or infinite angle;
/// [`DynError::NonFiniteResult`] if an entry overflows.
pub fn mass_matrix(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    mut out: MatMut<'_, f64>,
) -> Result<(), DynError> {
    check::dense("the mass matrix", model)?;
    let n = check::inputs(model, data, &[("q", q)])?;
    check::square_output(&out, n)?;
    update_frames(&mut data.frames, q, None);
    assemble(
        model,
        &data.frames,
        &mut data.subtrees,
        &mut data.mass_row,
        out.as_mut(),
    );
    check::finite_matrix("mass matrix", &out)
}

/// Fills `out` with `M` from the link directions in `frames` (already updated); `row` is
/// scratch of `n` entries.
pub(crate) fn assemble(
    model: &ChainModel,
    frames: &[LinkFrame],
    subtrees: &mut [Subtree],
    row: &mut [f64],
    mut out: MatMut<'_, f64>,
) {
    accumulate_subtrees(model, frames, subtrees);
    let n = model.n_links();
    // Walking from the tip to the base, row[j] holds M_ij for j >= i: moving the reference
    // point from joint i + 1 back to joint i adds (p_{i+1} - p_i) x (e_z x h_j) = L_i u_i . h_j.
    // Row i of the upper triangle is column i of the lower one: contiguous writes.
    for i in (0..n).rev() {
        let reach = joint_offset(model, frames, i);
        row[i] = subtrees[i].second_moment;
        for (entry, subtree) in row[i + 1..].iter_mut().zip(&subtrees[i + 1..]) {
            *entry += dot(reach, subtree.first_moment);
        }
        for (j, entry) in row.iter().enumerate().skip(i) {
            out[(j, i)] = *entry;
        }
    }
    mirror_lower_to_upper(out);
}

/// `L_i u_i`: joint `i + 1` relative to joint `i`.
fn joint_offset(model: &ChainModel, frames: &[LinkFrame], i: usize) -> [f64; 2] {
    let length = model.links()[i].length;
    [length * frames[i].axis[0], length * frames[i].axis[1]]
}

/// Copies the strict lower triangle of a square matrix onto its upper triangle, in strips of
/// columns so that the transposed reads stay in cache.
fn mirror_lower_to_upper(mut out: MatMut<'_, f64>) {
    const STRIP: usize = 64;
    let n = out.nrows();
    for first in (0..n).step_by(STRIP) {
        let width = STRIP.min(n - first);
        for j in first..first + width {
            for i in first..j {
                out[(i, j)] = out[(j, i)];
            }
        }
        // Rows above the strip's diagonal block mirror the strip's rows left of it.
        let (above, strip_rows) = out.rb_mut().split_at_row_mut(first);
        above
            .submatrix_mut(0, first, first, width)
            .copy_from(strip_rows.rb().submatrix(0, 0, width, first).transpose());
    }
}

/// The composite bodies of links `i..n` for every `i`, from the tip back (O(n)).
pub(crate) fn accumulate_subtrees(
    model: &ChainModel,
    frames: &[LinkFrame],
    subtrees: &mut [Subtree],
) {
    let mut child = Subtree::default();
    for i in (0..model.n_links()).rev() {
        let link = &model.links()[i];
        let u = frames[i].axis;
        let reach = link.length;
        // The child's moments are about joint i + 1 = joint i + L_i u_i.
        let own = link.mass * link.com;
        let current = Subtree {
            mass: link.mass + child.mass,
            first_moment: [
                own * u[0] + child.first_moment[0] + child.mass * reach * u[0],
                own * u[1] + child.first_moment[1] + child.mass * reach * u[1],
            ],
            second_moment: link.inertia
                + own * link.com
                + child.second_moment
                + 2.0 * reach * dot(u, child.first_moment)
                + child.mass * reach * reach,
        };
        subtrees[i] = current;
        child = current;
    }
}
