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

use crate::data::{LINK_PADDING, ReducedData};
use crate::error::{ReduceError, check_finite_result, check_input};
use crate::model::ReducedModel;
use lane_math::{Lane, Pack, REDUCTION_LIMIT, sin_cos_in_range, sin_cos_lanes};
use pulp::{Simd, WithSimd};

/// Per-link products the pre-pass leaves for the pass besides the sine and cosine, in this order
/// in the buffer: `S_l phi_dot_l^2`, `L_l sin phi_l`, `L_l cos phi_l`,
/// `L_l cos(phi_l) phi_dot_l^2`, `L_l sin(phi_l) phi_dot_l^2`.
pub(crate) const PRODUCTS: usize = 5;

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
    check_input("a", a, m)?;
    check_input("a_dot", a_dot, m)
}

/// Checks that the terms in `data` are finite, naming the first that is not.
pub(crate) fn check_terms(data: &ReducedData) -> Result<(), ReduceError> {
    check_finite_result("reduced mass matrix M*", &data.mass)?;
    check_finite_result("reduced Coriolis vector C*", &data.coriolis)?;
    check_finite_result("reduced gravity vector G*", &data.gravity)
}

/// Whether every value is finite: one test of all of them, without the early exit that keeps a
/// search from vectorising.
#[inline(always)]
pub(crate) fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |finite, v| finite & v.is_finite())
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

/// An `(x, y)` pair: a column of the `2 x m` prefix sum `P_l`.
pub(crate) type Pair<L> = [L; 2];

/// How the kernel's numbers sit in registers (see the [module documentation](self)).
pub(crate) trait Layout: Copy {
    /// A register of the pass: several coordinates of one state, or one coordinate (of one state
    /// or of several side by side).
    type Register: Lane;
    /// One number of each state: `f64` for one state, a register of states for a batch.
    type Value: Lane;
    /// What building a register needs.
    fn register_context(self) -> <Self::Register as Lane>::Context;
    /// What building a value needs.
    fn value_context(self) -> <Self::Value as Lane>::Context;
    /// How many registers a row of `m` coordinates takes.
    fn chunks(self, m: usize) -> usize;
    /// `value` in every coordinate of a register.
    fn spread(self, value: Self::Value) -> Self::Register;
    /// Register `chunk` of a constant row of the layout's `m` coordinates starting at `row[0]`;
    /// `row` continues for at least [`LINK_PADDING`] values (the lanes past the `m` coordinates
    /// are zero).
    fn constant_row(self, row: &[f64], chunk: usize) -> Self::Register;
    /// Coordinate `k` of the row held in the registers `row`.
    fn coordinate(self, row: &[Self::Register], k: usize) -> Self::Value;
    /// The step `P_{l+1} = P_l + L_l w_l Phi_l` of register `chunk` of the columns `pair` of
    /// `P_l`, from `L_l sin phi_l`, `L_l cos phi_l` and the constant row `row` of `Phi` (see
    /// [`constant_row`](Self::constant_row)).
    #[inline(always)]
    fn joint_step(
        self,
        [px, py]: Pair<Self::Register>,
        [l_sin, l_cos]: Pair<Self::Register>,
        row: &[f64],
        chunk: usize,
    ) -> Pair<Self::Register> {
        joint_step_by([px, py], [l_sin, l_cos], self.constant_row(row, chunk))
    }

    /// The per-link values of all links into `links` (the pre-pass).
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[Self::Value],
        a_dot: &[Self::Value],
        links: &mut LinkBuffers<'_>,
    );
}

/// One state, its coordinates side by side in one register of the instruction set `S` (`m` at
/// most its lanes, which are at most [`LINK_PADDING`]); the pre-pass runs across links.
#[derive(Clone, Copy)]
pub(crate) struct CoordinateLanes<S: Simd> {
    simd: S,
    /// All bits set in the lanes of the `m` coordinates, none past them.
    mask: Pack<S>,
}

impl<S: Simd> CoordinateLanes<S> {
    /// The layout for `m` coordinates.
    #[inline(always)]
    pub(crate) fn new(simd: S, m: usize) -> Self {
        let mut mask = [0.0; LINK_PADDING];
        for lane in &mut mask[..m] {
            *lane = f64::from_bits(!0);
        }
        Self {
            simd,
            mask: Pack::load(simd, &mask),
        }
    }
}

