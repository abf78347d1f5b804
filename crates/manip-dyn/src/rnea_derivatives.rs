//! Analytic derivatives of inverse dynamics (eq 12), `d tau / d q` and `d tau / d v`, in closed
//! form from `O(n)` prefix and suffix sums; each `n x n` Jacobian is then filled at two
//! multiply-adds per entry. `d tau / d qdd = M`.
//!
//! # Derivation
//!
//! Write the chain in absolute angles `phi_j = q_0 + ... + q_j` (`phi = T q`, `T` lower
//! triangular of ones), `u_j = (cos phi_j, sin phi_j) = (c_j, s_j)`, rates `w = T v` and
//! accelerations `alpha = T qdd`. With `mu_j` the mass beyond link `j` and
//! `S_j = m_j r_j + L_j mu_j`, the kinetic energy is `1/2 w^T H w` with
//! `H_jl = h_jl cos(phi_j - phi_l)`, `h_jl = L_min(j,l) S_max(j,l)` off the diagonal, and the
//! potential `V = g sum_j S_j s_j` (the derivation is in `modal_reduce::terms`). Lagrange's
//! equations give the generalised forces in absolute angles
//!
//! ```text
//! f_j = sum_l h_jl [cos(phi_j - phi_l) alpha_l + sin(phi_j - phi_l) w_l^2] + g S_j c_j,
//! ```
//!
//! and the joint torques are `tau = T^T f` (virtual work), so
//! `d tau / d q = T^T X T` and `d tau / d v = T^T Y T` with `X = df/dphi`, `Y = df/dw`:
//!
//! ```text
//! X_jl = h_jl (s_j E_l^x - c_j E_l^y),  E_l = (c_l alpha_l - s_l w_l^2, s_l alpha_l + c_l w_l^2),
//! Y_jl = h_jl (s_j F_l^x - c_j F_l^y),  F_l = 2 w_l u_l                     (l != j),
//! X_jj = -sum_{l != j} X_jl - g S_j s_j,   Y_jj = 0.
//! ```
//!
//! *Closed form.* Because `h_jl` factors (`L_l S_j` below the diagonal, `L_j S_l` above), the
//! double suffix sums `(T^T X T)_ik = sum_{j>=i} sum_{l>=k} X_jl` collapse. With the prefix and
//! suffix sums `B_k = sum_{l<k} L_l E_l`, `A_k = sum_{l>=k} S_l E_l`, the joint positions
//! `lambda_k = sum_{j<k} L_j u_j`, the subtree moments `sigma_i = sum_{j>=i} S_j u_j`, the row
//! sums `kappa_j = sum_l X_jl = -g S_j s_j` and `K_i = sum_{j>=i} kappa_j`:
//!
//! ```text
//! (T^T X T)_ik = K_i - B_k^x sigma_i^y + B_k^y sigma_i^x                              (k <= i)
//!              = base_k - A_k^x lambda_i^y + A_k^y lambda_i^x                         (k > i)
//! base_k = K_k - B_k^x sigma_k^y + B_k^y sigma_k^x + A_k^x lambda_k^y - A_k^y lambda_k^x
//! ```
//!
//! and the same for `T^T Y T` with `F` for `E` and row sums
//! `kappa_j = S_j (s_j B_j^x - c_j B_j^y) + L_j (s_j A_{j+1}^x - c_j A_{j+1}^y)` (its diagonal
//! is zero rather than minus the row sum). So both Jacobians are semiseparable of rank 3 in each
//! triangle: `O(n)` work for the sums, then two multiply-adds per entry.

use faer::MatMut;
use pulp::{Simd, WithSimd};

use crate::check;
use crate::crba;
use crate::data::{ChainData, LinkFrame};
use crate::derivative_data::{DerivativeData, LinkTerms};
use crate::error::DynError;
use crate::model::ChainModel;
use crate::rnea::newton_euler;

