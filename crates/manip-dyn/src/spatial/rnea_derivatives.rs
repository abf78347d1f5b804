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
//! `H_k`: six or twelve multiply-adds an entry.

use faer::{Mat, MatMut};

use super::algebra::{Force, Motion, Symmetric6};
use super::data::SpatialData;
use super::derivative_data::{Six, SpatialDerivativeData};
use super::kinematics::update_poses;
use super::model::SpatialModel;
use super::rnea::newton_euler;
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
    update_poses(model, data, q);
    newton_euler(
        model,
        data,
        Some(v),
        Some(qdd),
        true,
        &mut derivatives.value,
    );
    check::finite_result("tau", &derivatives.value)?;
    differentiate(model, data, derivatives);
    check::finite_matrix("the derivatives", &derivatives.blocks.as_mut())
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

fn motion(x: &Six) -> Motion {
    Motion {
        linear: [x[0], x[1], x[2]],
        angular: [x[3], x[4], x[5]],
    }
}

fn dot6(a: &Six, b: &Six) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn add6(a: &Six, b: &Six) -> Six {
    [0, 1, 2, 3, 4, 5].map(|k| a[k] + b[k])
}

/// `B m` for the 6 x 6 operator stored by columns.
fn apply_columns(columns: &[Six; 6], m: &Six) -> Six {
    [0, 1, 2, 3, 4, 5].map(|r| (0..6).map(|c| columns[c][r] * m[c]).sum())
}

/// The derivative matrices from the Newton-Euler pass left in `data` (link-frame velocities,
/// accelerations and transmitted forces, and the poses).
fn differentiate(
    model: &SpatialModel,
    data: &SpatialData,
    derivatives: &mut SpatialDerivativeData,
) {
    let n = model.n_links();
    let d = derivatives;
    // Tip to base: composite inertia and Coriolis operator in the base frame.
    for i in (0..n).rev() {
        let pose = &data.poses[i];
        let inertia = pose.act_inertia(&model.matrices[i]);
        let velocity = pose.act_motion(&data.velocities[i]);
        let momentum = inertia.apply(&velocity);
        let mut operator = [[0.0; 6]; 6];
        for (c, column) in operator.iter_mut().enumerate() {
            let mut unit = [0.0; 6];
            unit[c] = 1.0;
            let e = motion(&unit);
            let f = inertia
                .apply(&e.cross_motion(&velocity))
                .plus(&e.cross_force(&momentum))
                .plus(&velocity.cross_force(&inertia.apply(&e)));
            *column = six_force(&f);
        }
        if i + 1 < n {
            d.composite[i] = inertia.plus(&d.composite[i + 1]);
            for (column, child) in operator.iter_mut().zip(&d.coriolis[i + 1]) {
                *column = add6(column, child);
            }
        } else {
            d.composite[i] = inertia;
        }
        d.coriolis[i] = operator;
    }
    // Base to tip: the per-link vectors.
    let g = model.gravity();
    let mut parent_velocity = Motion::default();
    let mut parent_acceleration = Motion {
        linear: [-g[0], -g[1], -g[2]],
        angular: [0.0; 3],
    };
    for i in 0..n {
        let pose = &data.poses[i];
        let axis = pose.act_motion(&model.axes[i]);
        let composite: &Symmetric6 = &d.composite[i];
        let w = parent_velocity.cross_motion(&axis);
        let beta = parent_acceleration
            .cross_motion(&axis)
            .plus(&w.cross_motion(&parent_velocity).times(-1.0));
        let force = pose.act_force(&data.forces[i]);
        let axis6 = six_motion(&axis);
        let coriolis = &d.coriolis[i];
        d.axis[i] = axis6;
        d.p[i] = six_force(&composite.apply(&axis));
        d.q[i] = [0, 1, 2, 3, 4, 5].map(|c| dot6(&coriolis[c], &axis6));
        d.w[i] = six_motion(&w);
        d.beta[i] = six_motion(&beta);
        let bw = apply_columns(coriolis, &d.w[i]);
        d.g[i] = add6(
            &add6(
                &six_force(&axis.cross_force(&force)),
                &six_force(&composite.apply(&beta)),
            ),
            &bw,
        );
        d.h[i] = add6(
            &six_force(&composite.apply(&w).times(2.0)),
            &apply_columns(coriolis, &axis6),
        );
        parent_velocity = pose.act_motion(&data.velocities[i]);
        parent_acceleration = pose.act_motion(&data.accelerations[i]);
    }
    // Moved out and back (no allocation) so that `fill` reads the vectors while writing it.
    let mut blocks = std::mem::replace(&mut d.blocks, Mat::new());
    let (mut d_q, rest) = blocks.as_mut().split_at_col_mut(n);
    let (mut d_v, mut mass) = rest.split_at_col_mut(n);
    fill(d, &mut d_q, &mut d_v, &mut mass);
    d.blocks = blocks;
}

/// The entries of the three matrices from the per-link vectors.
fn fill(
    d: &SpatialDerivativeData,
    d_q: &mut MatMut<'_, f64>,
    d_v: &mut MatMut<'_, f64>,
    mass: &mut MatMut<'_, f64>,
) {
    let n = d.value.len();
    for k in 0..n {
        for i in 0..n {
            if i >= k {
                d_q[(i, k)] = dot6(&d.p[i], &d.beta[k]) + dot6(&d.q[i], &d.w[k]);
                d_v[(i, k)] = 2.0 * dot6(&d.p[i], &d.w[k]) + dot6(&d.q[i], &d.axis[k]);
                let entry = dot6(&d.p[i], &d.axis[k]);
                mass[(i, k)] = entry;
                mass[(k, i)] = entry;
            } else {
                d_q[(i, k)] = dot6(&d.axis[i], &d.g[k]);
                d_v[(i, k)] = dot6(&d.axis[i], &d.h[k]);
            }
        }
    }
}
