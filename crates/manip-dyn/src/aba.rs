//! Forward dynamics by the articulated-body algorithm (ABA), O(n).
//!
//! Planar spatial vectors, all in base-frame axes and each referred to a point: a motion
//! `(alpha, a_x, a_y)` is a body's angular acceleration and the acceleration of its material point
//! at the reference point; a force `(n, f_x, f_y)` is a moment about the reference point and a
//! force. Link `i`'s quantities are referred to its joint `p_i`. Moving a motion from `p_i` to
//! `p_{i+1} = p_i + d` multiplies it by `X(d) = [[1, 0, 0], [-d_y, 1, 0], [d_x, 0, 1]]`; moving a
//! force back from `p_{i+1}` to `p_i` multiplies it by `X(d)^T`. The joint's motion axis is
//! `S = (1, 0, 0)`.
//!
//! Link `i` obeys `f_i = H_i A_i + b_i + X_i^T f_{i+1}`, with `f_i` the force it receives from its
//! parent, `A_i` its acceleration, `H_i` its inertia about `p_i` and `b_i = (0, -m c omega^2 u)`
//! the centripetal bias; the child's acceleration is `A_{i+1} = X_i A_i + beta_i + S qdd_{i+1}`,
//! `beta_i = (0, -L omega^2 u)`, and `tau_i = S^T f_i`. Gravity is an upward acceleration of the
//! base. The backward sweep condenses the chain tip-first into articulated inertias
//! `f_i = IA_i A_i + pA_i`; the forward sweep then solves each joint's acceleration.
//!
//! The algorithm is written once, as [`kernel`], over the number type [`AbaLane`]: `f64` for one
//! state ([`aba`]) and a SIMD register of several states side by side for a batch
//! ([`aba_batch`](crate::aba_batch())), with the same operations in the same order, so a state
//! gives the same bits alone or in a batch. Three passes: the absolute angles and rates from the
//! base, then the sines and cosines of all angles at once (`lane_math::sin_cos`); the backward
//! sweep; the forward sweep. Both sweeps are written so that the chain of dependent operations
//! from one link to the next is short (one division, and a few multiply-adds), since at `n = 10`
//! their latency, not the operation count, bounds the time.

use lane_math::{Lane, Pack, sin_cos};
use pulp::{Arch, Simd, WithSimd};

use crate::check;
use crate::data::{ArticulatedLink, ChainData, LinkFrame};
use crate::error::DynError;
use crate::model::ChainModel;

/// The number type of [`kernel`]: a [`Lane`] with a storage form for the values kept per link
/// between the passes, loads of a link's inputs from row-major states, and the pivot test.
pub(crate) trait AbaLane: Lane {
    /// One value per link in the workspace: `f64`, or [`MAX_WIDTH`] lanes.
    type Slot: Copy + Default + std::fmt::Debug;
    /// The value held in `slot`.
    fn get(context: Self::Context, slot: &Self::Slot) -> Self;
    /// Stores `self` into `slot`.
    fn set(self, slot: &mut Self::Slot);
    /// Entry `i` of each of the `WIDTH` states of `rows` (row-major, `n` values a state).
    fn gather(context: Self::Context, rows: &[f64], n: usize, i: usize) -> Self;
    /// Writes the lanes into entry `i` of each state of `rows`.
    fn scatter(self, rows: &mut [f64], n: usize, i: usize);
    /// The pivot test of [`check::pivot`]: `Ok` if `pivot` is finite and above
    /// `PIVOT_FLOOR * scale` in every lane. One state gets the exact error; a batch gets
    /// `NotPositiveDefinite` for any failing lane (its states are then redone one at a time),
    /// and never passes what the exact test refuses.
    fn check_pivot(context: Self::Context, pivot: Self, scale: Self) -> Result<(), DynError>;
    /// The sines and cosines of `angle` into `sin` and `cos` ([`lane_math::sin_cos`]): for one
    /// state through a dispatch to `arch`, for a batch in the batch's own dispatch.
    fn sin_cos_all(arch: Arch, angle: &[f64], sin: &mut [f64], cos: &mut [f64]);
}

/// The most `f64` lanes of a SIMD register (AVX-512).
pub(crate) const MAX_WIDTH: usize = 8;

impl AbaLane for f64 {
    type Slot = f64;

    #[inline(always)]
    fn get((): (), slot: &f64) -> f64 {
        *slot
    }

    #[inline(always)]
    fn set(self, slot: &mut f64) {
        *slot = self;
    }

