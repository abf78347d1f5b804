//! Forward dynamics by the articulated-body algorithm (ABA), `O(n)`, in link frames (Featherstone
//! 2008, table 7.1; Pinocchio's `aba`).
//!
//! Three sweeps. Base to tip: each link's placement `X_i` in its parent, velocity
//! `v_i = X_i^-1 v_{i-1} + S_i qd_i`, velocity-product acceleration `c_i = v_i x S_i qd_i` and
//! bias force `p_i = v_i x* I_i v_i`. Tip to base: the articulated inertia `IA_i = I_i +
//! X_{i+1}^-T IA'_{i+1} X_{i+1}^-1` and bias `pA_i`, `U_i = IA_i S_i`, `D_i = S_i^T U_i`,
//! `u_i = tau_i - S_i^T pA_i`, and what link `i` passes to its parent once its joint
//! acceleration is solved out: `IA'_i = IA_i - U_i U_i^T / D_i`,
//! `pA'_i = pA_i + IA'_i c_i + U_i u_i / D_i`. Base to tip: `a_0 = -g` (gravity as an upward
//! acceleration of the base), `a'_i = X_i^-1 a_{i-1} + c_i`, `qdd_i = (u_i - U_i^T a'_i) / D_i`,
//! `a_i = a'_i + S_i qdd_i`.
//!
//! Written once, as [`kernel`], over the number type [`AbaLane`] (`f64` for one state, a SIMD
//! register of states for [`aba_batch`](super::aba_batch())) with the same operations in the same
//! order, so a state gives the same bits alone and in a batch; the sines and cosines of all joint
//! values come first, at once, from [`lane_math::sin_cos`].

use lane_math::Lane;

use super::algebra::{Force, Mat3, Motion, Symmetric6, Transform, Vec3, splat3, sub};
use super::data::{AbaLink, SpatialData};
use super::kinematics::joint_placement;
use super::model::SpatialModel;
use crate::aba::AbaLane;
use crate::check;
use crate::error::DynError;

/// Forward dynamics by the articulated-body algorithm: the joint accelerations `qdd` that the
/// torques (or forces, for prismatic joints) `tau` produce at the state `(q, v)`, in `O(n)`.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialModel, aba};
/// let pendulum = SpatialModel::from_planar(&ChainModel::uniform(1, 1.0, 3.0, 9.81)?);
/// let mut data = SpatialData::new(&pendulum);
/// let mut qdd = [0.0];
/// aba(&pendulum, &mut data, &[0.0], &[0.0], &[0.0], &mut qdd)?;
/// // Released horizontally: qdd = -m g c / (m L^2 / 3) = -1.5 g / L.
/// assert!((qdd[0] + 1.5 * 9.81).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::SingularJoint`]
/// naming the first joint (from the tip) whose articulated inertia about its axis is not positive
/// beyond rounding (a joint that moves no mass or inertia, or link parameters too disparate for
/// double precision),
/// [`DynError::NonFiniteResult`] if the accelerations overflow.
pub fn aba(
    model: &SpatialModel,
    data: &mut SpatialData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let n = super::check_inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::output("qdd", qdd, n)?;
    let buffers = AbaBuffers {
        angle: &mut data.angle,
        sin: &mut data.sin,
        cos: &mut data.cos,
        links: &mut data.articulated,
        arch: data.arch,
    };
    kernel::<f64>((), model, buffers, [q, v, tau], qdd)?;
    check::finite_result("qdd", qdd)
}

/// The joint, if any, that moves no mass or inertia at the positions `q` (its link and every link
/// beyond massless, or their masses on its axis), so that the mass matrix is singular there:
/// [`aba`] at rest with no torque, its [`DynError::SingularJoint`]. `None` as well when [`aba`]
/// refuses `q` for another reason (its length, a non-finite entry), which is the caller's to
/// name. Allocates its workspace: a check before a run, not per-step code.
pub fn singular_joint(model: &SpatialModel, q: &[f64]) -> Option<usize> {
    let n = model.n_links();
    let mut data = SpatialData::new(model);
    let zeros = vec![0.0; n];
    let mut qdd = vec![0.0; n];
    match aba(model, &mut data, q, &zeros, &zeros, &mut qdd) {
        Err(DynError::SingularJoint { index }) => Some(index),
        _ => None,
    }
}

