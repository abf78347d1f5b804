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
    if m == 0 {
        return Ok(());
    }
    let (axes, moments) = (&data.prefix_axes, &data.prefix_moments);
    let prefix = |i: usize| (&axes[i * m..(i + 1) * m], &moments[i * m..(i + 1) * m]);
    let split = model.n_obstacle_pairs();
    let (obstacle_gradients, self_gradients) = data.modal_gradient.split_at_mut(split * m);
    let (obstacle_closest, self_closest) = data.closest.split_at(split);
    // Link-major: each link's prefix sums serve all its obstacles.
    let per_link = model.obstacles().len();
    if per_link > 0 {
        let links = obstacle_gradients
            .chunks_exact_mut(per_link * m)
            .zip(obstacle_closest.chunks_exact(per_link));
        for (link, (gradients, closest)) in links.enumerate() {
            let (w, u) = prefix(link);
            for (gradient, closest) in gradients.chunks_exact_mut(m).zip(closest) {
                let n = closest.normal;
                let arm = cross(closest.point, n);
                for ((g, w), u) in gradient.iter_mut().zip(w).zip(u) {
                    *g = dot(*w, arm) - dot(*u, n);
                }
            }
        }
    }
    let pairs = model.pairs()[split..].iter().zip(self_closest);
    for ((pair, closest), gradient) in pairs.zip(self_gradients.chunks_exact_mut(m)) {
        let Pair::Links { link, other } = *pair else {
            continue;
        };
        let n = closest.normal;
        let arm = cross(closest.other, n);
        let ((w_lo, u_lo), (w_hi, u_hi)) = (prefix(link), prefix(other));
        let sums = w_lo.iter().zip(u_lo).zip(w_hi.iter().zip(u_hi));
        for (g, ((w_lo, u_lo), (w_hi, u_hi))) in gradient.iter_mut().zip(sums) {
            let w = sub(*w_hi, *w_lo);
            let u = sub(*u_hi, *u_lo);
            *g = dot(u, n) - dot(w, arm);
        }
    }
    Ok(())
}
