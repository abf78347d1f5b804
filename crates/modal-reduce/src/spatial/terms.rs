//! `M*`, `C*` and `G*` of a spatial modal arm in `O(n m^2)`, without the `2n x 2n` mass matrix
//! (`docs/theory.md`, section 8).
//!
//! Everything is written in each link's own frame (axes `e_x` along the link, `e_y`, `e_z`),
//! where its joints turn about coordinate axes and its inertia is diagonal. The modal rates move
//! link `i` with angular velocity `w_i = Jb_i a_dot` and its centre of mass with velocity
//! `v_i = Jv_i a_dot` (both in link `i`'s frame): entering the link, the carried Jacobians turn
//! by `Rz(z_i)^T`, then by `Ry(y_i)^T` (two numbers of each row), and the joints add their
//! columns, `Jb_i = Ry^T (Rz^T Jb_{i-1} + e_z [P_i, 0]) + e_y [0, P_i]` (`[P_i, 0]` and
//! `[0, P_i]` the link's rows of the modal map, `P_i` row `i` of the planar one); the velocity
//! Jacobian of the joint point `p_{i-1}`, `Jp`, turns alike (the joints turn about that point),
//! `Jv_i = Jp_i + Jb_i x (L_i / 2) e_x` and the next joint's `Jp_{i+1} = Jp_i + Jb_i x L_i e_x`
//! (two multiply-adds a row each), `3 x m` each, in `O(m)` a link. The angular velocity and
//! acceleration, the acceleration of the joint point and gravity are carried and turned the same
//! way. Then, from the kinetic energy `T = (1/2) sum_i m_i |v_i|^2 + w_i^T I_i w_i` and the
//! potential `V = -sum_i m_i g . c_i`,
//!
//! - `M* = sum_i m_i Jv_i^T Jv_i + Jb_i^T I_i Jb_i` (`I_i = diag(Ixx, Iyy, Izz)`, the principal
//!   moments about the centre of mass),
//! - `C* = sum_i Jv_i^T (m_i a_i) + Jb_i^T (I_i w_dot_i + w_i x I_i w_i)`, with `a_i` and
//!   `w_dot_i` the accelerations at zero modal acceleration,
//! - `G* = -sum_i m_i Jv_i^T g_i` (`g_i` gravity in link `i`'s frame),
//!
//! `O(m^2)` a link for `M*`, `O(m)` for the others. The tests hold them against the joint torques
//! of the Newton-Euler recursion (`J^T tau`), the Lagrangian's finite differences, the planar
//! reduced model and Pinocchio through the URDF export.
//!
//! # Evaluation
//!
//! - A pre-pass forms every link's joint angles and rates (`J a`, `J a_dot`, from the planar map
//!   transposed, a register of links at a time) and the angles' sines and cosines in the same
//!   registers ([`lane_math::sin_cos_lanes`]), so that the pass along the chain has no
//!   trigonometry left.
//! - The pass (`accumulate`) is written once over the planar kernel's register layouts
//!   (`Registers`): one state of `m = 4` or `8` coordinates holds each row of the Jacobians, of
//!   `C*` and `G*` and each diagonal of `M*` in one register (`CoordinateLanes`, `MassRows`),
//!   so that a row's update is one vector operation (`m = 4` in registers of 4 lanes, compiled
//!   for AVX-512 where there is one: `TermsOfOneState::run`); more coordinates go one a
//!   number (`OneStateScalar`); a batch holds one coordinate of several states a register
//!   (`StateLanes`). Each entry gets the same operations in the same order in all of them, so a
//!   state gives the same bits alone and in a batch.
//! - The rows of `J` per link (`[P_i, 0]`, `[0, P_i]`) are constants of the model, loaded as
//!   registers.
//! - Of the motion carried from link to link (module `carried`), one state keeps `w`, `w_dot`
//!   and gravity in the lanes of one register a component, so that their two turns a link are
//!   eight vector operations, and the joint point's acceleration in numbers. The gyroscopic
//!   torque is `w x I_b w = [(Izz - Iyy) w_y w_z, (Ixx - Izz) w_z w_x,
//!   (Iyy - Ixx) w_x w_y]`, the differences of moments formed with the model.

use super::carried::{
    ACCEL, CarriedMotion, GRAVITY, OMEGA, OMEGA_DOT, PackedMotion, SeparateMotion, to_child,
};
use super::data::SpatialReducedData;
use super::model::SpatialReducedModel;
use super::motion::JointTurns;
use crate::error::{ReduceError, check_terms_finite};
use crate::forward::right_hand_side;
use crate::model::LINK_PADDING;
use crate::terms::{CoordinateLanes, OneStateScalar, Registers, StateLanes};
use lane_math::dense::{ldlt_in_place, ldlt_solve_in_place};
use lane_math::{Lane, Pack, check_all_finite, check_len, sin_cos_lanes};
use pulp::{Arch, Simd, WithSimd};
use std::iter::Zip;
use std::slice;

