//! The analytic derivatives of the reduced forward dynamics ([`reduced_derivatives`]) of many
//! independent states at once, SIMD across states: each group's `M*`, `C*`, `G*` and
//! accelerations as [`forward_dynamics_batch`](crate::forward_dynamics_batch) forms them, then
//! the two passes of [`crate::derivatives`] with lane `i` of every register holding state `i`.
//! The operations, and their order, are those of one state, so each state's results are the
//! same bits as [`reduced_derivatives`] gives it.
//!
//! A group whose inputs are not all finite, or one of whose states fails, is redone one state
//! at a time by [`reduced_derivatives`], which names the failure; so are the states left over
//! after the last whole group, and every state of a model with more than
//! [`MAX_BATCH_COORDS`] coordinates.

use lane_math::{Lane, Pack, check_len};
use pulp::{Simd, WithSimd};

use crate::batch::{MAX_BATCH_COORDS, Planar, ReducedBatchData};
use crate::batch_driver::{
    BatchError, Groups, MAX_WIDTH, accelerations, check_states, gather, in_groups, scatter,
};
use crate::cache_aligned::CacheAligned;
use crate::derivatives::{
    LINK_VALUES, LinkTrig, ReducedDerivatives, Scratch, StateOf, VECTORS, differentiate,
    reduced_derivatives,
};
use crate::error::ReduceError;
use crate::model::ReducedModel;

/// Workspace of [`reduced_derivatives_batch`] for one [`ReducedModel`]: create it once, reuse it
/// for every batch. Its memory is a [`ReducedBatchData`]'s, a [`ReducedDerivatives`]'s (for
/// the states evaluated one at a time) and the per-link values of the pass from the tip,
/// `8 (5 + 2m)` numbers a link.
#[derive(Debug, Clone)]
pub struct ReducedDerivativesBatch {
    /// The terms of a group, and the one-state workspace of the forward dynamics.
    batch: ReducedBatchData,
    /// Per link: the values of the pass from the tip, `MAX_WIDTH` lanes each.
    links: CacheAligned,
    /// The one-state workspace of the derivatives.
    single: ReducedDerivatives,
}

impl ReducedDerivativesBatch {
    /// A workspace sized for `model`, for the instruction set of this processor.
    ///
    /// # Panics
    /// When the system refuses the memory; [`ReducedDerivativesBatch::try_new`] returns the
    /// error.
    pub fn new(model: &ReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`ReducedDerivativesBatch::new`], or [`ReduceError::OutOfMemory`] when the system
    /// refuses the memory.
    pub fn try_new(model: &ReducedModel) -> Result<Self, ReduceError> {
        const WHAT: &str = "the workspace of the reduced model's batch derivatives";
        Ok(Self {
            batch: ReducedBatchData::try_new(model)?,
            links: CacheAligned::try_zeros(links_len(model), WHAT)?,
            single: ReducedDerivatives::new(model),
        })
    }
}

/// The per-link values of the pass from the tip for `model`'s groups: `5 + 2m` numbers a link
/// in `MAX_WIDTH` lanes each, none for a model whose states go one at a time.
fn links_len(model: &ReducedModel) -> usize {
    let m = model.n_coords();
    if m > MAX_BATCH_COORDS {
        return 0;
    }
    model.n_links() * (LINK_VALUES + 2 * m) * MAX_WIDTH
}