impl<S: Simd> Layout for CoordinateLanes<S> {
    type Register = Pack<S>;
    type Value = f64;

    #[inline(always)]
    fn register_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn value_context(self) {}

    #[inline(always)]
    fn chunks(self, _: usize) -> usize {
        1
    }

    #[inline(always)]
    fn spread(self, value: f64) -> Pack<S> {
        Pack::splat(self.simd, value)
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], _: usize) -> Pack<S> {
        Pack::load(self.simd, row).and_bits(self.mask)
    }

    #[inline(always)]
    fn coordinate(self, row: &[Pack<S>], k: usize) -> f64 {
        row[0].lane(k)
    }

    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[f64],
        a_dot: &[f64],
        links: &mut LinkBuffers<'_>,
    ) {
        link_values_across_links(self.simd, model, a, a_dot, links);
    }
}

/// One state, one coordinate a number (for more coordinates than a register holds); the
/// pre-pass runs across links in registers of `S`.
#[derive(Clone, Copy)]
pub(crate) struct OneStateScalar<S>(pub(crate) S);

impl<S: Simd> Layout for OneStateScalar<S> {
    type Register = f64;
    type Value = f64;

    #[inline(always)]
    fn register_context(self) {}

    #[inline(always)]
    fn value_context(self) {}

    #[inline(always)]
    fn chunks(self, m: usize) -> usize {
        m
    }

    #[inline(always)]
    fn spread(self, value: f64) -> f64 {
        value
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], chunk: usize) -> f64 {
        row[chunk]
    }

    #[inline(always)]
    fn coordinate(self, row: &[f64], k: usize) -> f64 {
        row[k]
    }

    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[f64],
        a_dot: &[f64],
        links: &mut LinkBuffers<'_>,
    ) {
        link_values_across_links(self.0, model, a, a_dot, links);
    }
}

/// Several states side by side, lane `i` of every register holding state `i`; one coordinate a
/// register. Only for states that pass [`angles_in_range`]: its sines and cosines skip the test
/// for angles beyond the reduction's range (four vector operations a link).
#[derive(Clone, Copy)]
pub(crate) struct StateLanes<S: Simd> {
    simd: S,
    /// A coordinate whose column of `Phi` is all ones ([`ReducedModel::unit_column`]), or
    /// `usize::MAX`: the multiplications by that column are skipped, which gives the same bits
    /// (`x * 1 = x` exactly) with fewer operations.
    unit: usize,
}

impl<S: Simd> StateLanes<S> {
    /// The layout of `S`, skipping the multiplications by the column `unit` of `Phi` (all ones;
    /// `usize::MAX` for none).
    #[inline(always)]
    pub(crate) fn new(simd: S, unit: usize) -> Self {
        Self { simd, unit }
    }
}

impl<S: Simd> Layout for StateLanes<S> {
    type Register = Pack<S>;
    type Value = Pack<S>;

    #[inline(always)]
    fn register_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn value_context(self) -> S {
        self.simd
    }

    #[inline(always)]
    fn chunks(self, m: usize) -> usize {
        m
    }

    #[inline(always)]
    fn spread(self, value: Pack<S>) -> Pack<S> {
        value
    }

    #[inline(always)]
    fn constant_row(self, row: &[f64], chunk: usize) -> Pack<S> {
        Pack::splat(self.simd, row[chunk])
    }

    #[inline(always)]
    fn coordinate(self, row: &[Pack<S>], k: usize) -> Pack<S> {
        row[k]
    }

    #[inline(always)]
    fn joint_step(
        self,
        [px, py]: Pair<Pack<S>>,
        [l_sin, l_cos]: Pair<Pack<S>>,
        row: &[f64],
        chunk: usize,
    ) -> Pair<Pack<S>> {
        if chunk == self.unit {
            // `x * 1 + y` rounds as `x + y`.
            [px - l_sin, py + l_cos]
        } else {
            joint_step_by([px, py], [l_sin, l_cos], self.constant_row(row, chunk))
        }
    }

