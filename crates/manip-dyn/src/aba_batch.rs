//! Forward dynamics by the articulated-body algorithm of many independent states at once, SIMD
//! across states.
//!
//! The states of a batch are taken `W` at a time, `W` the number of `f64` lanes of the widest
//! instruction set the processor has (8 with AVX-512, 4 with AVX2; chosen at run time by
//! [`pulp::Arch`], so one binary runs everywhere), and each group runs through the kernel of one
//! state (`crate::aba`), written once over `AbaLane`: lane `i` of every register holds state
//! `i` of the group (structure of arrays). The operations, and their order, are those of
//! [`aba`], so each state's result is the same.
//!
//! A group whose inputs are not all finite, or one of whose states fails (a pivot not positive
//! beyond rounding, an overflow), is redone one state at a time by [`aba`], which names the
//! failure; so are the states left over after the last whole group, and every state of a chain
//! of more than [`MAX_BATCH_LINKS`] links.

use lane_math::Pack;
use lane_math::{Classify, ErrorClass, try_filled};
use pulp::{Arch, Simd, WithSimd};

use crate::aba::{LinkBuffers, MAX_WIDTH, aba, kernel};
use crate::data::{ArticulatedLink, ChainData, LinkFrame};
use crate::error::DynError;
use crate::model::ChainModel;

/// The most links evaluated SIMD across states: an [`AbaBatchData`] holds 640 bytes a link for
/// them (ten values of eight lanes), 2.6 MB at this limit. Longer chains run their batches one
/// state at a time, in the `O(n)` memory of a [`ChainData`].
pub const MAX_BATCH_LINKS: usize = 4096;

/// Why a batch was refused: its slices do not hold whole states, or one state failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BatchError {
    /// The slices do not hold the same whole number of states of `n` values each, or the
    /// workspace was built for another chain.
    #[error(transparent)]
    Shape(DynError),
    /// The state at this index (0-based; the lowest one that failed) was refused.
    #[error("state {state}: {error}")]
    State {
        /// 0-based index of the state in the batch.
        state: usize,
        /// Why [`aba`] refused it.
        error: DynError,
    },
}

impl Classify for BatchError {
    /// The class of the [`DynError`] inside.
    fn class(&self) -> ErrorClass {
        match self {
            Self::Shape(error) | Self::State { error, .. } => error.class(),
        }
    }
}

/// Workspace of [`aba_batch`] for one [`ChainModel`]: create it once, reuse it for every batch.
/// It holds a [`ChainData::recursive`] for the states evaluated one at a time and, for chains of
/// up to [`MAX_BATCH_LINKS`] links, 640 bytes a link of lanes.
#[derive(Clone)]
pub struct AbaBatchData {
    /// Per link and lane (`[link][lane]`, `MAX_WIDTH` lanes): absolute angle, sine, cosine.
    angle: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    /// Per link, `MAX_WIDTH` lanes of each value.
    frames: Vec<LinkFrame<[f64; MAX_WIDTH]>>,
    articulated: Vec<ArticulatedLink<[f64; MAX_WIDTH]>>,
    /// The one-state workspace.
    single: ChainData,
    /// The instruction set found at construction.
    arch: Arch,
}

impl AbaBatchData {
    /// A workspace sized for `model`, for the instruction set of this processor.
    ///
    /// ```
    /// use manip_dyn::{AbaBatchData, ChainModel};
    /// let data = AbaBatchData::new(&ChainModel::uniform(10, 0.1, 0.1, 9.81)?);
    /// assert_eq!(data.n_links(), 10);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    ///
    /// # Panics
    /// When the system refuses the memory; [`AbaBatchData::try_new`] returns the error.
    pub fn new(model: &ChainModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`AbaBatchData::new`], or [`DynError::OutOfMemory`] when the system refuses the memory.
    pub fn try_new(model: &ChainModel) -> Result<Self, DynError> {
        const WHAT: &str = "the workspace of the batch ABA";
        let n = model.n_links();
        let lanes = if n <= MAX_BATCH_LINKS { n } else { 0 };
        Ok(Self {
            angle: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            sin: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            cos: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            frames: try_filled(lanes, LinkFrame::default(), WHAT)?,
            articulated: try_filled(lanes, ArticulatedLink::default(), WHAT)?,
            single: ChainData::try_recursive(model)?,
            arch: Arch::new(),
        })
    }

    /// Number of links of the chain this workspace was built for.
    pub fn n_links(&self) -> usize {
        self.single.n_links()
    }
}

impl std::fmt::Debug for AbaBatchData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AbaBatchData")
            .field("n_links", &self.n_links())
            .finish_non_exhaustive()
    }
}

