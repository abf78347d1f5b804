//! [`Evaluator::eval_batch`](crate::Evaluator::eval_batch): many input points at once, SIMD
//! across points.
//!
//! The points are taken `W` at a time, `W` the number of `f64` lanes of the widest instruction
//! set the processor has (8 with AVX-512, 4 with AVX2, 1 without either; chosen at run time by
//! [`pulp::Arch`], so one binary runs everywhere), and each group runs through the kernel of one
//! point (`kernel.rs`) with lane `i` of every register holding point `i` of the group (structure
//! of arrays). The inputs' checks and range policy and the last step's policies are those of one
//! point, applied lane by lane, so each point's outputs are bit for bit those of
//! [`Evaluator::eval`](crate::Evaluator::eval).
//!
//! A group with a refused point (a non-finite or out-of-range input, an output on which no rule
//! fires under [`NoRuleFired::Error`](crate::NoRuleFired::Error), a non-finite output) is redone
//! one point at a time, which names the failure and leaves the rows before it written; so are the
//! points after the last whole group.

use lane_math::Pack;
use pulp::{Arch, Simd, WithSimd};

use crate::error::FuzzyError;
use crate::kernel::{self, Workspace};
use crate::options::{EvalOptions, load_input, output_value};
use crate::system::FuzzySystem;

/// The most `f64` lanes of a SIMD register (AVX-512): the stride of the batch's buffers.
const MAX_WIDTH: usize = 8;

/// The batch's buffers (slots of [`MAX_WIDTH`] values) and the instruction set found at
/// construction.
#[derive(Debug, Clone)]
pub(crate) struct BatchWorkspace {
    work: Workspace<MAX_WIDTH>,
    /// The instruction set of the dispatch.
    pub(crate) arch: Arch,
}

impl BatchWorkspace {
    /// Buffers for a group of points of `system`.
    pub(crate) fn new(system: &FuzzySystem) -> Self {
        Self {
            work: Workspace::new(system),
            arch: Arch::new(),
        }
    }

    /// Evaluates the rows of `inputs` into the rows of `outputs` (shapes checked by the caller),
    /// with `point` evaluating one row (`Evaluator::eval`) for the rows outside whole groups and
    /// the groups with a refused row.
    pub(crate) fn run(
        &mut self,
        system: &FuzzySystem,
        options: &EvalOptions,
        inputs: &[f64],
        outputs: &mut [f64],
        point: impl FnMut(&[f64], &mut [f64]) -> Result<(), FuzzyError>,
    ) -> Result<(), FuzzyError> {
        let arch = self.arch;
        arch.dispatch(Batch {
            system,
            options,
            work: &mut self.work,
            inputs,
            outputs,
            point,
        })
    }
}

/// One batch, run by [`pulp::Arch::dispatch`] with the processor's instruction set.
struct Batch<'a, F> {
    system: &'a FuzzySystem,
    options: &'a EvalOptions,
    work: &'a mut Workspace<MAX_WIDTH>,
    inputs: &'a [f64],
    outputs: &'a mut [f64],
    point: F,
}

impl<F: FnMut(&[f64], &mut [f64]) -> Result<(), FuzzyError>> WithSimd for Batch<'_, F> {
    type Output = Result<(), FuzzyError>;

    #[inline(always)]
    fn with_simd<S: Simd>(mut self, simd: S) -> Self::Output {
        let width = S::F64_LANES;
        let rows = self.outputs.len() / self.system.outputs().len();
        let grouped = if width <= MAX_WIDTH {
            rows - rows % width
        } else {
            0
        };
        for first in (0..grouped).step_by(width) {
            if !self.group(simd, first) {
                self.rows(first, first + width)?;
            }
        }
        self.rows(grouped, rows)
    }
}

impl<F: FnMut(&[f64], &mut [f64]) -> Result<(), FuzzyError>> Batch<'_, F> {
    /// Rows `first..first + S::F64_LANES` in SIMD; `false` (nothing written) if one of them is
    /// refused.
    #[inline(always)]
    fn group<S: Simd>(&mut self, simd: S, first: usize) -> bool {
        let width = S::F64_LANES;
        let (n_in, n_out) = (self.system.inputs().len(), self.system.outputs().len());
        let rows = &self.inputs[first * n_in..(first + width) * n_in];
        for (lane, row) in rows.chunks_exact(n_in).enumerate() {
            for (i, &value) in row.iter().enumerate() {
                match load_input(self.system, self.options, i, value) {
                    Ok(x) => self.work.x[i][lane] = x,
                    Err(_) => return false,
                }
            }
        }
        let (c, methods) = (self.system.compiled(), self.system.methods());
        let mut slots = self.work.slots();
        if c.separable.is_some() {
            // A row beyond the separable form's limits is evaluated as `eval` evaluates it, by
            // the general kernel: the group's rows then go one at a time, each taking its own
            // path, so that a row's bits never depend on the rows beside it.
            if !kernel::separable_sums::<Pack<S>, MAX_WIDTH>(simd, c, &mut slots) {
                return false;
            }
        } else {
            kernel::fire::<Pack<S>, MAX_WIDTH>(simd, c, methods.and, methods.or, &mut slots);
            kernel::sums::<Pack<S>, MAX_WIDTH>(simd, c, &mut slots);
        }
        // Every output of the group is checked before the first is written; each replaces its
        // weighted sum.
        for (o, pair) in self.work.sums.chunks_exact_mut(2).enumerate() {
            let (weighted, total) = pair.split_at_mut(1);
            for (value, &total) in weighted[0][..width].iter_mut().zip(&total[0][..width]) {
                match output_value(self.system, self.options, o, *value, total) {
                    Ok(output) => *value = output,
                    Err(_) => return false,
                }
            }
        }
        let rows = &mut self.outputs[first * n_out..(first + width) * n_out];
        for (lane, row) in rows.chunks_exact_mut(n_out).enumerate() {
            for (out, pair) in row.iter_mut().zip(self.work.sums.chunks_exact(2)) {
                *out = pair[0][lane];
            }
        }
        true
    }

    /// Rows `first..last` one at a time; an error names its row.
    fn rows(&mut self, first: usize, last: usize) -> Result<(), FuzzyError> {
        let (n_in, n_out) = (self.system.inputs().len(), self.system.outputs().len());
        for row in first..last {
            let x = &self.inputs[row * n_in..(row + 1) * n_in];
            (self.point)(x, &mut self.outputs[row * n_out..(row + 1) * n_out]).map_err(|e| {
                FuzzyError::Batch {
                    row,
                    source: Box::new(e),
                }
            })?;
        }
        Ok(())
    }
}
