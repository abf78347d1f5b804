//! Forward dynamics by the articulated-body algorithm of many independent states at once, SIMD
//! across states.
//!
//! The driver ([`crate::batch_driver`], shared with the spatial batch) takes the states `W` at a
//! time, `W` the number of `f64` lanes of the widest instruction set the processor has (8 with
//! AVX-512, 4 with AVX2; chosen at run time by [`pulp::Arch`], so one binary runs everywhere), and
//! each group runs through the kernel of one state (`crate::aba`), written once over `AbaLane`:
//! lane `i` of every register holds state `i` of the group (structure of arrays). The operations,
//! and their order, are those of [`aba`], so each state's result is the same.
//!
//! A group whose inputs are not all finite, or one of whose states fails (a pivot not positive
//! beyond rounding, an overflow), is redone one state at a time by [`aba`], which names the
//! failure; so are the states left over after the last whole group, and every state of a chain
//! of more than [`MAX_BATCH_LINKS`] links.

use lane_math::{Pack, try_filled};
use pulp::{Arch, Simd};

use crate::aba::{LinkBuffers, MAX_WIDTH, aba, kernel};
use crate::batch_driver::{AbaKernel, BatchError, MAX_BATCH_LINKS, run_batch};
use crate::data::{ArticulatedLink, ChainData, LinkFrame};
use crate::error::DynError;
use crate::model::ChainModel;

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
    let workspace = (
        "data (an AbaBatchData built for another model)",
        data.n_links(),
    );
    let arch = data.arch;
    run_batch(Planar { model, data }, arch, workspace, [q, v, tau], qdd)
}

/// The planar chain's part of a batch: the kernel of [`crate::aba`] and [`aba`].
struct Planar<'a> {
    model: &'a ChainModel,
    data: &'a mut AbaBatchData,
}

impl AbaKernel for Planar<'_> {
    fn n_links(&self) -> usize {
        self.model.n_links()
    }

    #[inline(always)]
    fn group<S: Simd>(
        &mut self,
        simd: S,
        inputs: [&[f64]; 3],
        qdd: &mut [f64],
    ) -> Result<(), DynError> {
        let links = LinkBuffers {
            angle: &mut self.data.angle,
            sin: &mut self.data.sin,
            cos: &mut self.data.cos,
            frames: &mut self.data.frames,
            articulated: &mut self.data.articulated,
            arch: self.data.arch,
        };
        kernel::<Pack<S>>(simd, self.model, links, inputs, qdd)
    }

    fn one_state(&mut self, inputs: [&[f64]; 3], qdd: &mut [f64]) -> Result<(), DynError> {
        let [q, v, tau] = inputs;
        aba(self.model, &mut self.data.single, q, v, tau, qdd)
    }
}