/// The per-link workspace of [`kernel`] for `L::WIDTH` states: `angle`, `sin` and `cos` hold `n`
/// values of `WIDTH` lanes each (`[link][lane]`), `links` one slot a link.
pub(crate) struct AbaBuffers<'a, T> {
    pub(crate) angle: &'a mut [f64],
    pub(crate) sin: &'a mut [f64],
    pub(crate) cos: &'a mut [f64],
    pub(crate) links: &'a mut [AbaLink<T>],
    pub(crate) arch: pulp::Arch,
}

#[inline(always)]
fn get3<L: AbaLane>(context: L::Context, slots: &[L::Slot; 3]) -> Vec3<L> {
    [
        L::get(context, &slots[0]),
        L::get(context, &slots[1]),
        L::get(context, &slots[2]),
    ]
}

#[inline(always)]
fn get33<L: AbaLane>(context: L::Context, slots: &[[L::Slot; 3]; 3]) -> Mat3<L> {
    [
        get3::<L>(context, &slots[0]),
        get3::<L>(context, &slots[1]),
        get3::<L>(context, &slots[2]),
    ]
}

#[inline(always)]
fn set3<L: AbaLane>(values: Vec3<L>, slots: &mut [L::Slot; 3]) {
    let [x, y, z] = values;
    x.set(&mut slots[0]);
    y.set(&mut slots[1]);
    z.set(&mut slots[2]);
}

