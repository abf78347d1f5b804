//! Analytic derivatives of forward dynamics: `d qdd / d q`, `d qdd / d v` and
//! `d qdd / d tau = M^-1`. Differentiating `M(q) qdd + b(q, v) = tau` at the ABA's `qdd` gives
//! `d qdd / d q = -M^-1 d tau / d q` and `d qdd / d v = -M^-1 d tau / d v` with the RNEA
//! derivatives taken at `(q, v, qdd)` (Carpentier and Mansard 2018, eq. 12; what Pinocchio's
//! `computeABADerivatives` returns). `M^-1` comes in `O(n^2)` from the articulated-body
//! factorisation the ABA has just built ([`minv`](super::minv), theory.md eqs. S1-S3), never
//! from `M`; the two products with it are one dense `n x n` by `n x 2n` matrix product.

use faer::{MatMut, MatRef};
use pulp::{Simd, WithSimd};

use super::aba::aba;
use super::data::SpatialData;
use super::derivative_data::SpatialDerivativeData;
use super::minv::inverse_mass_matrix;
use super::model::SpatialModel;
use super::rnea_derivatives::differentiate_at;
use crate::check;
use crate::error::DynError;

/// Forward dynamics and its analytic derivatives at `(q, v, tau)`: `qdd` (as
/// [`aba`](super::aba())), `d qdd / d q`, `d qdd / d v` and `d qdd / d tau = M^-1`, into
/// `derivatives`. `M^-1` in `O(n^2)` (theory.md eqs. S1-S3), the RNEA derivatives in
/// `O(n^2)`, then their product with `M^-1`; allocation-free.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialData, SpatialDerivativeData, SpatialModel, aba_derivatives};
/// // A pendulum: qdd = (tau - m g c cos q) / J, so d qdd / d q = m g c sin q / J.
/// let pendulum = SpatialModel::from_planar(&ChainModel::uniform(1, 1.0, 2.0, 9.81)?);
/// let mut data = SpatialData::new(&pendulum);
/// let mut derivatives = SpatialDerivativeData::new(&pendulum);
/// aba_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// let j = 2.0 / 3.0;
/// assert!((derivatives.d_q()[(0, 0)] - 2.0 * 9.81 * 0.5 * 0.3_f64.sin() / j).abs() < 1e-12);
/// assert!((derivatives.d_input()[(0, 0)] - 1.0 / j).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// As [`rnea_derivatives`](super::rnea_derivatives()) and [`aba`](super::aba()) ([`DynError::SingularJoint`] naming the
/// first joint, from the tip, whose articulated inertia about its axis is not positive).
pub fn aba_derivatives(
    model: &SpatialModel,
    data: &mut SpatialData,
    derivatives: &mut SpatialDerivativeData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<(), DynError> {
    check::dense_count("the ABA derivatives", model.n_links())?;
    let n = super::check_inputs(model, data, &[("q", q), ("v", v), ("tau", tau)])?;
    lane_math::check_len(
        "derivatives (a SpatialDerivativeData built for another model)",
        derivatives.n_links(),
        n,
    )?;
    let mut qdd = std::mem::take(&mut derivatives.accelerations);
    let solved = aba(model, data, q, v, tau, &mut qdd)
        .and_then(|()| differentiate_at(model, data, derivatives, q, v, &qdd));
    derivatives.value.copy_from_slice(&qdd);
    derivatives.accelerations = qdd;
    solved?;
    let SpatialDerivativeData {
        blocks, rhs, sweep, ..
    } = derivatives;
    let (jacobians, mut minv) = blocks.as_mut().split_at_col_mut(2 * n);
    rhs.copy_from(jacobians.as_ref());
    inverse_mass_matrix(
        data.arch,
        model,
        &data.articulated,
        &data.poses,
        sweep,
        minv.as_mut(),
    );
    data.arch.dispatch(NegatedProduct {
        out: jacobians,
        minv: minv.as_ref(),
        rhs: rhs.as_ref(),
    });
    check::finite_matrix("the derivatives", &blocks.as_mut())
}

/// `out = -minv rhs` (`n x n` by `n x 2n`), column by column as sums of `minv`'s columns, under
/// [`pulp::Arch::dispatch`] (the loops vectorise with this processor's widest registers; at
/// these sizes faster than a general matrix product's packing).
struct NegatedProduct<'a> {
    out: MatMut<'a, f64>,
    minv: MatRef<'a, f64>,
    rhs: MatRef<'a, f64>,
}

impl WithSimd for NegatedProduct<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let NegatedProduct { mut out, minv, rhs } = self;
        let n = minv.nrows();
        let contiguous = "the blocks of a faer Mat are column-major";
        for c in 0..rhs.ncols() {
            let column = out
                .as_mut()
                .col_mut(c)
                .try_as_col_major_mut()
                .expect(contiguous)
                .as_slice_mut();
            let factors = rhs.col(c).try_as_col_major().expect(contiguous).as_slice();
            column.fill(0.0);
            for (k, &factor) in factors.iter().enumerate().take(n) {
                let factor = -factor;
                let source = minv.col(k).try_as_col_major().expect(contiguous).as_slice();
                for (entry, &m) in column.iter_mut().zip(source) {
                    *entry += m * factor;
                }
            }
        }
    }
}