/// Computes `M*`, `C*` and `G*` at the modal state `(a, a_dot)` into `data` (read them with
/// [`SpatialReducedData::mass_matrix`], [`coriolis`](SpatialReducedData::coriolis) and
/// [`gravity`](SpatialReducedData::gravity)). Allocation-free.
///
/// Errors: a workspace of another model, inputs of the wrong length or not finite, and terms
/// that are not finite (inputs too large for double precision).
pub fn spatial_reduced_terms(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    check_shapes(model, data, a, a_dot)?;
    let outcome = TermsOfOneState {
        model,
        data: &mut *data,
        a,
        a_dot,
        solve: None,
    }
    .run();
    if outcome.finite {
        return Ok(());
    }
    check_state(model, data, a, a_dot)?;
    check_terms(data)
}

/// Checks that the terms in `data` are finite, naming the first that is not.
pub(crate) fn check_terms(data: &SpatialReducedData) -> Result<(), ReduceError> {
    check_terms_finite(&data.mass_matrix, &data.coriolis, &data.gravity)
}

impl TermsOfOneState<'_> {
    /// Runs the kernel on the workspace's instruction set: on AVX-512 with `m = 4`, in AVX2's
    /// registers of 4 lanes, whose rows they fill (half-filled registers of 8 lanes measured
    /// about 350 against 255 ns a call at 10 links), but compiled for AVX-512, whose 32 registers
    /// rather than 16 keep the pass along the links out of memory. The same bits, as on every
    /// instruction set.
    #[inline(always)]
    pub(crate) fn run(self) -> Outcome {
        let arch = self.data.arch;
        #[cfg(target_arch = "x86_64")]
        if let (4, Arch::V4(v4)) = (self.model.n_coords(), arch) {
            return v4.vectorize(InAvx2Registers { v3: *v4, op: self });
        }
        arch.dispatch(self)
    }
}

/// `op` on AVX2's registers, called inside an AVX-512 dispatch ([`TermsOfOneState::run`]).
#[cfg(target_arch = "x86_64")]
struct InAvx2Registers<Op> {
    v3: pulp::x86::V3,
    op: Op,
}

#[cfg(target_arch = "x86_64")]
impl<Op: WithSimd> pulp::NullaryFnOnce for InAvx2Registers<Op> {
    type Output = Op::Output;

    #[inline(always)]
    fn call(self) -> Op::Output {
        self.op.with_simd(self.v3)
    }
}

/// [`spatial_reduced_terms`] after its checks, and with `solve` the forward dynamics' `L D L^T`
/// solve ([`spatial_forward_dynamics`](super::spatial_forward_dynamics)), run by
/// [`run`](Self::run) so that the kernel and the solve are compiled for the processor's
/// instruction set.
///
/// Its inputs' values are not checked beforehand: a number that is not finite in `a`, `a_dot`
/// or `tau_star` makes every term it enters not finite (NaN and infinity carry through every
/// operation, even a product by zero, and the sine of an infinity is NaN; every angle and rate
/// takes every coordinate), so one test of the results ([`Outcome::finite`]) stands for the
/// checks of the inputs, which the caller names only when it fails.
pub(crate) struct TermsOfOneState<'a> {
    pub(crate) model: &'a SpatialReducedModel,
    pub(crate) data: &'a mut SpatialReducedData,
    pub(crate) a: &'a [f64],
    pub(crate) a_dot: &'a [f64],
    /// `tau_star` and where `a_ddot` goes (`m` each, checked).
    pub(crate) solve: Option<(&'a [f64], &'a mut [f64])>,
}

/// What [`TermsOfOneState`] found.
pub(crate) struct Outcome {
    /// Whether the solve, if any, found `M*` numerically positive definite.
    pub(crate) positive_definite: bool,
    /// Whether `M*`, `C*`, `G*` and the solve's `a_ddot` (where solved) are all finite (`a_ddot`
    /// is written only where this and `positive_definite` hold).
    pub(crate) finite: bool,
}

