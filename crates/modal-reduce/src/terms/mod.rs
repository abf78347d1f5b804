//! The default path: `M*`, `C*` and `G*` (eq 14) in `O(n m^2)` without forming the `n x n` mass
//! matrix, from prefix sums along the chain in absolute link angles.
//!
//! # Derivation
//!
//! Number links from 0 at the base. Link `l` has absolute angle `phi_l = theta_0 + ... + theta_l`;
//! with `theta = J a + theta_0` (eq 8) this is `phi_l = Phi_l . a + phi0_l`, where the row
//! `Phi_l = J_0 + ... + J_l` (running sum of the rows of `J`) and `phi0_l` are constants, so
//! `phi_dot_l = Phi_l . a_dot` and `phi_ddot_l = Phi_l . a_ddot`. Write
//! `u_l = (cos phi_l, sin phi_l)`, `w_l = (-sin phi_l, cos phi_l)`, and let `L_l`, `m_l`, `r_l`,
//! `I_l` be the link's length, mass, centre-of-mass offset and inertia.
//!
//! *The chain in absolute angles.* Joint `l` sits at `p_l = sum_{j<l} L_j u_j` and the centre of
//! mass of link `l` at `c_l = p_l + r_l u_l`, so `c_dot_l = sum_{j<l} L_j phi_dot_j w_j +
//! r_l phi_dot_l w_l`. Expanding `T = 1/2 sum_l (m_l |c_dot_l|^2 + I_l phi_dot_l^2)` gives
//! `T = 1/2 phi_dot^T H phi_dot` with
//!
//! ```text
//! H_jl = h_jl cos(phi_j - phi_l),   h_ll = I_l + m_l r_l^2 + L_l^2 mu_l,   h_jl = L_j S_l  (j < l),
//! mu_l = sum_{i>l} m_i  (mass beyond link l),   S_l = m_l r_l + L_l mu_l.
//! ```
//!
//! The potential is `V = g sum_l m_l (c_l)_y = g sum_l S_l sin phi_l`. Lagrange's equations
//! for this `H` give the Coriolis/centrifugal forces `c_j = sum_l h_jl sin(phi_j - phi_l)
//! phi_dot_l^2` and the gravity forces `dV/dphi_l = g S_l cos phi_l`.
//!
//! *Reduction.* `phi = Phi a + phi0` with constant `Phi` (rows `Phi_l`) is an exact holonomic
//! constraint, so the reduced system is Lagrangian with `M* = Phi^T H Phi`,
//! `C* = Phi^T c(phi, Phi a_dot)` and `G* = Phi^T dV/dphi`; these are the projections
//! `J^T M J`, `J^T C`, `J^T G` of eq 14, written in absolute rather than relative angles.
//!
//! *Prefix sums.* With `P_l = sum_{j<l} L_j w_j Phi_j` (`2 x m`) and
//! `q_l = -sum_{j<l} L_j phi_dot_j^2 u_j` (the acceleration of joint `l` when `a_ddot = 0`):
//!
//! ```text
//! v_l = P_l^T w_l = sum_{j<l} L_j cos(phi_j - phi_l) Phi_j^T
//! w_l . q_l       = sum_{j<l} L_j phi_dot_j^2 sin(phi_l - phi_j)
//! ```
//!
//! and splitting each double sum into `j < l`, `j = l` and `j > l`:
//!
//! ```text
//! M* = K + A + A^T,   A = sum_l Phi_l^T (S_l v_l)^T,   K = sum_l h_ll Phi_l^T Phi_l  (constant),
//! c_l = S_l (w_l . q_l) - L_l sum_{j>l} S_j phi_dot_j^2 sin(phi_j - phi_l).
//! ```
//!
//! The second part of `c_l` is a suffix sum, but its projection is a prefix sum again: exchanging
//! the order of summation, `sum_l L_l sum_{j>l} S_j phi_dot_j^2 sin(phi_j - phi_l) Phi_l^T =
//! sum_j S_j phi_dot_j^2 P_j^T u_j`, so
//!
//! ```text
//! C* = sum_l (S_l (w_l . q_l) Phi_l^T - S_l phi_dot_l^2 P_l^T u_l),
//! G* = g sum_l S_l cos(phi_l) Phi_l^T,
//! P_{l+1} = P_l + L_l w_l Phi_l,   q_{l+1} = q_l - L_l phi_dot_l^2 u_l.
//! ```
//!
//! So one pass from the base builds `P_l` and `q_l` and accumulates `M*`, `C*` and `G*`. Per link
//! this is one sine-cosine pair, `O(m)` work for `v_l`, `P_l^T u_l`, `P_l` and the projections,
//! and `O(m^2)` for the update of `A` (one multiply-add an entry; `M*` is symmetrised from it at
//! the end).
//!
//! # Evaluation
//!
//! A pre-pass computes, for all links at once, what depends on one link only: `phi_l`,
//! `phi_dot_l`, `sin phi_l`, `cos phi_l` and the products `S_l phi_dot_l^2`,
//! `L_l sin phi_l`, `L_l cos phi_l`, `L_l cos(phi_l) phi_dot_l^2` and
//! `L_l sin(phi_l) phi_dot_l^2` (the steps of `q_l`): for one state it runs across links, a
//! register of consecutive links at a time, where the pass could only use one lane for them; a
//! batch, whose registers hold states either way, runs it link by link, the angles and rates in
//! one loop and the rest in a second, in registers. Then the pass runs over the links with what
//! is left, the prefix sums, reading each link's values through zipped iterators (no bounds
//! checks).
//!
//! The model holds the rows `S_l Phi_l` besides `Phi_l`, so that `S_l` multiplies no
//! state-dependent value: `A` is summed as `sum_l (S_l Phi_l)^T v_l^T`, `C*`'s first part as
//! `sum_l (w_l . q_l) (S_l Phi_l)^T` and `G*` as `g sum_l cos(phi_l) (S_l Phi_l)^T`, one
//! multiplication by `S_l` fewer per coordinate and link than with `Phi_l`.
//!
//! A free base angle `alpha0` adds to every absolute angle: its column of `Phi` is all ones
//! (`ReducedModel::unit_column`). A batch whose last coordinate is such a column skips the
//! multiplications by it (in `phi_l`, `phi_dot_l` and the update of `P_l`), which gives the same
//! bits, since `x * 1 = x` exactly: four vector operations fewer a link.
//!
//! The kernel is written once, generic over a `Layout`: how its numbers sit in SIMD registers.
//! One state either has its coordinates side by side in one register (`CoordinateLanes`: each
//! per-coordinate loop of the pass is one vector operation, and the pre-pass runs across links,
//! a register of consecutive links at a time), or one coordinate a number (`OneStateScalar`,
//! when `m` exceeds the register); a batch ([`forward_dynamics_batch`]) has one coordinate of
//! several states in a register (`StateLanes`). Every state gets the same operations in the
//! same order in each, lane by lane, so a state gives the same bits alone or in a batch. Its
//! fused multiply-adds ([`Lane::mul_add`], rounded once by every instruction set) take one
//! operation where a multiply and an add took two, and half the latency.
//!
//! [`forward_dynamics_batch`]: crate::forward_dynamics_batch