    #[inline(always)]
    fn link_values(
        self,
        model: &ReducedModel,
        a: &[Pack<S>],
        a_dot: &[Pack<S>],
        links: &mut LinkBuffers<'_>,
    ) {
        let simd = self.simd;
        let width = S::F64_LANES;
        let constants = model.link_constants();
        let m = a.len();
        let n = model.n_links();
        let rows = model.angle_rows()[..n * m].chunks_exact(m);
        let offsets = &constants.angle_offset[..n];
        let LinkBuffers {
            angle, products, ..
        } = links;
        let angles = angle[..n * width].chunks_exact_mut(width);
        // The rates where the first product goes, until the products replace them.
        let rates = products[..n * width].chunks_exact_mut(width);
        for (((phi, &offset), angle), rate) in rows.zip(offsets).zip(angles).zip(rates) {
            let inputs = AcrossStates {
                simd,
                a,
                a_dot,
                phi,
                unit: self.unit,
            };
            let [angle_l, rate_l] = link_angle_rate(simd, Pack::splat(simd, offset), &inputs);
            angle_l.store(angle);
            rate_l.store(rate);
        }
        let (moments, lengths) = (&constants.first_moment[..n], &constants.length[..n]);
        let (angle, registers) = links.angles_and_registers(n, width);
        let per_link = angle.chunks_exact(width).zip(moments).zip(lengths);
        for (((angle, &moment), &length), out) in per_link.zip(registers) {
            let rate = Pack::load(simd, &*out[2]);
            // Within the reduction's range: `angles_in_range` held (see `StateLanes`).
            let (sin, cos) = sin_cos_in_range(simd, Pack::load(simd, angle));
            let (moment, length) = (Pack::splat(simd, moment), Pack::splat(simd, length));
            let [p0, p1, p2, p3, p4] = link_products([sin, cos, rate], moment, length);
            store_link(out, [sin, cos, p0, p1, p2, p3, p4]);
        }
    }
}

/// `[px - l_sin phi, py + l_cos phi]`, each rounded once: the step of a column pair of `P_l`
/// (see [`Layout::joint_step`]).
#[inline(always)]
fn joint_step_by<R: Lane>([px, py]: Pair<R>, [l_sin, l_cos]: Pair<R>, phi: R) -> Pair<R> {
    [l_sin.neg_mul_add(phi, px), l_cos.mul_add(phi, py)]
}

/// Whether every link's absolute angle is within [`REDUCTION_LIMIT`] in every state of `a` (of
/// [`StateLanes`]), by the model's bound `|phi_l| <= max |phi0| + sum_k max_l |(Phi_l)_k| |a_k|`
/// kept under half the limit, a margin far beyond the rounding of the sums. One test for a
/// group of states instead of one a link; a group that fails is left to the one-state path,
/// which tests each angle (far beyond any arm's range: a quarter of a million turns).
#[inline(always)]
pub(crate) fn angles_in_range<S: Simd>(simd: S, model: &ReducedModel, a: &[Pack<S>]) -> bool {
    let (offset, columns) = model.angle_bound().split_first().unwrap_or((&0.0, &[]));
    let mut bound = Pack::splat(simd, *offset);
    for (a_k, &column) in a.iter().zip(columns) {
        bound = bound + a_k.abs() * Pack::splat(simd, column);
    }
    Pack::splat(simd, 0.5 * REDUCTION_LIMIT).all_greater(bound)
}

/// The pre-pass of one state: [`link_angle_rate`], the sines and cosines, then
/// [`link_products`], each a loop over registers of consecutive links (the last one padded with
/// the zeros of the padded constants). Separate loops, so that the sines and cosines (long
/// chains of dependent operations) run alone, short enough for the processor to overlap them.
#[inline(always)]
fn link_values_across_links<S: Simd>(
    simd: S,
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    links: &mut LinkBuffers<'_>,
) {
    if S::F64_LANES > LINK_PADDING {
        // Wider registers than the padding: one link at a time.
        across_links::<f64>((), model, a, a_dot, links);
    } else {
        across_links::<Pack<S>>(simd, model, a, a_dot, links);
    }
}