/// Inverse dynamics and its analytic derivatives at `(q, v, qdd)`: `tau` (as [`rnea`]),
/// `d tau / d q`, `d tau / d v` and `d tau / d qdd = M`, into `derivatives` (read them with
/// [`DerivativeData::value`], [`d_q`](DerivativeData::d_q), [`d_v`](DerivativeData::d_v) and
/// [`d_input`](DerivativeData::d_input)). `O(n^2)`, dominated by writing the three matrices;
/// allocation-free. The closed form is derived in the
/// module documentation of `src/rnea_derivatives.rs`.
///
/// [`rnea`]: crate::rnea()
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, DerivativeData, rnea_derivatives};
/// // A pendulum: tau = (I + m c^2) qdd + m g c cos q, so d tau / d q = -m g c sin q.
/// let pendulum = ChainModel::uniform(1, 1.0, 2.0, 9.81)?;
/// let (mut data, mut derivatives) = (ChainData::new(&pendulum), DerivativeData::new(&pendulum));
/// rnea_derivatives(&pendulum, &mut data, &mut derivatives, &[0.3], &[1.5], &[0.7])?;
/// assert!((derivatives.d_q()[(0, 0)] + 2.0 * 9.81 * 0.5 * 0.3_f64.sin()).abs() < 1e-12);
/// assert_eq!(derivatives.d_v()[(0, 0)], 0.0);
/// assert!((derivatives.d_input()[(0, 0)] - 2.0 / 3.0).abs() < 1e-12);
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if a slice does not have `n` entries or `data` or `derivatives` was
/// built for another chain, [`DynError::NonFinite`] for a NaN or infinite input,
/// [`DynError::NonFiniteResult`] if a result overflows.
pub fn rnea_derivatives(
    model: &ChainModel,
    data: &mut ChainData,
    derivatives: &mut DerivativeData,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
) -> Result<(), DynError> {
    check::dense("the RNEA derivatives", model)?;
    let n = check::inputs(model, data, &[("q", q), ("v", v), ("qdd", qdd)])?;
    check::derivative_workspace(derivatives, n)?;
    newton_euler(
        model,
        data,
        q,
        Some(v),
        Some(qdd),
        model.gravity(),
        &mut derivatives.value,
    );
    check::finite_result("tau", &derivatives.value)?;
    // The Newton-Euler pass left the link directions and rates of (q, v) in `data.frames`.
    let stride = derivatives.stride;
    let arch = derivatives.arch;
    arch.dispatch(Partials {
        model,
        frames: &data.frames,
        qdd,
        terms: &mut derivatives.links,
        blocks: &mut derivatives.blocks,
        stride,
    });
    crba::assemble(
        model,
        &data.frames,
        &mut data.subtrees,
        &mut data.mass_row,
        MatMut::from_row_major_slice_with_stride_mut(
            &mut derivatives.blocks[2 * n..],
            n,
            n,
            stride,
        ),
    );
    check::finite_result("tau derivatives", &derivatives.blocks)
}

/// [`fill_partials`] with `sign = 1`, by [`pulp::Arch::dispatch`] so that its loops vectorise
/// with the processor's instruction set.
struct Partials<'a> {
    model: &'a ChainModel,
    frames: &'a [LinkFrame],
    qdd: &'a [f64],
    terms: &'a mut LinkTerms,
    blocks: &'a mut [f64],
    stride: usize,
}

impl WithSimd for Partials<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let Self {
            model,
            frames,
            qdd,
            terms,
            blocks,
            stride,
        } = self;
        fill_partials(model, frames, qdd, 1.0, terms, blocks, stride);
    }
}

/// Writes `sign * d tau / d q` and `sign * d tau / d v` at the accelerations `qdd` into the first
/// two `n`-column blocks of the row-major `n x stride` `blocks`, from `frames` already updated at
/// `(q, v)` (inputs validated). Inlined, so that inside a SIMD dispatch the loops vectorise with
/// its instruction set.
#[inline(always)]
pub(crate) fn fill_partials(
    model: &ChainModel,
    frames: &[LinkFrame],
    qdd: &[f64],
    sign: f64,
    terms: &mut LinkTerms,
    blocks: &mut [f64],
    stride: usize,
) {
    let n = model.n_links();
    link_terms(model, frames, qdd, sign, terms);
    let [lambda_x, lambda_y] = &terms.lambda;
    let [sigma_x, sigma_y] = &terms.sigma;
    for (i, row) in blocks.chunks_exact_mut(stride).enumerate() {
        let (d_q, rest) = row.split_at_mut(n);
        let d_v = &mut rest[..n];
        for (which, out) in [d_q, d_v].into_iter().enumerate() {
            let [a_x, a_y] = &terms.suffix[which];
            let [b_x, b_y] = &terms.prefix[which];
            let (k_i, base) = (terms.row_sum[which][i], &terms.base[which]);
            let (lower, upper) = out.split_at_mut(i + 1);
            let (s_x, s_y) = (sigma_x[i], sigma_y[i]);
            for ((entry, &bx), &by) in lower.iter_mut().zip(b_x.iter()).zip(b_y.iter()) {
                *entry = k_i - bx * s_y + by * s_x;
            }
            let (l_x, l_y) = (lambda_x[i], lambda_y[i]);
            let columns = i + 1..n;
            for (((entry, &ax), &ay), &b) in upper
                .iter_mut()
                .zip(&a_x[columns.clone()])
                .zip(&a_y[columns.clone()])
                .zip(&base[columns])
            {
                *entry = b - ax * l_y + ay * l_x;
            }
        }
    }
}

