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
//! `O(m^2)` per link; then an `L D L^T` factorisation of `M*` and `3m` small solves.

use faer::MatRef;

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result, check_len};
use crate::forward::forward_dynamics;
use crate::model::ReducedModel;
use crate::small_linalg::{ldlt_in_place, ldlt_solve_in_place};

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
    /// `m` each: `P^s`, `P^c`, `Q^x`, `Q^y` and the `F` counterparts of `Q`.
    prefix: [Vec<f64>; 6],
    /// `m x m` each, column-major (row `k` is column `k`): `D_a`, `D_v`; then the factor of `M*`.
    partial: [Vec<f64>; 2],
    factor: Vec<f64>,
    /// `m`: one right-hand side of the solves.
    column: Vec<f64>,
}

impl ReducedDerivatives {
    /// A workspace sized for `model`.
    pub fn new(model: &ReducedModel) -> Self {
        let (n, m) = (model.n_links(), model.n_coords());
        Self {
            n_links: n,
            n_coords: m,
            a_ddot: vec![0.0; m],
            jacobians: vec![0.0; 3 * m * m],
            rate: vec![0.0; n],
            accel: vec![0.0; n],
            diagonal: vec![0.0; n],
            prefix: std::array::from_fn(|_| vec![0.0; m]),
            partial: [vec![0.0; m * m], vec![0.0; m * m]],
            factor: vec![0.0; m * m],
            column: vec![0.0; m],
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
    // `forward_dynamics` left each link's sine and cosine in `data.links`.
    partials(model, data, derivatives, a_dot);
    let m = model.n_coords();
    let d = &mut *derivatives;
    d.factor.copy_from_slice(&data.mass);
    if !ldlt_in_place((), &mut d.factor, m) {
        return Err(ReduceError::NotPositiveDefinite);
    }
    // Column k of each block: -M*^-1 D_a e_k, -M*^-1 D_v e_k, M*^-1 e_k.
    for k in 0..m {
        for block in 0..3 {
            let column = &mut d.column;
            match block {
                2 => {
                    column.fill(0.0);
                    column[k] = 1.0;
                }
                _ => {
                    for (entry, &value) in column.iter_mut().zip(&d.partial[block][k * m..]) {
                        *entry = -value;
                    }
                }
            }
            ldlt_solve_in_place(&d.factor, m, column);
            for (i, &value) in column.iter().enumerate() {
                d.jacobians[i * 3 * m + block * m + k] = value;
            }
        }
    }
    check_finite_result("reduced dynamics derivatives", &d.jacobians)
}

/// `D_a` and `D_v` (column-major) at the state of `data` (sines and cosines of the link angles)
/// and the accelerations in `derivatives`.
fn partials(
    model: &ReducedModel,
    data: &ReducedData,
    derivatives: &mut ReducedDerivatives,
    a_dot: &[f64],
) {
    let m = model.n_coords();
    let g = model.chain().gravity();
    let (sin, cos) = (&data.links.sin, &data.links.cos);
    let rows = model.angle_rows();
    let links = model.link_constants();
    let ReducedDerivatives {
        a_ddot,
        rate,
        accel,
        diagonal,
        prefix,
        partial,
        ..
    } = derivatives;
    // From the tip: w_l, alpha_l, and the part of X_ll from A_{l+1} and gravity.
    let mut suffix = [0.0; 2];
    for l in (0..links.len()).rev() {
        let phi = &rows[l * m..(l + 1) * m];
        let (w, alpha) = phi
            .iter()
            .zip(a_dot.iter().zip(a_ddot.iter()))
            .fold((0.0, 0.0), |(w, alpha), (p, (v, acc))| {
                (w + p * v, alpha + p * acc)
            });
        rate[l] = w;
        accel[l] = alpha;
        let (s, c, link) = (sin[l], cos[l], &links[l]);
        diagonal[l] = -link.length * (s * suffix[0] - c * suffix[1]) - g * link.first_moment * s;
        let e = motion_e(c, s, w, alpha);
        suffix = [
            suffix[0] + link.first_moment * e[0],
            suffix[1] + link.first_moment * e[1],
        ];
    }
    // From the base: the prefix sums and the projections.
    for p in prefix.iter_mut() {
        p.fill(0.0);
    }
    for q in partial.iter_mut() {
        q.fill(0.0);
    }
    let [p_sin, p_cos, q_x, q_y, qf_x, qf_y] = prefix;
    let [d_a, d_v] = partial;
    let mut before = [0.0; 2];
    for (l, (link, phi)) in links.iter().zip(rows.chunks_exact(m)).enumerate() {
        let (s, c, w, alpha) = (sin[l], cos[l], rate[l], accel[l]);
        let moment = link.first_moment;
        let e = motion_e(c, s, w, alpha);
        let f = [2.0 * w * c, 2.0 * w * s];
        let weight = diagonal[l] - moment * (s * before[0] - c * before[1]);
        // D += above ⊗ Phi + Phi ⊗ below (stored column-major: d[k * m + i] = D_ik).
        for k in 0..m {
            let below_a = moment * (s * q_x[k] - c * q_y[k]);
            let below_v = moment * (s * qf_x[k] - c * qf_y[k]);
            for i in 0..m {
                let above_a = moment * (e[0] * p_sin[i] - e[1] * p_cos[i]) + weight * phi[i];
                let above_v = moment * (f[0] * p_sin[i] - f[1] * p_cos[i]);
                d_a[k * m + i] += above_a * phi[k] + phi[i] * below_a;
                d_v[k * m + i] += above_v * phi[k] + phi[i] * below_v;
            }
        }
        let length = link.length;
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
}

/// `E_l = (c alpha - s w^2, s alpha + c w^2)`.
#[inline(always)]
fn motion_e(c: f64, s: f64, w: f64, alpha: f64) -> [f64; 2] {
    let w2 = w * w;
    [c * alpha - s * w2, s * alpha + c * w2]
}