impl WithSimd for TermsOfOneState<'_> {
    type Output = Outcome;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Outcome {
        let Self {
            model,
            data,
            a,
            a_dot,
            solve,
        } = self;
        let SpatialReducedData {
            link_rates,
            link_sin,
            link_cos,
            point_jacobian,
            com_jacobian,
            momentum_jacobian,
            body_jacobian,
            body_inertia_jacobian,
            mass_matrix,
            coriolis,
            gravity,
            factor,
            solution,
            ..
        } = data;
        let buffers = [&mut **link_sin, &mut **link_cos, &mut **link_rates];
        link_values(simd, model, a, a_dot, buffers);
        let (n, padded) = (model.n_links(), model.padded_links());
        let turns = TurnsOfLinks::new(n, padded, link_sin, link_cos, link_rates);
        let out = OneStateTerms {
            mass_matrix: &mut *mass_matrix,
            coriolis: &mut *coriolis,
            gravity: &mut *gravity,
        };
        // The sizes a batch runs SIMD across states, on the stack, the coordinates side by side
        // in one register where they fit; `m` a constant of the solve for them.
        let m = match model.n_coords() {
            4 => {
                on_stack::<S, 4>(simd, model, turns, out);
                4
            }
            8 => {
                on_stack::<S, 8>(simd, model, turns, out);
                8
            }
            m => {
                let work = TermsLanes {
                    point_jacobian,
                    com_jacobian,
                    momentum_jacobian,
                    body_jacobian,
                    body_inertia_jacobian,
                    mass_matrix: out.mass_matrix,
                    coriolis: out.coriolis,
                    gravity: out.gravity,
                };
                let work = accumulate(OneStateScalar(simd), model, turns, m, work);
                mirror_lower(work.mass_matrix, m);
                m
            }
        };
        let terms: [&[f64]; 3] = [mass_matrix, coriolis, gravity];
        let Some((tau_star, a_ddot)) = solve else {
            return Outcome {
                positive_definite: true,
                finite: all_finite(terms),
            };
        };
        // `m` a constant of the solve for the sizes of the batch.
        match m {
            4 => solve_on_stack::<4>(factor, terms, tau_star, a_ddot),
            8 => solve_on_stack::<8>(factor, terms, tau_star, a_ddot),
            m => {
                let positive_definite = solve_in_place(factor, terms, tau_star, solution, m);
                finish(positive_definite, terms, solution, a_ddot)
            }
        }
    }
}

/// The outcome of a solve of `terms` into `solution`, which is copied to `a_ddot` only where
/// `M*` was positive definite and the terms and the solution are finite, so that a call that
/// fails leaves `a_ddot` as it was.
#[inline(always)]
fn finish(
    positive_definite: bool,
    terms: [&[f64]; 3],
    solution: &[f64],
    a_ddot: &mut [f64],
) -> Outcome {
    let finite = all_finite(terms) && all_finite([solution]);
    if positive_definite && finite {
        a_ddot.copy_from_slice(solution);
    }
    Outcome {
        positive_definite,
        finite,
    }
}

/// Whether every number of `values` is finite: one pass without an early exit, so that it
/// vectorises.
#[inline(always)]
fn all_finite<const N: usize>(values: [&[f64]; N]) -> bool {
    let mut bad = false;
    for values in values {
        for &x in values {
            bad |= !x.is_finite();
        }
    }
    !bad
}

/// `a_ddot = M*^{-1} (tau* - C* - G*)` by an `L D L^T` factor of `M*` into `factor` (kept for the
/// derivatives), `terms` `[M*, C*, G*]` of `m` coordinates. Gives `false` if `M*` is not
/// numerically positive definite.
#[inline(always)]
fn solve_in_place(
    factor: &mut [f64],
    [mass_matrix, coriolis, gravity]: [&[f64]; 3],
    tau_star: &[f64],
    a_ddot: &mut [f64],
    m: usize,
) -> bool {
    let factor = &mut factor[..m * m];
    factor.copy_from_slice(&mass_matrix[..m * m]);
    if !ldlt_in_place::<f64>((), factor, m) {
        return false;
    }
    right_hand_side(tau_star, coriolis, gravity, a_ddot);
    ldlt_solve_in_place(factor, m, a_ddot);
    true
}

/// [`solve_in_place`] of `M` coordinates on a copy of `M*` and of the right-hand side on the
/// stack, so that the factorisation and the solve run in registers rather than through memory
/// (the same operations, so the same bits); the factor is stored into `factor` after, the
/// solution as [`finish`] says.
#[inline(always)]
fn solve_on_stack<const M: usize>(
    factor: &mut [f64],
    terms: [&[f64]; 3],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Outcome {
    let mut stack = [[0.0; M]; M];
    let mut x = [0.0; M];
    let positive_definite = solve_in_place(stack.as_flattened_mut(), terms, tau_star, &mut x, M);
    factor[..M * M].copy_from_slice(stack.as_flattened());
    finish(positive_definite, terms, &x, a_ddot)
}

/// Where one state's terms go: `M*` (`m x m`, row-major), `C*`, `G*`.
struct OneStateTerms<'a> {
    mass_matrix: &'a mut [f64],
    coriolis: &'a mut [f64],
    gravity: &'a mut [f64],
}

/// [`accumulate`] of one state of `M` coordinates on stack registers, the coordinates side by
/// side in one register of `S` where they fit ([`CoordinateLanes`]), else one a number.
#[inline(always)]
fn on_stack<S: Simd, const M: usize>(
    simd: S,
    model: &SpatialReducedModel,
    turns: TurnsOfLinks<'_>,
    out: OneStateTerms<'_>,
) {
    if M <= S::F64_LANES && S::F64_LANES <= LINK_PADDING {
        in_layout::<_, M, 1>(CoordinateLanes::new(simd, M), model, turns, out);
    } else {
        in_layout::<_, M, M>(OneStateScalar(simd), model, turns, out);
    }
}