    #[inline(always)]
    fn gather((): (), rows: &[f64], _n: usize, i: usize) -> f64 {
        rows[i]
    }

    #[inline(always)]
    fn scatter(self, rows: &mut [f64], _n: usize, i: usize) {
        rows[i] = self;
    }

    #[inline(always)]
    fn check_pivot((): (), pivot: f64, scale: f64) -> Result<(), DynError> {
        check::pivot("articulated inertia", pivot, scale)
    }

    #[inline(always)]
    fn sin_cos_all(arch: Arch, angle: &[f64], sin: &mut [f64], cos: &mut [f64]) {
        arch.dispatch(SinCos { angle, sin, cos });
    }
}

impl<S: Simd> AbaLane for Pack<S> {
    type Slot = [f64; MAX_WIDTH];

    #[inline(always)]
    fn get(simd: S, slot: &[f64; MAX_WIDTH]) -> Self {
        Self::load(simd, slot)
    }

    #[inline(always)]
    fn set(self, slot: &mut [f64; MAX_WIDTH]) {
        self.store(slot);
    }

    #[inline(always)]
    fn gather(simd: S, rows: &[f64], n: usize, i: usize) -> Self {
        let mut lanes = [0.0; MAX_WIDTH];
        for (lane, slot) in lanes[..Self::WIDTH].iter_mut().enumerate() {
            *slot = rows[lane * n + i];
        }
        Self::load(simd, &lanes)
    }

    #[inline(always)]
    fn scatter(self, rows: &mut [f64], n: usize, i: usize) {
        let mut lanes = [0.0; MAX_WIDTH];
        self.store(&mut lanes);
        for (lane, &value) in lanes[..Self::WIDTH].iter().enumerate() {
            rows[lane * n + i] = value;
        }
    }

    #[inline(always)]
    fn check_pivot(simd: S, pivot: Self, scale: Self) -> Result<(), DynError> {
        // pivot > PIVOT_FLOOR * scale by the sign of their difference (exact for finite
        // doubles), pivot below infinity and above the largest subnormal (`check::pivot`):
        // three vector compares. A NaN fails them all.
        let margin = pivot - scale * check::PIVOT_FLOOR;
        let finite = Self::splat(simd, f64::INFINITY).all_greater(pivot);
        let largest_subnormal = f64::from_bits(f64::MIN_POSITIVE.to_bits() - 1);
        if finite
            && margin.all_greater(Self::splat(simd, 0.0))
            && pivot.all_greater(Self::splat(simd, largest_subnormal))
        {
            Ok(())
        } else {
            Err(DynError::NotPositiveDefinite)
        }
    }

    #[inline(always)]
    fn sin_cos_all(_: Arch, angle: &[f64], sin: &mut [f64], cos: &mut [f64]) {
        sin_cos(angle, sin, cos);
    }
}

/// Forward dynamics by the articulated-body algorithm: the joint accelerations `qdd` that the
/// torques `tau` produce at the state `(q, v)`, solving eq 12 for `theta_ddot` in O(n).
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, aba};
/// let pendulum = ChainModel::uniform(1, 1.0, 3.0, 9.81)?;
/// let mut data = ChainData::new(&pendulum);
/// let mut qdd = [0.0];
/// aba(&pendulum, &mut data, &[0.0], &[0.0], &[0.0], &mut qdd)?;
/// // Released horizontally: qdd = -m g c / (m L^2 / 3) = -1.5 g / L.
/// assert!((qdd[0] + 1.5 * 9.81).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` was built for another
/// chain, [`DynError::NonFinite`] for a NaN or infinite input, [`DynError::NotPositiveDefinite`]
/// if an articulated inertia about a joint axis is not positive beyond rounding (link parameters
/// too disparate for double precision), [`DynError::NonFiniteResult`] if the accelerations
/// overflow.
pub fn aba(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::output("qdd", qdd, n)?;
    articulated_body(model, data, q, v, tau, qdd)?;
    check::finite_result("qdd", qdd)
}

/// The articulated-body algorithm on validated inputs. Leaves the link frames of `(q, v)` in
/// `data.frames` and each joint's articulated inertia in `data.articulated`.
pub(crate) fn articulated_body(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let links = LinkBuffers {
        angle: &mut data.angle,
        sin: &mut data.sin,
        cos: &mut data.cos,
        frames: &mut data.frames,
        articulated: &mut data.articulated,
        arch: data.arch,
    };
    kernel::<f64>((), model, links, [q, v, tau], qdd)
}