/// [`link_values_across_links`] in registers of `L` (`L::WIDTH` at most [`LINK_PADDING`]).
#[inline(always)]
fn across_links<L: Lane>(
    context: L::Context,
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    links: &mut LinkBuffers<'_>,
) {
    let constants = model.link_constants();
    let n = model.n_links();
    for l in (0..n).step_by(L::WIDTH) {
        let inputs = AcrossLinks::<L> {
            context,
            model,
            a,
            a_dot,
            l,
        };
        let offset = L::load(context, &constants.angle_offset[l..]);
        links.store_angle_rate(l, 1, link_angle_rate(context, offset, &inputs));
    }
    links.sin_cos::<L>(context, n.next_multiple_of(L::WIDTH));
    for l in (0..n).step_by(L::WIDTH) {
        let angles = links.load_trig_rate(context, l, 1);
        let moment = L::load(context, &constants.first_moment[l..]);
        let length = L::load(context, &constants.length[l..]);
        links.store_products(l, 1, link_products(angles, moment, length));
    }
}

/// The inputs of [`link_angle_rate`] for the consecutive links `l..l + L::WIDTH` of one state (its
/// coordinates spread across the lanes).
struct AcrossLinks<'a, L: Lane> {
    context: L::Context,
    model: &'a ReducedModel,
    a: &'a [f64],
    a_dot: &'a [f64],
    l: usize,
}

impl<L: Lane> LinkInputs<L> for AcrossLinks<'_, L> {
    #[inline(always)]
    fn coords(&self) -> usize {
        self.a.len()
    }

    #[inline(always)]
    fn add_terms(&self, k: usize, angle: L, rate: L) -> (L, L) {
        let column = self.model.link_constants().angle_column(k);
        let phi = L::load(self.context, &column[self.l..]);
        (
            L::splat(self.context, self.a[k]).mul_add(phi, angle),
            L::splat(self.context, self.a_dot[k]).mul_add(phi, rate),
        )
    }
}

/// The inputs of [`link_angle_rate`] for link `phi` (its row `Phi_l`) of several states side by side.
struct AcrossStates<'a, S: Simd> {
    simd: S,
    a: &'a [Pack<S>],
    a_dot: &'a [Pack<S>],
    phi: &'a [f64],
    /// The column of ones of `Phi`, or `usize::MAX` (see [`StateLanes`]).
    unit: usize,
}

impl<S: Simd> LinkInputs<Pack<S>> for AcrossStates<'_, S> {
    #[inline(always)]
    fn coords(&self) -> usize {
        self.a.len()
    }

    #[inline(always)]
    fn add_terms(&self, k: usize, angle: Pack<S>, rate: Pack<S>) -> (Pack<S>, Pack<S>) {
        if k == self.unit {
            // `x * 1 + y` rounds as `x + y`.
            return (angle + self.a[k], rate + self.a_dot[k]);
        }
        let phi = Pack::splat(self.simd, self.phi[k]);
        (
            self.a[k].mul_add(phi, angle),
            self.a_dot[k].mul_add(phi, rate),
        )
    }
}

/// The state-dependent inputs of [`link_angle_rate`].
trait LinkInputs<L> {
    /// The number of coordinates `m`.
    fn coords(&self) -> usize;
    /// `(angle + a_k (Phi_l)_k, rate + a_dot_k (Phi_l)_k)`, each rounded once.
    fn add_terms(&self, k: usize, angle: L, rate: L) -> (L, L);
}

/// `[phi_l, phi_dot_l]` of one link (or one lane's link each), from its angle offset `phi0_l`
/// and the state: `phi_l = phi0_l + Phi_l . a`, `phi_dot_l = Phi_l . a_dot`.
#[inline(always)]
fn link_angle_rate<L: Lane>(
    context: L::Context,
    angle_offset: L,
    inputs: &impl LinkInputs<L>,
) -> [L; 2] {
    let mut angle = angle_offset;
    let mut rate = L::splat(context, 0.0);
    for k in 0..inputs.coords() {
        (angle, rate) = inputs.add_terms(k, angle, rate);
    }
    [angle, rate]
}

/// The [`PRODUCTS`] of one link (or one lane's link each) from `[sin phi_l, cos phi_l, phi_dot_l]`, its first moment
/// `S_l` and its length `L_l`.
#[inline(always)]
fn link_products<L: Lane>([sin, cos, rate]: [L; 3], moment: L, length: L) -> [L; PRODUCTS] {
    let rate2 = rate * rate;
    let (l_sin, l_cos) = (sin * length, cos * length);
    [rate2 * moment, l_sin, l_cos, l_cos * rate2, l_sin * rate2]
}

