//! Analytic derivatives of forward dynamics: `d qdd / d q`, `d qdd / d v` and
//! `d qdd / d tau = M^-1`, in `O(n^2)`.
//!
//! Differentiating `M(q) qdd + C(q, v) + G(q) = tau` at fixed `tau` gives
//! `d qdd / d q = -M^-1 (d tau / d q)` and `d qdd / d v = -M^-1 (d tau / d v)`, the inverse-
//! dynamics partials taken at the forward-dynamics solution `qdd` (as Pinocchio does). The
//! partials come in closed form from [`rnea_derivatives`](crate::rnea_derivatives()); the `3n`
//! right-hand sides `[-d tau / d q | -d tau / d v | 1]` are then solved together by the
//! articulated-body factorisation of `M` that [`aba`](crate::aba()) has just built: with no
//! velocity and no gravity, the bias sweep of the ABA computes `M^-1 b` in `O(n)` for any `b`,
//! so the `3n` solves cost `O(n^2)` and never form `M`.
//!
//! The right-hand sides are columns of a row-major matrix whose rows are padded to whole SIMD
//! registers. The sweeps take the columns a few registers at a time (SIMD across right-hand sides,
//! the instruction set chosen at run time by [`pulp::Arch`]), and run each group from the tip to
//! the base and back with its sweep state in registers; the per-joint constants of the sweeps
//! are computed once, before the groups.

use lane_math::{Lane, Pack};
use pulp::{Simd, WithSimd};

use crate::aba::{ArticulatedLink, articulated_body};
use crate::check;
use crate::data::ChainData;
use crate::derivative_data::{DerivativeData, SweepLink};
use crate::error::DynError;
use crate::kinematics::LinkFrame;
use crate::model::ChainModel;
use crate::rnea_derivatives::fill_partials;

/// The most SIMD registers of right-hand sides one group of the sweeps carries: three registers
/// of sweep state each, twelve in all, fit the register file of AVX2 and AVX-512.
const GROUP: usize = 4;

/// Forward dynamics and its analytic derivatives at `(q, v, tau)`: `qdd` (as [`aba`]),
/// `d qdd / d q`, `d qdd / d v` and `d qdd / d tau = M^-1`, into `derivatives` (read them with
/// [`DerivativeData::value`], [`d_q`](DerivativeData::d_q), [`d_v`](DerivativeData::d_v) and
/// [`d_input`](DerivativeData::d_input)). `O(n^2)` and allocation-free; the method is in the
/// module documentation of `src/aba_derivatives.rs`.
///
/// [`aba`]: crate::aba()
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, DerivativeData, aba_derivatives};
/// // A pendulum: qdd = (tau - m g c cos q) / (m L^2 / 3).
/// let pendulum = ChainModel::uniform(1, 1.0, 3.0, 9.81)?;
/// let (mut data, mut derivatives) = (ChainData::new(&pendulum), DerivativeData::new(&pendulum));
/// aba_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// let inertia = 3.0 / 3.0;
/// assert!((derivatives.d_q()[(0, 0)] - 3.0 * 9.81 * 0.5 * 0.3_f64.sin() / inertia).abs() < 1e-12);
/// assert_eq!(derivatives.d_v()[(0, 0)], 0.0);
/// assert!((derivatives.d_input()[(0, 0)] - 1.0 / inertia).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` or `derivatives` was
/// built for another chain, [`DynError::NonFinite`] for a NaN or infinite input,
/// [`DynError::NotPositiveDefinite`] if an articulated inertia is not positive beyond rounding
/// (as in [`aba`]), [`DynError::NonFiniteResult`] if a result overflows.
pub fn aba_derivatives(
    model: &ChainModel,
    data: &mut ChainData,
    derivatives: &mut DerivativeData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<(), DynError> {
    check::dense("the ABA derivatives", model)?;
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    check::derivative_workspace(derivatives, n)?;
    articulated_body(model, data, q, v, tau, &mut derivatives.value)?;
    check::finite_result("qdd", &derivatives.value)?;
    let arch = derivatives.arch;
    arch.dispatch(Jacobians {
        model,
        frames: &data.frames,
        articulated: &data.articulated,
        derivatives: &mut *derivatives,
    });
    check::finite_result("qdd derivatives", &derivatives.blocks)
}

/// The Jacobians of [`aba_derivatives`] once the ABA has run, by [`pulp::Arch::dispatch`] with
/// the processor's instruction set.
struct Jacobians<'a> {
    model: &'a ChainModel,
    /// The link frames and articulated inertias the ABA left.
    frames: &'a [LinkFrame],
    articulated: &'a [ArticulatedLink],
    derivatives: &'a mut DerivativeData,
}

