//! The driver of the planar and the spatial batch ABA ([`aba_batch`](crate::aba_batch) and
//! [`spatial::aba_batch`](crate::spatial::aba_batch)), written once over a chain family's
//! [`AbaKernel`].
//!
//! It checks the workspace and that the slices hold whole states, takes the states `W` at a time
//! (`W` the `f64` lanes of the widest instruction set [`pulp::Arch`] finds at run time: 8 with
//! AVX-512, 4 with AVX2) through the family's kernel over [`Pack`](lane_math::Pack), and redoes
//! one state at a time, by the family's one-state ABA, which names the failure, a group whose
//! inputs are not all finite or one of whose states fails (a pivot not positive beyond rounding,
//! an overflow); so are the states left over after the last whole group, and every state of a
//! chain of more than [`MAX_BATCH_LINKS`] links.

use lane_math::{Classify, ErrorClass, all_finite, check_len};
use pulp::{Arch, Simd, WithSimd};

use crate::aba::MAX_WIDTH;
use crate::error::DynError;

/// The most links evaluated SIMD across states: an [`AbaBatchData`](crate::AbaBatchData) holds
/// 640 bytes a link for them (ten values of eight lanes), 2.6 MB at this limit. Longer chains
/// run their batches one state at a time, in the `O(n)` memory of a
/// [`ChainData`](crate::ChainData).
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
        /// Why the one-state ABA refused it.
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

/// What a chain family brings to the driver: its ABA kernel over a group of states and its
/// one-state ABA.
pub(crate) trait AbaKernel {
    /// The chain's number of links (joints) `n`.
    fn n_links(&self) -> usize;

    /// The kernel over one group of `S::F64_LANES` states (`inputs`, `q`, `v`, `tau`, and `qdd`
    /// hold exactly those; the inputs are finite).
    fn group<S: Simd>(
        &mut self,
        simd: S,
        inputs: [&[f64]; 3],
        qdd: &mut [f64],
    ) -> Result<(), DynError>;

    /// The one-state ABA of one state, which names a failure.
    fn one_state(&mut self, inputs: [&[f64]; 3], qdd: &mut [f64]) -> Result<(), DynError>;
}

/// Checks that the workspace (`workspace` names it; built for `workspace_links` links) belongs
/// to `kernel`'s chain and that `q`, `v`, `tau` and `qdd` hold the same whole number of states
/// of `n` values each, then runs the batch with `arch`'s instruction set.
pub(crate) fn run_batch<K: AbaKernel>(
    kernel: K,
    arch: Arch,
    workspace: (&'static str, usize),
    inputs: [&[f64]; 3],
    qdd: &mut [f64],
) -> Result<(), BatchError> {
    let n = kernel.n_links();
    let shape = |name, found, expected| {
        check_len(name, found, expected).map_err(|e| BatchError::Shape(e.into()))
    };
    shape(workspace.0, workspace.1, n)?;
    let [q, v, tau] = inputs;
    let values = q.len() - q.len() % n;
    shape("q (whole states of n values)", q.len(), values)?;
    shape("v (as many values as q)", v.len(), values)?;
    shape("tau (as many values as q)", tau.len(), values)?;
    shape("qdd (as many values as q)", qdd.len(), values)?;
    arch.dispatch(Batch {
        kernel,
        inputs,
        qdd,
    })
}

/// One batch, run by [`pulp::Arch::dispatch`] with the processor's instruction set.
struct Batch<'a, K> {
    kernel: K,
    /// `q`, `v`, `tau`.
    inputs: [&'a [f64]; 3],
    qdd: &'a mut [f64],
}

impl<K: AbaKernel> WithSimd for Batch<'_, K> {
    type Output = Result<(), BatchError>;

    #[inline(always)]
    fn with_simd<S: Simd>(mut self, simd: S) -> Self::Output {
        let n = self.kernel.n_links();
        let width = S::F64_LANES;
        let states = self.qdd.len() / n;
        if width > MAX_WIDTH || n > MAX_BATCH_LINKS {
            return self.states(0, states);
        }
        let grouped = states - states % width;
        for first in (0..grouped).step_by(width) {
            let range = first * n..(first + width) * n;
            let inputs = self.inputs.map(|x| &x[range.clone()]);
            let out = &mut self.qdd[range];
            let done = inputs.iter().all(|x| all_finite(x))
                && self.kernel.group(simd, inputs, out).is_ok()
                && all_finite(out);
            if !done {
                self.states(first, first + width)?;
            }
        }
        self.states(grouped, states)
    }
}

impl<K: AbaKernel> Batch<'_, K> {
    /// States `first..last` one at a time, by the family's one-state ABA.
    fn states(&mut self, first: usize, last: usize) -> Result<(), BatchError> {
        let n = self.kernel.n_links();
        for state in first..last {
            let range = state * n..(state + 1) * n;
            let inputs = self.inputs.map(|x| &x[range.clone()]);
            self.kernel
                .one_state(inputs, &mut self.qdd[range])
                .map_err(|error| BatchError::State { state, error })?;
        }
        Ok(())
    }
}
