//! How many states [`forward_dynamics_batch`](crate::forward_dynamics_batch) evaluates side by
//! side, for callers that assemble their own batches: a lock-step group of closed-loop runs
//! (`sim-core`) fills whole SIMD groups instead of leaving a remainder to be evaluated one state
//! at a time.

use pulp::{Arch, Simd, WithSimd};

use crate::batch::MAX_BATCH_COORDS;
use crate::batch_driver::MAX_WIDTH;
use crate::model::ReducedModel;

/// The number of states [`forward_dynamics_batch`](crate::forward_dynamics_batch) evaluates in
/// one SIMD group for `model` on this processor: 8 with AVX-512, 4 with AVX2, 2 with NEON, and
/// 1 when the states go one at a time (no SIMD instruction set, or a model of more than
/// [`MAX_BATCH_COORDS`] coordinates). A batch of a multiple of this many states has no
/// remainder evaluated one at a time.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedModel, batch_lanes};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// assert!([1, 2, 4, 8].contains(&batch_lanes(&model)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn batch_lanes(model: &ReducedModel) -> usize {
    if model.n_coords() > MAX_BATCH_COORDS {
        return 1;
    }
    simd_lanes()
}

/// The number of `f64` lanes of the instruction set [`Arch::new`] picks on this processor (1
/// without SIMD, or with registers wider than the batches' [`MAX_WIDTH`]).
pub(crate) fn simd_lanes() -> usize {
    Arch::new().dispatch(Lanes)
}

/// The lane count of the instruction set [`Arch::dispatch`] picks.
struct Lanes;

impl WithSimd for Lanes {
    type Output = usize;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> usize {
        if S::F64_LANES <= MAX_WIDTH {
            S::F64_LANES
        } else {
            1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use backbone_kin::{BaseAngle, ModalMap};
    use manip_dyn::ChainModel;

    #[test]
    fn the_lanes_are_those_of_the_instruction_set_and_one_for_large_families() {
        let chain = ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap();
        let paper = ReducedModel::new(chain.clone(), ModalMap::paper(10).unwrap()).unwrap();
        let lanes = batch_lanes(&paper);
        #[cfg(target_arch = "x86_64")]
        {
            let expected = if pulp::x86::V4::try_new().is_some() {
                8
            } else if pulp::x86::V3::try_new().is_some() {
                4
            } else {
                1
            };
            assert_eq!(lanes, expected);
        }
        assert!([1, 2, 4, 8].contains(&lanes), "{lanes}");
        // Three harmonics with alpha0 free: 7 coordinates, beyond the batch's SIMD kernels.
        let large = ReducedModel::from_chain(chain, 3, BaseAngle::Free).unwrap();
        assert!(large.n_coords() > MAX_BATCH_COORDS);
        assert_eq!(batch_lanes(&large), 1);
    }
}
