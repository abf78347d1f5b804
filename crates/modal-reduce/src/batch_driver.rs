//! The driver of the planar and the spatial batch ([`forward_dynamics_batch`] and
//! [`spatial_forward_dynamics_batch`]), written once over an arm family's [`BatchKernel`].
//!
//! It checks that the slices hold whole states, takes the states `W` at a time (`W` the `f64`
//! lanes of the widest instruction set [`pulp::Arch`] finds at run time: 8 with AVX-512, 4 with
//! AVX2), gathers each group's inputs into lanes (lane `i` of every register holds state `i` of
//! the group), has the kernel form `M*`, `C*` and `G*` of the group, solves
//! `M* a_ddot = tau* - C* - G*` by `L D L^T` ([`lane_math::dense`]) and scatters the
//! accelerations: the operations of the one-state path, in its order, so each state's result is
//! the same bits. A group whose inputs are not all finite, or one of whose states fails (a
//! non-positive pivot, an overflow, an angle the kernel does not take), is redone one state at a
//! time by the family's one-state forward dynamics, which names the failure; so are the states
//! left over after the last whole group, and every state of a model without a SIMD kernel.
//!
//! [`forward_dynamics_batch`]: crate::forward_dynamics_batch
//! [`spatial_forward_dynamics_batch`]: crate::spatial::spatial_forward_dynamics_batch

use lane_math::dense::{ldlt_in_place, ldlt_solve_in_place};
use lane_math::{Classify, ErrorClass, Lane, Pack, check_len};
use pulp::{Arch, Simd, WithSimd};

use crate::error::ReduceError;
use lane_math::all_finite;

/// The most `f64` lanes of a SIMD register (AVX-512).
pub(crate) const MAX_WIDTH: usize = 8;

/// Why a batch was refused: its slices do not hold whole states, or one state failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BatchError {
    /// The slices do not hold the same whole number of states of `m` values each.
    #[error(transparent)]
    Shape(ReduceError),
    /// The state at this index (0-based; the lowest one that failed) was refused.
    #[error("state {state}: {error}")]
    State {
        /// 0-based index of the state in the batch.
        state: usize,
        /// Why the one-state forward dynamics refused it.
        error: ReduceError,
    },
}

impl BatchError {
    /// The [`ReduceError`] inside: the shape's, or the refused state's (its index dropped).
    pub fn into_reduce_error(self) -> ReduceError {
        match self {
            Self::Shape(error) | Self::State { error, .. } => error,
        }
    }
}

impl Classify for BatchError {
    /// The class of the [`ReduceError`] inside.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Shape(error) | Self::State { error, .. } => error.class(),
        }
    }
}

/// What an arm family brings to the driver: its SIMD kernel of one group and its one-state path.
pub(crate) trait BatchKernel: Sized {
    /// The model's number of modal coordinates `m`.
    fn n_coords(&self) -> usize;

    /// Runs `batch` with the group size `M = m` when the family has a SIMD kernel for it
    /// ([`Batch::groups`]), one state at a time otherwise ([`Batch::one_at_a_time`]).
    fn dispatch<S: Simd>(batch: Batch<'_, Self>, simd: S) -> Result<(), BatchError>;

    /// `M*` (row-major `M x M`), `C*` and `G*` of one group of `S::F64_LANES` states, whose
    /// finite coordinates and rates are `a` and `a_dot`; `false` if the kernel does not take these
    /// states (the outputs are then unspecified).
    fn terms<S: Simd, const M: usize>(
        &mut self,
        simd: S,
        a: &[Pack<S>; M],
        a_dot: &[Pack<S>; M],
        mass: &mut [[Pack<S>; M]; M],
        coriolis: &mut [Pack<S>; M],
        gravity: &mut [Pack<S>; M],
    ) -> bool;

    /// The one-state forward dynamics of one state, which names a failure.
    fn one_state(
        &mut self,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        a_ddot: &mut [f64],
    ) -> Result<(), ReduceError>;
}

/// Checks that `a`, `a_dot`, `tau_star` and `a_ddot` hold the same whole number of states of
/// `kernel`'s `m` values each, then runs the batch with `arch`'s instruction set.
pub(crate) fn run_batch<K: BatchKernel>(
    kernel: K,
    arch: Arch,
    inputs: [&[f64]; 3],
    a_ddot: &mut [f64],
) -> Result<(), BatchError> {
    check_states(kernel.n_coords(), inputs, a_ddot)?;
    arch.dispatch(Batch {
        kernel,
        inputs,
        a_ddot,
    })
}

/// Checks that `a`, `a_dot`, `tau_star` (`inputs`) and `a_ddot` hold the same whole number of
/// states of `m` values each; returns that number of values.
pub(crate) fn check_states(
    m: usize,
    [a, a_dot, tau_star]: [&[f64]; 3],
    a_ddot: &[f64],
) -> Result<usize, BatchError> {
    let values = a.len() - a.len() % m;
    let shape =
        |name, found| check_len(name, found, values).map_err(|e| BatchError::Shape(e.into()));
    shape("a (whole states of m values)", a.len())?;
    shape("a_dot (as many values as a)", a_dot.len())?;
    shape("tau_star (as many values as a)", tau_star.len())?;
    shape("a_ddot (as many values as a)", a_ddot.len())?;
    Ok(values)
}

/// One batch, run by [`pulp::Arch::dispatch`] with the processor's instruction set.
pub(crate) struct Batch<'a, K> {
    kernel: K,
    /// `a`, `a_dot`, `tau_star`.
    inputs: [&'a [f64]; 3],
    a_ddot: &'a mut [f64],
}

impl<K: BatchKernel> WithSimd for Batch<'_, K> {
    type Output = Result<(), BatchError>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Self::Output {
        K::dispatch(self, simd)
    }
}

