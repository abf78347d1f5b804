//! Analytic derivatives of the reduced forward dynamics (eq 15): `d a_ddot / d a`,
//! `d a_ddot / d a_dot` and `d a_ddot / d tau* = M*^-1`, in `O(n m^2)` without forming any
//! `n x n` matrix.
//!
//! # Derivation
//!
//! Differentiating `M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau*` at fixed `tau*` gives
//! `d a_ddot / d a = -M*^-1 D_a` and `d a_ddot / d a_dot = -M*^-1 D_v`, where `D_a` and `D_v` are
//! the partials of the reduced inverse dynamics `M* a_ddot + C* + G*` at the solution `a_ddot`.
//! In the absolute link angles of [`crate::terms`] (`phi = Phi a + phi0`, rates `w = Phi a_dot`,
//! accelerations `alpha = Phi a_ddot`) the reduced inverse dynamics is `Phi^T f(phi, w, alpha)`
//! with `f` the chain's generalised forces in absolute angles, so `D_a = Phi^T X Phi` and
//! `D_v = Phi^T Y Phi` with the `n x n` partials of `manip_dyn::rnea_derivatives`:
//!
//! ```text
//! X_jl = h_jl (s_j E_l^x - c_j E_l^y),  E_l = (c_l alpha_l - s_l w_l^2, s_l alpha_l + c_l w_l^2),
//! Y_jl = h_jl (s_j F_l^x - c_j F_l^y),  F_l = 2 w_l u_l                     (l != j),
//! X_jj = -sum_{l != j} X_jl - g S_j s_j,   Y_jj = 0,
//! ```
//!
//! `h_jl = L_min(j,l) S_max(j,l)`, `u_l = (c_l, s_l)`. Because `h_jl` factors, the projection
//! splits into prefix sums, as `M*` does in [`crate::terms`]: with the `m`-vectors
//! `P^s_j = sum_{l<j} L_l s_l Phi_l`, `P^c_j = sum_{l<j} L_l c_l Phi_l` and
//! `Q_j = sum_{l<j} L_l E_l Phi_l` (two `m`-vectors), the part above the diagonal is
//! `sum_j S_j (E_j^x P^s_j - E_j^y P^c_j) Phi_j^T`, the part below it
//! `sum_j S_j Phi_j (s_j Q_j^x - c_j Q_j^y)^T`, and the diagonal `sum_j X_jj Phi_j Phi_j^T` with
//! `X_jj = -L_j (s_j A_{j+1}^x - c_j A_{j+1}^y) - S_j (s_j B_j^x - c_j B_j^y) - g S_j s_j` from the
//! scalar sums `A_k = sum_{l>=k} S_l E_l` and `B_j = sum_{l<j} L_l E_l`. `D_v` is the same with
//! `F` for `E` and no diagonal. One pass from the tip (`A`) and one from the base (the rest),
//! `O(m^2)` per link (`O(m)` for the vectors of the link, then a rank-2 update of each partial);
//! then an `L D L^T` factorisation of `M*` and one substitution sweep over the rows of the
//! `m x 3m` right-hand side `[-D_a | -D_v | 1]`, which gives the three Jacobians at once. The
//! paper's sizes (`m = 2` to `5`) run on stack arrays of compile-time size, which the compiler
//! unrolls; other sizes on the workspace's vectors.

use faer::MatRef;
use pulp::{Simd, WithSimd};

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::forward::forward_dynamics;
use crate::model::ReducedModel;
use lane_math::check_len;
use lane_math::dense::{ldlt_in_place, ldlt_solve_rows_in_place};

/// Results and scratch of [`reduced_derivatives`] for one [`ReducedModel`]: `O(n + m^2)` memory,
/// built once; every call then fills it without allocating.
///
/// After a call, [`a_ddot`](Self::a_ddot) holds the modal accelerations and
/// [`d_a`](Self::d_a), [`d_a_dot`](Self::d_a_dot) and [`d_tau_star`](Self::d_tau_star) their
/// `m x m` Jacobians, entry `(i, j) = d a_ddot_i / d in_j`.
#[derive(Debug, Clone)]
pub struct ReducedDerivatives {
    n_links: usize,
    n_coords: usize,
    a_ddot: Vec<f64>,
    /// Row-major `m x 3m`: row `i` is `[d_a row i | d_a_dot row i | d_tau_star row i]`.
    jacobians: Vec<f64>,
    /// Per link (`n` each): signed absolute rate `w_l`, acceleration `alpha_l`, and the
    /// diagonal weight `X_ll`.
    rate: Vec<f64>,
    accel: Vec<f64>,
    diagonal: Vec<f64>,
    /// Scratch of the sizes without a stack version: [`VECTORS`] vectors of `m`, one after
    /// the other, and the factor of `M*` (`m x m`).
    vectors: Vec<f64>,
    factor: Vec<f64>,
}

