//! Reduced forward dynamics of a spatial modal arm for many independent states at once, SIMD
//! across states: [`spatial_forward_dynamics`] of each state, the same bits.
//!
//! The driver is the planar batch's (`batch_driver.rs`): the states are taken `W` at a time
//! (`W` the `f64` lanes of the widest instruction set [`pulp::Arch`] finds at run time, 8 with
//! AVX-512, 4 with AVX2), lane `i` of every register holding state `i` of the group, and each
//! group runs through the kernel of one state (`accumulate`, the recursion in the links' frames
//! of [`terms`](super::terms)) and the `L D L^T` solve, written once over the register layouts of
//! the [`terms`](super::terms) module (one coordinate of the group's states a register here),
//! with the same operations in the same order. A group whose inputs
//! are not all finite, or one of whose states fails, is redone one state at a time by
//! [`spatial_forward_dynamics`], which names the failure; so are the states after the last whole
//! group, and every state of a model of more than [`MAX_SPATIAL_BATCH_COORDS`] coordinates.
//!
//! Memory: the kernel forms each link's joint angles from the map's rows as it goes and keeps
//! only the `3 x m` Jacobians, `M*`, `C*` and `G*` of a group, on the stack, so a batch needs
//! nothing of size `n` beyond the model (`O(n m)`) and the one-state workspace. These stack
//! Jacobians are declared here and in the one-state `in_layout` of [`terms`](super::terms) rather
//! than by one shared helper, because the two hold different registers (`M` packs of states here,
//! `C` registers of a coordinate layout there) and a helper taking the kernel as a closure would
//! be compiled without the dispatch's instruction set.

use lane_math::{Lane, Pack};
use pulp::{Arch, Simd};

use super::data::SpatialReducedData;
use super::forward::spatial_forward_dynamics;
use super::model::SpatialReducedModel;
use super::terms::{TermsLanes, TurnsFromModes, accumulate};
use crate::batch_driver::{Batch, BatchError, BatchKernel, run_batch};
use crate::batch_group::simd_lanes;
use crate::error::ReduceError;
use crate::terms::StateLanes;

/// The most modal coordinates evaluated SIMD across states (`K = 2` harmonics per plane);
/// larger models run their batches one state at a time.
pub const MAX_SPATIAL_BATCH_COORDS: usize = 8;

/// Workspace of [`spatial_forward_dynamics_batch`] for one [`SpatialReducedModel`]: create it
/// once, reuse it for every batch. It holds a [`SpatialReducedData`] for the states evaluated one
/// at a time; the SIMD groups need nothing more.
#[derive(Debug, Clone)]
pub struct SpatialReducedBatchData {
    /// The one-state workspace.
    single: SpatialReducedData,
    /// The instruction set found at construction.
    arch: Arch,
}

impl SpatialReducedBatchData {
    /// A workspace sized for `model`, for the instruction set of this processor.
    ///
    /// # Panics
    /// When the system refuses the memory; [`SpatialReducedBatchData::try_new`] returns the
    /// error.
    pub fn new(model: &SpatialReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`SpatialReducedBatchData::new`], or [`ReduceError::OutOfMemory`] when the system
    /// refuses the memory.
    pub fn try_new(model: &SpatialReducedModel) -> Result<Self, ReduceError> {
        Ok(Self {
            single: SpatialReducedData::try_new(model)?,
            arch: Arch::new(),
        })
    }
}

/// The number of states [`spatial_forward_dynamics_batch`] evaluates in one SIMD group for
/// `model` on this processor (as [`batch_lanes`](crate::batch_lanes) for a planar arm): 8 with
/// AVX-512, 4 with AVX2, and 1 when the states go one at a time (no SIMD, or more than
/// [`MAX_SPATIAL_BATCH_COORDS`] coordinates).
pub fn spatial_batch_lanes(model: &SpatialReducedModel) -> usize {
    if model.n_coords() > MAX_SPATIAL_BATCH_COORDS {
        return 1;
    }
    simd_lanes()
}

/// [`spatial_forward_dynamics`] of a batch of states: `a`, `a_dot`, `tau_star` and `a_ddot` hold
/// `N` states of `m` values each, state after state (row-major `N x m`), and state `i` of
/// `a_ddot` gets what `spatial_forward_dynamics` gives for state `i` of the inputs, bit for bit.
///
/// SIMD across states (the instruction set chosen at run time); allocation-free. On an error
/// `a_ddot` is unspecified.
///
/// ```
/// use modal_reduce::spatial::{
///     SpatialReducedBatchData, SpatialReducedData, SpatialReducedModel, spatial_forward_dynamics,
///     spatial_forward_dynamics_batch,
/// };
///
/// let model = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81])?;
/// let states = 11;
/// let a: Vec<f64> = (0..4 * states).map(|i| 0.1 * (i as f64).sin()).collect();
/// let a_dot: Vec<f64> = (0..4 * states).map(|i| 0.2 * (i as f64).cos()).collect();
/// let tau_star = vec![0.05; 4 * states];
/// let mut a_ddot = vec![0.0; 4 * states];
/// let mut batch = SpatialReducedBatchData::new(&model);
/// spatial_forward_dynamics_batch(&model, &mut batch, &a, &a_dot, &tau_star, &mut a_ddot)?;
/// let (mut data, mut one) = (SpatialReducedData::new(&model), [0.0; 4]);
/// spatial_forward_dynamics(&model, &mut data, &a[36..40], &a_dot[36..40], &tau_star[36..40], &mut one)?;
/// assert_eq!(&a_ddot[36..40], one.as_slice());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn spatial_forward_dynamics_batch(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedBatchData,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
) -> Result<(), BatchError> {
    data.single.check_model(model).map_err(BatchError::Shape)?;
    let kernel = Spatial {
        model,
        single: &mut data.single,
    };
    run_batch(kernel, data.arch, [a, a_dot, tau_star], a_ddot)
}

