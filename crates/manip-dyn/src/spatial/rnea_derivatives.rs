//! Analytic derivatives of inverse dynamics, `d tau / d q`, `d tau / d v` and `M`, in the base
//! frame (Carpentier and Mansard 2018, as Pinocchio's `computeRNEADerivatives` computes them),
//! `O(n^2)`.
//!
//! In the base frame, with `J_i` joint `i`'s axis, `v_i`, `a_i` link `i`'s spatial velocity and
//! acceleration (`a_{-1} = -g`, `v_{-1} = 0`), `I_i` its inertia and `F_i = sum_{j >= i} f_j`
//! the force joint `i` transmits, `tau_i = J_i . F_i`. A change of `q_k` moves links `k..n`
//! rigidly by the screw `J_k`; every base-frame quantity of those links is carried along (which
//! cancels in `tau_i` for `i >= k`) and the velocities and accelerations gain
//! `dv_j = w_k = v_{k-1} x J_k`, `da_j = beta_k + w_k x v_j`,
//! `beta_k = a_{k-1} x J_k - w_k x v_{k-1}`. With the composite inertia
//! `Ic_i = sum_{j >= i} I_j` and Coriolis operator `Bc_i = sum_{j >= i} B_j`,
//! `B_j w = I_j (w x v_j) + w x* I_j v_j + v_j x* I_j w`:
//!
//! ```text
//! d tau_i / d q_k  = J_i . (Ic_i beta_k + Bc_i w_k)                  (i >= k)
//!                  = J_i . (J_k x* F_k + Ic_k beta_k + Bc_k w_k)     (i < k)
//! d tau_i / d qd_k = J_i . (2 Ic_m w_k + Bc_m J_k),  m = max(i, k)
//! d tau_i / d qdd_k = J_i . Ic_m J_k                                 (M)
//! ```
//!
//! For `i >= k` the entries are `P_i . beta_k + Q_i . w_k` with `P_i = Ic_i J_i` and
//! `Q_i = Bc_i^T J_i`; for `i < k`, `J_i . G_k` and `J_i . H_k` with column constants `G_k`,
//! `H_k`: six to nine multiply-adds an entry, computed down each column over the links.
//!
//! Everything runs in the base frame, its origin moved to the first joint's (a translation of
//! the origin changes no joint-space quantity, and keeps the sums' digits when the first joint
//! sits far from the base; `data`'s poses are left in that frame): one sweep base to tip gives `J_i`, `v_i`, `a_i`, `w_i`,
//! `beta_i` and each link's own force `f_i = I_i a_i + v_i x* I_i v_i` (the Newton-Euler
//! recursion with the base-frame axes, `v_i = v_{i-1} + J_i qd_i`,
//! `a_i = a_{i-1} + J_i qdd_i + v_i x J_i qd_i`, no per-link frame change), one sweep tip to
//! base sums `Ic_i`, `Bc_i`, `F_i` and gives `tau_i` with the per-link vectors.
//!
//! The Coriolis operator is sparse. With a body's inertia `[[m E, -[mc]x], [[mc]x, C]]`, its
//! velocity `(v, omega)` and momentum `(h, h_omega) = I (v, omega)`,
//! `B = -I crm(v) + crf(v) I + (w -> w x* h)` has the blocks
//! `B = [[0, -2 [h]x], [0, D]]`, `D = [omega]x C - C [omega]x - [v]x [mc]x - [mc]x [v]x -
//! [h_omega]x` (the mass terms cancel in the left column), so `Bc_i` is the subtree's linear
//! momentum `Hc_i` and a 3 x 3 `Dc_i`, and `Q_i = (0, 2 Hc_i x J_i,linear + Dc_i^T J_i,angular)`.

use faer::{Mat, MatMut};
use lane_math::{Lane, Pack};
use pulp::{Simd, WithSimd};