/// The `O(n)` sums of the module documentation, scaled by `sign`.
fn link_terms(
    model: &ChainModel,
    frames: &[LinkFrame],
    qdd: &[f64],
    sign: f64,
    terms: &mut LinkTerms,
) {
    let n = model.n_links();
    let (links, frames, qdd) = (model.links(), &frames[..n], &qdd[..n]);
    let g = model.gravity();
    // Every vector cut to its length here, so that the loops below index without checks.
    let LinkTerms {
        moment,
        accel,
        lambda: [lambda_x, lambda_y],
        sigma: [sigma_x, sigma_y],
        suffix: [[aq_x, aq_y], [av_x, av_y]],
        prefix: [[bq_x, bq_y], [bv_x, bv_y]],
        row_sum: [kq, kv],
        base: [base_q, base_v],
    } = terms;
    let (moment, accel) = (&mut moment[..n], &mut accel[..n]);
    let (lambda_x, lambda_y) = (&mut lambda_x[..n], &mut lambda_y[..n]);
    let (sigma_x, sigma_y) = (&mut sigma_x[..n], &mut sigma_y[..n]);
    let (aq_x, aq_y) = (&mut aq_x[..=n], &mut aq_y[..=n]);
    let (av_x, av_y) = (&mut av_x[..=n], &mut av_y[..=n]);
    let (bq_x, bq_y) = (&mut bq_x[..n], &mut bq_y[..n]);
    let (bv_x, bv_y) = (&mut bv_x[..n], &mut bv_y[..n]);
    let (kq, kv) = (&mut kq[..n], &mut kv[..n]);
    let (base_q, base_v) = (&mut base_q[..n], &mut base_v[..n]);
    // From the base: absolute accelerations (needed by E before the sweep from the tip).
    let mut alpha = 0.0;
    for (accel, &qdd_i) in accel.iter_mut().zip(qdd) {
        alpha += qdd_i;
        *accel = alpha;
    }
    // From the tip: S_j, sigma_i, A_k (both sets).
    let mut beyond = 0.0;
    let mut sigma = [0.0; 2];
    let (mut a_q, mut a_v) = ([0.0; 2], [0.0; 2]);
    (aq_x[n], aq_y[n], av_x[n], av_y[n]) = (0.0, 0.0, 0.0, 0.0);
    for j in (0..n).rev() {
        let (link, frame) = (&links[j], &frames[j]);
        let [c, s] = frame.axis;
        let moment_j = link.mass * link.com + link.length * beyond;
        beyond += link.mass;
        moment[j] = moment_j;
        sigma = [sigma[0] + moment_j * c, sigma[1] + moment_j * s];
        (sigma_x[j], sigma_y[j]) = (sigma[0], sigma[1]);
        let [ex, ey] = motion_e(c, s, frame.omega, accel[j]);
        let [fx, fy] = motion_f(c, s, frame.omega);
        a_q = [a_q[0] + sign * moment_j * ex, a_q[1] + sign * moment_j * ey];
        a_v = [a_v[0] + sign * moment_j * fx, a_v[1] + sign * moment_j * fy];
        (aq_x[j], aq_y[j], av_x[j], av_y[j]) = (a_q[0], a_q[1], a_v[0], a_v[1]);
    }
    // From the base: lambda_k, B_k, the row sums kappa_j (from B_j, before adding link j, and
    // A_{j+1}).
    let mut lambda = [0.0; 2];
    let (mut b_q, mut b_v) = ([0.0; 2], [0.0; 2]);
    for j in 0..n {
        let (link, frame) = (&links[j], &frames[j]);
        let [c, s] = frame.axis;
        let (moment_j, length) = (moment[j], link.length);
        (lambda_x[j], lambda_y[j]) = (lambda[0], lambda[1]);
        lambda = [lambda[0] + length * c, lambda[1] + length * s];
        let [ex, ey] = motion_e(c, s, frame.omega, accel[j]);
        let [fx, fy] = motion_f(c, s, frame.omega);
        (bq_x[j], bq_y[j], bv_x[j], bv_y[j]) = (b_q[0], b_q[1], b_v[0], b_v[1]);
        kq[j] = -sign * g * moment_j * s;
        kv[j] = moment_j * (s * b_v[0] - c * b_v[1]) + length * (s * av_x[j + 1] - c * av_y[j + 1]);
        b_q = [b_q[0] + sign * length * ex, b_q[1] + sign * length * ey];
        b_v = [b_v[0] + sign * length * fx, b_v[1] + sign * length * fy];
    }
    // From the tip: K_i = sum_{j>=i} kappa_j, then base_k.
    let sets = [
        (kq, base_q, [&*aq_x, &*aq_y], [&*bq_x, &*bq_y]),
        (kv, base_v, [&*av_x, &*av_y], [&*bv_x, &*bv_y]),
    ];
    for (row_sum, base, [a_x, a_y], [b_x, b_y]) in sets {
        let mut total = 0.0;
        for k in (0..n).rev() {
            total += row_sum[k];
            row_sum[k] = total;
        }
        for k in 0..n {
            base[k] = row_sum[k] - b_x[k] * sigma_y[k] + b_y[k] * sigma_x[k] + a_x[k] * lambda_y[k]
                - a_y[k] * lambda_x[k];
        }
    }
}

/// `E_l = (c alpha - s w^2, s alpha + c w^2)`, the vector of `d/dq`.
#[inline(always)]
fn motion_e(c: f64, s: f64, w: f64, alpha: f64) -> [f64; 2] {
    let w2 = w * w;
    [c * alpha - s * w2, s * alpha + c * w2]
}

/// `F_l = 2 w u`, the vector of `d/dv`.
#[inline(always)]
fn motion_f(c: f64, s: f64, w: f64) -> [f64; 2] {
    [2.0 * w * c, 2.0 * w * s]
}