/// The `m`-vectors of the pass from the base: `P^s`, `P^c`, `Q^x`, `Q^y`, the `F` counterparts
/// of `Q`, and the link's four update vectors (above and below the diagonal, for `D_a` and
/// `D_v`).
const VECTORS: usize = 10;

/// The most coordinates on stack arrays (`K = 2` harmonics with `alpha0` free).
const MAX_STACK_COORDS: usize = 5;

impl ReducedDerivatives {
    /// A workspace sized for `model`.
    pub fn new(model: &ReducedModel) -> Self {
        let (n, m) = (model.n_links(), model.n_coords());
        // The stack sizes need no heap scratch.
        let heap = m > MAX_STACK_COORDS;
        Self {
            n_links: n,
            n_coords: m,
            a_ddot: vec![0.0; m],
            jacobians: vec![0.0; 3 * m * m],
            rate: vec![0.0; n],
            accel: vec![0.0; n],
            diagonal: vec![0.0; n],
            vectors: vec![0.0; if heap { VECTORS * m } else { 0 }],
            factor: vec![0.0; if heap { m * m } else { 0 }],
        }
    }

    /// The modal accelerations `a_ddot` (eq 15) of the last call.
    pub fn a_ddot(&self) -> &[f64] {
        &self.a_ddot
    }

    /// `d a_ddot / d a` (`m x m`).
    pub fn d_a(&self) -> MatRef<'_, f64> {
        self.block(0)
    }

    /// `d a_ddot / d a_dot` (`m x m`).
    pub fn d_a_dot(&self) -> MatRef<'_, f64> {
        self.block(1)
    }

    /// `d a_ddot / d tau* = M*^-1` (`m x m`).
    pub fn d_tau_star(&self) -> MatRef<'_, f64> {
        self.block(2)
    }

    fn block(&self, index: usize) -> MatRef<'_, f64> {
        let m = self.n_coords;
        MatRef::from_row_major_slice_with_stride(&self.jacobians[index * m..], m, m, 3 * m)
    }
}

/// The reduced forward dynamics (as [`forward_dynamics`]) and its analytic derivatives with
/// respect to `a`, `a_dot` and `tau*` at one state, into `derivatives`, for any modal map (any
/// number of harmonics, `alpha0` free or fixed). `O(n m^2)` like [`crate::reduced_terms`], never
/// forming an `n x n` matrix; allocation-free. `data` holds `M*`, `C*` and `G*` afterwards. The
/// derivation is in the module documentation of `src/derivatives.rs`.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedData, ReducedDerivatives, ReducedModel, reduced_derivatives};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let (mut data, mut derivatives) = (ReducedData::new(&model), ReducedDerivatives::new(&model));
/// let (a, a_dot, tau_star) = ([0.4, -0.3, 1.2], [0.5, 0.2, -0.1], [1.0, -0.5, 0.2]);
/// reduced_derivatives(&model, &mut data, &mut derivatives, &a, &a_dot, &tau_star)?;
/// // d a_ddot / d tau* is the inverse of M*.
/// let product = data.mass_matrix() * derivatives.d_tau_star();
/// for i in 0..3 {
///     for j in 0..3 {
///         let identity = if i == j { 1.0 } else { 0.0 };
///         assert!((product[(i, j)] - identity).abs() < 1e-12);
///     }
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// As [`forward_dynamics`], and [`ReduceError::Dimension`] if `derivatives` was built for
/// another model.
pub fn reduced_derivatives(
    model: &ReducedModel,
    data: &mut ReducedData,
    derivatives: &mut ReducedDerivatives,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
) -> Result<(), ReduceError> {
    check_len(
        "derivative workspace links",
        derivatives.n_links,
        model.n_links(),
    )?;
    check_len(
        "derivative workspace coordinates",
        derivatives.n_coords,
        model.n_coords(),
    )?;
    forward_dynamics(model, data, a, a_dot, tau_star, &mut derivatives.a_ddot)?;
    // `forward_dynamics` left each link's sine and cosine in `data.links`, and M* in `data`.
    let arch = data.arch;
    let positive_definite = match model.n_coords() {
        2..=MAX_STACK_COORDS => arch.dispatch(OnStack {
            model,
            data,
            derivatives: &mut *derivatives,
            a_dot,
        }),
        m => {
            let ReducedDerivatives {
                a_ddot,
                jacobians,
                rate,
                accel,
                diagonal,
                vectors,
                factor,
                ..
            } = derivatives;
            let links = LinkScratch {
                rate,
                accel,
                diagonal,
            };
            differentiate(
                model, data, m, a_dot, a_ddot, links, vectors, factor, jacobians,
            )
        }
    };
    if !positive_definite {
        return Err(ReduceError::NotPositiveDefinite);
    }
    check_finite_result("reduced dynamics derivatives", &derivatives.jacobians)
}

