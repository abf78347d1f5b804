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

use crate::check;
use crate::crba;
use crate::data::ChainData;
use crate::derivative_data::{DerivativeData, LinkTerms};
use crate::error::DynError;
use crate::kinematics::LinkFrame;
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
    fill_partials(
        model,
        &data.frames,
        qdd,
        1.0,
        &mut derivatives.links,
        &mut derivatives.blocks,
        stride,
    );
    crba::assemble(
        model,
        &data.frames,
        &mut data.subtrees,
        &mut data.mass_row,
        MatMut::from_row_major_slice_with_stride_mut(&mut derivatives.blocks[2 * n..], n, n, stride),
    );
    check::finite_result("tau derivatives", &derivatives.blocks)
}

/// Writes `sign * d tau / d q` and `sign * d tau / d v` at the accelerations `qdd` into the first
/// two `n`-column blocks of the row-major `n x stride` `blocks`, from `frames` already updated at
/// `(q, v)` (inputs validated). Inlined, so that inside `aba_derivatives`' SIMD dispatch the
/// loops vectorise with its instruction set.
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
    let links = model.links();
    let g = model.gravity();
    // From the tip: S_j, sigma_i, A_k (both sets).
    let mut beyond = 0.0;
    let mut sigma = [0.0; 2];
    let mut suffix = [[0.0; 2]; 2];
    for which in 0..2 {
        terms.suffix[which][0][n] = 0.0;
        terms.suffix[which][1][n] = 0.0;
    }
    // From the base: absolute accelerations (needed by E before the sweep from the tip).
    let mut alpha = 0.0;
    for (accel, &qdd_i) in terms.accel.iter_mut().zip(qdd) {
        alpha += qdd_i;
        *accel = alpha;
    }
    for j in (0..n).rev() {
        let link = &links[j];
        let frame = &frames[j];
        let [c, s] = frame.axis;
        let moment = link.mass * link.com + link.length * beyond;
        beyond += link.mass;
        let (w, alpha) = (frame.omega, terms.accel[j]);
        terms.moment[j] = moment;
        terms.rate[j] = w;
        sigma = [sigma[0] + moment * c, sigma[1] + moment * s];
        terms.sigma[0][j] = sigma[0];
        terms.sigma[1][j] = sigma[1];
        for (which, [ex, ey]) in [motion_e(c, s, w, alpha), motion_f(c, s, w)]
            .into_iter()
            .enumerate()
        {
            let sum = &mut suffix[which];
            *sum = [sum[0] + sign * moment * ex, sum[1] + sign * moment * ey];
            terms.suffix[which][0][j] = sum[0];
            terms.suffix[which][1][j] = sum[1];
        }
    }
    // From the base: lambda_k, B_k, the row sums kappa_j.
    let mut lambda = [0.0; 2];
    let mut prefix = [[0.0; 2]; 2];
    for j in 0..n {
        let link = &links[j];
        let [c, s] = frames[j].axis;
        let (moment, w, alpha) = (terms.moment[j], terms.rate[j], terms.accel[j]);
        terms.lambda[0][j] = lambda[0];
        terms.lambda[1][j] = lambda[1];
        lambda = [lambda[0] + link.length * c, lambda[1] + link.length * s];
        for (which, [ex, ey]) in [motion_e(c, s, w, alpha), motion_f(c, s, w)]
            .into_iter()
            .enumerate()
        {
            let sum = &mut prefix[which];
            terms.prefix[which][0][j] = sum[0];
            terms.prefix[which][1][j] = sum[1];
            // kappa_j from B_j (before adding link j) and A_{j+1}.
            terms.row_sum[which][j] = if which == 0 {
                -sign * g * moment * s
            } else {
                let (ax, ay) = (terms.suffix[1][0][j + 1], terms.suffix[1][1][j + 1]);
                moment * (s * sum[0] - c * sum[1]) + link.length * (s * ax - c * ay)
            };
            *sum = [
                sum[0] + sign * link.length * ex,
                sum[1] + sign * link.length * ey,
            ];
        }
    }
    // From the tip: K_i = sum_{j>=i} kappa_j, then base_k.
    for which in 0..2 {
        let mut total = 0.0;
        for k in (0..n).rev() {
            total += terms.row_sum[which][k];
            terms.row_sum[which][k] = total;
        }
        for k in 0..n {
            let (ax, ay) = (terms.suffix[which][0][k], terms.suffix[which][1][k]);
            let (bx, by) = (terms.prefix[which][0][k], terms.prefix[which][1][k]);
            terms.base[which][k] = terms.row_sum[which][k] - bx * terms.sigma[1][k]
                + by * terms.sigma[0][k]
                + ax * terms.lambda[1][k]
                - ay * terms.lambda[0][k];
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