/// The per-link buffers of the kernel: every link's angle, its sine and cosine, and the
/// [`PRODUCTS`], each entry `W` values side by side (`W` the lanes of the layout's
/// [`Value`](Layout::Value): one state's links have one, a batch's the states of a group).
pub(crate) struct LinkBuffers<'a> {
    /// `phi_l`, `[link][lane]`.
    pub(crate) angle: &'a mut [f64],
    /// `sin phi_l`, as `angle`.
    pub(crate) sin: &'a mut [f64],
    /// `cos phi_l`, as `sin`.
    pub(crate) cos: &'a mut [f64],
    /// The products, `[product][link][lane]`.
    pub(crate) products: &'a mut [f64],
    /// The links of each product's buffer: `n`, or more for padding.
    pub(crate) links: usize,
}

impl LinkBuffers<'_> {
    /// Stores `[phi_l, phi_dot_l]` of link `l` (the rate where the first product goes, until
    /// [`store_products`](Self::store_products)), entries of `width` lanes: of the links
    /// `l..l + L::WIDTH` for a register across links (`width` 1), of link `l` for a register of
    /// states (`width` `L::WIDTH`).
    #[inline(always)]
    fn store_angle_rate<L: Lane>(&mut self, l: usize, width: usize, [angle, rate]: [L; 2]) {
        let entry = l * width;
        angle.store(&mut self.angle[entry..]);
        rate.store(&mut self.products[entry..]);
    }

    /// The sines and cosines of the first `entries` angles (a whole number of registers of
    /// `L`), a register at a time.
    #[inline(always)]
    fn sin_cos<L: Lane>(&mut self, context: L::Context, entries: usize) {
        let width = L::WIDTH;
        let angle = self.angle[..entries].chunks_exact(width);
        let sin = self.sin[..entries].chunks_exact_mut(width);
        let cos = self.cos[..entries].chunks_exact_mut(width);
        for ((angle, sin), cos) in angle.zip(sin).zip(cos) {
            let (sin_x, cos_x) = sin_cos_lanes(context, L::load(context, angle));
            sin_x.store(sin);
            cos_x.store(cos);
        }
    }

    /// The entries of the first `registers` registers of `width` lanes, in the order of
    /// [`values`](Self::values), to be written by [`store_link`]; and the angles.
    #[inline(always)]
    fn angles_and_registers(
        &mut self,
        registers: usize,
        width: usize,
    ) -> (&[f64], impl Iterator<Item = [&mut [f64]; 2 + PRODUCTS]>) {
        let size = registers * width;
        let mut rest = &mut *self.products;
        let [p0, p1, p2, p3, p4] = std::array::from_fn(|_| {
            let (product, tail) = std::mem::take(&mut rest).split_at_mut(self.links * width);
            rest = tail;
            product[..size].chunks_exact_mut(width)
        });
        let sin = self.sin[..size].chunks_exact_mut(width);
        let registers = sin
            .zip(self.cos[..size].chunks_exact_mut(width))
            .zip(p0)
            .zip(p1)
            .zip(p2)
            .zip(p3)
            .zip(p4)
            .map(|((((((sin, cos), p0), p1), p2), p3), p4)| [sin, cos, p0, p1, p2, p3, p4]);
        (&self.angle[..size], registers)
    }

    /// `[sin phi_l, cos phi_l, phi_dot_l]` of link `l` after [`sin_cos`](Self::sin_cos).
    #[inline(always)]
    fn load_trig_rate<L: Lane>(&self, context: L::Context, l: usize, width: usize) -> [L; 3] {
        let entry = l * width;
        [
            L::load(context, &self.sin[entry..]),
            L::load(context, &self.cos[entry..]),
            L::load(context, &self.products[entry..]),
        ]
    }

    /// Stores the [`PRODUCTS`] of link `l` (entries as in
    /// [`store_angle_rate`](Self::store_angle_rate)).
    #[inline(always)]
    fn store_products<L: Lane>(&mut self, l: usize, width: usize, products: [L; PRODUCTS]) {
        for (p, value) in products.iter().enumerate() {
            value.store(&mut self.products[(p * self.links + l) * width..]);
        }
    }

    /// The entries the pre-pass left for the first `registers` registers of `width` lanes, for
    /// the pass: `[sin phi_l, cos phi_l]` and the [`PRODUCTS`], each a slice of `width`
    /// values (read by [`load_link`]), zipped so that the pass reads them without bounds
    /// checks.
    #[inline(always)]
    fn values(
        &self,
        registers: usize,
        width: usize,
    ) -> impl Iterator<Item = [&[f64]; 2 + PRODUCTS]> {
        let size = registers * width;
        let stride = self.links * width;
        let [p0, p1, p2, p3, p4] =
            std::array::from_fn(|p| self.products[p * stride..][..size].chunks_exact(width));
        let sin = self.sin[..size].chunks_exact(width);
        sin.zip(self.cos[..size].chunks_exact(width))
            .zip(p0)
            .zip(p1)
            .zip(p2)
            .zip(p3)
            .zip(p4)
            .map(|((((((sin, cos), p0), p1), p2), p3), p4)| [sin, cos, p0, p1, p2, p3, p4])
    }
}

