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
//! splits into prefix and suffix sums, as `M*` does in [`crate::terms`]. Off the diagonal,
//! `sum_{j != l} X_jl Phi_j Phi_l^T = sum_l (E_l^x U^s_l - E_l^y U^c_l) Phi_l^T` with the
//! `m`-vectors `U^s_l = sum_{j != l} h_jl s_j Phi_j` and `U^c_l` (the same with `c_j`), and
//! `U_l = S_l P_l + L_l R_l` with the prefix sums `P^s_l = sum_{j<l} L_j s_j Phi_j` (and `P^c_l`)
//! and the suffix sums `R^s_l = sum_{j>l} S_j s_j Phi_j` (and `R^c_l`). So, with `F` for `E` and
//! no diagonal for `D_v`,
//!
//! ```text
//! D_a = sum_l z^a_l Phi_l^T,   z^a_l = E_l^x U^s_l - E_l^y U^c_l + X_ll Phi_l,
//! D_v = sum_l z^v_l Phi_l^T,   z^v_l = F_l^x U^s_l - F_l^y U^c_l,
//! ```
//!
//! one rank-1 update of each partial a link, and the diagonal
//! `X_ll = -L_l (s_l A_{l+1}^x - c_l A_{l+1}^y) - S_l (s_l B_l^x - c_l B_l^y) - g S_l s_l` from the
//! scalar sums `A_k = sum_{j>=k} S_j E_j` and `B_l = sum_{j<l} L_j E_j`. One pass from the tip
//! (`A`, `R`; it leaves `E_l`, `F_l`, the tip's part of `X_ll` and `L_l R_l` for each link) and
//! one from the base (`B`, `P`, the updates), `O(m^2)` per link; then an `L D L^T`
//! factorisation of `M*` and one substitution sweep over the rows of the `m x 3m` right-hand
//! side `[-D_a | -D_v | 1]`, which gives the three Jacobians at once. The sums are taken with
//! fused multiply-adds, the kernel compiled for the processor's instruction set. The
//! paper's sizes (`m = 2` to `5`) run on stack arrays of compile-time size, which the compiler
//! unrolls; other sizes on the workspace's vectors.

use faer::MatRef;
use pulp::{Simd, WithSimd};

use crate::data::ReducedData;
use crate::error::{ReduceError, check_finite_result};
use crate::forward::forward_dynamics;
use crate::model::ReducedModel;
use lane_math::dense::{ldlt_in_place, ldlt_solve_rows_in_place};
use lane_math::{Lane, check_len};

/// Results and scratch of [`reduced_derivatives`] for one [`ReducedModel`]: `O(n m + m^2)`
/// memory, built once; every call then fills it without allocating.
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
    /// What the pass from the tip leaves for the pass from the base, [`LINK_VALUES`]` + 2m`
    /// numbers a link: `E_l`, `F_l`, `X_ll`'s part from the tip, then `L_l R^s_l` and
    /// `L_l R^c_l`.
    links: Vec<f64>,
    /// Scratch of the sizes without a stack version: [`VECTORS`] vectors of `m`, one after
    /// the other, and the factor of `M*` (`m x m`).
    vectors: Vec<f64>,
    factor: Vec<f64>,
}

/// The scalars a link keeps between the passes: `E_l` (2), `F_l` (2) and the part of `X_ll`
/// from the tip.
pub(crate) const LINK_VALUES: usize = 5;

/// The `m`-vectors of the passes: `R^s`, `R^c` (from the tip), `P^s`, `P^c` (from the base),
/// and the link's update vectors `z_a`, `z_v`.
pub(crate) const VECTORS: usize = 6;