/// The articulated-body algorithm for `L::WIDTH` states: `inputs` are `q`, `v` and `tau`, each
/// `WIDTH` states of `n` values one after another (row-major), and `qdd` gets the accelerations
/// in the same layout. Inputs finite, sizes checked by the caller.
#[inline(always)]
pub(crate) fn kernel<L: AbaLane>(
    context: L::Context,
    model: &SpatialModel,
    buffers: AbaBuffers<'_, L::Slot>,
    inputs: [&[f64]; 3],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let n = model.n_links();
    let width = L::WIDTH;
    let [q, v, tau] = inputs;
    let AbaBuffers {
        angle,
        sin,
        cos,
        links,
        arch,
    } = buffers;
    let (angle, sin, cos) = (
        &mut angle[..n * width],
        &mut sin[..n * width],
        &mut cos[..n * width],
    );
    let links = &mut links[..n];
    for (i, lanes) in angle.chunks_exact_mut(width).enumerate() {
        L::gather(context, q, n, i).store(lanes);
    }
    L::sin_cos_all(arch, angle, sin, cos);
    let zero = L::splat(context, 0.0);
    let zero3 = [zero; 3];

    // Base to tip: placements, velocities, velocity-product accelerations, bias forces.
    let mut velocity = Motion {
        linear: zero3,
        angular: zero3,
    };
    for (i, link) in links.iter_mut().enumerate() {
        let at = i * width;
        let placement = joint_placement(
            context,
            &model.joints()[i],
            L::load(context, &angle[at..]),
            L::load(context, &sin[at..]),
            L::load(context, &cos[at..]),
        );
        let axis = splat_motion::<L>(context, &model.axes[i]);
        let joint_velocity = axis.times(L::gather(context, v, n, i));
        velocity = placement.inv_act_motion(&velocity).plus(&joint_velocity);
        let bias = velocity.cross_motion(&joint_velocity);
        // A massless link (the cross of a universal joint) has no bias force.
        let force = if model.massless[i] {
            Force {
                linear: zero3,
                angular: zero3,
            }
        } else {
            let momentum = model.inertias[i].apply(context, &velocity);
            velocity.cross_force(&momentum)
        };
        for (r, row) in placement.rotation.into_iter().enumerate() {
            set3::<L>(row, &mut link.rotation[r]);
        }
        set3::<L>(placement.translation, &mut link.translation);
        set3::<L>(bias.linear, &mut link.bias[0]);
        set3::<L>(bias.angular, &mut link.bias[1]);
        set3::<L>(force.linear, &mut link.force[0]);
        set3::<L>(force.angular, &mut link.force[1]);
    }

    // Tip to base: articulated inertias and biases, each joint's acceleration solved out.
    let mut carried_inertia = Symmetric6 {
        a: [zero3; 3],
        b: [zero3; 3],
        c: [zero3; 3],
    };
    let mut carried_force = Force {
        linear: zero3,
        angular: zero3,
    };
    for i in (0..n).rev() {
        let link = &mut links[i];
        // A massless link adds no inertia and no bias force to what its children pass.
        let (inertia, force) = if model.massless[i] {
            (carried_inertia, carried_force)
        } else {
            let own = Force {
                linear: get3::<L>(context, &link.force[0]),
                angular: get3::<L>(context, &link.force[1]),
            };
            (
                Symmetric6::splat(context, &model.matrices[i]).plus(&carried_inertia),
                own.plus(&carried_force),
            )
        };
        let axis = splat_motion::<L>(context, &model.axes[i]);
        let coupling = inertia.apply(&axis);
        let pivot = axis.dot(&coupling);
        L::check_pivot(context, pivot, L::splat(context, model.pivot_scales[i])).map_err(
            |error| match error {
                DynError::NotPositiveDefinite => DynError::SingularJoint { index: i },
                other => other,
            },
        )?;
        let inverse = L::splat(context, 1.0) / pivot;
        let residual = L::gather(context, tau, n, i) - axis.dot(&force);
        set3::<L>(coupling.linear, &mut link.coupling[0]);
        set3::<L>(coupling.angular, &mut link.coupling[1]);
        inverse.set(&mut link.inverse);
        residual.set(&mut link.residual);
        if i > 0 {
            let placement = Transform {
                rotation: get33::<L>(context, &link.rotation),
                translation: get3::<L>(context, &link.translation),
            };
            let bias = Motion {
                linear: get3::<L>(context, &link.bias[0]),
                angular: get3::<L>(context, &link.bias[1]),
            };
            let condensed = inertia.minus_outer(&coupling, inverse);
            let passed = force
                .plus(&condensed.apply(&bias))
                .plus(&coupling.times(residual * inverse));
            carried_inertia = placement.act_inertia(&condensed);
            carried_force = placement.act_force(&passed);
        }
    }

    // Base to tip: accelerations.
    let mut acceleration = Motion {
        linear: sub(zero3, splat3(context, model.gravity())),
        angular: zero3,
    };
    for (i, link) in links.iter().enumerate() {
        let placement = Transform {
            rotation: get33::<L>(context, &link.rotation),
            translation: get3::<L>(context, &link.translation),
        };
        let bias = Motion {
            linear: get3::<L>(context, &link.bias[0]),
            angular: get3::<L>(context, &link.bias[1]),
        };
        let coupling = Force {
            linear: get3::<L>(context, &link.coupling[0]),
            angular: get3::<L>(context, &link.coupling[1]),
        };
        acceleration = placement.inv_act_motion(&acceleration).plus(&bias);
        let residual = L::get(context, &link.residual);
        let joint = (residual - acceleration.dot(&coupling)) * L::get(context, &link.inverse);
        joint.scatter(qdd, n, i);
        let axis = splat_motion::<L>(context, &model.axes[i]);
        acceleration = acceleration.plus(&axis.times(joint));
    }
    Ok(())
}

/// A model's motion vector as the number type `L`.
#[inline(always)]
fn splat_motion<L: Lane>(context: L::Context, m: &Motion) -> Motion<L> {
    Motion {
        linear: splat3(context, m.linear),
        angular: splat3(context, m.angular),
    }
}