/// Writes a register of [`LinkBuffers::angles_and_registers`].
#[inline(always)]
fn store_link<L: Lane>(out: [&mut [f64]; 2 + PRODUCTS], values: [L; 2 + PRODUCTS]) {
    for (value, out) in values.into_iter().zip(out) {
        value.store(out);
    }
}

/// Reads a register of [`LinkBuffers::values`].
#[inline(always)]
fn load_link<L: Lane>(context: L::Context, entries: [&[f64]; 2 + PRODUCTS]) -> [L; 2 + PRODUCTS] {
    // (No closure: its body would be compiled without the dispatch's instruction set.)
    let [sin, cos, p0, p1, p2, p3, p4] = entries;
    [
        L::load(context, sin),
        L::load(context, cos),
        L::load(context, p0),
        L::load(context, p1),
        L::load(context, p2),
        L::load(context, p3),
        L::load(context, p4),
    ]
}

/// The results and scratch of the kernel, in registers of a [`Layout`]: `m` rows of
/// [`chunks`](Layout::chunks) registers, or one row.
pub(crate) struct Terms<'a, R> {
    /// `A` (see [`accumulate`]), row after row.
    pub(crate) mass: &'a mut [R],
    /// `C*`.
    pub(crate) coriolis: &'a mut [R],
    /// `G*`.
    pub(crate) gravity: &'a mut [R],
    /// Columns of `P_l`.
    pub(crate) joint: &'a mut [Pair<R>],
    /// `v_l`.
    pub(crate) v: &'a mut [R],
}

