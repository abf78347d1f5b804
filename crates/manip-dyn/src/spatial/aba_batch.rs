//! [`aba`](super::aba()) of a batch of states, SIMD across states on `lane-math`: the ABA's
//! [`kernel`](super::aba) over [`Pack`] for each group of states that fills a register, the
//! same operations in the same order as one state, so every state gets the same bits as alone.

use lane_math::{Pack, try_filled};
use pulp::{Arch, Simd, WithSimd};

use super::aba::{AbaBuffers, aba, kernel};
use super::data::{AbaLink, SpatialData};
use super::model::SpatialModel;
use crate::aba::MAX_WIDTH;
use crate::aba_batch::{BatchError, MAX_BATCH_LINKS, all_finite};
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
        "data (a SpatialBatchData built for another model)",
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
    model: &'a SpatialModel,
    data: &'a mut SpatialBatchData,
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
            let finite = inputs.iter().all(|x| all_finite(x));
            let buffers = AbaBuffers {
                angle: &mut self.data.angle,
                sin: &mut self.data.sin,
                cos: &mut self.data.cos,
                links: &mut self.data.links,
                arch: self.data.arch,
            };
            let out = &mut self.qdd[range];
            let ok = finite
                && kernel::<Pack<S>>(simd, self.model, buffers, inputs, out).is_ok()
                && all_finite(out);
            if !ok {
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
