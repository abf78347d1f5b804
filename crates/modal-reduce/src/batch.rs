//! Reduced forward dynamics (eq 15) of many independent states at once, SIMD across states.
//!
//! The states of a batch are taken `W` at a time, `W` the number of `f64` lanes of the widest
//! instruction set the processor has (8 with AVX-512, 4 with AVX2; chosen at run time by
//! [`pulp::Arch`], so one binary runs everywhere), and each group runs through the same kernel as
//! one state ([`crate::terms`], [`lane_math::dense`]), written once over
//! [`Lane`](lane_math::Lane): lane `i` of every register holds state `i` of the group
//! (structure of arrays). The operations, and their order, are those of the one-state path, so
//! each state's result is the same.
//!
//! A group whose inputs are not all finite, or one of whose states fails (a non-positive pivot,
//! an overflow), is redone one state at a time by [`forward_dynamics`], which names the failure;
//! so are the states left over after the last whole group, and every state of a model with more
//! than [`MAX_BATCH_COORDS`] coordinates.

use lane_math::{Classify, ErrorClass};
use pulp::{Arch, Simd, WithSimd};

use crate::cache_aligned::CacheAligned;
use crate::data::{PRODUCTS, ReducedData};
use crate::error::{ReduceError, all_finite, check_len};
use crate::forward::forward_dynamics;
use crate::model::ReducedModel;
use crate::terms::{LinkBuffers, StateLanes, Terms, accumulate, angles_in_range, extract};
use lane_math::dense::{ldlt_in_place, ldlt_solve_in_place};
use lane_math::{Lane, Pack};

/// The most `f64` lanes of a SIMD register (AVX-512).
pub(crate) const MAX_WIDTH: usize = 8;

/// The most modal coordinates evaluated SIMD across states (`K = 2` harmonics with `alpha0`
/// free); larger models run their batches one state at a time.
pub const MAX_BATCH_COORDS: usize = 5;

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
        /// Why [`forward_dynamics`] refused it.
        error: ReduceError,
    },
}

impl Classify for BatchError {
    /// The class of the [`ReduceError`] inside.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Shape(error) | Self::State { error, .. } => error.class(),
        }
    }
}

/// Workspace of [`forward_dynamics_batch`] for one [`ReducedModel`]: create it once, reuse it for
/// every batch. Its memory is `O(n)` like a [`ReducedData`]'s (which it holds, for the states
/// evaluated one at a time) plus eight buffers of `n` values per lane (`512 n` bytes).
#[derive(Debug, Clone)]
pub struct ReducedBatchData {
    /// Per link and lane (`[link][lane]`, `MAX_WIDTH` lanes): the absolute angle, its sine and
    /// cosine.
    angle: CacheAligned,
    sin: CacheAligned,
    cos: CacheAligned,
    /// Per product, link and lane: the products of [`crate::terms`].
    products: CacheAligned,
    /// The one-state workspace.
    single: ReducedData,
    /// The instruction set found at construction.
    arch: Arch,
}