use super::algebra::{
    Force, Mat3, Motion, RigidSum, Transform, Vec3, add, cross, dot, mat_add, mat_t_vec, mat_vec,
    scale,
};
use super::data::SpatialData;
use super::derivative_data::{
    MAX_LANES, Six, SpatialDerivativeData, column_of, padded, store_first,
};
use super::kinematics::update_poses_about_first_joint;
use super::model::SpatialModel;
use crate::check;
use crate::error::DynError;

/// Inverse dynamics and its analytic derivatives at `(q, v, qdd)`: `tau` (as
/// [`rnea`](super::rnea())), `d tau / d q`, `d tau / d v` and `d tau / d qdd = M`, into
/// `derivatives`. `O(n^2)`, allocation-free; derived in the module documentation.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialDerivativeData, SpatialModel, rnea_derivatives};
/// // A pendulum: tau = (I + m c^2) qdd + m g c cos q, so d tau / d q = -m g c sin q.
/// let pendulum = SpatialModel::from_planar(&ChainModel::uniform(1, 1.0, 2.0, 9.81)?);
/// let mut data = SpatialData::new(&pendulum);
/// let mut derivatives = SpatialDerivativeData::new(&pendulum);
/// rnea_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// assert!((derivatives.d_q()[(0, 0)] + 2.0 * 9.81 * 0.5 * 0.3_f64.sin()).abs() < 1e-12);
/// assert!(derivatives.d_v()[(0, 0)].abs() < 1e-15);
/// assert!((derivatives.d_input()[(0, 0)] - 2.0 / 3.0).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links; [`DynError::Dimension`] if a slice does not have `n` entries or a workspace was built
/// for another chain; [`DynError::NonFinite`] for a NaN or infinite input;
/// [`DynError::NonFiniteResult`] if a result overflows.
pub fn rnea_derivatives(
    model: &SpatialModel,
    data: &mut SpatialData,
    derivatives: &mut SpatialDerivativeData,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
) -> Result<(), DynError> {
    check::dense_count("the RNEA derivatives", model.n_links())?;
    let n = super::check_inputs(model, data, &[("q", q), ("v", v), ("qdd", qdd)])?;
    lane_math::check_len(
        "derivatives (a SpatialDerivativeData built for another model)",
        derivatives.n_links(),
        n,
    )?;
    update_poses_about_first_joint(model, data, q);
    for (i, pose) in data.poses.iter().enumerate() {
        carry_to_base(model, derivatives, i, pose);
    }
    differentiate_at(model, data, derivatives, v, qdd, Jacobians::WithMass)?;
    check::finite_matrix("the derivatives", &derivatives.blocks.as_mut())
}

/// Joint `i`'s axis `J_i` (into the component rows of `d`) and link `i`'s inertia `I_i` (into
/// `d.composite`; a massless link has none) carried to the base frame by the link's pose, for
/// [`differentiate_at`]; returns `J_i`.
#[inline(always)]
pub(crate) fn carry_to_base(
    model: &SpatialModel,
    d: &mut SpatialDerivativeData,
    i: usize,
    pose: &Transform,
) -> Motion {
    let axis = pose.act_motion(&model.axes[i]);
    for (row, value) in d.rows.iter_mut().zip(six_motion(&axis)) {
        row[i] = value;
    }
    if !model.massless[i] {
        d.composite[i] = pose.act_rigid_inertia(&model.inertias[i]);
    }
    axis
}

/// Which matrices [`differentiate_at`] fills, and where.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Jacobians {
    /// `d tau / d q`, `d tau / d v` and `M` into the blocks (`rnea_derivatives`).
    WithMass,
    /// `d tau / d q` and `d tau / d v` into `rhs`, for the product with `-M^-1` of
    /// [`aba_derivatives`](super::aba_derivatives()), which needs no `M`.
    IntoRhs,
}