/// The spatial family's part of a batch: the kernel of [`super::terms`] and
/// [`spatial_forward_dynamics`].
struct Spatial<'a> {
    model: &'a SpatialReducedModel,
    single: &'a mut SpatialReducedData,
}

impl BatchKernel for Spatial<'_> {
    fn n_coords(&self) -> usize {
        self.model.n_coords()
    }

    #[inline(always)]
    fn dispatch<S: Simd>(batch: Batch<'_, Self>, simd: S) -> Result<(), BatchError> {
        match batch.kernel().model.n_coords() {
            4 => batch.groups::<S, 4>(simd),
            8 => batch.groups::<S, 8>(simd),
            _ => batch.one_at_a_time(),
        }
    }

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
        let zero = Pack::splat(simd, 0.0);
        let mut jacobians = [[[zero; M]; 3]; 5];
        let [point, com, momentum, body, body_inertia] = &mut jacobians;
        let work = TermsLanes {
            point_jacobian: point.as_flattened_mut(),
            com_jacobian: com.as_flattened_mut(),
            momentum_jacobian: momentum.as_flattened_mut(),
            body_jacobian: body.as_flattened_mut(),
            body_inertia_jacobian: body_inertia.as_flattened_mut(),
            mass_matrix: mass.as_flattened_mut(),
            coriolis,
            gravity,
        };
        let turns = TurnsFromModes {
            context: simd,
            model: self.model,
            a,
            a_dot,
            next: 0,
        };
        // M*'s lower triangle, all the solve reads.
        accumulate(
            StateLanes::new(simd, usize::MAX),
            self.model,
            turns,
            M,
            work,
        );
        true
    }

    fn one_state(
        &mut self,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        a_ddot: &mut [f64],
    ) -> Result<(), ReduceError> {
        spatial_forward_dynamics(self.model, self.single, a, a_dot, tau_star, a_ddot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::SpatialLinkInertia;
    use backbone_kin::{BasePose, SpatialModalMap};

    /// An arm of unequal links, tilted base, oblique gravity, `K` harmonics.
    fn arm(harmonics: usize) -> SpatialReducedModel {
        let lengths: Vec<f64> = (0..9).map(|i| 0.08 + 0.01 * (i % 4) as f64).collect();
        let links = lengths
            .iter()
            .enumerate()
            .map(|(i, &l)| {
                let bending = SpatialLinkInertia::rod(0.1 + 0.02 * i as f64, l).principal[1];
                SpatialLinkInertia {
                    mass: 0.1 + 0.02 * i as f64,
                    principal: [1e-6, bending, bending + 5e-7],
                }
            })
            .collect();
        let base = BasePose {
            xyz: [0.1, -0.2, 0.3],
            rpy: [0.2, -0.4, 0.7],
        };
        let map = SpatialModalMap::new(&lengths, harmonics).unwrap();
        SpatialReducedModel::new(map, base, links, [0.5, -1.0, -9.7]).unwrap()
    }

    /// Every instruction set gives every state the same bits, in a batch and alone (the kernel
    /// is one, its fused multiply-adds rounded once by every instruction set), so results do not
    /// depend on the machine; and a model beyond the SIMD sizes too (one state at a time).
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        for harmonics in [1, 2, 3] {
            let model = arm(harmonics);
            let m = model.n_coords();
            let states = 19;
            let value = |i: usize, scale: f64| scale * ((i as f64) * 0.7).sin();
            let a: Vec<f64> = (0..m * states).map(|i| value(i, 1.1)).collect();
            let a_dot: Vec<f64> = (0..m * states).map(|i| value(i + 5, 2.0)).collect();
            let tau_star: Vec<f64> = (0..m * states).map(|i| value(i + 9, 0.3)).collect();
            let mut reference: Option<Vec<u64>> = None;
            for arch in lane_math::instruction_sets() {
                let mut batch_data = SpatialReducedBatchData::new(&model);
                batch_data.arch = arch;
                batch_data.single.arch = arch;
                let mut batch = vec![0.0; m * states];
                spatial_forward_dynamics_batch(
                    &model,
                    &mut batch_data,
                    &a,
                    &a_dot,
                    &tau_star,
                    &mut batch,
                )
                .unwrap();
                let mut data = SpatialReducedData::new(&model);
                data.arch = arch;
                let mut alone = vec![0.0; m * states];
                for (s, out) in alone.chunks_exact_mut(m).enumerate() {
                    let state = s * m..(s + 1) * m;
                    let (a, a_dot) = (&a[state.clone()], &a_dot[state.clone()]);
                    spatial_forward_dynamics(&model, &mut data, a, a_dot, &tau_star[state], out)
                        .unwrap();
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