/// [`aba`] of a batch of states: `q`, `v`, `tau` and `qdd` hold `N` states of `n` values each,
/// state after state (row-major `N x n`), and state `i` of `qdd` gets what `aba` gives for
/// state `i` of the inputs.
///
/// SIMD across states (structure of arrays, the instruction set chosen at run time);
/// allocation-free. On an error `qdd` is unspecified.
///
/// ```
/// use manip_dyn::{AbaBatchData, ChainData, ChainModel, aba, aba_batch};
///
/// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
/// let states = 11;
/// let q: Vec<f64> = (0..10 * states).map(|i| 0.1 * (i as f64).sin()).collect();
/// let v: Vec<f64> = (0..10 * states).map(|i| 0.2 * (i as f64).cos()).collect();
/// let tau = vec![0.01; 10 * states];
/// let mut qdd = vec![0.0; 10 * states];
/// aba_batch(&arm, &mut AbaBatchData::new(&arm), &q, &v, &tau, &mut qdd)?;
/// let mut one = [0.0; 10];
/// aba(&arm, &mut ChainData::new(&arm), &q[100..], &v[100..], &tau[100..], &mut one)?;
/// assert_eq!(&qdd[100..], one.as_slice());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`BatchError::Shape`] if the workspace was built for another chain or the slices do not hold
/// the same whole number of states; [`BatchError::State`] with the lowest failing state and what
/// [`aba`] says of it.
pub fn aba_batch(
    model: &ChainModel,
    data: &mut AbaBatchData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), BatchError> {
    let n = model.n_links();
    let shape = |name, found, expected| {
        if found == expected {
            Ok(())
        } else {
            Err(BatchError::Shape(DynError::Dimension {
                name,
                expected,
                found,
            }))
        }
    };
    shape(
        "data (an AbaBatchData built for another model)",
        data.n_links(),
        n,
    )?;
    let values = q.len() - q.len() % n;
    shape("q (whole states of n values)", q.len(), values)?;
    shape("v (as many values as q)", v.len(), values)?;
    shape("tau (as many values as q)", tau.len(), values)?;
    shape("qdd (as many values as q)", qdd.len(), values)?;
    let arch = data.arch;
    arch.dispatch(Batch {
        model,
        data,
        inputs: [q, v, tau],
        qdd,
    })
}

/// One batch, run by [`pulp::Arch::dispatch`] with the processor's instruction set.
struct Batch<'a> {
    model: &'a ChainModel,
    data: &'a mut AbaBatchData,
    /// `q`, `v`, `tau`.
    inputs: [&'a [f64]; 3],
    qdd: &'a mut [f64],
}

impl WithSimd for Batch<'_> {
    type Output = Result<(), BatchError>;

    #[inline(always)]
    fn with_simd<S: Simd>(mut self, simd: S) -> Self::Output {
        let n = self.model.n_links();
        let width = S::F64_LANES;
        let states = self.qdd.len() / n;
        if width > MAX_WIDTH || n > MAX_BATCH_LINKS {
            return self.states(0, states);
        }
        let grouped = states - states % width;
        for first in (0..grouped).step_by(width) {
            let range = first * n..(first + width) * n;
            let inputs = self.inputs.map(|x| &x[range.clone()]);
            let links = LinkBuffers {
                angle: &mut self.data.angle,
                sin: &mut self.data.sin,
                cos: &mut self.data.cos,
                frames: &mut self.data.frames,
                articulated: &mut self.data.articulated,
                arch: self.data.arch,
            };
            let out = &mut self.qdd[range];
            if !group::<S>(simd, self.model, links, inputs, out) {
                self.states(first, first + width)?;
            }
        }
        self.states(grouped, states)
    }
}

impl Batch<'_> {
    /// States `first..last` one at a time, by [`aba`].
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError> {
        let n = self.model.n_links();
        for state in first..last {
            let range = state * n..(state + 1) * n;
            let [q, v, tau] = self.inputs.map(|x| &x[range.clone()]);
            aba(
                self.model,
                &mut self.data.single,
                q,
                v,
                tau,
                &mut self.qdd[range],
            )
            .map_err(|error| BatchError::State { state, error })?;
        }
        Ok(())
    }
}

/// One group of `S::F64_LANES` states (`inputs` and `out` hold exactly those): `false` if an
/// input is not finite or any state failed (`out` is then unspecified).
#[inline(always)]
fn group<S: Simd>(
    simd: S,
    model: &ChainModel,
    links: LinkBuffers<'_, [f64; MAX_WIDTH]>,
    inputs: [&[f64]; 3],
    out: &mut [f64],
) -> bool {
    inputs.iter().all(|x| all_finite(x))
        && kernel::<Pack<S>>(simd, model, links, inputs, out).is_ok()
        && all_finite(out)
}

/// Whether every value is finite, without an early exit, so that the loop vectorises.
#[inline(always)]
pub(crate) fn all_finite(values: &[f64]) -> bool {
    values.iter().fold(true, |all, v| all & v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ChainData, Link, aba};

    /// Every instruction set gives every state the same bits, in a batch and alone (see
    /// [`lane_math::instruction_sets`]).
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        let links: Vec<Link> = (0..13)
            .map(|i| Link::uniform_beam(0.05 + 0.01 * (i % 5) as f64, 0.1 + 0.03 * i as f64))
            .collect::<Result<_, _>>()
            .unwrap();
        let model = ChainModel::new(links, 9.81).unwrap();
        let (n, states) = (model.n_links(), 19);
        let value = |i: usize, scale: f64| scale * ((i as f64) * 0.7).sin();
        let q: Vec<f64> = (0..n * states).map(|i| value(i, 1.3)).collect();
        let v: Vec<f64> = (0..n * states).map(|i| value(i + 5, 2.0)).collect();
        let tau: Vec<f64> = (0..n * states).map(|i| value(i + 9, 0.5)).collect();
        let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut alone = vec![0.0; n * states];
        let mut single = ChainData::new(&model);
        for (s, out) in alone.chunks_exact_mut(n).enumerate() {
            let state = s * n..(s + 1) * n;
            aba(
                &model,
                &mut single,
                &q[state.clone()],
                &v[state.clone()],
                &tau[state],
                out,
            )
            .unwrap();
        }
        for arch in lane_math::instruction_sets() {
            let mut data = AbaBatchData::new(&model);
            data.arch = arch;
            let mut batch = vec![0.0; n * states];
            aba_batch(&model, &mut data, &q, &v, &tau, &mut batch).unwrap();
            assert_eq!(bits(&batch), bits(&alone), "{arch:?}");
        }
    }
}