/// [`reduced_derivatives`] of a batch of states: `a`, `a_dot`, `tau_star` and `a_ddot` hold `N`
/// states of `m` values each, state after state (row-major `N x m`), and `jacobians` holds `N`
/// blocks of `3 m^2`, each what [`ReducedDerivatives::jacobians`] gives for that state (row `i`:
/// `[d_a row i | d_a_dot row i | d_tau_star row i]`). State `i` gets the same bits as
/// [`reduced_derivatives`] gives it.
///
/// SIMD across states (structure of arrays, the instruction set chosen at run time);
/// allocation-free. On an error the outputs are unspecified.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedData, ReducedDerivatives, ReducedDerivativesBatch, ReducedModel};
/// use modal_reduce::{reduced_derivatives, reduced_derivatives_batch};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let states = 11;
/// let a: Vec<f64> = (0..3 * states).map(|i| 0.1 * (i as f64).sin()).collect();
/// let a_dot: Vec<f64> = (0..3 * states).map(|i| 0.2 * (i as f64).cos()).collect();
/// let tau_star = vec![0.05; 3 * states];
/// let (mut a_ddot, mut jacobians) = (vec![0.0; 3 * states], vec![0.0; 27 * states]);
/// let mut work = ReducedDerivativesBatch::new(&model);
/// reduced_derivatives_batch(&model, &mut work, &a, &a_dot, &tau_star, &mut a_ddot, &mut jacobians)?;
/// let (mut data, mut one) = (ReducedData::new(&model), ReducedDerivatives::new(&model));
/// reduced_derivatives(&model, &mut data, &mut one, &a[30..], &a_dot[30..], &tau_star[30..])?;
/// assert_eq!(&a_ddot[30..], one.a_ddot());
/// assert_eq!(&jacobians[270..], one.jacobians());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`BatchError::Shape`] when the slices do not hold the same whole number of states, or the
/// workspace was built for another model; [`BatchError::State`] with the lowest state that
/// [`reduced_derivatives`] refuses.
pub fn reduced_derivatives_batch(
    model: &ReducedModel,
    work: &mut ReducedDerivativesBatch,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
    a_ddot: &mut [f64],
    jacobians: &mut [f64],
) -> Result<(), BatchError> {
    let shape = |error: ReduceError| BatchError::Shape(error);
    work.batch.single.check_model(model).map_err(shape)?;
    check_len(
        "derivative workspace links",
        work.links.get().len(),
        links_len(model),
    )
    .map_err(|e| shape(e.into()))?;
    let m = model.n_coords();
    let values = check_states(m, [a, a_dot, tau_star], a_ddot)?;
    check_len(
        "jacobians (3 m values for each value of a)",
        jacobians.len(),
        3 * m * values,
    )
    .map_err(|e| shape(e.into()))?;
    let arch = work.batch.arch;
    arch.dispatch(DerivativesBatch {
        model,
        work,
        inputs: [a, a_dot, tau_star],
        a_ddot,
        jacobians,
    })
}

/// One batch of derivatives, run by [`pulp::Arch::dispatch`] with the processor's instruction
/// set.
struct DerivativesBatch<'a> {
    model: &'a ReducedModel,
    work: &'a mut ReducedDerivativesBatch,
    /// `a`, `a_dot`, `tau_star`.
    inputs: [&'a [f64]; 3],
    a_ddot: &'a mut [f64],
    jacobians: &'a mut [f64],
}

impl WithSimd for DerivativesBatch<'_> {
    type Output = Result<(), BatchError>;

    #[inline(always)]
    fn with_simd<S: Simd>(mut self, simd: S) -> Self::Output {
        match self.model.n_coords() {
            2 => self.groups::<S, 2>(simd),
            3 => self.groups::<S, 3>(simd),
            4 => self.groups::<S, 4>(simd),
            5 => self.groups::<S, 5>(simd),
            m => {
                let states = self.a_ddot.len() / m;
                self.states(0, states)
            }
        }
    }
}

impl DerivativesBatch<'_> {
    /// Whole groups of `S::F64_LANES` states of `M = m` coordinates in SIMD, the rest one at a
    /// time.
    #[inline(always)]
    fn groups<S: Simd, const M: usize>(mut self, simd: S) -> Result<(), BatchError> {
        let states = self.a_ddot.len() / M;
        in_groups::<Self, S, M>(&mut self, simd, states)
    }
}

