//! Analytic derivatives of forward dynamics: `d qdd / d q`, `d qdd / d v` and
//! `d qdd / d tau = M^-1`. Differentiating `M(q) qdd + b(q, v) = tau` at the ABA's `qdd` gives
//! `d qdd / d q = -M^-1 d tau / d q` and `d qdd / d v = -M^-1 d tau / d v` with the RNEA
//! derivatives taken at `(q, v, qdd)` (Carpentier and Mansard 2018, eq. 12; what Pinocchio's
//! `computeABADerivatives` returns). `M^-1` comes in `O(n^2)` from the articulated-body
//! factorisation the ABA has just built ([`minv`](super::minv), theory.md eqs. S1-S3), never
//! from `M`; the two products with it are one dense `n x n` by `n x 2n` matrix product, in SIMD
//! registers.

use faer::{MatMut, MatRef};
use lane_math::{Lane, Pack};
use pulp::{Simd, WithSimd};

use super::algebra::{Force, Motion, Symmetric6, Transform};
use super::data::SpatialData;
use super::derivative_data::{MAX_LANES, SpatialDerivativeData, column_of, padded, store_first};
use super::kinematics::{placement_about_first_joint, sin_cos_dispatched};
use super::minv::inverse_mass_matrix;
use super::model::SpatialModel;
use super::rnea_derivatives::{Jacobians, carry_to_base, differentiate_at};
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
    let solved = aba_base_frame(model, data, derivatives, [q, v, tau], &mut qdd)
        .and_then(|()| check::finite_result("qdd", &qdd))
        .and_then(|()| differentiate_at(model, data, derivatives, v, &qdd, Jacobians::IntoRhs));
    derivatives.value.copy_from_slice(&qdd);
    derivatives.accelerations = qdd;
    solved?;
    let SpatialDerivativeData {
        blocks,
        rhs,
        sweep,
        joints,
        minv_columns,
        ..
    } = derivatives;
    let (jacobians, mut minv) = blocks.as_mut().split_at_col_mut(2 * n);
    inverse_mass_matrix(data.arch, joints, sweep, minv_columns);
    let stride = padded(n);
    for k in 0..n {
        column_of(&mut minv, k).copy_from_slice(&minv_columns[k * stride..k * stride + n]);
    }
    // The product's entries test the three matrices: a NaN or infinity in column `k` of `M^-1`
    // (row `r`) reaches every entry `(r, c)` of the product (through `M^-1_rk rhs_kc`, NaN when
    // `rhs_kc = 0`), one in `rhs_kc` reaches entry `(k, c)` (through `M^-1_kk > 0`).
    let finite = data.arch.dispatch(Product {
        out: jacobians,
        columns: minv_columns,
        rhs: rhs.as_ref(),
    });
    if finite {
        Ok(())
    } else {
        Err(DynError::NonFiniteResult {
            name: "the derivatives",
        })
    }
}