/// [`rnea_derivatives`] on checked inputs with every link's axis and inertia at `q` already
/// carried to the base frame ([`carry_to_base`]), the matrices of `jacobians` only, and without
/// the test of the matrices (which [`aba_derivatives`](super::aba_derivatives()) makes once, on
/// its own results).
pub(crate) fn differentiate_at(
    model: &SpatialModel,
    data: &mut SpatialData,
    derivatives: &mut SpatialDerivativeData,
    v: &[f64],
    qdd: &[f64],
    jacobians: Jacobians,
) -> Result<(), DynError> {
    let d = derivatives;
    newton_euler_base_frame(model, d, v, qdd);
    differentiate(model, d);
    check::finite_result("tau", &d.value)?;
    let n = model.n_links();
    // Moved out and back (no allocation) so that `Fill` reads the vectors while writing them.
    let target = match jacobians {
        Jacobians::WithMass => &mut d.blocks,
        Jacobians::IntoRhs => &mut d.rhs,
    };
    let mut matrices = std::mem::replace(target, Mat::new());
    let (d_q, rest) = matrices.as_mut().split_at_col_mut(n);
    let (d_v, mass) = rest.split_at_col_mut(n);
    let mass = (jacobians == Jacobians::WithMass).then_some(mass);
    data.arch.dispatch(Fill { d, d_q, d_v, mass });
    match jacobians {
        Jacobians::WithMass => d.blocks = matrices,
        Jacobians::IntoRhs => d.rhs = matrices,
    }
    Ok(())
}

fn six_motion(m: &Motion) -> Six {
    let [a, b, c] = m.linear;
    let [d, e, f] = m.angular;
    [a, b, c, d, e, f]
}

fn six_force(f: &Force) -> Six {
    let [a, b, c] = f.linear;
    let [d, e, g] = f.angular;
    [a, b, c, d, e, g]
}

/// Entry `i` of six component rows (written out: an array `map` here is not inlined).
#[inline(always)]
fn entries<R: AsRef<[f64]>>(rows: &[R], i: usize) -> Six {
    let r = |c: usize| rows[c].as_ref()[i];
    [r(0), r(1), r(2), r(3), r(4), r(5)]
}

fn motion_of(x: &Six) -> Motion {
    Motion {
        linear: [x[0], x[1], x[2]],
        angular: [x[3], x[4], x[5]],
    }
}

fn force_of(x: &Six) -> Force {
    Force {
        linear: [x[0], x[1], x[2]],
        angular: [x[3], x[4], x[5]],
    }
}

