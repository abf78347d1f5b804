//! Allocation-free evaluation of a fuzzy system: singleton fuzzification, rule firing (product
//! or minimum AND, probabilistic sum or maximum OR, rule weights) and the centre-average
//! defuzzifier of eq 21.

use crate::batch::BatchWorkspace;
use crate::error::FuzzyError;
use crate::kernel::{self, Workspace};
use crate::options::{EvalOptions, OutOfRange, defuzzify, fired_output, load_input};
use crate::system::FuzzySystem;

/// Evaluates a [`FuzzySystem`] with its own scratch space: after [`Evaluator::new`], evaluating
/// allocates nothing. Clone it to evaluate on several threads.
///
/// One point at a time ([`eval`](Self::eval)) or many at once ([`eval_batch`](Self::eval_batch),
/// SIMD across points): both run the same kernel, so a point gives the same outputs either way.
///
/// ```
/// use fuzzy_sugeno::{paper_controller, Evaluator};
///
/// let mut controller = Evaluator::new(paper_controller());
/// let mut torques = [0.0; 2];
/// // [da1, da2, a1_dot, a2_dot] -> [tau1*, tau2*]
/// controller.eval(&[0.3, 0.0, 0.0, 0.0], &mut torques)?;
/// assert!((torques[0] + 80.0).abs() < 1e-12); // see the crate's tests for the hand calculation
/// assert_eq!(torques[1], 0.0);
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Evaluator {
    system: FuzzySystem,
    options: EvalOptions,
    /// The kernel's buffers for one point.
    one: Workspace<1>,
    /// The kernel's buffers for a group of points, and the instruction set.
    batch: BatchWorkspace,
    /// The first input evaluated outside its range under [`OutOfRange::AsGiven`].
    outside: Option<OutsideRange>,
}

/// An input evaluated outside its variable's range, as given ([`OutOfRange::AsGiven`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutsideRange {
    /// The input's index.
    pub index: usize,
    /// The value evaluated.
    pub value: f64,
}

impl Evaluator {
    /// An evaluator with the default [`EvalOptions`] (inputs as given, as MATLAB's `evalfis`
    /// evaluates them; middle of range when no rule fires).
    pub fn new(system: FuzzySystem) -> Self {
        let one = Workspace::new(&system);
        let batch = BatchWorkspace::new(&system);
        Self {
            system,
            options: EvalOptions::default(),
            one,
            batch,
            outside: None,
        }
    }

    /// An evaluator with the given options; fails if [`NoRuleFired::Values`](crate::NoRuleFired::Values) does not hold one
    /// finite value per output.
    pub fn with_options(system: FuzzySystem, options: EvalOptions) -> Result<Self, FuzzyError> {
        options.check(system.outputs().len())?;
        let mut evaluator = Self::new(system);
        evaluator.options = options;
        Ok(evaluator)
    }

    /// The system being evaluated.
    pub fn system(&self) -> &FuzzySystem {
        &self.system
    }

    /// The evaluation options.
    pub fn options(&self) -> &EvalOptions {
        &self.options
    }

    /// Evaluates the system: `inputs` has one value per input variable, `outputs` one slot per
    /// output variable. On error `outputs` is left untouched.
    pub fn eval(&mut self, inputs: &[f64], outputs: &mut [f64]) -> Result<(), FuzzyError> {
        if eval_point(&self.system, &self.options, &mut self.one, inputs, outputs)? {
            self.note_outside(inputs);
        }
        Ok(())
    }

    /// The first input this evaluator evaluated outside its range under
    /// [`OutOfRange::AsGiven`] (by [`eval`](Self::eval), [`eval_batch`](Self::eval_batch) or
    /// [`fire`](Self::fire)), if any: where MATLAB's `evalfis` warns that an input left its
    /// range. `None` under the other policies.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, Evaluator, OutsideRange};
    ///
    /// let mut controller = Evaluator::new(paper_controller());
    /// let mut torques = [0.0; 2];
    /// controller.eval(&[0.1, 0.0, 0.0, 0.0], &mut torques)?;
    /// assert_eq!(controller.first_outside_range(), None);
    /// // da1 = -0.414 is outside [-0.3, 0.3]: evaluated as given, as MATLAB does.
    /// controller.eval(&[-0.414, -0.263, 0.904, 0.246], &mut torques)?;
    /// assert_eq!(controller.first_outside_range(), Some(OutsideRange { index: 0, value: -0.414 }));
    /// assert!((torques[0] - 75.93).abs() < 0.01);
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn first_outside_range(&self) -> Option<OutsideRange> {
        self.outside
    }