impl WithSimd for Jacobians<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Self {
            model,
            frames,
            articulated,
            derivatives,
        } = self;
        let n = model.n_links();
        let DerivativeData {
            value: qdd,
            blocks,
            stride,
            links,
            solve,
            ..
        } = derivatives;
        let stride = *stride;
        // The right-hand sides [-d tau / d q | -d tau / d v | 1].
        fill_partials(model, frames, qdd, -1.0, links, blocks, stride);
        for (i, row) in blocks.chunks_exact_mut(stride).enumerate() {
            let identity = &mut row[2 * n..3 * n];
            identity.fill(0.0);
            identity[i] = 1.0;
        }
        for (((sweep, link), frame), joint) in
            solve.iter_mut().zip(model.links()).zip(frames).zip(articulated)
        {
            let inverse = 1.0 / joint.d;
            *sweep = SweepLink {
                offset: [link.length * frame.axis[0], link.length * frame.axis[1]],
                coupling: joint.u_lin,
                gain: [joint.u_lin[0] * inverse, joint.u_lin[1] * inverse],
                inverse,
            };
        }
        solve_in_place(simd, solve, blocks, stride);
    }
}

/// Overwrites the row-major `n x stride` matrix `rhs` (`stride` a multiple of the register
/// width) with `M^-1 rhs`, by the bias and acceleration sweeps of the ABA at zero velocity and
/// gravity on the articulated inertias in `links`, [`GROUP`] registers of columns at a time.
#[inline(always)]
fn solve_in_place<S: Simd>(simd: S, links: &[SweepLink], rhs: &mut [f64], stride: usize) {
    let width = S::F64_LANES;
    let mut first = 0;
    while first + GROUP * width <= stride {
        solve_columns::<S, GROUP>(simd, links, rhs, stride, first);
        first += GROUP * width;
    }
    while first < stride {
        solve_columns::<S, 1>(simd, links, rhs, stride, first);
        first += width;
    }
}

/// [`solve_in_place`] on the `G` registers of columns from column `first`.
#[inline(always)]
fn solve_columns<S: Simd, const G: usize>(
    simd: S,
    links: &[SweepLink],
    rhs: &mut [f64],
    stride: usize,
    first: usize,
) {
    let width = S::F64_LANES;
    let splat = |x: f64| Pack::<S>::splat(simd, x);
    let zero = splat(0.0);
    // From the tip: each column's condensed force (x, y) and joint torque, and in place of b_i
    // the residual b_i - S^T pA_i (see `aba`).
    let (mut fx, mut fy, mut torque) = ([zero; G], [zero; G], [zero; G]);
    for (link, row) in links.iter().zip(rhs.chunks_exact_mut(stride)).rev() {
        let row = &mut row[first..first + G * width];
        let [ux, uy] = link.offset.map(splat);
        let [gx, gy] = link.gain.map(splat);
        for (g, slot) in row.chunks_exact_mut(width).enumerate() {
            let b = Pack::load(simd, slot);
            let residual = b - (torque[g] + ux * fy[g] - uy * fx[g]);
            torque[g] = b;
            residual.store(slot);
            fx[g] = fx[g] + gx * residual;
            fy[g] = fy[g] + gy * residual;
        }
    }
    // From the base: each column's parent acceleration (angular, x, y) moved to the joint.
    let (mut angular, mut ax, mut ay) = ([zero; G], [zero; G], [zero; G]);
    for (link, row) in links.iter().zip(rhs.chunks_exact_mut(stride)) {
        let row = &mut row[first..first + G * width];
        let [dx, dy] = link.offset.map(splat);
        let [cx, cy] = link.coupling.map(splat);
        let inverse = splat(link.inverse);
        for (g, slot) in row.chunks_exact_mut(width).enumerate() {
            let x = Pack::load(simd, slot);
            let own = (x - ax[g] * cx - ay[g] * cy) * inverse;
            (own - angular[g]).store(slot);
            angular[g] = own;
            ax[g] = ax[g] - dy * own;
            ay[g] = ay[g] + dx * own;
        }
    }
}