/// [`on_stack`] in the layout `layout`, whose rows of `M` coordinates take `C` registers: the
/// kernel, then the registers' coordinates into `out`.
#[inline(always)]
fn in_layout<Y: MassRows<Value = f64>, const M: usize, const C: usize>(
    layout: Y,
    model: &SpatialReducedModel,
    turns: TurnsOfLinks<'_>,
    out: OneStateTerms<'_>,
) {
    let zero = Y::Register::splat(layout.register_context(), 0.0);
    debug_assert_eq!(layout.chunks(M), C);
    let mut jacobians = [[[zero; C]; 3]; 5];
    let [point, com, momentum, body, body_inertia] = &mut jacobians;
    let mut mass = [[zero; C]; M];
    let (mut coriolis, mut gravity) = ([zero; C], [zero; C]);
    let work = TermsLanes {
        point_jacobian: point.as_flattened_mut(),
        com_jacobian: com.as_flattened_mut(),
        momentum_jacobian: momentum.as_flattened_mut(),
        body_jacobian: body.as_flattened_mut(),
        body_inertia_jacobian: body_inertia.as_flattened_mut(),
        mass_matrix: mass.as_flattened_mut(),
        coriolis: &mut coriolis,
        gravity: &mut gravity,
    };
    let work = accumulate(layout, model, turns, M, work);
    for k in 0..M {
        for l in 0..=k {
            out.mass_matrix[k * M + l] = layout.mass_entry(work.mass_matrix, M, k, l);
        }
        out.coriolis[k] = layout.coordinate(work.coriolis, k);
        out.gravity[k] = layout.coordinate(work.gravity, k);
    }
    mirror_lower(out.mass_matrix, M);
}

/// Copies the lower triangle of the `m x m` row-major `matrix` onto its upper one.
#[inline(always)]
fn mirror_lower<L: Copy>(matrix: &mut [L], m: usize) {
    for k in 0..m {
        for l in 0..k {
            matrix[l * m + k] = matrix[k * m + l];
        }
    }
}

/// The sines and cosines of every link's joint angles (`theta = J a`) and its joint rates
/// (`J a_dot`) into `sin`, `cos` and `rates`, the `z` joints' (the model's
/// [`padded_links`](SpatialReducedModel::padded_links) values), then the `y` joints': a register
/// of links at a time, the padding links at angle zero, each angle the multiply-adds of
/// [`TurnsFromModes`] in its order and [`sin_cos_lanes`] (so the same bits).
#[inline(always)]
fn link_values<S: Simd>(
    simd: S,
    model: &SpatialReducedModel,
    a: &[f64],
    a_dot: &[f64],
    [sin, cos, rates]: [&mut [f64]; 3],
) {
    if S::F64_LANES > LINK_PADDING {
        // Wider registers than the padding: one link at a time.
        links_in_registers::<f64>((), model, a, a_dot, [sin, cos, rates]);
    } else {
        links_in_registers::<Pack<S>>(simd, model, a, a_dot, [sin, cos, rates]);
    }
}

/// [`link_values`] in registers of `L` (`L::WIDTH` at most [`LINK_PADDING`]).
#[inline(always)]
fn links_in_registers<L: Lane>(
    context: L::Context,
    model: &SpatialReducedModel,
    a: &[f64],
    a_dot: &[f64],
    [sin, cos, rates]: [&mut [f64]; 3],
) {
    let (half, padded) = (model.n_coords() / 2, model.padded_links());
    let zero = L::splat(context, 0.0);
    for l in (0..model.n_links()).step_by(L::WIDTH) {
        let (mut angles, mut link_rates) = ([zero; 2], [zero; 2]);
        for k in 0..half {
            let column = L::load(context, &model.angle_column(k)[l..]);
            angles = [
                L::splat(context, a[k]).mul_add(column, angles[0]),
                L::splat(context, a[half + k]).mul_add(column, angles[1]),
            ];
            link_rates = [
                L::splat(context, a_dot[k]).mul_add(column, link_rates[0]),
                L::splat(context, a_dot[half + k]).mul_add(column, link_rates[1]),
            ];
        }
        for (plane, (angle, rate)) in angles.into_iter().zip(link_rates).enumerate() {
            let at = plane * padded + l;
            let (s, c) = sin_cos_lanes(context, angle);
            s.store(&mut sin[at..]);
            c.store(&mut cos[at..]);
            rate.store(&mut rates[at..]);
        }
    }
}

/// Two slices side by side.
type Pairs<'a> = Zip<slice::Iter<'a, f64>, slice::Iter<'a, f64>>;

/// The turns of all links of one state, formed beforehand ([`link_values`]), link after link
/// (one zip of the six slices, so one test of the end a link).
struct TurnsOfLinks<'a> {
    links: Zip<Zip<Pairs<'a>, Pairs<'a>>, Pairs<'a>>,
}

impl<'a> TurnsOfLinks<'a> {
    /// The turns of `n` links from the buffers of [`SpatialReducedData`] (the `z` joints' values
    /// then the `y` joints', `padded` each).
    #[inline(always)]
    fn new(n: usize, padded: usize, sin: &'a [f64], cos: &'a [f64], rates: &'a [f64]) -> Self {
        let pairs = |values: &'a [f64]| {
            let (z, y) = values.split_at(padded);
            z[..n].iter().zip(&y[..n])
        };
        Self {
            links: pairs(sin).zip(pairs(cos)).zip(pairs(rates)),
        }
    }
}

