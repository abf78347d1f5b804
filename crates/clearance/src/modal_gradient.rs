//! The gradients of every pair's clearance with respect to the modal coordinates.

use crate::closest::Closest;
use crate::data::{Block, ClearanceData, LANES};
use crate::distances::in_registers;
use crate::error::ClearanceError;
use crate::model::ClearanceModel;
use crate::vector::{V3, add, cross, dot, scale, sub};
use backbone_kin::ModalMap;
use lane_math::check_len;
use pulp::{Simd, WithSimd};

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
    data.check_model(model)?;
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
/// The sums are kept [`LANES`] coordinates to a block, coordinate by coordinate, so that a pair's
/// gradient takes a few register operations a block.
fn planar_gradients(model: &ClearanceModel, data: &mut ClearanceData, map: &ModalMap) {
    let blocks = data.n_coords.div_ceil(LANES);
    let prefix = &mut data.prefix_planar;
    for (i, point) in data.points[..model.n_links()].iter().enumerate() {
        for (b, entries) in map.row(i).chunks(LANES).enumerate() {
            // The padding lanes stay zero.
            let previous = if i == 0 {
                [[0.0; LANES]; 3]
            } else {
                prefix[(i - 1) * blocks + b]
            };
            let mut sums = previous;
            for (l, &entry) in entries.iter().enumerate() {
                sums[0][l] = previous[0][l] + entry * point[1];
                sums[1][l] = previous[1][l] - entry * point[0];
                sums[2][l] = previous[2][l] + entry;
            }
            prefix[i * blocks + b] = sums;
        }
    }
    let m = data.n_coords;
    let pairs = PlanarPairs { model, data };
    match m {
        2 => in_registers(pairs.with_coords::<2>()),
        3 => in_registers(pairs.with_coords::<3>()),
        4 => in_registers(pairs.with_coords::<4>()),
        _ => in_registers(pairs.with_coords::<0>()),
    }
}

/// Every pair's gradient from the planar prefix sums (a [`WithSimd`] operation, so that the
/// blocks compile to registers of [`LANES`]); `M` is the number of coordinates when it is small
/// (the loops over them then unroll), or 0 for any number.
struct PlanarPairs<'a, const M: usize> {
    model: &'a ClearanceModel,
    data: &'a mut ClearanceData,
}

impl<'a> PlanarPairs<'a, 0> {
    /// The same pairs, for `M` coordinates.
    fn with_coords<const M: usize>(self) -> PlanarPairs<'a, M> {
        PlanarPairs {
            model: self.model,
            data: self.data,
        }
    }
}

impl<const M: usize> WithSimd for PlanarPairs<'_, M> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Self { model, data } = self;
        let coords = if M == 0 { data.n_coords } else { M };
        let blocks = coords.div_ceil(LANES);
        let prefix = |i: usize| &data.prefix_planar[i * blocks..(i + 1) * blocks];
        let wrench = |point: V3, n: V3| [n[0], n[1], point[0] * n[1] - point[1] * n[0]];
        // `(T_lo - T_hi) . f` (`T_lo . f` without `T_hi`) for the coordinates of one block,
        // summed as `dot` sums, the block in registers of `S`.
        let apply = |lo: &Block, hi: Option<&Block>, f: V3, gradient: &mut [f64]| {
            let mut sums = [0.0; LANES];
            let (out, out_tail) = S::as_mut_simd_f64s(&mut sums);
            let lanes = |k: usize| {
                let (lo, lo_tail) = S::as_simd_f64s(&lo[k]);
                let hi = hi.map(|hi| S::as_simd_f64s(&hi[k]));
                (lo, lo_tail, hi)
            };
            let term = |k: usize, r: usize| {
                let (lo, _, hi) = lanes(k);
                let t = match hi {
                    Some((hi, _)) => simd.sub_f64s(lo[r], hi[r]),
                    None => lo[r],
                };
                simd.mul_f64s(t, simd.splat_f64s(f[k]))
            };
            for (r, out) in out.iter_mut().enumerate() {
                *out = simd.add_f64s(simd.add_f64s(term(0, r), term(1, r)), term(2, r));
            }
            let head = LANES - out_tail.len();
            for (l, out) in out_tail.iter_mut().enumerate() {
                let t = |k: usize| lo[k][head + l] - hi.map_or(0.0, |hi| hi[k][head + l]);
                *out = t(0) * f[0] + t(1) * f[1] + t(2) * f[2];
            }
            gradient.copy_from_slice(&sums[..gradient.len()]);
        };
        for_each_pair(
            model,
            coords,
            (&data.closest, &mut data.modal_gradient),
            |link, closest, gradient| {
                let f = wrench(closest.point, closest.normal);
                for (g, t) in gradient.chunks_mut(LANES).zip(prefix(link)) {
                    apply(t, None, f, g);
                }
            },
            |(link, other), closest, gradient| {
                let f = wrench(closest.other, closest.normal);
                for (g, (lo, hi)) in gradient
                    .chunks_mut(LANES)
                    .zip(prefix(link).iter().zip(prefix(other)))
                {
                    apply(lo, Some(hi), f, g);
                }
            },
        );
    }
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
    let n = model.n_links();
    let mut pairs = self_closest.iter().zip(self_gradients.chunks_exact_mut(m));
    for link in 0..n {
        for other in link + 2..n {
            if let Some((closest, gradient)) = pairs.next() {
                links((link, other), closest, gradient);
            }
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