impl Groups for DerivativesBatch<'_> {
    #[inline(always)]
    fn group<S: Simd, const M: usize>(&mut self, simd: S, first: usize) -> bool {
        let width = S::F64_LANES;
        let range = first * M..(first + width) * M;
        let inputs = self.inputs.map(|x| &x[range.clone()]);
        let blocks = first * 3 * M * M..(first + width) * 3 * M * M;
        let outputs = (&mut self.a_ddot[range], &mut self.jacobians[blocks]);
        group::<S, M>(simd, self.model, self.work, inputs, outputs)
    }

    /// States `first..last` one at a time, by [`reduced_derivatives`].
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError> {
        let m = self.model.n_coords();
        let work = &mut *self.work;
        for state in first..last {
            let range = state * m..(state + 1) * m;
            let [a, a_dot, tau_star] = self.inputs.map(|x| &x[range.clone()]);
            let data = &mut work.batch.single;
            reduced_derivatives(self.model, data, &mut work.single, a, a_dot, tau_star)
                .map_err(|error| BatchError::State { state, error })?;
            self.a_ddot[range].copy_from_slice(work.single.a_ddot());
            let block = state * 3 * m * m..(state + 1) * 3 * m * m;
            self.jacobians[block].copy_from_slice(work.single.jacobians());
        }
        Ok(())
    }
}