impl Iterator for TurnsOfLinks<'_> {
    type Item = JointTurns<f64>;

    #[inline(always)]
    fn next(&mut self) -> Option<JointTurns<f64>> {
        let (((&sin_z, &sin_y), (&cos_z, &cos_y)), (&rate_z, &rate_y)) = self.links.next()?;
        Some(JointTurns {
            sin: [sin_z, sin_y],
            cos: [cos_z, cos_y],
            rates: [rate_z, rate_y],
        })
    }
}

/// The turns of a link formed as the kernel reaches it, from the modal state (`a`, `a_dot`, `m`
/// values each): `theta = J a`, `J a_dot` by multiply-adds over the row of the planar map, then
/// [`sin_cos_lanes`] (for a batch, whose registers hold states: nothing of size `n` is kept),
/// link after link from `next`.
pub(crate) struct TurnsFromModes<'a, L: Lane> {
    pub(crate) context: L::Context,
    pub(crate) model: &'a SpatialReducedModel,
    pub(crate) a: &'a [L],
    pub(crate) a_dot: &'a [L],
    pub(crate) next: usize,
}

impl<L: Lane> Iterator for TurnsFromModes<'_, L> {
    type Item = JointTurns<L>;

    #[inline(always)]
    fn next(&mut self) -> Option<JointTurns<L>> {
        let i = self.next;
        if i == self.model.n_links() {
            return None;
        }
        self.next += 1;
        let context = self.context;
        let half = self.model.n_coords() / 2;
        let zero = L::splat(context, 0.0);
        let (mut angles, mut rates) = ([zero; 2], [zero; 2]);
        for (k, &r) in self.model.map().planar().row(i)[..half].iter().enumerate() {
            let r = L::splat(context, r);
            angles = [
                self.a[k].mul_add(r, angles[0]),
                self.a[half + k].mul_add(r, angles[1]),
            ];
            rates = [
                self.a_dot[k].mul_add(r, rates[0]),
                self.a_dot[half + k].mul_add(r, rates[1]),
            ];
        }
        let (sin_z, cos_z) = sin_cos_lanes(context, angles[0]);
        let (sin_y, cos_y) = sin_cos_lanes(context, angles[1]);
        Some(JointTurns {
            sin: [sin_z, sin_y],
            cos: [cos_z, cos_y],
            rates,
        })
    }
}

/// The buffers of [`accumulate`], in registers of its layout (`c` the layout's
/// [`chunks`](Registers::chunks) of `m` coordinates): `3 x c` row-major Jacobians `Jw`, `Jo`, `Jv`,
/// `m Jv`, `Jb` and `I_b Jb`, `M*` (as [`MassRows`] keeps it), `C*` and `G*` (`c` each).
pub(crate) struct TermsLanes<'w, R> {
    pub(crate) point_jacobian: &'w mut [R],
    pub(crate) com_jacobian: &'w mut [R],
    pub(crate) momentum_jacobian: &'w mut [R],
    pub(crate) body_jacobian: &'w mut [R],
    pub(crate) body_inertia_jacobian: &'w mut [R],
    pub(crate) mass_matrix: &'w mut [R],
    pub(crate) coriolis: &'w mut [R],
    pub(crate) gravity: &'w mut [R],
}