    /// Records the first input of `rows` (rows of one value per input) outside its range, under
    /// [`OutOfRange::AsGiven`], until one is found.
    fn note_outside(&mut self, rows: &[f64]) {
        if self.outside.is_some() || self.options.out_of_range != OutOfRange::AsGiven {
            return;
        }
        let variables = self.system.inputs();
        self.outside = rows
            .iter()
            .zip(variables.iter().cycle())
            .enumerate()
            .find(|(_, (v, var))| **v < var.range[0] || **v > var.range[1])
            .map(|(k, (&value, _))| OutsideRange {
                index: k % variables.len(),
                value,
            });
    }

    /// Evaluates many input vectors: `inputs` holds rows of one value per input variable,
    /// `outputs` the matching rows of one slot per output, and row `i` of `outputs` gets what
    /// [`eval`](Self::eval) gives for row `i` of `inputs`, bit for bit.
    ///
    /// The rows are evaluated `W` at a time, SIMD across rows, `W` the number of `f64` lanes of
    /// the widest instruction set of the processor (8 with AVX-512, 4 with AVX2, chosen at run
    /// time); a group with a refused row, and the rows after the last whole group, are evaluated
    /// one at a time. An error names the failing row; the rows before it hold their results, that
    /// row and the ones after it are left untouched.
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, Evaluator};
    ///
    /// let mut controller = Evaluator::new(paper_controller());
    /// let points: Vec<f64> = (0..4 * 13).map(|k| 0.1 * (k as f64).sin()).collect();
    /// let mut torques = vec![0.0; 2 * 13];
    /// controller.eval_batch(&points, &mut torques)?;
    /// let mut one = [0.0; 2];
    /// controller.eval(&points[4 * 12..], &mut one)?;
    /// assert_eq!(&torques[2 * 12..], one.as_slice());
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn eval_batch(&mut self, inputs: &[f64], outputs: &mut [f64]) -> Result<(), FuzzyError> {
        let (n_in, n_out) = (self.system.inputs().len(), self.system.outputs().len());
        let rows = inputs.len() / n_in;
        if rows * n_in != inputs.len() {
            return Err(FuzzyError::BatchLength {
                len: inputs.len(),
                inputs: n_in,
            });
        }
        if outputs.len() != rows * n_out {
            return Err(FuzzyError::OutputCount {
                expected: rows * n_out,
                found: outputs.len(),
            });
        }
        let (system, options, one) = (&self.system, &self.options, &mut self.one);
        let point = |x: &[f64], y: &mut [f64]| eval_point(system, options, one, x, y).map(|_| ());
        let result = self.batch.run(system, options, inputs, outputs, point);
        // The rows evaluated: all of them, or those before the failing one.
        let done = match &result {
            Ok(()) => rows,
            Err(FuzzyError::Batch { row, .. }) => *row,
            Err(_) => 0,
        };
        self.note_outside(&inputs[..done * n_in]);
        result
    }

    /// Computes and returns every rule's firing strength at `inputs` (antecedents combined by
    /// the rule's AND/OR, times the rule's weight), in rule order.
    pub fn fire(&mut self, inputs: &[f64]) -> Result<&[f64], FuzzyError> {
        if fire_point(&self.system, &self.options, &mut self.one, inputs)? {
            self.note_outside(inputs);
        }
        Ok(self.firing_strengths())
    }

    /// The firing strengths computed by the last [`fire`](Self::fire) (zeros before the first).
    /// [`eval`](Self::eval) computes them too, except for a system whose rules are a complete
    /// grid with a separable form (such as the paper's controller), which it evaluates without
    /// them: call `fire` to read the strengths at a point.
    pub fn firing_strengths(&self) -> &[f64] {
        let c = self.system.compiled();
        self.one.values[c.strength_base..c.slot_count].as_flattened()
    }
}

/// Checks one point's inputs, applies the range policy and fires the rules; whether an input
/// lies outside its range.
#[inline]
fn fire_point(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
) -> Result<bool, FuzzyError> {
    let loaded = load_inputs(system, options, work, inputs)?;
    let methods = system.methods();
    let mut slots = work.slots_at(loaded.kernel_inputs(inputs));
    kernel::fire::<f64, 1>((), system.compiled(), methods.and, methods.or, &mut slots);
    Ok(loaded.outside)
}

/// What [`load_inputs`] found.
struct Loaded {
    /// Whether an input lies outside its range (as given).
    outside: bool,
    /// Whether the inputs were clamped into the workspace's `x` ([`OutOfRange::Clamp`] and an
    /// input outside its range); else the kernel evaluates them as given.
    clamped: bool,
}

