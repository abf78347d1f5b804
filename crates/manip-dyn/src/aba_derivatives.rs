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

use crate::aba::articulated_body;
use crate::check;
use crate::data::{ArticulatedLink, ChainData, LinkFrame};
use crate::derivative_data::{DerivativeData, ROW_ALIGNMENT, SweepLink};
use crate::error::DynError;
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
    let finite = arch.dispatch(Jacobians {
        model,
        frames: &data.frames,
        articulated: &data.articulated,
        derivatives,
    });
    if finite {
        Ok(())
    } else {
        Err(DynError::NonFiniteResult {
            name: "qdd derivatives",
        })
    }
}

/// The Jacobians of [`aba_derivatives`] once the ABA has run, by [`pulp::Arch::dispatch`] with
/// the processor's instruction set; its output is whether they are all finite.
struct Jacobians<'a> {
    model: &'a ChainModel,
    /// The link frames and articulated inertias the ABA left.
    frames: &'a [LinkFrame],
    articulated: &'a [ArticulatedLink],
    derivatives: &'a mut DerivativeData,
}

impl WithSimd for Jacobians<'_> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> bool {
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
            for (k, entry) in row[2 * n..3 * n].iter_mut().enumerate() {
                *entry = if k == i { 1.0 } else { 0.0 };
            }
        }
        for (((sweep, link), frame), joint) in solve
            .iter_mut()
            .zip(model.links())
            .zip(frames)
            .zip(articulated)
        {
            let inverse = 1.0 / joint.d;
            *sweep = SweepLink {
                offset: [link.length * frame.axis[0], link.length * frame.axis[1]],
                coupling: joint.u_lin,
                gain: [joint.u_lin[0] * inverse, joint.u_lin[1] * inverse],
                inverse,
            };
        }
        solve_in_place(simd, solve, blocks, stride)
    }
}

/// Overwrites the row-major `n x stride` matrix `rhs` (`stride` a multiple of the register
/// width) with `M^-1 rhs`, by the bias and acceleration sweeps of the ABA at zero velocity and
/// gravity on the articulated inertias in `links`, [`GROUP`] registers of columns at a time.
/// Returns whether every entry of the result is finite.
#[inline(always)]
fn solve_in_place<S: Simd>(simd: S, links: &[SweepLink], rhs: &mut [f64], stride: usize) -> bool {
    let width = S::F64_LANES;
    let mut first = 0;
    let mut finite = true;
    while first + GROUP * width <= stride {
        finite &= solve_columns::<S, GROUP>(simd, links, rhs, stride, first);
        first += GROUP * width;
    }
    while first < stride {
        finite &= solve_columns::<S, 1>(simd, links, rhs, stride, first);
        first += width;
    }
    finite
}

/// [`solve_in_place`] on the `G` registers of columns from column `first`; whether the results
/// are all finite.
#[inline(always)]
fn solve_columns<S: Simd, const G: usize>(
    simd: S,
    links: &[SweepLink],
    rhs: &mut [f64],
    stride: usize,
    first: usize,
) -> bool {
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
    // From the base: each column's parent acceleration (angular, x, y) moved to the joint. Every
    // result x adds 0 x to `poison`: 0 if x is finite, NaN if not.
    let (mut angular, mut ax, mut ay) = ([zero; G], [zero; G], [zero; G]);
    let mut poison = [zero; G];
    for (link, row) in links.iter().zip(rhs.chunks_exact_mut(stride)) {
        let row = &mut row[first..first + G * width];
        let [dx, dy] = link.offset.map(splat);
        let [cx, cy] = link.coupling.map(splat);
        let inverse = splat(link.inverse);
        for (g, slot) in row.chunks_exact_mut(width).enumerate() {
            let x = Pack::load(simd, slot);
            let own = (x - ax[g] * cx - ay[g] * cy) * inverse;
            let result = own - angular[g];
            result.store(slot);
            poison[g] = poison[g] + result * zero;
            angular[g] = own;
            ax[g] = ax[g] - dy * own;
            ay[g] = ay[g] + dx * own;
        }
    }
    let mut lanes = [0.0; ROW_ALIGNMENT];
    poison.iter().all(|register| {
        register.store(&mut lanes);
        lanes[..width].iter().all(|&x| x == 0.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pulp::{Arch, Scalar};

    /// [`solve_in_place`] by run-time dispatch.
    struct Solve<'a> {
        links: &'a [SweepLink],
        rhs: &'a mut [f64],
        stride: usize,
    }

    impl WithSimd for Solve<'_> {
        type Output = bool;

        fn with_simd<S: Simd>(self, simd: S) -> bool {
            solve_in_place(simd, self.links, self.rhs, self.stride)
        }
    }

    /// The finiteness check fused into the sweeps flags an infinite or NaN result in any column
    /// (in a whole group of registers, in a single register after it, in the last one), with the
    /// widest instruction set here and without SIMD, and both give the same solution.
    #[test]
    fn the_sweeps_flag_non_finite_results_in_every_column() {
        let joint = SweepLink {
            offset: [0.08, 0.06],
            coupling: [-0.02, 0.05],
            gain: [-0.4, 1.0],
            inverse: 20.0,
        };
        let links = [joint; 3];
        let stride = (GROUP + 1) * ROW_ALIGNMENT;
        let rhs: Vec<f64> = (0..3 * stride).map(|k| (k as f64 * 0.7).sin()).collect();
        for bad in [None, Some(f64::INFINITY), Some(f64::NAN)] {
            for column in [0, 13, GROUP * ROW_ALIGNMENT + 3, stride - 1] {
                let mut fast = rhs.clone();
                if let Some(x) = bad {
                    fast[stride + column] = x;
                }
                let mut scalar = fast.clone();
                let dispatched = Arch::new().dispatch(Solve {
                    links: &links,
                    rhs: &mut fast,
                    stride,
                });
                let plain = solve_in_place(Scalar::new(), &links, &mut scalar, stride);
                assert_eq!(dispatched, bad.is_none(), "column {column}, {bad:?}");
                assert_eq!(plain, bad.is_none(), "column {column}, {bad:?}");
                if bad.is_none() {
                    assert_eq!(fast, scalar);
                }
            }
        }
    }
}