impl<K: BatchKernel> Batch<'_, K> {
    /// The kernel, for [`BatchKernel::dispatch`] to choose `M`.
    pub(crate) fn kernel(&self) -> &K {
        &self.kernel
    }

    /// Whole groups of `S::F64_LANES` states of `M = m` coordinates in SIMD, the rest one at a
    /// time.
    #[inline(always)]
    pub(crate) fn groups<S: Simd, const M: usize>(mut self, simd: S) -> Result<(), BatchError> {
        let states = self.a_ddot.len() / M;
        in_groups::<Self, S, M>(&mut self, simd, states)
    }

    /// Every state one at a time.
    pub(crate) fn one_at_a_time(mut self) -> Result<(), BatchError> {
        let states = self.a_ddot.len() / self.kernel.n_coords();
        self.states(0, states)
    }
}

impl<K: BatchKernel> Groups for Batch<'_, K> {
    #[inline(always)]
    fn group<S: Simd, const M: usize>(&mut self, simd: S, first: usize) -> bool {
        let width = S::F64_LANES;
        let range = first * M..(first + width) * M;
        let inputs = self.inputs.map(|x| &x[range.clone()]);
        group::<S, M, K>(simd, &mut self.kernel, inputs, &mut self.a_ddot[range])
    }

    /// States `first..last` one at a time, by the kernel's one-state path.
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError> {
        let m = self.kernel.n_coords();
        for state in first..last {
            let range = state * m..(state + 1) * m;
            let [a, a_dot, tau_star] = self.inputs.map(|x| &x[range.clone()]);
            self.kernel
                .one_state(a, a_dot, tau_star, &mut self.a_ddot[range])
                .map_err(|error| BatchError::State { state, error })?;
        }
        Ok(())
    }
}

/// A batch split into groups of SIMD lanes ([`in_groups`]): one group in lanes, or states one
/// at a time.
pub(crate) trait Groups {
    /// The group of `S::F64_LANES` states from `first`, of `M` coordinates, in lanes; `false` if
    /// it is to be redone one state at a time.
    fn group<S: Simd, const M: usize>(&mut self, simd: S, first: usize) -> bool;

    /// States `first..last` one at a time, which names a failure.
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError>;
}

/// The `states` of `batch`: whole groups of `S::F64_LANES` in SIMD (a group that fails redone
/// one state at a time), the rest one at a time; all of them one at a time when the registers
/// are wider than [`MAX_WIDTH`].
#[inline(always)]
pub(crate) fn in_groups<G: Groups, S: Simd, const M: usize>(
    batch: &mut G,
    simd: S,
    states: usize,
) -> Result<(), BatchError> {
    let width = S::F64_LANES;
    if width > MAX_WIDTH {
        return batch.states(0, states);
    }
    let grouped = states - states % width;
    for first in (0..grouped).step_by(width) {
        if !batch.group::<S, M>(simd, first) {
            batch.states(first, first + width)?;
        }
    }
    batch.states(grouped, states)
}