/// `[a]x`, the cross-product matrix of `a`.
fn cross_matrix(a: Vec3) -> Mat3 {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

/// The block `D` of one body's Coriolis operator `B = [[0, -2 [h]x], [0, D]]` (module
/// documentation), from its base-frame inertia `inertia`, velocity `(v, omega)` and momentum
/// `(h, h_omega)`: `D = [omega]x C - C [omega]x - [v]x [mc]x - [mc]x [v]x - [h_omega]x`, with
/// `C` the rotational block of the inertia and `mc` its first moment.
fn coriolis_block(inertia: &RigidSum, velocity: &Motion, momentum: &Force) -> Mat3 {
    let mc = inertia.moment;
    let (v, omega) = (velocity.linear, velocity.angular);
    // K = [omega]x C: column k is omega x (column k of C); C [omega]x = -K^T (C symmetric).
    let kt = [
        cross(omega, inertia.rotational[0]),
        cross(omega, inertia.rotational[1]),
        cross(omega, inertia.rotational[2]),
    ];
    // [a]x [b]x = b a^T - (a . b) E.
    let vm = dot(v, mc);
    let hw = cross_matrix(momentum.angular);
    let mut d = [[0.0; 3]; 3];
    for (r, row) in d.iter_mut().enumerate() {
        for (k, entry) in row.iter_mut().enumerate() {
            let diagonal = if r == k { 2.0 * vm } else { 0.0 };
            *entry = kt[k][r] + kt[r][k] + diagonal - mc[r] * v[k] - v[r] * mc[k] - hw[r][k];
        }
    }
    d
}

/// The composite Coriolis operator `[[0, -2 [h]x], [0, d]]` applied to the motion `m`.
fn apply_coriolis(momentum: Vec3, d: &Mat3, m: &Motion) -> Force {
    Force {
        linear: scale(cross(momentum, m.angular), -2.0),
        angular: mat_vec(d, m.angular),
    }
}

/// The Newton-Euler forward sweep in the base frame, base to tip, on the axes `J_i` and
/// inertias `I_i` of [`carry_to_base`] in `d`: each joint's `w_i` and `beta_i`, and each link's
/// own momentum `I_i v_i`, Coriolis block and force `f_i = I_i a_i + v_i x* I_i v_i` (into `g`,
/// until [`differentiate`] replaces it), with `v_i = v_{i-1} + J_i qd_i` and
/// `a_i = a_{i-1} + J_i qdd_i + v_i x J_i qd_i` (a massless link has none of the three).
fn newton_euler_base_frame(
    model: &SpatialModel,
    d: &mut SpatialDerivativeData,
    v: &[f64],
    qdd: &[f64],
) {
    let g = model.gravity();
    let mut velocity = Motion::default();
    let mut acceleration = Motion {
        linear: [-g[0], -g[1], -g[2]],
        angular: [0.0; 3],
    };
    for i in 0..model.n_links() {
        let axis = motion_of(&entries(&d.rows[..6], i));
        let w = velocity.cross_motion(&axis);
        let beta = acceleration
            .cross_motion(&axis)
            .plus(&w.cross_motion(&velocity).times(-1.0));
        let joint_velocity = axis.times(v[i]);
        velocity = velocity.plus(&joint_velocity);
        acceleration = acceleration
            .plus(&axis.times(qdd[i]))
            .plus(&velocity.cross_motion(&joint_velocity));
        d.w[i] = six_motion(&w);
        d.beta[i] = six_motion(&beta);
        if model.massless[i] {
            continue;
        }
        let inertia = &d.composite[i];
        let own = inertia.apply(&velocity);
        let force = inertia
            .apply(&acceleration)
            .plus(&velocity.cross_force(&own));
        d.coriolis[i] = coriolis_block(inertia, &velocity, &own);
        d.momentum[i] = own.linear;
        d.g[i] = six_force(&force);
    }
}

/// Tip to base, from what [`newton_euler_base_frame`] left: the subtree sums (composite
/// inertia `Ic_i`, momentum `Hc_i`, Coriolis block `Dc_i` and transmitted force `F_i`),
/// `tau_i = J_i . F_i`, and the per-link vectors `P_i`, `Q_i`, `G_i`, `H_i` of the entries.
fn differentiate(model: &SpatialModel, d: &mut SpatialDerivativeData) {
    let mut composite = RigidSum::default();
    let mut momentum = [0.0; 3];
    let mut coriolis = [[0.0; 3]; 3];
    let mut force = Force::default();
    for i in (0..model.n_links()).rev() {
        // A massless link adds nothing to the sums.
        if !model.massless[i] {
            composite = d.composite[i].plus(&composite);
            momentum = add(d.momentum[i], momentum);
            coriolis = mat_add(&d.coriolis[i], &coriolis);
            force = force_of(&d.g[i]).plus(&force);
        }
        let axis = motion_of(&entries(&d.rows[..6], i));
        let (w, beta) = (motion_of(&d.w[i]), motion_of(&d.beta[i]));
        d.value[i] = axis.dot(&force);
        let p = composite.apply(&axis);
        // Q = Bc^T J = (0, 2 Hc x J_linear + Dc^T J_angular).
        let q = add(
            scale(cross(momentum, axis.linear), 2.0),
            mat_t_vec(&coriolis, axis.angular),
        );
        for (row, value) in d.rows[6..]
            .iter_mut()
            .zip(six_force(&p).into_iter().chain(q))
        {
            row[i] = value;
        }
        d.g[i] = six_force(
            &axis
                .cross_force(&force)
                .plus(&composite.apply(&beta))
                .plus(&apply_coriolis(momentum, &coriolis, &w)),
        );
        d.h[i] = six_force(
            &composite
                .apply(&w)
                .times(2.0)
                .plus(&apply_coriolis(momentum, &coriolis, &axis)),
        );
    }
}

/// The entries of the matrices (`M` when `mass` is given) from the per-link vectors, column
/// by column, each entry a sum of products down the component rows in SIMD registers (under
/// [`pulp::Arch::dispatch`]), stored straight into the matrices.
struct Fill<'a> {
    d: &'a SpatialDerivativeData,
    d_q: MatMut<'a, f64>,
    d_v: MatMut<'a, f64>,
    mass: Option<MatMut<'a, f64>>,
}