/// `M*` (its lower triangle: entry `(k, l)`, `l <= k`, of every row; the rest unspecified), `C*`
/// and `G*` (the module's sums) of `m` coordinates into `work`, each link's turns from `turns`:
/// the kernel of [`spatial_reduced_terms`] (one state, `layout` [`CoordinateLanes`] or
/// [`OneStateScalar`]) and of the batch across states
/// ([`spatial_forward_dynamics_batch`](super::spatial_forward_dynamics_batch),
/// [`StateLanes`](crate::terms::StateLanes)), the same operations in the same order for each
/// entry in all of them. Returns `work`.
///
/// What depends on the link alone (its motion, gravity in its frame, the torque and acceleration
/// of `C*`) is one number of each state ([`Registers::Value`]); the rows of the Jacobians, of
/// `M*`, `C*` and `G*` are registers of coordinates ([`Registers::Register`]). Row `2i` of `J` is
/// `[P_i, 0]` and row `2i + 1` is `[0, P_i]` (`P_i` row `i` of the planar map), both constants
/// of the model ([`SpatialReducedModel::joint_rows`]): the joints add them to the `z` and `y`
/// rows of `Jb`, an addition a register each.
#[inline(always)]
pub(crate) fn accumulate<'w, Y: MassRows>(
    layout: Y,
    model: &SpatialReducedModel,
    mut turns: impl Iterator<Item = JointTurns<Y::Value>>,
    m: usize,
    work: TermsLanes<'w, Y::Register>,
) -> TermsLanes<'w, Y::Register> {
    // No closures: a closure is compiled without the instruction set of the SIMD dispatch that
    // inlines this function, and would call its intrinsics.
    let context = layout.value_context();
    let zero = Y::Register::splat(layout.register_context(), 0.0);
    let chunks = layout.chunks(m);
    let TermsLanes {
        point_jacobian,
        com_jacobian,
        momentum_jacobian,
        body_jacobian,
        body_inertia_jacobian,
        mass_matrix,
        coriolis,
        gravity: gravity_terms,
    } = work;
    let rows = 3 * chunks;
    let point_jacobian = &mut point_jacobian[..rows];
    let (com_jacobian, momentum_jacobian) =
        (&mut com_jacobian[..rows], &mut momentum_jacobian[..rows]);
    let (body_jacobian, body_inertia_jacobian) = (
        &mut body_jacobian[..rows],
        &mut body_inertia_jacobian[..rows],
    );
    let (mass_matrix, coriolis, gravity_terms) = (
        &mut mass_matrix[..layout.mass_len(m)],
        &mut coriolis[..chunks],
        &mut gravity_terms[..chunks],
    );
    for buffer in [
        &mut *body_jacobian,
        &mut *point_jacobian,
        &mut *mass_matrix,
        &mut *coriolis,
        &mut *gravity_terms,
    ] {
        buffer.fill(zero);
    }
    // Gravity in the base's frame, `R_0^T g`.
    let (world_gravity, base) = (model.gravity(), model.base_rotation());
    let mut gravity = [0.0; 3];
    for (d, entry) in gravity.iter_mut().enumerate() {
        *entry = base[2][d].mul_add(
            world_gravity[2],
            base[1][d].mul_add(world_gravity[1], base[0][d] * world_gravity[0]),
        );
    }
    let mut motion = layout.motion_at_rest(gravity);
    let per_link = (model.map().link_lengths().iter())
        .zip(model.links())
        .zip(model.spin_moments());
    for (i, ((&length, inertia), spin_moments)) in per_link.enumerate() {
        // `next` called here, not through an iterator adapter: an adapter is compiled without the
        // instruction set of the SIMD dispatch and would call the batch's intrinsics.
        let Some(JointTurns { sin, cos, rates }) = turns.next() else {
            break;
        };
        let [sin_z, sin_y] = sin;
        let [cos_z, cos_y] = cos;
        let [rate_z, rate_y] = rates;
        // Into the frame after the joint about z (`Rz^T`), that joint's motion, into the link's
        // frame (`Ry^T`, the plane (z, x)).
        motion.turn([0, 1], sin_z, cos_z);
        // w_dot += (w x e_z) z_dot; w += e_z z_dot; w_dot += (w x e_y) y_dot; w += e_y y_dot.
        let [wx, wy, wz] = motion.vector(OMEGA);
        let w_dot = motion.vector(OMEGA_DOT);
        let w_dot_x = wy.mul_add(rate_z, w_dot[0]);
        motion.set(OMEGA_DOT, 1, wx.neg_mul_add(rate_z, w_dot[1]));
        let wz = wz + rate_z;
        motion.set(OMEGA, 2, wz);
        motion.set(OMEGA_DOT, 0, wz.neg_mul_add(rate_y, w_dot_x));
        motion.set(OMEGA_DOT, 2, wx.mul_add(rate_y, w_dot[2]));
        motion.set(OMEGA, 1, wy + rate_y);
        motion.turn([2, 0], sin_y, cos_y);
        let (omega, omega_dot, accel) = (
            motion.vector(OMEGA),
            motion.vector(OMEGA_DOT),
            motion.vector(ACCEL),
        );
        // The acceleration along the link at zero joint accelerations: `a_p + r L change`,
        // `change = w_dot x e_x + w x (w x e_x)` (`r = 1/2` at the centre of mass).
        let (half_length, full) = (
            Y::Value::splat(context, 0.5 * length),
            Y::Value::splat(context, length),
        );
        let (xy, xz) = (omega[0] * omega[1], omega[0] * omega[2]);
        let squares = omega[2].mul_add(omega[2], omega[1] * omega[1]);
        let change_y = xy + omega_dot[2];
        let change_z = xz - omega_dot[1];
        let com_accel = [
            squares.neg_mul_add(half_length, accel[0]),
            change_y.mul_add(half_length, accel[1]),
            change_z.mul_add(half_length, accel[2]),
        ];
        motion.set(ACCEL, 0, squares.neg_mul_add(full, accel[0]));
        motion.set(ACCEL, 1, change_y.mul_add(full, accel[1]));
        motion.set(ACCEL, 2, change_z.mul_add(full, accel[2]));
        let principal = [
            Y::Value::splat(context, inertia.principal[0]),
            Y::Value::splat(context, inertia.principal[1]),
            Y::Value::splat(context, inertia.principal[2]),
        ];
        // w x I_b w.
        let spin = [
            Y::Value::splat(context, spin_moments[0]) * (omega[1] * omega[2]),
            Y::Value::splat(context, spin_moments[1]) * xz,
            Y::Value::splat(context, spin_moments[2]) * xy,
        ];
        let mut torque = spin;
        for d in 0..3 {
            torque[d] = principal[d].mul_add(omega_dot[d], spin[d]);
        }
        let weight = spread(layout, motion.vector(GRAVITY));
        let (torque, com_accel) = (spread(layout, torque), spread(layout, com_accel));
        let principal = spread(layout, principal);
        let mass = layout.spread(Y::Value::splat(context, inertia.mass));
        let (half_length, full) = (layout.spread(half_length), layout.spread(full));
        let (sin_z, cos_z) = (layout.spread(sin_z), layout.spread(cos_z));
        let (sin_y, cos_y) = (layout.spread(sin_y), layout.spread(cos_y));
        let joint_rows = model.joint_rows(i);
        // In the link's frame: Jb (turned, plus the joints' columns `e_z [P_i, 0]`,
        // `e_y [0, P_i]`), Jp (turned); Jv = Jp + Jb x (L/2 e_x), the momentum Jacobian m Jv,
        // I_b Jb; C* += (m Jv)^T a_c + Jb^T torque, G* -= (m Jv)^T g; the next joint's
        // Jp = Jp + Jb x (L e_x).
        for k in 0..chunks {
            let (mut body, mut point) = (
                column(body_jacobian, chunks, k),
                column(point_jacobian, chunks, k),
            );
            to_child(&mut body, [0, 1], sin_z, cos_z);
            to_child(&mut point, [0, 1], sin_z, cos_z);
            body[2] = body[2] + layout.constant_row(joint_rows, k);
            body[1] = body[1] + layout.constant_row(&joint_rows[m..], k);
            to_child(&mut body, [2, 0], sin_y, cos_y);
            to_child(&mut point, [2, 0], sin_y, cos_y);
            let v = [
                point[0],
                body[2].mul_add(half_length, point[1]),
                body[1].neg_mul_add(half_length, point[2]),
            ];
            let p = [v[0] * mass, v[1] * mass, v[2] * mass];
            point[1] = body[2].mul_add(full, point[1]);
            point[2] = body[1].neg_mul_add(full, point[2]);
            for d in 0..3 {
                body_jacobian[d * chunks + k] = body[d];
                point_jacobian[d * chunks + k] = point[d];
                com_jacobian[d * chunks + k] = v[d];
                momentum_jacobian[d * chunks + k] = p[d];
                body_inertia_jacobian[d * chunks + k] = body[d] * principal[d];
            }
            coriolis[k] = dot_add(body, torque, dot_add(p, com_accel, coriolis[k]));
            gravity_terms[k] = p[2].neg_mul_add(
                weight[2],
                p[1].neg_mul_add(weight[1], p[0].neg_mul_add(weight[0], gravity_terms[k])),
            );
        }
        // M* += (m Jv)^T Jv + Jb^T I_b Jb.
        layout.add_outers(
            mass_matrix,
            [momentum_jacobian, body_jacobian],
            [com_jacobian, body_inertia_jacobian],
            m,
        );
    }
    TermsLanes {
        point_jacobian,
        com_jacobian,
        momentum_jacobian,
        body_jacobian,
        body_inertia_jacobian,
        mass_matrix,
        coriolis,
        gravity: gravity_terms,
    }
}