mod kernel;
mod layout;
mod links;

use lane_math::Lane;
use pulp::{Simd, WithSimd};

use crate::data::ReducedData;
use crate::error::{ReduceError, check_terms_finite};
use crate::model::{LINK_PADDING, ReducedModel};
pub(crate) use kernel::{Terms, accumulate, extract};
use lane_math::all_finite;
use lane_math::check_values;
pub(crate) use layout::{CoordinateLanes, Layout, OneStateScalar, Registers, StateLanes};
pub(crate) use links::{LinkBuffers, angles_in_range};

/// Computes `M*(a)`, `C*(a, a_dot)` and `G*(a)` (eq 14) into `data` in `O(n m^2)`, by prefix
/// sums along the chain (the default path; see the [module documentation](self) for the
/// derivation).
///
/// Read the results with [`ReducedData::mass_matrix`], [`ReducedData::coriolis`] and
/// [`ReducedData::gravity`]. Allocation-free.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedData, ReducedModel, reduced_terms};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let mut data = ReducedData::new(&model);
/// reduced_terms(&model, &mut data, &[0.3, -0.2, 0.5], &[1.0, 0.5, -0.4])?;
/// let m_star = data.mass_matrix();
/// assert!((m_star[(0, 1)] - m_star[(1, 0)]).abs() < 1e-15);
/// assert!(m_star[(2, 2)] > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reduced_terms(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    check_state(model, data, a, a_dot)?;
    let arch = data.arch;
    arch.dispatch(TermsOfOneState {
        model,
        data: &mut *data,
        a,
        a_dot,
    });
    check_terms(data)
}

/// Checks that `data` was made for `model` and that `a` and `a_dot` are `m` finite values each.
pub(crate) fn check_state(
    model: &ReducedModel,
    data: &ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_values("a", a, m)?;
    check_values("a_dot", a_dot, m)?;
    Ok(())
}

/// Checks that the terms in `data` are finite, naming the first that is not.
pub(crate) fn check_terms(data: &ReducedData) -> Result<(), ReduceError> {
    check_terms_finite(&data.mass, &data.coriolis, &data.gravity)
}

/// The terms of [`reduced_terms`] (inputs already checked), run by [`pulp::Arch::dispatch`] so
/// that the kernel is compiled for the processor's instruction set.
struct TermsOfOneState<'a> {
    model: &'a ReducedModel,
    data: &'a mut ReducedData,
    a: &'a [f64],
    a_dot: &'a [f64],
}