/// Per-link scratch of [`differentiate`] (`n` each): `w_l`, `alpha_l` and `X_ll`.
struct LinkScratch<'a> {
    rate: &'a mut [f64],
    accel: &'a mut [f64],
    diagonal: &'a mut [f64],
}

/// [`differentiate`] for the sizes on stack arrays, run by [`pulp::Arch::dispatch`] so that it
/// is compiled for the processor's instruction set (the same operations in the same order as
/// without; no fused multiply-adds).
struct OnStack<'a> {
    model: &'a ReducedModel,
    data: &'a ReducedData,
    derivatives: &'a mut ReducedDerivatives,
    a_dot: &'a [f64],
}

impl WithSimd for OnStack<'_> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> bool {
        let Self {
            model,
            data,
            derivatives,
            a_dot,
        } = self;
        match model.n_coords() {
            2 => on_stack::<2>(model, data, derivatives, a_dot),
            3 => on_stack::<3>(model, data, derivatives, a_dot),
            4 => on_stack::<4>(model, data, derivatives, a_dot),
            _ => on_stack::<5>(model, data, derivatives, a_dot),
        }
    }
}

/// [`differentiate`] for a compile-time `M`, on local arrays; the Jacobians are copied into
/// `derivatives`.
#[inline(always)]
fn on_stack<const M: usize>(
    model: &ReducedModel,
    data: &ReducedData,
    derivatives: &mut ReducedDerivatives,
    a_dot: &[f64],
) -> bool {
    let mut vectors = [[0.0; M]; VECTORS];
    let mut factor = [[0.0; M]; M];
    let mut jacobians = [[[0.0; M]; 3]; M];
    let ReducedDerivatives {
        a_ddot,
        rate,
        accel,
        diagonal,
        ..
    } = derivatives;
    let links = LinkScratch {
        rate,
        accel,
        diagonal,
    };
    let positive_definite = differentiate(
        model,
        data,
        M,
        a_dot,
        a_ddot,
        links,
        vectors.as_flattened_mut(),
        factor.as_flattened_mut(),
        jacobians.as_flattened_mut().as_flattened_mut(),
    );
    derivatives
        .jacobians
        .copy_from_slice(jacobians.as_flattened().as_flattened());
    positive_definite
}