/// One group of `S::F64_LANES` states of `M` coordinates (`inputs` and `out` hold exactly
/// those): gathers the inputs into lanes, has the kernel form the terms, solves and scatters the
/// accelerations. `false` if an input is not finite or any state failed (`out` is then
/// unspecified).
#[inline(always)]
fn group<S: Simd, const M: usize, K: BatchKernel>(
    simd: S,
    kernel: &mut K,
    inputs: [&[f64]; 3],
    out: &mut [f64],
) -> bool {
    let Some(lanes) = gather::<S, M>(simd, inputs) else {
        return false;
    };
    match accelerations::<S, M, K>(simd, kernel, lanes) {
        Some((a_ddot, _)) => scatter(&a_ddot, out),
        None => false,
    }
}

/// The inputs `a`, `a_dot`, `tau*` of one group of `S::F64_LANES` states (each slice holds
/// exactly those, state after state) in lanes: lane `i` of every register holds state `i`.
/// `None` if an input is not finite.
#[inline(always)]
pub(crate) fn gather<S: Simd, const M: usize>(
    simd: S,
    inputs: [&[f64]; 3],
) -> Option<[[Pack<S>; M]; 3]> {
    let width = S::F64_LANES;
    if !(all_finite(inputs[0]) & all_finite(inputs[1]) & all_finite(inputs[2])) {
        return None;
    }
    // Loops, not closures: a closure is compiled without the dispatch's instruction set.
    let zero = Pack::splat(simd, 0.0);
    let mut buffer = [0.0; MAX_WIDTH];
    let mut lanes = [[zero; M]; 3];
    for (values, packs) in inputs.iter().zip(&mut lanes) {
        for (k, pack) in packs.iter_mut().enumerate() {
            for (lane, slot) in buffer[..width].iter_mut().enumerate() {
                *slot = values[lane * M + k];
            }
            *pack = Pack::load(simd, &buffer);
        }
    }
    Some(lanes)
}

/// The accelerations of one group in lanes (`[a, a_dot, tau*]`, [`gather`]ed): the kernel's
/// `M*`, `C*` and `G*`, then `M* a_ddot = tau* - C* - G*` solved by `L D L^T` as in the
/// one-state path. Returns `a_ddot` and `M*`; `None` if the kernel refuses the states or `M*`
/// is not positive definite in some lane.
#[inline(always)]
#[allow(
    clippy::type_complexity,
    reason = "registers of one group: a vector and a matrix"
)]
pub(crate) fn accelerations<S: Simd, const M: usize, K: BatchKernel>(
    simd: S,
    kernel: &mut K,
    [a, a_dot, tau_star]: [[Pack<S>; M]; 3],
) -> Option<([Pack<S>; M], [[Pack<S>; M]; M])> {
    let zero = Pack::splat(simd, 0.0);
    let mut mass = [[zero; M]; M];
    let (mut coriolis, mut gravity) = ([zero; M], [zero; M]);
    if !kernel.terms(simd, &a, &a_dot, &mut mass, &mut coriolis, &mut gravity) {
        return None;
    }
    // The right-hand side tau* - C* - G* and the solve, as in the one-state path.
    let mut x = tau_star;
    for ((x, &c), &g) in x.iter_mut().zip(&coriolis).zip(&gravity) {
        *x = *x - c - g;
    }
    let mut factor = mass;
    if !ldlt_in_place(simd, factor.as_flattened_mut(), M) {
        return None;
    }
    ldlt_solve_in_place(factor.as_flattened(), M, &mut x);
    Some((x, mass))
}

/// Writes the values `packs` of one group into `out`, state after state (`packs.len()` values a
/// state, lane `i` state `i`); `false` if any is not finite.
#[inline(always)]
pub(crate) fn scatter<S: Simd>(packs: &[Pack<S>], out: &mut [f64]) -> bool {
    let width = S::F64_LANES;
    let per_state = packs.len();
    let mut buffer = [0.0; MAX_WIDTH];
    let mut finite = true;
    for (k, value) in packs.iter().enumerate() {
        value.store(&mut buffer);
        for (lane, &v) in buffer[..width].iter().enumerate() {
            finite &= v.is_finite();
            out[lane * per_state + k] = v;
        }
    }
    finite
}