/// The articulated-body algorithm (as [`aba`](super::aba())) run in the base frame (its origin
/// at the first joint's, [`placement_about_first_joint`]), as
/// Pinocchio's `computeABADerivatives` runs it: `qdd` from `inputs` (`q`, `v`, `tau`), each
/// link's pose into `data`, its base-frame axis and inertia into `derivatives`
/// ([`carry_to_base`]) and each
/// joint's [`BaseFrameJoint`](super::derivative_data::BaseFrameJoint) into `derivatives.joints`, for the RNEA derivatives and `M^-1`
/// that follow. With every quantity in the base frame, the frame changes `X_i` of the
/// link-frame algorithm are identities: base to tip, `v_i = v_{i-1} + S_i qd_i`,
/// `c_i = v_i x S_i qd_i` and `p_i = v_i x* I_i v_i`; tip to base, `IA_i = I_i + IA'_{i+1}`,
/// `pA_i = p_i + pA'_{i+1}`, `U_i = IA_i S_i`, `D_i = S_i . U_i`, `u_i = tau_i - S_i . pA_i`,
/// `IA'_i = IA_i - U_i U_i^T / D_i`, `pA'_i = pA_i + IA'_i c_i + U_i u_i / D_i`; base to tip,
/// `a_{-1} = -g`, `a'_i = a_{i-1} + c_i`, `qdd_i = (u_i - U_i . a'_i) / D_i`,
/// `a_i = a'_i + S_i qdd_i`. Inputs finite, sizes checked by the caller.
fn aba_base_frame(
    model: &SpatialModel,
    data: &mut SpatialData,
    derivatives: &mut SpatialDerivativeData,
    inputs: [&[f64]; 3],
    qdd: &mut [f64],
) -> Result<(), DynError> {
    let [q, v, tau] = inputs;
    let n = model.n_links();
    sin_cos_dispatched(data.arch, q, &mut data.sin, &mut data.cos);
    let mut pose = Transform::IDENTITY;
    let mut velocity = Motion::default();
    for (i, &speed) in v.iter().enumerate().take(n) {
        let placement = placement_about_first_joint(model, data, q, i);
        pose = pose.compose(&placement);
        data.poses[i] = pose;
        let axis = carry_to_base(model, derivatives, i, &pose);
        let joint = &mut derivatives.joints[i];
        joint.axis = axis;
        let joint_velocity = joint.axis.times(speed);
        velocity = velocity.plus(&joint_velocity);
        joint.bias = velocity.cross_motion(&joint_velocity);
        // A massless link (the cross of a universal joint) has no inertia and no bias force.
        if !model.massless[i] {
            let momentum = derivatives.composite[i].apply(&velocity);
            joint.force = velocity.cross_force(&momentum);
        }
    }
    let (joints, inertias) = (&mut derivatives.joints, &derivatives.composite);
    let mut carried_inertia = Symmetric6::default();
    let mut carried_force = Force::default();
    for i in (0..n).rev() {
        let joint = &mut joints[i];
        let (inertia, force) = if model.massless[i] {
            (carried_inertia, carried_force)
        } else {
            (
                carried_inertia.plus_rigid(&inertias[i]),
                joint.force.plus(&carried_force),
            )
        };
        let coupling = inertia.apply(&joint.axis);
        let pivot = joint.axis.dot(&coupling);
        check::pivot("articulated inertia", pivot, model.pivot_scales[i]).map_err(|error| {
            match error {
                DynError::NotPositiveDefinite => DynError::SingularJoint { index: i },
                other => other,
            }
        })?;
        let inverse = 1.0 / pivot;
        let residual = tau[i] - joint.axis.dot(&force);
        joint.coupling = coupling;
        joint.inverse = inverse;
        joint.residual = residual;
        carried_inertia = inertia.minus_outer(&coupling, inverse);
        carried_force = force
            .plus(&carried_inertia.apply(&joint.bias))
            .plus(&coupling.times(residual * inverse));
    }
    let g = model.gravity();
    let mut acceleration = Motion {
        linear: [-g[0], -g[1], -g[2]],
        angular: [0.0; 3],
    };
    for (joint, out) in joints.iter().zip(qdd.iter_mut()) {
        acceleration = acceleration.plus(&joint.bias);
        *out = (joint.residual - acceleration.dot(&joint.coupling)) * joint.inverse;
        acceleration = acceleration.plus(&joint.axis.times(*out));
    }
    Ok(())
}

/// `out = -minv rhs` (`n x n` by `n x 2n`) under [`pulp::Arch::dispatch`], returning whether
/// every entry is finite: one or two SIMD registers of rows of [`GROUP`] output columns at a
/// time, the sums over `k` of `minv`'s column `k` times `rhs[(k, c)]` kept in registers (at
/// these sizes faster than a general matrix product's packing). `columns` holds `minv`'s
/// columns, each zero-padded to [`padded`]`(n)` entries, so that a whole register can be read
/// at any row.
struct Product<'a> {
    out: MatMut<'a, f64>,
    columns: &'a [f64],
    rhs: MatRef<'a, f64>,
}