impl Loaded {
    /// The inputs the kernel evaluates: `None` (the workspace's clamped `x`) or `inputs`.
    #[inline(always)]
    fn kernel_inputs<'a>(&self, inputs: &'a [f64]) -> Option<&'a [[f64; 1]]> {
        (!self.clamped).then_some(inputs.as_chunks::<1>().0)
    }
}

/// Checks one point's inputs against the range policy and, where it clamps them, writes them
/// clamped into `work.x`.
#[inline(always)]
fn load_inputs(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
) -> Result<Loaded, FuzzyError> {
    let variables = system.inputs();
    if inputs.len() != variables.len() {
        return Err(FuzzyError::InputCount {
            expected: variables.len(),
            found: inputs.len(),
        });
    }
    // Every input within its range, and so finite: evaluated as given under every policy.
    let mut inside = true;
    for (&value, variable) in inputs.iter().zip(variables) {
        let [min, max] = variable.range;
        inside &= (value >= min) & (value <= max);
    }
    if inside {
        return Ok(Loaded {
            outside: false,
            clamped: false,
        });
    }
    let finite = inputs.iter().all(|value| value.is_finite());
    let outside = (inputs.iter().zip(variables))
        .any(|(&value, variable)| value < variable.range[0] || value > variable.range[1]);
    let clamped = options.out_of_range == OutOfRange::Clamp;
    if finite && !(outside && options.out_of_range == OutOfRange::Error) {
        if clamped {
            for ((slot, &value), variable) in work.x.iter_mut().zip(inputs).zip(variables) {
                let [min, max] = variable.range;
                slot[0] = value.clamp(min, max);
            }
        }
        return Ok(Loaded { outside, clamped });
    }
    // An input refused: the first, as `load_input` words it.
    for (index, (slot, &value)) in work.x.iter_mut().zip(inputs).enumerate() {
        slot[0] = load_input(system, options, index, value)?;
    }
    Ok(Loaded { outside, clamped })
}

/// [`Evaluator::eval`] with the evaluator's parts; whether an input lies outside its range.
#[inline(always)]
fn eval_point(
    system: &FuzzySystem,
    options: &EvalOptions,
    work: &mut Workspace<1>,
    inputs: &[f64],
    outputs: &mut [f64],
) -> Result<bool, FuzzyError> {
    let n_out = system.outputs().len();
    if outputs.len() != n_out {
        return Err(FuzzyError::OutputCount {
            expected: n_out,
            found: outputs.len(),
        });
    }
    let loaded = load_inputs(system, options, work, inputs)?;
    let c = system.compiled();
    let mut slots = work.slots_at(loaded.kernel_inputs(inputs));
    if !kernel::separable_sums::<f64, 1>((), c, &mut slots) {
        let methods = system.methods();
        kernel::fire::<f64, 1>((), c, methods.and, methods.or, &mut slots);
        kernel::sums::<f64, 1>((), c, &mut slots);
    }
    // Every output is checked before the first is written; each replaces its weighted sum. All
    // defuzzified first, the policies applied only if a total is not positive or a value not
    // finite.
    let method = system.methods().defuzzification;
    let mut fired = true;
    for pair in work.sums.chunks_exact_mut(2) {
        let (value, total) = (defuzzify(method, pair[0][0], pair[1][0]), pair[1][0]);
        fired &= (total > 0.0) & value.is_finite();
        pair[0][0] = value;
    }
    if !fired {
        for (o, pair) in work.sums.chunks_exact_mut(2).enumerate() {
            pair[0][0] = fired_output(system, options, o, pair[0][0], pair[1][0])?;
        }
    }
    for (out, pair) in outputs.iter_mut().zip(work.sums.chunks_exact(2)) {
        *out = pair[0][0];
    }
    Ok(loaded.outside)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every instruction set gives every point the same bits, in a batch and alone (see
    /// [`lane_math::instruction_sets`]), inputs inside and outside their ranges.
    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        let mut evaluator = Evaluator::new(crate::paper_controller());
        let n_in = evaluator.system.inputs().len();
        let n_out = evaluator.system.outputs().len();
        let points = 29;
        let inputs: Vec<f64> = (0..n_in * points)
            .map(|i| 3.0 * ((i as f64) * 0.37).sin())
            .collect();
        let mut alone = vec![0.0; n_out * points];
        for (x, y) in inputs.chunks_exact(n_in).zip(alone.chunks_exact_mut(n_out)) {
            evaluator.eval(x, y).unwrap();
        }
        let bits = |x: &[f64]| x.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for arch in lane_math::instruction_sets() {
            evaluator.batch.arch = arch;
            let mut batch = vec![0.0; n_out * points];
            evaluator.eval_batch(&inputs, &mut batch).unwrap();
            assert_eq!(bits(&batch), bits(&alone), "{arch:?}");
        }
    }
}
