//! The pass over the links: the prefix sums that accumulate `M*`, `C*` and `G*` (eq 14; see
//! the [parent module](super)).

use lane_math::Lane;

use super::layout::Layout;
use super::links::{LinkBuffers, load_link};
use crate::data::{PRODUCTS, Pair};
use crate::model::{LINK_PADDING, ReducedModel};

/// The results and scratch of the kernel, in registers of a [`Layout`]: `m` rows of
/// [`chunks`](super::Registers::chunks) registers, or one row.
pub(crate) struct Terms<'a, R> {
    /// `A` (see [`accumulate`]), row after row.
    pub(crate) mass: &'a mut [R],
    /// `C*`.
    pub(crate) coriolis: &'a mut [R],
    /// `G*`.
    pub(crate) gravity: &'a mut [R],
    /// Columns of `P_l`.
    pub(crate) joint: &'a mut [Pair<R>],
    /// `v_l`.
    pub(crate) v: &'a mut [R],
}

/// The sums of the module documentation, for `m` coordinates, into `terms` in the registers of
/// `layout`: `A` (all of it; `M* = K + A + A^T`, see [`extract`]), `C*` and `G*`.
#[inline(always)]
pub(crate) fn accumulate<Y: Layout>(
    layout: Y,
    model: &ReducedModel,
    a: &[Y::Value],
    a_dot: &[Y::Value],
    m: usize,
    mut links: LinkBuffers<'_>,
    terms: &mut Terms<'_, Y::Register>,
) {
    let (rc, vc) = (layout.register_context(), layout.value_context());
    let chunks = layout.chunks(m);
    let zero = Y::Register::splat(rc, 0.0);
    let (a, a_dot) = (&a[..m], &a_dot[..m]);
    let mass = &mut terms.mass[..m * chunks];
    let coriolis = &mut terms.coriolis[..chunks];
    let gravity = &mut terms.gravity[..chunks];
    let joint = &mut terms.joint[..chunks];
    let v = &mut terms.v[..chunks];
    mass.fill(zero);
    coriolis.fill(zero);
    gravity.fill(zero);
    joint.fill([zero; 2]);
    let n = model.n_links();
    let rows = model.angle_rows();
    let mut q = [Y::Value::splat(vc, 0.0); 2];
    layout.link_values(model, a, a_dot, &mut links);
    // The pass: P_l, q_l, and the sums of M* and C*.
    // Each link's rows zipped with its values, so that nothing is bounds-checked.
    let moment_rows = model.moment_rows();
    let width = Y::Value::WIDTH;
    let links_rows = padded_rows(rows, n, m).zip(padded_rows(moment_rows, n, m));
    for ((row, moment_row), entries) in links_rows.zip(links.values(n, width)) {
        let [sin, cos, moment_rate2, l_sin, l_cos, drop_x, drop_y]: [Y::Value; 2 + PRODUCTS] =
            load_link(vc, entries);
        // w_l . q_l, which S_l Phi_l multiplies.
        // (No closures or array maps here: their bodies would be compiled without the
        // instruction set of the dispatch, and its intrinsics called, not inlined.)
        let force = layout.spread(sin.neg_mul_add(q[0], cos * q[1]));
        let (sin, cos) = (layout.spread(sin), layout.spread(cos));
        let moment_rate2 = layout.spread(moment_rate2);
        add_gravity(layout, gravity, cos, moment_row);
        let (l_sin, l_cos) = (layout.spread(l_sin), layout.spread(l_cos));
        for c in 0..chunks {
            let moment_phi = layout.constant_row(moment_row, c);
            let [px, py] = joint[c];
            v[c] = sin.neg_mul_add(px, cos * py);
            let along = sin.mul_add(py, cos * px);
            coriolis[c] = moment_rate2.neg_mul_add(along, force.mul_add(moment_phi, coriolis[c]));
        }
        // A += (S_l Phi_l)^T v_l^T, row by row.
        for (j, &moment_phi_j) in moment_row[..m].iter().enumerate() {
            let moment_phi_j = Y::Register::splat(rc, moment_phi_j);
            for c in 0..chunks {
                let entry = &mut mass[j * chunks + c];
                *entry = v[c].mul_add(moment_phi_j, *entry);
            }
        }
        for (c, pair) in joint.iter_mut().enumerate() {
            *pair = layout.joint_step(*pair, [l_sin, l_cos], row, c);
        }
        q = [q[0] - drop_x, q[1] - drop_y];
    }
    let g = model.chain().gravity();
    for value in gravity {
        *value = *value * g;
    }
}

/// The `n` rows of `m` values of `rows` (`Phi` or the rows `S_l Phi_l`), each with the
/// [`LINK_PADDING`] values after it that [`Registers::constant_row`](super::Registers::constant_row) may read.
#[inline(always)]
pub(super) fn padded_rows(rows: &[f64], n: usize, m: usize) -> impl Iterator<Item = &[f64]> {
    rows[..n * m + LINK_PADDING]
        .windows(m + LINK_PADDING)
        .step_by(m)
}

/// `gravity += cos(phi_l) S_l Phi_l^T` for link `moment_row` (`S_l Phi_l`, followed by the
/// padding of [`Registers::constant_row`](super::Registers::constant_row)).
#[inline(always)]
pub(super) fn add_gravity<Y: Layout>(
    layout: Y,
    gravity: &mut [Y::Register],
    cos: Y::Register,
    moment_row: &[f64],
) {
    for (c, value) in gravity.iter_mut().enumerate() {
        *value = cos.mul_add(layout.constant_row(moment_row, c), *value);
    }
}

/// The terms left by [`accumulate`] in the registers of `layout`, as numbers of each state:
/// `M* = K + (A + A^T)` (its upper triangle, mirrored), `C*` and `G*`.
#[inline(always)]
pub(crate) fn extract<Y: Layout>(
    layout: Y,
    model: &ReducedModel,
    m: usize,
    terms: &Terms<'_, Y::Register>,
    mass: &mut [Y::Value],
    coriolis: &mut [Y::Value],
    gravity: &mut [Y::Value],
) {
    let chunks = layout.chunks(m);
    let constant = model.constant_mass();
    let vc = layout.value_context();
    for j in 0..m {
        let row = &terms.mass[j * chunks..(j + 1) * chunks];
        for k in j..m {
            let other = &terms.mass[k * chunks..(k + 1) * chunks];
            let sum = layout.coordinate(row, k) + layout.coordinate(other, j);
            let entry = sum + Y::Value::splat(vc, constant[j * m + k]);
            mass[j * m + k] = entry;
            mass[k * m + j] = entry;
        }
        coriolis[j] = layout.coordinate(terms.coriolis, j);
        gravity[j] = layout.coordinate(terms.gravity, j);
    }
}