impl WithSimd for Fill<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Fill {
            d,
            mut d_q,
            mut d_v,
            mut mass,
        } = self;
        let n = d.value.len();
        let r = |c: usize| &d.rows[c][..padded(n)];
        let axes = [r(0), r(1), r(2), r(3), r(4), r(5)];
        let p = [r(6), r(7), r(8), r(9), r(10), r(11)];
        let pq = [r(6), r(7), r(8), r(9), r(10), r(11), r(12), r(13), r(14)];
        for k in 0..n {
            let axis = entries(&axes, k);
            let p_k = entries(&p, k);
            let (w, beta) = (&d.w[k], &d.beta[k]);
            let dq = [
                beta[0], beta[1], beta[2], beta[3], beta[4], beta[5], w[3], w[4], w[5],
            ];
            let dv = [
                2.0 * w[0],
                2.0 * w[1],
                2.0 * w[2],
                2.0 * w[3],
                2.0 * w[4],
                2.0 * w[5],
                axis[3],
                axis[4],
                axis[5],
            ];
            // i < k: J_i . G_k; i >= k: P_i . beta_k + Q_i . w_k.
            let column = column_of(&mut d_q, k);
            combine(simd, &mut column[..k], &axes, &d.g[k], 0);
            combine(simd, &mut column[k..], &pq, &dq, k);
            // i < k: J_i . H_k; i >= k: 2 P_i . w_k + Q_i . J_k.
            let column = column_of(&mut d_v, k);
            combine(simd, &mut column[..k], &axes, &d.h[k], 0);
            combine(simd, &mut column[k..], &pq, &dv, k);
            // M: i < k: J_i . P_k; i >= k: P_i . J_k.
            if let Some(mass) = mass.as_mut() {
                let column = column_of(mass, k);
                combine(simd, &mut column[..k], &axes, &p_k, 0);
                combine(simd, &mut column[k..], &p, &axis, k);
            }
        }
    }
}

/// `out[j] = sum_c rows[c][first + j] x[c]`, a register of `S` at a time (the rows hold a
/// whole register past `first + out.len()`; the last, partial register goes through
/// [`store_first`]).
#[inline(always)]
fn combine<S: Simd, const C: usize>(
    simd: S,
    out: &mut [f64],
    rows: &[&[f64]; C],
    x: &[f64; C],
    first: usize,
) {
    let width = Pack::<S>::WIDTH;
    let mut factors = [Pack::splat(simd, 0.0); C];
    for (factor, &value) in factors.iter_mut().zip(x) {
        *factor = Pack::splat(simd, value);
    }
    let mut at = 0;
    while at < out.len() {
        let row = first + at;
        let mut sum = Pack::load(simd, &rows[0][row..]) * factors[0];
        for c in 1..C {
            sum = Pack::load(simd, &rows[c][row..]).mul_add(factors[c], sum);
        }
        if at + width <= out.len() {
            sum.store(&mut out[at..]);
        } else {
            let mut last = [0.0; MAX_LANES];
            sum.store(&mut last);
            let rows = out.len() - at;
            store_first(&mut out[at..], &last, rows);
        }
        at += width;
    }
}