/// The most coordinates on stack arrays (`K = 2` harmonics with `alpha0` free), each size
/// matched in [`Differentiate`].
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
            links: vec![0.0; n * (LINK_VALUES + 2 * m)],
            vectors: vec![0.0; if heap { VECTORS * m } else { 0 }],
            factor: vec![0.0; if heap { m * m } else { 0 }],
        }
    }

    /// The modal accelerations `a_ddot` (eq 15) of the last call.
    #[inline]
    pub fn a_ddot(&self) -> &[f64] {
        &self.a_ddot
    }

    /// The three Jacobians side by side, row-major `m x 3m`: row `i` is
    /// `[d_a row i | d_a_dot row i | d_tau_star row i]`.
    #[inline]
    pub fn jacobians(&self) -> &[f64] {
        &self.jacobians
    }

    /// `d a_ddot / d a` (`m x m`).
    #[inline]
    pub fn d_a(&self) -> MatRef<'_, f64> {
        self.block(0)
    }

    /// `d a_ddot / d a_dot` (`m x m`).
    #[inline]
    pub fn d_a_dot(&self) -> MatRef<'_, f64> {
        self.block(1)
    }

    /// `d a_ddot / d tau* = M*^-1` (`m x m`).
    #[inline]
    pub fn d_tau_star(&self) -> MatRef<'_, f64> {
        self.block(2)
    }

    #[inline]
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
    let positive_definite = arch.dispatch(Differentiate {
        model,
        data,
        derivatives: &mut *derivatives,
        a_dot,
    });
    if !positive_definite {
        return Err(ReduceError::NotPositiveDefinite);
    }
    check_finite_result("reduced dynamics derivatives", &derivatives.jacobians)
}

/// The scratch of [`differentiate`] in the numbers `L` of one state or of a group of states:
/// the per-link values of the pass from the tip ([`LINK_VALUES`]` + 2m` a link, each
/// `L::WIDTH` lanes side by side in `links`), [`VECTORS`] `m`-vectors one after the other, and
/// the factor of `M*` (`m x m`).
pub(crate) struct Scratch<'a, L> {
    pub(crate) links: &'a mut [f64],
    pub(crate) vectors: &'a mut [L],
    pub(crate) factor: &'a mut [L],
}

/// The sines and cosines of the links' absolute angles that the terms left: link `l`'s lanes
/// at `sin[l * stride..]` and `cos[l * stride..]`.
pub(crate) struct LinkTrig<'a> {
    pub(crate) sin: &'a [f64],
    pub(crate) cos: &'a [f64],
    pub(crate) stride: usize,
}

/// What [`differentiate`] reads of a state (or of each state of a group): its rates, its
/// accelerations and `M*` (row-major `m x m`).
pub(crate) struct StateOf<'a, L> {
    pub(crate) a_dot: &'a [L],
    pub(crate) a_ddot: &'a [L],
    pub(crate) mass: &'a [L],
}

/// [`differentiate`] run by [`pulp::Arch::dispatch`], so that it is compiled for the
/// processor's instruction set (its fused multiply-adds among them).
struct Differentiate<'a> {
    model: &'a ReducedModel,
    data: &'a ReducedData,
    derivatives: &'a mut ReducedDerivatives,
    a_dot: &'a [f64],
}

impl WithSimd for Differentiate<'_> {
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
            5 => on_stack::<5>(model, data, derivatives, a_dot),
            m => {
                let ReducedDerivatives {
                    a_ddot,
                    jacobians,
                    links,
                    vectors,
                    factor,
                    ..
                } = derivatives;
                let scratch = Scratch {
                    links,
                    vectors,
                    factor,
                };
                let state = StateOf {
                    a_dot,
                    a_ddot,
                    mass: &data.mass,
                };
                differentiate(
                    (),
                    model,
                    one_state_trig(data),
                    m,
                    state,
                    scratch,
                    jacobians,
                )
            }
        }
    }
}

/// The sines and cosines that the one-state terms left in `data`.
#[inline(always)]
fn one_state_trig(data: &ReducedData) -> LinkTrig<'_> {
    LinkTrig {
        sin: data.links.sin.get(),
        cos: data.links.cos.get(),
        stride: 1,
    }
}