/// [`lane_math::sin_cos`] run by [`pulp::Arch::dispatch`], so that it is compiled for the
/// processor's instruction set: it vectorises, and its fused multiply-adds are single
/// instructions. (Only the sines and cosines of one state: its sweeps, chains of dependent
/// scalar operations, gain nothing from the instruction set; with them in the dispatch too, one
/// state measured no faster.)
struct SinCos<'a> {
    angle: &'a [f64],
    sin: &'a mut [f64],
    cos: &'a mut [f64],
}

impl WithSimd for SinCos<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        sin_cos(self.angle, self.sin, self.cos);
    }
}

/// The per-link workspace of [`kernel`] for `L::WIDTH` states: `angle`, `sin` and `cos` hold
/// `n` values of `WIDTH` lanes each (`[link][lane]`), the others one slot a link.
pub(crate) struct LinkBuffers<'a, T> {
    /// Absolute angle `phi_i`, then its sine and cosine.
    pub(crate) angle: &'a mut [f64],
    pub(crate) sin: &'a mut [f64],
    pub(crate) cos: &'a mut [f64],
    /// Direction and angular velocity of each link.
    pub(crate) frames: &'a mut [LinkFrame<T>],
    /// Articulated-body quantities of each joint.
    pub(crate) articulated: &'a mut [ArticulatedLink<T>],
    /// The processor's instruction set, for one state's sines and cosines
    /// ([`AbaLane::sin_cos_all`]).
    pub(crate) arch: Arch,
}

/// The articulated-body algorithm for `L::WIDTH` states: `inputs` are `q`, `v` and `tau`, each
/// `WIDTH` states of `n` values one after another (row-major), and `qdd` gets the accelerations
/// in the same layout. Inputs finite, sizes checked by the caller.
#[inline(always)]
pub(crate) fn kernel<L: AbaLane>(
    context: L::Context,
    model: &ChainModel,
    links: LinkBuffers<'_, L::Slot>,
    inputs: [&[f64]; 3],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let n = model.n_links();
    let width = L::WIDTH;
    let [q, v, tau] = inputs;
    let LinkBuffers {
        angle,
        sin,
        cos,
        frames,
        articulated,
        arch,
    } = links;
    let (angle, sin, cos) = (
        &mut angle[..n * width],
        &mut sin[..n * width],
        &mut cos[..n * width],
    );
    let (frames, articulated) = (&mut frames[..n], &mut articulated[..n]);
    let zero = L::splat(context, 0.0);
    // The absolute angles and rates, base first.
    let (mut phi, mut omega) = (zero, zero);
    for (i, (angle, frame)) in angle
        .chunks_exact_mut(width)
        .zip(frames.iter_mut())
        .enumerate()
    {
        phi = phi + L::gather(context, q, n, i);
        omega = omega + L::gather(context, v, n, i);
        phi.store(angle);
        omega.set(&mut frame.omega);
    }
    L::sin_cos_all(arch, angle, sin, cos);
    backward_sweep::<L>(context, model, sin, cos, tau, frames, articulated)?;
    forward_sweep::<L>(context, model, frames, articulated, qdd);
    Ok(())
}