/// One group of `S::F64_LANES` states of `M` coordinates (`inputs` and the outputs hold exactly
/// those): the accelerations, then the Jacobians in lanes, scattered into `a_ddot` and
/// `jacobians`. `false` if an input is not finite or any state failed (the outputs are then
/// unspecified).
#[inline(always)]
fn group<S: Simd, const M: usize>(
    simd: S,
    model: &ReducedModel,
    work: &mut ReducedDerivativesBatch,
    inputs: [&[f64]; 3],
    (a_ddot_out, jacobians_out): (&mut [f64], &mut [f64]),
) -> bool {
    let Some(lanes) = gather::<S, M>(simd, inputs) else {
        return false;
    };
    let a_dot = lanes[1];
    let mut kernel = Planar {
        model,
        data: &mut work.batch,
    };
    let Some((a_ddot, mass)) = accelerations::<S, M, Planar<'_>>(simd, &mut kernel, lanes) else {
        return false;
    };
    let zero = Pack::splat(simd, 0.0);
    let mut vectors = [[zero; M]; VECTORS];
    let mut factor = [[zero; M]; M];
    let mut jacobians = [[[zero; M]; 3]; M];
    let trig = LinkTrig {
        sin: work.batch.sin.get(),
        cos: work.batch.cos.get(),
        stride: S::F64_LANES,
    };
    let scratch = Scratch {
        links: work.links.get_mut(),
        vectors: vectors.as_flattened_mut(),
        factor: factor.as_flattened_mut(),
    };
    let state = StateOf {
        a_dot: &a_dot,
        a_ddot: &a_ddot,
        mass: mass.as_flattened(),
    };
    let jacobians = jacobians.as_flattened_mut().as_flattened_mut();
    differentiate(simd, model, trig, M, state, scratch, jacobians)
        & scatter(&a_ddot, a_ddot_out)
        & scatter(jacobians, jacobians_out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ReducedData;
    use backbone_kin::BaseAngle;
    use manip_dyn::{ChainModel, Link};

    /// Every instruction set gives every state of a batch the bits of the one-state
    /// derivatives, for each modal family the batch has kernels for and one beyond them, over
    /// unequal links, with a state that is not finite and one whose `M*` overflows among them
    /// (their groups are redone one state at a time, which names the first failure).
    #[test]
    fn every_state_gets_the_bits_of_the_one_state_derivatives() {
        let links: Vec<Link> = (0..13)
            .map(|i| Link::uniform_beam(0.04 + 0.01 * (i % 3) as f64, 0.1 + 0.03 * i as f64))
            .collect::<Result<_, _>>()
            .unwrap();
        let chain = ChainModel::new(links, 9.81).unwrap();
        let families = [
            (1, BaseAngle::Fixed(1.2)),
            (1, BaseAngle::Free),
            (2, BaseAngle::Fixed(-0.4)),
            (2, BaseAngle::Free),
            (3, BaseAngle::Free),
        ];
        for (harmonics, base) in families {
            let model = ReducedModel::from_chain(chain.clone(), harmonics, base).unwrap();
            let m = model.n_coords();
            let states = 21;
            let value = |i: usize, scale: f64| scale * ((i as f64) * 0.37).sin();
            let a: Vec<f64> = (0..m * states).map(|i| value(i, 1.3)).collect();
            let a_dot: Vec<f64> = (0..m * states).map(|i| value(i + 3, 2.5)).collect();
            let tau_star: Vec<f64> = (0..m * states).map(|i| value(i + 7, 4.0)).collect();
            for arch in lane_math::instruction_sets() {
                let mut work = ReducedDerivativesBatch::new(&model);
                work.batch.arch = arch;
                let mut a_ddot = vec![0.0; m * states];
                let mut jacobians = vec![0.0; 3 * m * m * states];
                let outputs = (&mut a_ddot, &mut jacobians);
                reduced_derivatives_batch(
                    &model, &mut work, &a, &a_dot, &tau_star, outputs.0, outputs.1,
                )
                .unwrap();
                let mut data = ReducedData::new(&model);
                data.arch = arch;
                let mut one = ReducedDerivatives::new(&model);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                for s in 0..states {
                    let state = s * m..(s + 1) * m;
                    let inputs = (
                        &a[state.clone()],
                        &a_dot[state.clone()],
                        &tau_star[state.clone()],
                    );
                    reduced_derivatives(&model, &mut data, &mut one, inputs.0, inputs.1, inputs.2)
                        .unwrap();
                    assert_eq!(
                        bits(&a_ddot[state]),
                        bits(one.a_ddot()),
                        "m = {m}, {arch:?}, state {s}"
                    );
                    let block = &jacobians[s * 3 * m * m..(s + 1) * 3 * m * m];
                    assert_eq!(
                        bits(block),
                        bits(one.jacobians()),
                        "m = {m}, {arch:?}, state {s}"
                    );
                }
                // A rate that is not finite in state 9, an overflowing one in state 4: the lowest
                // failing state is named.
                let mut bad = a_dot.clone();
                bad[9 * m] = f64::NAN;
                bad[4 * m] = 1e300;
                let error = reduced_derivatives_batch(
                    &model,
                    &mut work,
                    &a,
                    &bad,
                    &tau_star,
                    &mut a_ddot,
                    &mut jacobians,
                )
                .unwrap_err();
                assert!(
                    matches!(error, BatchError::State { state: 4, .. }),
                    "{error}"
                );
            }
        }
    }

    #[test]
    fn slices_of_other_sizes_are_refused_with_the_field_named() {
        let model = ReducedModel::from_chain(
            ChainModel::uniform(6, 0.1, 0.1, 9.81).unwrap(),
            1,
            BaseAngle::Free,
        )
        .unwrap();
        let mut work = ReducedDerivativesBatch::new(&model);
        let (a, mut a_ddot) = (vec![0.1; 6], vec![0.0; 6]);
        let mut jacobians = vec![0.0; 27 * 2];
        let short = [0.0; 3];
        let error = reduced_derivatives_batch(
            &model,
            &mut work,
            &a,
            &short,
            &a,
            &mut a_ddot,
            &mut jacobians,
        )
        .unwrap_err();
        assert!(error.to_string().contains("a_dot"), "{error}");
        let error = reduced_derivatives_batch(
            &model,
            &mut work,
            &a,
            &a,
            &a,
            &mut a_ddot,
            &mut jacobians[..50],
        )
        .unwrap_err();
        assert!(error.to_string().contains("jacobians"), "{error}");
        let other = ReducedModel::from_chain(
            ChainModel::uniform(7, 0.1, 0.1, 9.81).unwrap(),
            1,
            BaseAngle::Free,
        )
        .unwrap();
        assert!(
            reduced_derivatives_batch(&other, &mut work, &a, &a, &a, &mut a_ddot, &mut jacobians)
                .is_err()
        );
    }
}