/// `[x, y, z]` in every coordinate of a register each.
#[inline(always)]
fn spread<Y: Registers>(layout: Y, values: [Y::Value; 3]) -> [Y::Register; 3] {
    [
        layout.spread(values[0]),
        layout.spread(values[1]),
        layout.spread(values[2]),
    ]
}

/// The coordinates `(p, q)` whose products `left_p right_q` make entry `(k, l)`, `l <= k`, of
/// `M*`'s sum of outer products (each term symmetric, so either order is the entry): `(l, k)`
/// when `k - l <= m / 2`, else `(k, l)`. These are the products [`CoordinateLanes`] forms on its
/// diagonals (lane `l` of diagonal `k - l`, or lane `k` of diagonal `m - (k - l)`), so that every
/// layout gives each entry the same operations.
#[inline(always)]
fn product_coordinates(m: usize, k: usize, l: usize) -> (usize, usize) {
    if k - l <= m / 2 { (l, k) } else { (k, l) }
}

/// How a layout keeps `M*` and adds the link's `(m Jv)^T Jv + Jb^T I_b Jb` to it: by default
/// one coordinate a register, entry `(k, l)` of the lower triangle at `k m + l`, each from the
/// products [`product_coordinates`] names.
pub(crate) trait MassRows: Registers {
    /// How the layout keeps the motion the pass carries.
    type Motion: CarriedMotion<Value = Self::Value>;

    /// That motion at rest under `gravity` (in the base's frame).
    fn motion_at_rest(self, gravity: [f64; 3]) -> Self::Motion;