impl ReducedBatchData {
    /// A workspace sized for `model`, for the instruction set of this processor.
    ///
    /// # Panics
    /// When the system refuses the memory; [`ReducedBatchData::try_new`] returns the error.
    pub fn new(model: &ReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`ReducedBatchData::new`], or [`ReduceError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_new(model: &ReducedModel) -> Result<Self, ReduceError> {
        const WHAT: &str = "the workspace of the reduced model's batch";
        let size = model.n_links() * MAX_WIDTH;
        let aligned = |len: usize| CacheAligned::try_zeros(len, WHAT);
        Ok(Self {
            angle: aligned(size)?,
            sin: aligned(size)?,
            cos: aligned(size)?,
            products: aligned(PRODUCTS * size)?,
            single: ReducedData::try_new(model)?,
            arch: Arch::new(),
        })
    }
}

/// [`forward_dynamics`] of a batch of states: `a`, `a_dot`, `tau_star` and `a_ddot` hold `N`
/// states of `m` values each, state after state (row-major `N x m`), and state `i` of `a_ddot`
/// gets what `forward_dynamics` gives for state `i` of the inputs.
///
/// SIMD across states (structure of arrays, the instruction set chosen at run time);
/// allocation-free. On an error `a_ddot` is unspecified.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedBatchData, ReducedData, ReducedModel, forward_dynamics, forward_dynamics_batch};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let states = 11;
/// let a: Vec<f64> = (0..3 * states).map(|i| 0.1 * (i as f64).sin()).collect();
/// let a_dot: Vec<f64> = (0..3 * states).map(|i| 0.2 * (i as f64).cos()).collect();
/// let tau_star = vec![0.05; 3 * states];
/// let mut a_ddot = vec![0.0; 3 * states];
/// forward_dynamics_batch(&model, &mut ReducedBatchData::new(&model), &a, &a_dot, &tau_star, &mut a_ddot)?;
/// let (mut data, mut one) = (ReducedData::new(&model), [0.0; 3]);
/// forward_dynamics(&model, &mut data, &a[30..], &a_dot[30..], &tau_star[30..], &mut one)?;
/// assert_eq!(&a_ddot[30..], one.as_slice());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn forward_dynamics_batch(
    model: &ReducedModel,
    data: &mut ReducedBatchData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), BatchError> {
    data.single.check_model(model).map_err(BatchError::Shape)?;
    check_batch_shape(model.n_coords(), [a, a_dot, tau_star], a_ddot)?;
    let arch = data.arch;
    arch.dispatch(Batch {
        model,
        data,
        inputs: [a, a_dot, tau_star],
        a_ddot,
    })
}

/// Checks that `a`, `a_dot`, `tau_star` (`inputs`) and `a_ddot` hold the same whole number of
/// states of `m` values each.
pub(crate) fn check_batch_shape(
    m: usize,
    inputs: [&[f64]; 3],
    a_ddot: &[f64],
) -> Result<(), BatchError> {
    let [a, a_dot, tau_star] = inputs;
    let values = a.len() - a.len() % m;
    let shape = |name, found| check_len(name, found, values).map_err(BatchError::Shape);
    shape("a (whole states of m values)", a.len())?;
    shape("a_dot (as many values as a)", a_dot.len())?;
    shape("tau_star (as many values as a)", tau_star.len())?;
    shape("a_ddot (as many values as a)", a_ddot.len())
}

/// One batch, run by [`pulp::Arch::dispatch`] with the processor's instruction set.
struct Batch<'a> {
    model: &'a ReducedModel,
    data: &'a mut ReducedBatchData,
    /// `a`, `a_dot`, `tau_star`.
    inputs: [&'a [f64]; 3],
    a_ddot: &'a mut [f64],
}

impl WithSimd for Batch<'_> {
    type Output = Result<(), BatchError>;

    #[inline(always)]
    fn with_simd<S: Simd>(mut self, simd: S) -> Self::Output {
        // With the last coordinate's column of Phi all ones (alpha0 free), a kernel that skips
        // the multiplications by it.
        let m = self.model.n_coords();
        match (m, self.model.unit_column() == Some(m - 1)) {
            (2, false) => self.run::<S, 2, false>(simd),
            (2, true) => self.run::<S, 2, true>(simd),
            (3, false) => self.run::<S, 3, false>(simd),
            (3, true) => self.run::<S, 3, true>(simd),
            (4, false) => self.run::<S, 4, false>(simd),
            (4, true) => self.run::<S, 4, true>(simd),
            (5, false) => self.run::<S, 5, false>(simd),
            (5, true) => self.run::<S, 5, true>(simd),
            _ => self.one_at_a_time(0),
        }
    }
}

impl Batch<'_> {
    /// Whole groups of `S::F64_LANES` states in SIMD, the rest one at a time; `UNIT_LAST`: the
    /// last coordinate's column of `Phi` is all ones.
    #[inline(always)]
    fn run<S: Simd, const M: usize, const UNIT_LAST: bool>(
        mut self,
        simd: S,
    ) -> Result<(), BatchError> {
        let width = S::F64_LANES;
        if width > MAX_WIDTH {
            return self.one_at_a_time(0);
        }
        let states = self.a_ddot.len() / M;
        let grouped = states - states % width;
        for first in (0..grouped).step_by(width) {
            let range = first * M..(first + width) * M;
            let inputs = self.inputs.map(|x| &x[range.clone()]);
            let links = LinkBuffers {
                angle: self.data.angle.get_mut(),
                sin: self.data.sin.get_mut(),
                cos: self.data.cos.get_mut(),
                products: self.data.products.get_mut(),
                links: self.model.n_links(),
            };
            let out = &mut self.a_ddot[range];
            if !group::<S, M, UNIT_LAST>(simd, self.model, links, inputs, out) {
                self.states(first, first + width)?;
            }
        }
        self.one_at_a_time(grouped)
    }

    /// States `first..` one at a time.
    fn one_at_a_time(&mut self, first: usize) -> Result<(), BatchError> {
        let states = self.a_ddot.len() / self.model.n_coords();
        self.states(first, states)
    }

    /// States `first..last` one at a time, by [`forward_dynamics`].
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError> {
        let m = self.model.n_coords();
        for state in first..last {
            let range = state * m..(state + 1) * m;
            let [a, a_dot, tau_star] = self.inputs.map(|x| &x[range.clone()]);
            forward_dynamics(
                self.model,
                &mut self.data.single,
                a,
                a_dot,
                tau_star,
                &mut self.a_ddot[range],
            )
            .map_err(|error| BatchError::State { state, error })?;
        }
        Ok(())
    }
}

/// One group of `S::F64_LANES` states (`inputs` and `out` hold exactly those): gathers the
/// inputs into lanes, runs the kernel and scatters the accelerations. `false` if an input is not
/// finite or any state failed (`out` is then unspecified).
#[inline(always)]
fn group<S: Simd, const M: usize, const UNIT_LAST: bool>(
    simd: S,
    model: &ReducedModel,
    links: LinkBuffers<'_>,
    inputs: [&[f64]; 3],
    out: &mut [f64],
) -> bool {
    let width = S::F64_LANES;
    if !(all_finite(inputs[0]) & all_finite(inputs[1]) & all_finite(inputs[2])) {
        return false;
    }
    let mut buffer = [0.0; MAX_WIDTH];
    let mut gather = |values: &[f64], k: usize| {
        for (lane, slot) in buffer[..width].iter_mut().enumerate() {
            *slot = values[lane * M + k];
        }
        Pack::<S>::load(simd, &buffer)
    };
    let a: [Pack<S>; M] = std::array::from_fn(|k| gather(inputs[0], k));
    let a_dot: [Pack<S>; M] = std::array::from_fn(|k| gather(inputs[1], k));
    let tau_star: [Pack<S>; M] = std::array::from_fn(|k| gather(inputs[2], k));
    if !angles_in_range(simd, model, &a) {
        return false;
    }
    let zero = Pack::splat(simd, 0.0);
    let (mut sums, mut mass) = ([[zero; M]; M], [[zero; M]; M]);
    let (mut coriolis_sums, mut gravity_sums) = ([zero; M], [zero; M]);
    let (mut coriolis, mut gravity, mut v) = ([zero; M], [zero; M], [zero; M]);
    let mut joint = [[zero; 2]; M];
    let mut terms = Terms {
        mass: sums.as_flattened_mut(),
        coriolis: &mut coriolis_sums,
        gravity: &mut gravity_sums,
        joint: &mut joint,
        v: &mut v,
    };
    let layout = StateLanes::new(simd, if UNIT_LAST { M - 1 } else { usize::MAX });
    accumulate(layout, model, &a, &a_dot, M, links, &mut terms);
    extract(
        layout,
        model,
        M,
        &terms,
        mass.as_flattened_mut(),
        &mut coriolis,
        &mut gravity,
    );
    // The right-hand side tau* - C* - G* and the solve, as in `forward_dynamics`.
    let mut x: [Pack<S>; M] = std::array::from_fn(|k| tau_star[k] - coriolis[k] - gravity[k]);
    if !ldlt_in_place(simd, mass.as_flattened_mut(), M) {
        return false;
    }
    ldlt_solve_in_place(mass.as_flattened(), M, &mut x);
    let mut finite = true;
    for (k, value) in x.iter().enumerate() {
        value.store(&mut buffer);
        for (lane, &v) in buffer[..width].iter().enumerate() {
            finite &= v.is_finite();
            out[lane * M + k] = v;
        }
    }
    finite
}

#[cfg(test)]
mod tests {
    use super::*;
    use backbone_kin::BaseAngle;
    use manip_dyn::{ChainModel, Link};

    /// Unequal links, and each modal family the batch has kernels for, and one beyond them.
    fn models() -> Vec<ReducedModel> {
        let links: Vec<Link> = (0..11)
            .map(|i| Link::uniform_beam(0.05 + 0.01 * (i % 4) as f64, 0.1 + 0.02 * i as f64))
            .collect::<Result<_, _>>()
            .unwrap();
        let chain = ChainModel::new(links, 9.81).unwrap();
        [
            (1, BaseAngle::Fixed(0.3)),
            (1, BaseAngle::Free),
            (2, BaseAngle::Fixed(-0.2)),
            (2, BaseAngle::Free),
            (3, BaseAngle::Free),
        ]
        .into_iter()
        .map(|(harmonics, base)| ReducedModel::from_chain(chain.clone(), harmonics, base).unwrap())
        .collect()
    }

    /// Every instruction set gives every state the same bits, in a batch and alone: the kernels
    /// do the same operations in the same order, whatever the width of the registers (8 lanes,
    /// 4 or 1), and every instruction set rounds a fused multiply-add once (in software without
    /// AVX2), so results do not depend on the machine.
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        for model in models() {
            let m = model.n_coords();
            let states = 19;
            let value = |i: usize, scale: f64| scale * ((i as f64) * 0.7).sin();
            let a: Vec<f64> = (0..m * states).map(|i| value(i, 1.1)).collect();
            let a_dot: Vec<f64> = (0..m * states).map(|i| value(i + 5, 2.0)).collect();
            let tau_star: Vec<f64> = (0..m * states).map(|i| value(i + 9, 3.0)).collect();
            let mut reference: Option<Vec<u64>> = None;
            for arch in lane_math::instruction_sets() {
                let mut batch_data = ReducedBatchData::new(&model);
                batch_data.arch = arch;
                let mut batch = vec![0.0; m * states];
                forward_dynamics_batch(&model, &mut batch_data, &a, &a_dot, &tau_star, &mut batch)
                    .unwrap();
                let mut data = ReducedData::new(&model);
                data.arch = arch;
                let mut alone = vec![0.0; m * states];
                for (s, out) in alone.chunks_exact_mut(m).enumerate() {
                    let state = s * m..(s + 1) * m;
                    let (a, a_dot) = (&a[state.clone()], &a_dot[state.clone()]);
                    forward_dynamics(&model, &mut data, a, a_dot, &tau_star[state], out).unwrap();
                }
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&batch),
                    bits(&alone),
                    "m = {m}, {arch:?}: batch and alone"
                );
                match &reference {
                    None => reference = Some(bits(&alone)),
                    Some(expected) => assert_eq!(&bits(&alone), expected, "m = {m}, {arch:?}"),
                }
            }
        }
    }
}