impl WithSimd for TermsOfOneState<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Self {
            model,
            data,
            a,
            a_dot,
        } = self;
        // The sizes evaluated SIMD across states in a batch run on stack arrays here too.
        match model.n_coords() {
            2 => StackTerms::<2>::compute(simd, model, data, a, a_dot).store(data),
            3 => StackTerms::<3>::compute(simd, model, data, a, a_dot).store(data),
            4 => StackTerms::<4>::compute(simd, model, data, a, a_dot).store(data),
            5 => StackTerms::<5>::compute(simd, model, data, a, a_dot).store(data),
            _ => accumulate_in_data(simd, model, data, a, a_dot),
        }
    }
}

/// [`accumulate`] for any `m`, one coordinate a number, into the slices of `data`.
#[inline(always)]
pub(crate) fn accumulate_in_data<S: Simd>(
    simd: S,
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) {
    let ReducedData {
        links,
        mass,
        coriolis,
        gravity,
        scratch,
        ..
    } = data;
    let layout = OneStateScalar(simd);
    let mut terms = Terms {
        mass: &mut scratch.mass,
        coriolis: &mut scratch.coriolis,
        gravity: &mut scratch.gravity,
        joint: &mut scratch.joint,
        v: &mut scratch.v,
    };
    let m = model.n_coords();
    let link_buffers = LinkBuffers {
        angle: links.angle.get_mut(),
        sin: links.sin.get_mut(),
        cos: links.cos.get_mut(),
        products: links.products.get_mut(),
        links: model.link_constants().padded,
    };
    accumulate(layout, model, a, a_dot, m, link_buffers, &mut terms);
    extract(layout, model, m, &terms, mass, coriolis, gravity);
}

/// `M*`, `C*` and `G*` of one state for a compile-time `M`, on the stack (the optimiser keeps
/// them in registers).
pub(crate) struct StackTerms<const M: usize> {
    /// `M*`.
    pub(crate) mass: [[f64; M]; M],
    /// `C*`.
    pub(crate) coriolis: [f64; M],
    /// `G*`.
    pub(crate) gravity: [f64; M],
}

impl<const M: usize> StackTerms<M> {
    /// [`accumulate`] for one state, with `data`'s per-link buffers: the coordinates in one
    /// register when they fit ([`CoordinateLanes`]), else one a number ([`OneStateScalar`]).
    #[inline(always)]
    pub(crate) fn compute<S: Simd>(
        simd: S,
        model: &ReducedModel,
        data: &mut ReducedData,
        a: &[f64],
        a_dot: &[f64],
    ) -> Self {
        if M <= S::F64_LANES && S::F64_LANES <= LINK_PADDING {
            Self::compute_in(CoordinateLanes::new(simd, M), model, data, a, a_dot)
        } else {
            Self::compute_in(OneStateScalar(simd), model, data, a, a_dot)
        }
    }

    /// [`compute`](Self::compute) in the layout `layout`.
    #[inline(always)]
    fn compute_in<Y: Layout<Value = f64>>(
        layout: Y,
        model: &ReducedModel,
        data: &mut ReducedData,
        a: &[f64],
        a_dot: &[f64],
    ) -> Self {
        let zero = Y::Register::splat(layout.register_context(), 0.0);
        // At most M registers a row (one coordinate a register).
        let mut mass = [[zero; M]; M];
        let (mut coriolis, mut gravity, mut v) = ([zero; M], [zero; M], [zero; M]);
        let mut joint = [[zero; 2]; M];
        let links = &mut data.links;
        let link_buffers = LinkBuffers {
            angle: links.angle.get_mut(),
            sin: links.sin.get_mut(),
            cos: links.cos.get_mut(),
            products: links.products.get_mut(),
            links: model.link_constants().padded,
        };
        let mut terms = Terms {
            mass: mass.as_flattened_mut(),
            coriolis: &mut coriolis,
            gravity: &mut gravity,
            joint: &mut joint,
            v: &mut v,
        };
        accumulate(layout, model, a, a_dot, M, link_buffers, &mut terms);
        let mut out = Self {
            mass: [[0.0; M]; M],
            coriolis: [0.0; M],
            gravity: [0.0; M],
        };
        extract(
            layout,
            model,
            M,
            &terms,
            out.mass.as_flattened_mut(),
            &mut out.coriolis,
            &mut out.gravity,
        );
        out
    }

    /// Copies the terms into `data`, where [`ReducedData::mass_matrix`] and the others read them.
    #[inline(always)]
    pub(crate) fn store(&self, data: &mut ReducedData) {
        data.mass.copy_from_slice(self.mass.as_flattened());
        data.coriolis.copy_from_slice(&self.coriolis);
        data.gravity.copy_from_slice(&self.gravity);
    }

    /// Whether every term is finite.
    #[inline(always)]
    pub(crate) fn all_finite(&self) -> bool {
        all_finite(self.mass.as_flattened())
            & all_finite(&self.coriolis)
            & all_finite(&self.gravity)
    }
}