/// [`differentiate`] for a compile-time `M`, its vectors and factor on local arrays; the
/// Jacobians are copied into `derivatives`.
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
    let ReducedDerivatives { a_ddot, links, .. } = derivatives;
    let scratch = Scratch {
        links,
        vectors: vectors.as_flattened_mut(),
        factor: factor.as_flattened_mut(),
    };
    let state = StateOf {
        a_dot,
        a_ddot,
        mass: &data.mass,
    };
    let positive_definite = differentiate(
        (),
        model,
        one_state_trig(data),
        M,
        state,
        scratch,
        jacobians.as_flattened_mut().as_flattened_mut(),
    );
    derivatives
        .jacobians
        .copy_from_slice(jacobians.as_flattened().as_flattened());
    positive_definite
}

/// The three Jacobians (row-major `m x 3m`, into `jacobians`) of one state (`L = f64`) or of
/// a group of states side by side (the same operations in the same order in every lane), from
/// the sines and cosines of the link angles `trig` and the state's rates, accelerations and
/// `M*`. `false` if `M*` is not numerically positive definite (in any lane).
#[inline(always)]
pub(crate) fn differentiate<L: Lane>(
    context: L::Context,
    model: &ReducedModel,
    trig: LinkTrig<'_>,
    m: usize,
    state: StateOf<'_, L>,
    scratch: Scratch<'_, L>,
    jacobians: &mut [L],
) -> bool {
    let n = model.n_links();
    let width = L::WIDTH;
    let splat = |x: f64| L::splat(context, x);
    let negative_zero = splat(-0.0);
    let g = model.chain().gravity();
    let (a_dot, a_ddot) = (&state.a_dot[..m], &state.a_ddot[..m]);
    let rows = &model.angle_rows()[..n * m];
    let constants = model.link_constants();
    let (lengths, moments) = (&constants.length[..n], &constants.first_moment[..n]);
    let stride = (LINK_VALUES + 2 * m) * width;
    let links = &mut scratch.links[..n * stride];
    let vectors = &mut scratch.vectors[..VECTORS * m];
    vectors.fill(splat(0.0));
    // Split one after the other (an array of slices mapped from the scratch would keep the
    // compiler from holding the stack sizes' vectors in registers).
    let (r_sin, rest) = vectors.split_at_mut(m);
    let (r_cos, rest) = rest.split_at_mut(m);
    let (p_sin, rest) = rest.split_at_mut(m);
    let (p_cos, rest) = rest.split_at_mut(m);
    let (z_a, z_v) = rest.split_at_mut(m);
    let trig_of = |l: usize| {
        let at = l * trig.stride;
        (
            L::load(context, &trig.sin[at..]),
            L::load(context, &trig.cos[at..]),
        )
    };
    // From the tip: E_l, F_l, the part of X_ll from A_{l+1} and gravity, and L_l R^s_l,
    // L_l R^c_l from the suffix sums R^s_l, R^c_l (links beyond l).
    let mut suffix = [splat(0.0); 2];
    let tip_first = rows.chunks_exact(m).zip(links.chunks_exact_mut(stride));
    for (l, (phi, link)) in tip_first.enumerate().rev() {
        let (mut w, mut alpha) = (splat(0.0), splat(0.0));
        for k in 0..m {
            w = splat(phi[k]).mul_add(a_dot[k], w);
            alpha = splat(phi[k]).mul_add(a_ddot[k], alpha);
        }
        let (s, c) = trig_of(l);
        let (moment, length) = (splat(moments[l]), splat(lengths[l]));
        let e = motion_e(c, s, w, alpha, negative_zero);
        let tip_part =
            (splat(-lengths[l]) * (s * suffix[0] - c * suffix[1])) - splat(g) * moment * s;
        let values = [e[0], e[1], splat(2.0) * w * c, splat(2.0) * w * s, tip_part];
        let (stored, vectors) = link.split_at_mut(LINK_VALUES * width);
        for (value, slot) in values.into_iter().zip(stored.chunks_exact_mut(width)) {
            value.store(slot);
        }
        let (l_r_sin, l_r_cos) = vectors.split_at_mut(m * width);
        let (moment_sin, moment_cos) = (moment * s, moment * c);
        for k in 0..m {
            (length * r_sin[k]).store(&mut l_r_sin[k * width..]);
            (length * r_cos[k]).store(&mut l_r_cos[k * width..]);
            r_sin[k] = moment_sin.mul_add(splat(phi[k]), r_sin[k]);
            r_cos[k] = moment_cos.mul_add(splat(phi[k]), r_cos[k]);
        }
        suffix = [
            moment.mul_add(e[0], suffix[0]),
            moment.mul_add(e[1], suffix[1]),
        ];
    }
    // From the base: the prefix sums P^s_l, P^c_l (links before l) and B_l, and the rank-1
    // update of each partial, accumulated with the opposite sign as the right-hand sides
    // -D_a and -D_v.
    let columns = 3 * m;
    let jacobians = &mut jacobians[..m * columns];
    jacobians.fill(splat(0.0));
    let mut before = [splat(0.0); 2];
    for (l, (phi, link)) in rows
        .chunks_exact(m)
        .zip(links.chunks_exact(stride))
        .enumerate()
    {
        let (s, c) = trig_of(l);
        let (moment, length) = (splat(moments[l]), splat(lengths[l]));
        let (stored, vectors) = link.split_at(LINK_VALUES * width);
        let value = |j: usize| L::load(context, &stored[j * width..]);
        let (e, f) = ([value(0), value(1)], [value(2), value(3)]);
        let weight = value(4) - moment * (s * before[0] - c * before[1]);
        let (l_r_sin, l_r_cos) = vectors.split_at(m * width);
        // z = -(E^x U^s - E^y U^c + X_ll Phi) with U = S_l P_l + L_l R_l, F for E in z_v.
        for i in 0..m {
            let u_sin = moment.mul_add(p_sin[i], L::load(context, &l_r_sin[i * width..]));
            let u_cos = moment.mul_add(p_cos[i], L::load(context, &l_r_cos[i * width..]));
            let inner = weight.mul_add(splat(phi[i]), e[0] * u_sin);
            z_a[i] = e[1].mul_add(u_cos, inner.xor_bits(negative_zero));
            z_v[i] = f[1].mul_add(u_cos, (f[0] * u_sin).xor_bits(negative_zero));
        }
        for (i, row) in jacobians.chunks_exact_mut(columns).enumerate() {
            let (d_a, d_v) = row[..2 * m].split_at_mut(m);
            for k in 0..m {
                d_a[k] = z_a[i].mul_add(splat(phi[k]), d_a[k]);
                d_v[k] = z_v[i].mul_add(splat(phi[k]), d_v[k]);
            }
        }
        for k in 0..m {
            let lp = length * splat(phi[k]);
            p_sin[k] = s.mul_add(lp, p_sin[k]);
            p_cos[k] = c.mul_add(lp, p_cos[k]);
        }
        before = [
            length.mul_add(e[0], before[0]),
            length.mul_add(e[1], before[1]),
        ];
    }
    // The right-hand side of M*^-1 itself, then all 3m columns solved at once.
    for (i, row) in jacobians.chunks_exact_mut(columns).enumerate() {
        row[2 * m + i] = splat(1.0);
    }
    let factor = &mut scratch.factor[..m * m];
    factor.copy_from_slice(&state.mass[..m * m]);
    if !ldlt_in_place(context, factor, m) {
        return false;
    }
    ldlt_solve_rows_in_place(factor, m, jacobians, columns);
    true
}

/// `E_l = (c alpha - s w^2, s alpha + c w^2)` (`negative_zero` flips a sign exactly).
#[inline(always)]
fn motion_e<L: Lane>(c: L, s: L, w: L, alpha: L, negative_zero: L) -> [L; 2] {
    let w2 = w * w;
    [
        c.mul_add(alpha, (s * w2).xor_bits(negative_zero)),
        s.mul_add(alpha, c * w2),
    ]
}
