//! Reduced forward dynamics (eq 15) of many independent states at once, SIMD across states.
//!
//! The driver ([`crate::batch_driver`], shared with the spatial batch) takes the states `W` at a
//! time, `W` the number of `f64` lanes of the widest instruction set the processor has (8 with
//! AVX-512, 4 with AVX2; chosen at run time by [`pulp::Arch`], so one binary runs everywhere), and
//! each group runs through the same kernel as one state ([`crate::terms`]), written once over
//! [`Lane`](lane_math::Lane): lane `i` of every register holds state `i` of the group (structure
//! of arrays). The operations, and their order, are those of the one-state path, so each state's
//! result is the same.
//!
//! A group whose inputs are not all finite, or one of whose states fails (a non-positive pivot,
//! an overflow), is redone one state at a time by [`forward_dynamics`], which names the failure;
//! so are the states left over after the last whole group, and every state of a model with more
//! than [`MAX_BATCH_COORDS`] coordinates.

use pulp::{Arch, Simd};

use crate::batch_driver::{Batch, BatchError, BatchKernel, MAX_WIDTH, run_batch};
use crate::cache_aligned::CacheAligned;
use crate::data::{PRODUCTS, ReducedData};
use crate::error::ReduceError;
use crate::forward::forward_dynamics;
use crate::model::ReducedModel;
use crate::terms::{LinkBuffers, StateLanes, Terms, accumulate, angles_in_range, extract};
use lane_math::{Lane, Pack};

/// The most modal coordinates evaluated SIMD across states (`K = 2` harmonics with `alpha0`
/// free); larger models run their batches one state at a time.
pub const MAX_BATCH_COORDS: usize = 5;

/// Workspace of [`forward_dynamics_batch`] for one [`ReducedModel`]: create it once, reuse it for
/// every batch. Its memory is `O(n)` like a [`ReducedData`]'s (which it holds, for the states
/// evaluated one at a time) plus eight buffers of `n` values per lane (`512 n` bytes).
#[derive(Debug, Clone)]
pub struct ReducedBatchData {
    /// Per link and lane (`[link][lane]`, `MAX_WIDTH` lanes): the absolute angle, its sine and
    /// cosine.
    angle: CacheAligned,
    pub(crate) sin: CacheAligned,
    pub(crate) cos: CacheAligned,
    /// Per product, link and lane: the products of [`crate::terms`].
    products: CacheAligned,
    /// The one-state workspace.
    pub(crate) single: ReducedData,
    /// The instruction set found at construction.
    pub(crate) arch: Arch,
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
    let arch = data.arch;
    let kernel = Planar { model, data };
    run_batch(kernel, arch, [a, a_dot, tau_star], a_ddot)
}

/// The planar family's part of a batch: the kernel of [`crate::terms`] and [`forward_dynamics`].
pub(crate) struct Planar<'a> {
    pub(crate) model: &'a ReducedModel,
    pub(crate) data: &'a mut ReducedBatchData,
}

impl BatchKernel for Planar<'_> {
    fn n_coords(&self) -> usize {
        self.model.n_coords()
    }

    #[inline(always)]
    fn dispatch<S: Simd>(batch: Batch<'_, Self>, simd: S) -> Result<(), BatchError> {
        match batch.kernel().model.n_coords() {
            2 => batch.groups::<S, 2>(simd),
            3 => batch.groups::<S, 3>(simd),
            4 => batch.groups::<S, 4>(simd),
            5 => batch.groups::<S, 5>(simd),
            _ => batch.one_at_a_time(),
        }
    }

    /// With the last coordinate's column of `Phi` all ones (`alpha0` free), a kernel that skips
    /// the multiplications by it.
    #[inline(always)]
    fn terms<S: Simd, const M: usize>(
        &mut self,
        simd: S,
        a: &[Pack<S>; M],
        a_dot: &[Pack<S>; M],
        mass: &mut [[Pack<S>; M]; M],
        coriolis: &mut [Pack<S>; M],
        gravity: &mut [Pack<S>; M],
    ) -> bool {
        if self.model.unit_column() == Some(M - 1) {
            self.terms_of::<S, M, true>(simd, a, a_dot, mass, coriolis, gravity)
        } else {
            self.terms_of::<S, M, false>(simd, a, a_dot, mass, coriolis, gravity)
        }
    }

    fn one_state(
        &mut self,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        a_ddot: &mut [f64],
    ) -> Result<(), ReduceError> {
        forward_dynamics(
            self.model,
            &mut self.data.single,
            a,
            a_dot,
            tau_star,
            a_ddot,
        )
    }
}

impl Planar<'_> {
    /// [`BatchKernel::terms`]; `UNIT_LAST`: the last coordinate's column of `Phi` is all ones.
    /// `false` for angles the kernel's sine and cosine do not take.
    #[inline(always)]
    fn terms_of<S: Simd, const M: usize, const UNIT_LAST: bool>(
        &mut self,
        simd: S,
        a: &[Pack<S>; M],
        a_dot: &[Pack<S>; M],
        mass: &mut [[Pack<S>; M]; M],
        coriolis: &mut [Pack<S>; M],
        gravity: &mut [Pack<S>; M],
    ) -> bool {
        if !angles_in_range(simd, self.model, a) {
            return false;
        }
        let links = LinkBuffers {
            angle: self.data.angle.get_mut(),
            sin: self.data.sin.get_mut(),
            cos: self.data.cos.get_mut(),
            products: self.data.products.get_mut(),
            links: self.model.n_links(),
        };
        let zero = Pack::splat(simd, 0.0);
        let mut sums = [[zero; M]; M];
        let (mut coriolis_sums, mut gravity_sums) = ([zero; M], [zero; M]);
        let mut v = [zero; M];
        let mut joint = [[zero; 2]; M];
        let mut terms = Terms {
            mass: sums.as_flattened_mut(),
            coriolis: &mut coriolis_sums,
            gravity: &mut gravity_sums,
            joint: &mut joint,
            v: &mut v,
        };
        let layout = StateLanes::new(simd, if UNIT_LAST { M - 1 } else { usize::MAX });
        accumulate(layout, self.model, a, a_dot, M, links, &mut terms);
        extract(
            layout,
            self.model,
            M,
            &terms,
            mass.as_flattened_mut(),
            coriolis,
            gravity,
        );
        true
    }
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