/// Output columns computed together (four register accumulators a register of rows).
const GROUP: usize = 4;

impl WithSimd for Product<'_> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> bool {
        let Product {
            mut out,
            columns,
            rhs,
        } = self;
        let (n, width) = (out.nrows(), out.ncols());
        let lanes = Pack::<S>::WIDTH;
        // `x 0` summed: NaN if and only if an entry is not finite.
        let mut check = Pack::splat(simd, 0.0);
        let mut row = 0;
        while row < n {
            // Two registers of rows when the second holds rows of `out` and the columns' padding
            // covers it.
            let two = row + lanes < n && row + 2 * lanes <= padded(n);
            let mut c = 0;
            while c < width {
                let at = Block { row, column: c };
                check = match (two, c + GROUP <= width) {
                    (true, true) => block::<S, 2, GROUP>(simd, &mut out, columns, rhs, at, check),
                    (false, true) => block::<S, 1, GROUP>(simd, &mut out, columns, rhs, at, check),
                    (true, false) => block::<S, 2, 1>(simd, &mut out, columns, rhs, at, check),
                    (false, false) => block::<S, 1, 1>(simd, &mut out, columns, rhs, at, check),
                };
                c += if c + GROUP <= width { GROUP } else { 1 };
            }
            row += if two { 2 * lanes } else { lanes };
        }
        Pack::splat(simd, 1.0).all_greater(check)
    }
}

/// The first row and column of a block of [`Product`].
#[derive(Clone, Copy)]
struct Block {
    row: usize,
    column: usize,
}

/// Rows `row..row + R WIDTH` (those below `n`) of the `G` output columns `column..column + G`
/// of [`Product`], summed in `k` order from zero with fused negated multiply-adds (the same
/// bits as summing and negating); returns `check` with `0 x` each sum added.
#[inline(always)]
fn block<S: Simd, const R: usize, const G: usize>(
    simd: S,
    out: &mut MatMut<'_, f64>,
    columns: &[f64],
    rhs: MatRef<'_, f64>,
    at: Block,
    check: Pack<S>,
) -> Pack<S> {
    let n = out.nrows();
    let lanes = Pack::<S>::WIDTH;
    let Block { row, column: c } = at;
    let factors: [&[f64]; G] = std::array::from_fn(|j| {
        let column = rhs.col(c + j).try_as_col_major();
        &column.expect(CONTIGUOUS).as_slice()[..n]
    });
    let zero = Pack::splat(simd, 0.0);
    let mut sums = [[zero; G]; R];
    for (k, column) in columns.chunks_exact(padded(n)).take(n).enumerate() {
        let rows = &column[row..row + R * lanes];
        let mut m = [zero; R];
        for (r, m) in m.iter_mut().enumerate() {
            *m = Pack::load(simd, &rows[r * lanes..]);
        }
        for (j, factor) in factors.iter().enumerate() {
            let f = Pack::splat(simd, factor[k]);
            for (sums, m) in sums.iter_mut().zip(&m) {
                sums[j] = m.neg_mul_add(f, sums[j]);
            }
        }
    }
    let mut check = check;
    for (r, sums) in sums.into_iter().enumerate() {
        let first = row + r * lanes;
        for (j, sum) in sums.into_iter().enumerate() {
            check = sum.mul_add(zero, check);
            if first >= n {
                continue;
            }
            let column = column_of(out, c + j);
            if first + lanes <= n {
                sum.store(&mut column[first..]);
            } else {
                let mut last = [0.0; MAX_LANES];
                sum.store(&mut last);
                store_first(&mut column[first..], &last, n - first);
            }
        }
    }
    check
}

const CONTIGUOUS: &str = "the blocks of a faer Mat are column-major";