/// The sums of the module documentation, for `m` coordinates, into `terms` in the registers of
/// `layout`: `A` (all of it; `M* = K + A + A^T`, see [`extract`]), `C*` and `G*`.
#[inline(always)]
pub(crate) fn accumulate<Y: Layout>(
    layout: Y,
    model: &ReducedModel,
    a: &[Y::Value],
    a_dot: &[Y::Value],
    m: usize,
    mut links: LinkBuffers<'_>,
    terms: &mut Terms<'_, Y::Register>,
) {
    let (rc, vc) = (layout.register_context(), layout.value_context());
    let chunks = layout.chunks(m);
    let zero = Y::Register::splat(rc, 0.0);
    let (a, a_dot) = (&a[..m], &a_dot[..m]);
    let mass = &mut terms.mass[..m * chunks];
    let coriolis = &mut terms.coriolis[..chunks];
    let gravity = &mut terms.gravity[..chunks];
    let joint = &mut terms.joint[..chunks];
    let v = &mut terms.v[..chunks];
    mass.fill(zero);
    coriolis.fill(zero);
    gravity.fill(zero);
    joint.fill([zero; 2]);
    let n = model.n_links();
    let rows = model.angle_rows();
    let mut q = [Y::Value::splat(vc, 0.0); 2];
    layout.link_values(model, a, a_dot, &mut links);
    // The pass: P_l, q_l, and the sums of M* and C*.
    // Each link's rows zipped with its values, so that nothing is bounds-checked.
    let moment_rows = model.moment_rows();
    let width = Y::Value::WIDTH;
    let links_rows = padded_rows(rows, n, m).zip(padded_rows(moment_rows, n, m));
    for ((row, moment_row), entries) in links_rows.zip(links.values(n, width)) {
        let [sin, cos, moment_rate2, l_sin, l_cos, drop_x, drop_y]: [Y::Value; 2 + PRODUCTS] =
            load_link(vc, entries);
        // w_l . q_l, which S_l Phi_l multiplies.
        // (No closures or array maps here: their bodies would be compiled without the
        // instruction set of the dispatch, and its intrinsics called, not inlined.)
        let force = layout.spread(sin.neg_mul_add(q[0], cos * q[1]));
        let (sin, cos) = (layout.spread(sin), layout.spread(cos));
        let moment_rate2 = layout.spread(moment_rate2);
        add_gravity(layout, gravity, cos, moment_row);
        let (l_sin, l_cos) = (layout.spread(l_sin), layout.spread(l_cos));
        for c in 0..chunks {
            let moment_phi = layout.constant_row(moment_row, c);
            let [px, py] = joint[c];
            v[c] = sin.neg_mul_add(px, cos * py);
            let along = sin.mul_add(py, cos * px);
            coriolis[c] = moment_rate2.neg_mul_add(along, force.mul_add(moment_phi, coriolis[c]));
        }
        // A += (S_l Phi_l)^T v_l^T, row by row.
        for (j, &moment_phi_j) in moment_row[..m].iter().enumerate() {
            let moment_phi_j = Y::Register::splat(rc, moment_phi_j);
            for c in 0..chunks {
                let entry = &mut mass[j * chunks + c];
                *entry = v[c].mul_add(moment_phi_j, *entry);
            }
        }
        for (c, pair) in joint.iter_mut().enumerate() {
            *pair = layout.joint_step(*pair, [l_sin, l_cos], row, c);
        }
        q = [q[0] - drop_x, q[1] - drop_y];
    }
    let g = model.chain().gravity();
    for value in gravity {
        *value = *value * g;
    }
}

/// The `n` rows of `m` values of `rows` (`Phi` or the rows `S_l Phi_l`), each with the
/// [`LINK_PADDING`] values after it that [`Layout::constant_row`] may read.
#[inline(always)]
fn padded_rows(rows: &[f64], n: usize, m: usize) -> impl Iterator<Item = &[f64]> {
    rows[..n * m + LINK_PADDING]
        .windows(m + LINK_PADDING)
        .step_by(m)
}

/// `gravity += cos(phi_l) S_l Phi_l^T` for link `moment_row` (`S_l Phi_l`, followed by the
/// padding of [`Layout::constant_row`]).
#[inline(always)]
fn add_gravity<Y: Layout>(
    layout: Y,
    gravity: &mut [Y::Register],
    cos: Y::Register,
    moment_row: &[f64],
) {
    for (c, value) in gravity.iter_mut().enumerate() {
        *value = cos.mul_add(layout.constant_row(moment_row, c), *value);
    }
}

/// The terms left by [`accumulate`] in the registers of `layout`, as numbers of each state:
/// `M* = K + (A + A^T)` (its upper triangle, mirrored), `C*` and `G*`.
#[inline(always)]
pub(crate) fn extract<Y: Layout>(
    layout: Y,
    model: &ReducedModel,
    m: usize,
    terms: &Terms<'_, Y::Register>,
    mass: &mut [Y::Value],
    coriolis: &mut [Y::Value],
    gravity: &mut [Y::Value],
) {
    let chunks = layout.chunks(m);
    let constant = model.constant_mass();
    let vc = layout.value_context();
    for j in 0..m {
        let row = &terms.mass[j * chunks..(j + 1) * chunks];
        for k in j..m {
            let other = &terms.mass[k * chunks..(k + 1) * chunks];
            let sum = layout.coordinate(row, k) + layout.coordinate(other, j);
            let entry = sum + Y::Value::splat(vc, constant[j * m + k]);
            mass[j * m + k] = entry;
            mass[k * m + j] = entry;
        }
        coriolis[j] = layout.coordinate(terms.coriolis, j);
        gravity[j] = layout.coordinate(terms.gravity, j);
    }
}