/// The three Jacobians (row-major `m x 3m`, into `jacobians`) at the state of `data` (the sines
/// and cosines of the link angles, `M*`) and the accelerations `a_ddot`; `vectors` holds
/// [`VECTORS`] `m`-vectors of scratch one after the other, and `factor` `m x m`. `false` if `M*` is not numerically
/// positive definite.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn differentiate(
    model: &ReducedModel,
    data: &ReducedData,
    m: usize,
    a_dot: &[f64],
    a_ddot: &[f64],
    links: LinkScratch<'_>,
    vectors: &mut [f64],
    factor: &mut [f64],
    jacobians: &mut [f64],
) -> bool {
    let n = model.n_links();
    let g = model.chain().gravity();
    let (a_dot, a_ddot) = (&a_dot[..m], &a_ddot[..m]);
    let (sin, cos) = (&data.links.sin.get()[..n], &data.links.cos.get()[..n]);
    let rows = &model.angle_rows()[..n * m];
    let constants = model.link_constants();
    let (lengths, moments) = (&constants.length[..n], &constants.first_moment[..n]);
    let (rate, accel, diagonal) = (
        &mut links.rate[..n],
        &mut links.accel[..n],
        &mut links.diagonal[..n],
    );
    // From the tip: w_l, alpha_l, and the part of X_ll from A_{l+1} and gravity.
    let mut suffix = [0.0; 2];
    for l in (0..n).rev() {
        let phi = &rows[l * m..(l + 1) * m];
        let (mut w, mut alpha) = (0.0, 0.0);
        for k in 0..m {
            w += phi[k] * a_dot[k];
            alpha += phi[k] * a_ddot[k];
        }
        rate[l] = w;
        accel[l] = alpha;
        let (s, c, moment) = (sin[l], cos[l], moments[l]);
        diagonal[l] = -lengths[l] * (s * suffix[0] - c * suffix[1]) - g * moment * s;
        let e = motion_e(c, s, w, alpha);
        suffix = [suffix[0] + moment * e[0], suffix[1] + moment * e[1]];
    }
    // From the base: the prefix sums, and the rank-2 update of each partial, accumulated with
    // the opposite sign as the right-hand sides -D_a and -D_v.
    // Split one after the other (an array of slices mapped from the scratch kept the compiler
    // from holding the stack sizes' vectors in registers).
    let vectors = &mut vectors[..VECTORS * m];
    // The six prefix sums start at zero.
    vectors[..6 * m].fill(0.0);
    let (p_sin, rest) = vectors.split_at_mut(m);
    let (p_cos, rest) = rest.split_at_mut(m);
    let (q_x, rest) = rest.split_at_mut(m);
    let (q_y, rest) = rest.split_at_mut(m);
    let (qf_x, rest) = rest.split_at_mut(m);
    let (qf_y, rest) = rest.split_at_mut(m);
    let (above_a, rest) = rest.split_at_mut(m);
    let (above_v, rest) = rest.split_at_mut(m);
    let (below_a, below_v) = rest.split_at_mut(m);
    let width = 3 * m;
    let jacobians = &mut jacobians[..m * width];
    jacobians.fill(0.0);
    let mut before = [0.0; 2];
    for (l, phi) in rows.chunks_exact(m).enumerate() {
        let (s, c, w, alpha) = (sin[l], cos[l], rate[l], accel[l]);
        let moment = moments[l];
        let e = motion_e(c, s, w, alpha);
        let f = [2.0 * w * c, 2.0 * w * s];
        let weight = diagonal[l] - moment * (s * before[0] - c * before[1]);
        // D += above ⊗ Phi + Phi ⊗ below.
        for i in 0..m {
            above_a[i] = -(moment * (e[0] * p_sin[i] - e[1] * p_cos[i]) + weight * phi[i]);
            above_v[i] = -(moment * (f[0] * p_sin[i] - f[1] * p_cos[i]));
            below_a[i] = -(moment * (s * q_x[i] - c * q_y[i]));
            below_v[i] = -(moment * (s * qf_x[i] - c * qf_y[i]));
        }
        for (i, row) in jacobians.chunks_exact_mut(width).enumerate() {
            let (d_a, d_v) = row[..2 * m].split_at_mut(m);
            for k in 0..m {
                d_a[k] += above_a[i] * phi[k] + phi[i] * below_a[k];
                d_v[k] += above_v[i] * phi[k] + phi[i] * below_v[k];
            }
        }
        let length = lengths[l];
        for k in 0..m {
            let lp = length * phi[k];
            p_sin[k] += s * lp;
            p_cos[k] += c * lp;
            q_x[k] += e[0] * lp;
            q_y[k] += e[1] * lp;
            qf_x[k] += f[0] * lp;
            qf_y[k] += f[1] * lp;
        }
        before = [before[0] + length * e[0], before[1] + length * e[1]];
    }
    // The right-hand side of M*^-1 itself, then all 3m columns solved at once.
    for (i, row) in jacobians.chunks_exact_mut(width).enumerate() {
        row[2 * m + i] = 1.0;
    }
    let factor = &mut factor[..m * m];
    factor.copy_from_slice(&data.mass[..m * m]);
    if !ldlt_in_place((), factor, m) {
        return false;
    }
    ldlt_solve_rows_in_place(factor, m, jacobians, width);
    true
}

/// `E_l = (c alpha - s w^2, s alpha + c w^2)`.
#[inline(always)]
fn motion_e(c: f64, s: f64, w: f64, alpha: f64) -> [f64; 2] {
    let w2 = w * w;
    [c * alpha - s * w2, s * alpha + c * w2]
}
