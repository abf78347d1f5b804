//! The gradients of every pair's clearance with respect to the modal coordinates.

use crate::data::ClearanceData;
use crate::error::ClearanceError;
use crate::model::{ClearanceModel, Pair};
use crate::vector::{add, cross, dot, scale, sub};
use backbone_kin::ModalMap;
use lane_math::check_len;

/// Fills every pair's `d d / d a = J^T d d / d theta` (after [`distances`](crate::distances)),
/// for the constant modal map `theta = J a + theta_0` (eq 8). Allocation-free.
///
/// With `d d / d theta_j = w_j . (c x n) - (w_j x p_j) . n` ([`joint_gradient`](crate::joint_gradient)),
/// the prefix sums `W_il = sum_{j <= i} J_jl w_j` and `U_il = sum_{j <= i} J_jl (w_j x p_j)`,
/// computed once in `O(n m)`, give each pair's gradient in `O(m)`: for link `i` against an
/// obstacle `d d / d a_l = W_il . (c x n) - U_il . n`, for links `i < k`
/// `d d / d a_l = -(W_kl - W_il) . (c_k x n) + (U_kl - U_il) . n`.
pub fn modal_gradients(
    model: &ClearanceModel,
    data: &mut ClearanceData,
    map: &ModalMap,
) -> Result<(), ClearanceError> {
    check_len("modal map joints", map.n_joints(), model.n_links())?;
    check_len("modal map coordinates", map.n_coords(), data.n_coords)?;
    let m = data.n_coords;
    for i in 0..model.n_links() {
        let w = data.axes[i];
        let moment = cross(w, data.points[i]);
        let row = map.row(i);
        for (l, &entry) in row.iter().enumerate() {
            let (prev_w, prev_u) = if i == 0 {
                ([0.0; 3], [0.0; 3])
            } else {
                (
                    data.prefix_axes[(i - 1) * m + l],
                    data.prefix_moments[(i - 1) * m + l],
                )
            };
            data.prefix_axes[i * m + l] = add(prev_w, scale(w, entry));
            data.prefix_moments[i * m + l] = add(prev_u, scale(moment, entry));
        }
    }
    for ((pair, closest), gradient) in model
        .pairs()
        .iter()
        .zip(&data.closest)
        .zip(data.modal_gradient.chunks_exact_mut(m.max(1)))
    {
        let n = closest.normal;
        match *pair {
            Pair::Obstacle { link, .. } => {
                let arm = cross(closest.point, n);
                for (l, g) in gradient.iter_mut().enumerate() {
                    let idx = link * m + l;
                    *g = dot(data.prefix_axes[idx], arm) - dot(data.prefix_moments[idx], n);
                }
            }
            Pair::Links { link, other } => {
                let arm = cross(closest.other, n);
                for (l, g) in gradient.iter_mut().enumerate() {
                    let (lo, hi) = (link * m + l, other * m + l);
                    let w = sub(data.prefix_axes[hi], data.prefix_axes[lo]);
                    let u = sub(data.prefix_moments[hi], data.prefix_moments[lo]);
                    *g = dot(u, n) - dot(w, arm);
                }
            }
        }
    }
    Ok(())
}