    /// The registers `M*` takes for `m` coordinates.
    #[inline(always)]
    fn mass_len(self, m: usize) -> usize {
        m * m
    }

    /// `M* += sum_r a_r b_r^T` on the lower triangle (at least), over the rows `r` of
    /// `left = [m Jv, Jb]` and `right = [Jv, I_b Jb]` (`3 x c` registers each), `r` in order:
    /// each entry gets the six multiply-adds in that order in every layout.
    #[inline(always)]
    fn add_outers(
        self,
        mass: &mut [Self::Register],
        left: [&[Self::Register]; 2],
        right: [&[Self::Register]; 2],
        m: usize,
    ) {
        debug_assert_eq!(self.chunks(m), m);
        for k in 0..m {
            for (l, entry) in mass[k * m..=k * m + k].iter_mut().enumerate() {
                let (p, q) = product_coordinates(m, k, l);
                for (left, right) in left.iter().zip(right) {
                    *entry = dot_add(column(left, m, p), column(right, m, q), *entry);
                }
            }
        }
    }

    /// Entry `(k, l)` of `M*`, `l <= k`.
    #[inline(always)]
    fn mass_entry(self, mass: &[Self::Register], m: usize, k: usize, l: usize) -> Self::Value {
        self.coordinate(&mass[k * m..(k + 1) * m], l)
    }
}

/// All coordinates of a row in one register: `M*` kept as its diagonals `D_j`, lane `i` the
/// entry `(i, (i + j) mod m)`, for `j = 0..=m/2` (the others are these by symmetry). A link adds
/// `a_r * (b_r turned by j lanes)` to each: one multiply-add and one permutation a diagonal and
/// row, where rows of `M*` would take a broadcast of each coordinate.
impl<S: Simd> MassRows for CoordinateLanes<S> {
    type Motion = PackedMotion<S>;

    #[inline(always)]
    fn motion_at_rest(self, gravity: [f64; 3]) -> PackedMotion<S> {
        PackedMotion::at_rest(self.register_context(), gravity)
    }

    #[inline(always)]
    fn mass_len(self, m: usize) -> usize {
        m / 2 + 1
    }

    #[inline(always)]
    fn add_outers(
        self,
        mass: &mut [Pack<S>],
        left: [&[Pack<S>]; 2],
        right: [&[Pack<S>]; 2],
        m: usize,
    ) {
        let diagonals = &mut mass[..=m / 2];
        for (left, right) in left.iter().zip(right) {
            for (&a, &b) in left[..3].iter().zip(&right[..3]) {
                for (j, diagonal) in diagonals.iter_mut().enumerate() {
                    *diagonal = a.mul_add(b.rotate_lanes(j, m), *diagonal);
                }
            }
        }
    }

    #[inline(always)]
    fn mass_entry(self, mass: &[Pack<S>], m: usize, k: usize, l: usize) -> f64 {
        let d = k - l;
        if d <= m / 2 {
            mass[d].lane(l)
        } else {
            mass[m - d].lane(k)
        }
    }
}

impl<S: Simd> MassRows for OneStateScalar<S> {
    type Motion = SeparateMotion<f64>;

    #[inline(always)]
    fn motion_at_rest(self, gravity: [f64; 3]) -> SeparateMotion<f64> {
        SeparateMotion::at_rest(0.0, gravity)
    }
}

impl<S: Simd> MassRows for StateLanes<S> {
    type Motion = SeparateMotion<Pack<S>>;

    #[inline(always)]
    fn motion_at_rest(self, gravity: [f64; 3]) -> SeparateMotion<Pack<S>> {
        let simd = self.value_context();
        SeparateMotion::at_rest(
            Pack::splat(simd, 0.0),
            gravity.map(|g| Pack::splat(simd, g)),
        )
    }
}

/// `acc + a . b` in fused multiply-adds, `a[0] b[0]` first.
#[inline(always)]
fn dot_add<L: Lane>(a: [L; 3], b: [L; 3], acc: L) -> L {
    a[2].mul_add(b[2], a[1].mul_add(b[1], a[0].mul_add(b[0], acc)))
}

/// Register column `k` of a `3 x c` row-major matrix of registers.
#[inline(always)]
fn column<L: Lane>(matrix: &[L], chunks: usize, k: usize) -> [L; 3] {
    [matrix[k], matrix[chunks + k], matrix[2 * chunks + k]]
}

/// Checks that `data` was made for `model` and that `a` and `a_dot` are `m` finite values each.
pub(crate) fn check_state(
    model: &SpatialReducedModel,
    data: &SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    check_shapes(model, data, a, a_dot)?;
    check_all_finite("a", a)?;
    check_all_finite("a_dot", a_dot)?;
    Ok(())
}

/// Checks that `data` was made for `model` and that `a` and `a_dot` are `m` values each (their
/// values not looked at: see [`TermsOfOneState`]).
pub(crate) fn check_shapes(
    model: &SpatialReducedModel,
    data: &SpatialReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_len("a", a.len(), m)?;
    check_len("a_dot", a_dot.len(), m)?;
    Ok(())
}
