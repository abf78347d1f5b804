//! The gradients of every pair's clearance with respect to the modal coordinates.

use crate::closest::Closest;
use crate::data::ClearanceData;
use crate::error::ClearanceError;
use crate::model::{ClearanceModel, Pair};
use crate::vector::{V3, add, cross, dot, scale, sub};
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
    if m == 0 {
        return Ok(());
    }
    if data.turns_about_z {
        planar_gradients(model, data, map);
    } else {
        spatial_gradients(model, data, map);
    }
    Ok(())
}

/// [`modal_gradients`] of a chain in the plane `z = 0` turning about `z`: joint `j`'s twist is
/// `(v_j, w_j) = (p_j x z, z) = ((p_jy, -p_jx, 0), (0, 0, 1))`, so the prefix sums reduce to three
/// numbers a coordinate, `T_il = sum_{j <= i} J_jl (p_jy, -p_jx, 1)`, and a pair's gradient is
/// `T_il . (n_x, n_y, (c x n)_z)` (the normal's `z` and the moment's in-plane part meet zeros).
fn planar_gradients(model: &ClearanceModel, data: &mut ClearanceData, map: &ModalMap) {
    let m = data.n_coords;
    let prefix = &mut data.prefix_planar;
    for (i, point) in data.points[..model.n_links()].iter().enumerate() {
        for (l, &entry) in map.row(i).iter().enumerate() {
            let [x, y, s] = if i == 0 {
                [0.0; 3]
            } else {
                prefix[(i - 1) * m + l]
            };
            prefix[i * m + l] = [x + entry * point[1], y - entry * point[0], s + entry];
        }
    }
    match m {
        2 => planar_pair_gradients::<2>(model, data),
        3 => planar_pair_gradients::<3>(model, data),
        4 => planar_pair_gradients::<4>(model, data),
        _ => planar_pair_gradients::<0>(model, data),
    }
}

/// Every pair's gradient from the planar prefix sums, `T_il . (n_x, n_y, (c x n)_z)`; `M` is the
/// number of coordinates when it is small (the loops over them then unroll), or 0 for any
/// number.
#[inline(always)]
fn planar_pair_gradients<const M: usize>(model: &ClearanceModel, data: &mut ClearanceData) {
    let m = data.n_coords;
    let prefix = |i: usize| {
        let sums = &data.prefix_planar[i * m..(i + 1) * m];
        if M == 0 { sums } else { &sums[..M] }
    };
    let wrench = |point: V3, n: V3| [n[0], n[1], point[0] * n[1] - point[1] * n[0]];
    for_each_pair(
        model,
        m,
        (&data.closest, &mut data.modal_gradient),
        |link, closest, gradient| {
            let f = wrench(closest.point, closest.normal);
            for (g, t) in gradient.iter_mut().zip(prefix(link)) {
                *g = dot(*t, f);
            }
        },
        |(link, other), closest, gradient| {
            let f = wrench(closest.other, closest.normal);
            for (g, (lo, hi)) in gradient
                .iter_mut()
                .zip(prefix(link).iter().zip(prefix(other)))
            {
                *g = dot(sub(*lo, *hi), f);
            }
        },
    );
}

/// Calls `obstacle(link, closest, gradient)` for every link-obstacle pair and
/// `links((link, other), closest, gradient)` for every self pair, `gradient` the pair's `m`
/// entries of `gradients` and `closest` its closest points.
#[inline(always)]
fn for_each_pair(
    model: &ClearanceModel,
    m: usize,
    (closest, gradients): (&[Closest], &mut [f64]),
    mut obstacle: impl FnMut(usize, &Closest, &mut [f64]),
    mut links: impl FnMut((usize, usize), &Closest, &mut [f64]),
) {
    let split = model.n_obstacle_pairs();
    let (obstacle_gradients, self_gradients) = gradients.split_at_mut(split * m);
    let (obstacle_closest, self_closest) = closest.split_at(split);
    // The link-obstacle pairs, link-major, then the self pairs in the model's order.
    let per_link = model.obstacles().len();
    if per_link > 0 {
        let pairs = obstacle_gradients
            .chunks_exact_mut(per_link * m)
            .zip(obstacle_closest.chunks_exact(per_link));
        for (link, (gradients, closest)) in pairs.enumerate() {
            for (gradient, closest) in gradients.chunks_exact_mut(m).zip(closest) {
                obstacle(link, closest, gradient);
            }
        }
    }
    let pairs = model.pairs()[split..].iter().zip(self_closest);
    for ((pair, closest), gradient) in pairs.zip(self_gradients.chunks_exact_mut(m)) {
        if let Pair::Links { link, other } = *pair {
            links((link, other), closest, gradient);
        }
    }
}

/// [`modal_gradients`] of any chain, through the six-number prefix sums.
fn spatial_gradients(model: &ClearanceModel, data: &mut ClearanceData, map: &ModalMap) {
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
    let (axes, moments) = (&data.prefix_axes, &data.prefix_moments);
    let prefix = |i: usize| (&axes[i * m..(i + 1) * m], &moments[i * m..(i + 1) * m]);
    for_each_pair(
        model,
        m,
        (&data.closest, &mut data.modal_gradient),
        |link, closest, gradient| {
            let n = closest.normal;
            let arm = cross(closest.point, n);
            let (w, u) = prefix(link);
            for ((g, w), u) in gradient.iter_mut().zip(w).zip(u) {
                *g = dot(*w, arm) - dot(*u, n);
            }
        },
        |(link, other), closest, gradient| {
            let n = closest.normal;
            let arm = cross(closest.other, n);
            let ((w_lo, u_lo), (w_hi, u_hi)) = (prefix(link), prefix(other));
            let sums = w_lo.iter().zip(u_lo).zip(w_hi.iter().zip(u_hi));
            for (g, ((w_lo, u_lo), (w_hi, u_hi))) in gradient.iter_mut().zip(sums) {
                let w = sub(*w_hi, *w_lo);
                let u = sub(*u_hi, *u_lo);
                *g = dot(u, n) - dot(w, arm);
            }
        },
    );
}