/// Condenses the chain from the tip: the articulated inertia and bias force of each joint, and
/// each link's direction into `frames`.
///
/// What link `i` sees of the links beyond it, once their joint accelerations are solved out, is
/// `f = IA' A + pA'` at joint `i + 1` with `IA' = [[0, 0], [0, K]]` and `pA' = (tau_{i+1},
/// force)`: `K`, the symmetric 2 x 2 resistance to translating the joint, is `[k_xx, k_xy,
/// k_yy]`. The rotational row of `IA'` vanishes and the moment of `pA'` is the joint torque
/// because a revolute joint transmits no other moment.
#[inline(always)]
fn backward_sweep<L: AbaLane>(
    context: L::Context,
    model: &ChainModel,
    sin: &[f64],
    cos: &[f64],
    tau: &[f64],
    frames: &mut [LinkFrame<L::Slot>],
    articulated: &mut [ArticulatedLink<L::Slot>],
) -> Result<(), DynError> {
    let n = model.n_links();
    let width = L::WIDTH;
    let zero = L::splat(context, 0.0);
    let (mut kxx, mut kxy, mut kyy) = (zero, zero, zero);
    let (mut fx, mut fy, mut torque) = (zero, zero, zero);
    for i in (0..n).rev() {
        let link = &model.links()[i];
        let (s, c) = (
            L::load(context, &sin[i * width..]),
            L::load(context, &cos[i * width..]),
        );
        let frame = &mut frames[i];
        c.set(&mut frame.axis[0]);
        s.set(&mut frame.axis[1]);
        let omega = L::get(context, &frame.omega);
        let w2 = omega * omega;
        // Joint i + 1 is at d = L u; r = e_z x d = L w; X(d) moves the child's quantities to
        // joint i, where the child's acceleration gains the centripetal bias beta = -omega^2 d.
        let (dx, dy) = (c * link.length, s * link.length);
        let mc = link.mass * link.com;
        // D_i = S^T IA_i S = I + m c^2 + r^T K r, with the products of r formed before K is
        // known, so that the chain from K to D is one multiply and two adds.
        let about_joint = L::splat(context, link.inertia + mc * link.com);
        let mass = L::splat(context, link.mass);
        let (rr_xx, rr_xy, rr_yy) = (dy * dy, dx * dy * 2.0, dx * dx);
        let d_axis = (kxx * rr_xx + about_joint) + (kyy * rr_yy - kxy * rr_xy);
        // U_i = m c w + K r; its rotational part is D_i.
        let u_lin = [
            (kxy * dx - kxx * dy) - s * mc,
            (kyy * dx - kxy * dy) + c * mc,
        ];
        // pA_i = b_i + X^T (pA' + K beta), b_i = (0, -m c omega^2 u).
        let force = [
            fx - (kxx * dx + kxy * dy) * w2,
            fy - (kxy * dx + kyy * dy) * w2,
        ];
        let bias_moment = torque + (dx * force[1] - dy * force[0]);
        let centripetal = w2 * mc;
        let bias_force = [force[0] - c * centripetal, force[1] - s * centripetal];
        // The scale of D_i's rounding: its terms' magnitudes, |r|^2 tr K bounding r^T K r.
        let scale = about_joint + (kxx + kyy) * (link.length * link.length);
        L::check_pivot(context, d_axis, scale)?;
        let tau_i = L::gather(context, tau, n, i);
        let residual = tau_i - bias_moment;
        let joint = &mut articulated[i];
        u_lin[0].set(&mut joint.u_lin[0]);
        u_lin[1].set(&mut joint.u_lin[1]);
        d_axis.set(&mut joint.d);
        residual.set(&mut joint.residual);
        // Solve the joint acceleration out: IA - U U^T / D and pA + U residual / D.
        let inverse = L::splat(context, 1.0) / d_axis;
        let along = residual * inverse;
        kxx = (kxx + mass) - u_lin[0] * u_lin[0] * inverse;
        kxy = kxy - u_lin[0] * u_lin[1] * inverse;
        kyy = (kyy + mass) - u_lin[1] * u_lin[1] * inverse;
        fx = bias_force[0] + u_lin[0] * along;
        fy = bias_force[1] + u_lin[1] * along;
        torque = tau_i;
    }
    Ok(())
}

/// Solves the joint accelerations from the base out, into `qdd` (row-major, `n` a state).
#[inline(always)]
fn forward_sweep<L: AbaLane>(
    context: L::Context,
    model: &ChainModel,
    frames: &[LinkFrame<L::Slot>],
    articulated: &[ArticulatedLink<L::Slot>],
    qdd: &mut [f64],
) {
    let n = model.n_links();
    // The parent's acceleration moved to joint i: angular, x, y (gravity as an upward base
    // acceleration).
    let (mut angular, mut ax, mut ay) = (
        L::splat(context, 0.0),
        L::splat(context, 0.0),
        L::splat(context, model.gravity()),
    );
    for (i, (link, (frame, joint))) in model
        .links()
        .iter()
        .zip(frames.iter().zip(articulated))
        .enumerate()
    {
        let get = |slot| L::get(context, slot);
        let inverse = L::splat(context, 1.0) / get(&joint.d);
        let gain = [
            get(&joint.u_lin[0]) * inverse,
            get(&joint.u_lin[1]) * inverse,
        ];
        // The link's angular acceleration: qdd_i + parent's = (tau_i - S^T pA_i - U_i^T A^-) / D_i.
        let own = get(&joint.residual) * inverse - (ax * gain[0] + ay * gain[1]);
        (own - angular).scatter(qdd, n, i);
        let omega = get(&frame.omega);
        let w2 = omega * omega;
        let (dx, dy) = (
            get(&frame.axis[0]) * link.length,
            get(&frame.axis[1]) * link.length,
        );
        ax = (ax - dx * w2) - dy * own;
        ay = (ay - dy * w2) + dx * own;
        angular = own;
    }
}
