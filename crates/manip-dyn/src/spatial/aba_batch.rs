//! [`aba`](super::aba()) of a batch of states, SIMD across states on `lane-math`: the ABA's
//! [`kernel`](super::aba) over [`Pack`] for each group of states that fills a register, the
//! same operations in the same order as one state, so every state gets the same bits as alone.

use lane_math::{Pack, try_filled};
use pulp::{Arch, Simd};

use super::aba::{AbaBuffers, aba, kernel};
use super::data::{AbaLink, SpatialData};
use super::model::SpatialModel;
use crate::aba::MAX_WIDTH;
use crate::batch_driver::{AbaKernel, BatchError, MAX_BATCH_LINKS, run_batch};
use crate::error::DynError;

/// Workspace of [`aba_batch`] for one [`SpatialModel`]: create it once, reuse it for every batch.
/// It holds a [`SpatialData`] for the states evaluated one at a time and, for chains of up to
/// [`MAX_BATCH_LINKS`](crate::MAX_BATCH_LINKS) links, about 3 KiB a link of lanes.
#[derive(Clone)]
pub struct SpatialBatchData {
    /// Per link and lane (`[link][lane]`): joint value, sine, cosine.
    angle: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    links: Vec<AbaLink<[f64; MAX_WIDTH]>>,
    single: SpatialData,
    arch: Arch,
}

impl SpatialBatchData {
    /// A workspace sized for `model`, for the instruction set of this processor.
    ///
    /// # Panics
    /// When the system refuses the memory; [`SpatialBatchData::try_new`] returns the error.
    pub fn new(model: &SpatialModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`SpatialBatchData::new`], or [`DynError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_new(model: &SpatialModel) -> Result<Self, DynError> {
        const WHAT: &str = "the workspace of the spatial batch ABA";
        let n = model.n_links();
        let lanes = if n <= MAX_BATCH_LINKS { n } else { 0 };
        Ok(Self {
            angle: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            sin: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            cos: try_filled(lanes * MAX_WIDTH, 0.0, WHAT)?,
            links: try_filled(lanes, AbaLink::default(), WHAT)?,
            single: SpatialData::try_new(model)?,
            arch: Arch::new(),
        })
    }

    /// Number of links of the chain this workspace was built for.
    pub fn n_links(&self) -> usize {
        self.single.n_links()
    }
}

impl std::fmt::Debug for SpatialBatchData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpatialBatchData")
            .field("n_links", &self.n_links())
            .finish_non_exhaustive()
    }
}

/// [`aba`](super::aba()) of a batch: `q`, `v`, `tau` and `qdd` hold `N` states of `n` values
/// each, state after state (row-major `N x n`), and state `i` of `qdd` gets what `aba` gives for
/// state `i` of the inputs, bit for bit. Allocation-free; on an error `qdd` is unspecified.
///
/// ```
/// use manip_dyn::ChainModel;
/// use manip_dyn::spatial::{SpatialBatchData, SpatialData, SpatialModel, aba, aba_batch};
/// let arm = SpatialModel::from_planar(&ChainModel::uniform(10, 0.1, 0.1, 9.81)?);
/// let states = 11;
/// let q: Vec<f64> = (0..10 * states).map(|i| 0.1 * (i as f64).sin()).collect();
/// let v: Vec<f64> = (0..10 * states).map(|i| 0.2 * (i as f64).cos()).collect();
/// let tau = vec![0.01; 10 * states];
/// let mut qdd = vec![0.0; 10 * states];
/// aba_batch(&arm, &mut SpatialBatchData::new(&arm), &q, &v, &tau, &mut qdd)?;
/// let mut one = [0.0; 10];
/// aba(&arm, &mut SpatialData::new(&arm), &q[100..], &v[100..], &tau[100..], &mut one)?;
/// assert_eq!(&qdd[100..], one.as_slice());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`BatchError::Shape`] if the workspace was built for another chain or the slices do not hold
/// the same whole number of states; [`BatchError::State`] with the lowest failing state and what
/// [`aba`](super::aba()) says of it.
pub fn aba_batch(
    model: &SpatialModel,
    data: &mut SpatialBatchData,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<(), BatchError> {
    let workspace = (
        "data (a SpatialBatchData built for another model)",
        data.n_links(),
    );
    let arch = data.arch;
    run_batch(Spatial { model, data }, arch, workspace, [q, v, tau], qdd)
}

/// The spatial chain's part of a batch: the kernel of [`super::aba`] and [`aba`](super::aba()).
struct Spatial<'a> {
    model: &'a SpatialModel,
    data: &'a mut SpatialBatchData,
}

impl AbaKernel for Spatial<'_> {
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
        let buffers = AbaBuffers {
            angle: &mut self.data.angle,
            sin: &mut self.data.sin,
            cos: &mut self.data.cos,
            links: &mut self.data.links,
            arch: self.data.arch,
        };
        kernel::<Pack<S>>(simd, self.model, buffers, inputs, qdd)
    }

    fn one_state(&mut self, inputs: [&[f64]; 3], qdd: &mut [f64]) -> Result<(), DynError> {
        let [q, v, tau] = inputs;
        aba(self.model, &mut self.data.single, q, v, tau, qdd)
    }
}
