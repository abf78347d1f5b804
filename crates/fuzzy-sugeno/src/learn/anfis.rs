//! ANFIS training (Jang, "ANFIS: Adaptive-Network-Based Fuzzy Inference System", IEEE SMC 23(3),
//! 1993): the hybrid rule of section IV-B in batch ("off-line") form.
//!
//! Each epoch, with the premise parameters fixed, the output is linear in the consequent
//! parameters (eq 14), so the forward pass fills the least-squares problem `A theta = y`
//! (eq 15) and solves it; the backward pass then propagates `E = sum_p (y_p - o_p)^2` (eq 3) back
//! to the premise parameters (eqs 5-8) and takes a gradient step of fixed length `kappa`
//! (eqs 9-10): `delta alpha = -kappa g / |g|`. `kappa` grows 10 % after four consecutive
//! decreases of the training error and shrinks 10 % after two consecutive up-down alternations
//! (section IV-C). With check data, the system of the epoch with the smallest check error is
//! kept; without, the one with the smallest training error.
//!
//! Everything is sized in [`Anfis::new`]; an epoch ([`Anfis::epoch`]) allocates nothing.

use super::data::TrainingData;
use super::premise::{gradient, repair};
use crate::compiled_mf::CompiledMf;
use crate::membership::MembershipFn;
use crate::system::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySystem, OutputFn, affine,
};
use crate::{ConsequentParameter, FuzzyError, LearningProblem};
use lane_math::dense::{LeastSquares, LeastSquaresError};

/// The most epochs one training may run.
const MAX_EPOCHS: usize = 1_000_000;
/// The largest least-squares matrix, rows (samples and ridge rows) times unknowns (8 bytes
/// each).
const MAX_LEAST_SQUARES_ENTRIES: usize = 25_000_000;
/// The most multiply-adds of one least-squares solve, rows times unknowns squared (about 15 s:
/// 3,072 unknowns took 12 s on the development machine).
const MAX_LEAST_SQUARES_WORK: usize = 40_000_000_000;
/// The most multiply-adds of a whole training, epochs times an epoch's least-squares solve and
/// evaluation of the rows (about six minutes: 25 times [`MAX_LEAST_SQUARES_WORK`]).
const MAX_TRAINING_WORK: usize = 1_000_000_000_000;
/// The cost of evaluating one antecedent of one rule at one row, in the least-squares solve's
/// multiply-adds (a membership degree and its share of the rule's product and of the gradient:
/// about 10 ns against 0.3 ns, measured on `hrm fis train` with a million check rows).
const EVALUATION_COST: usize = 32;
/// The largest ridge, relative to the mean squared column norm: beyond it the consequents are
/// all but zero (and `1e308` overflowed the regularised problem).
const MAX_RIDGE: f64 = 1e6;
/// Marks a "don't care" antecedent in the rule table.
const ANY: u32 = u32::MAX;

/// The settings of an ANFIS training.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnfisOptions {
    /// Epochs to run (at least 1, at most 1 000 000).
    pub epochs: usize,
    /// The initial step size `kappa`: the length of each premise step in parameter space
    /// (MATLAB's default, 0.01). Zero trains the consequents only.
    pub initial_step: f64,
    /// The factor applied to `kappa` after four consecutive decreases of the error (1.1).
    pub step_increase: f64,
    /// The factor applied to `kappa` after two consecutive up-down alternations (0.9).
    pub step_decrease: f64,
    /// The least-squares ridge, relative: `lambda = ridge * |A|_F^2 / unknowns`. Zero is plain
    /// least squares, which refuses data that do not determine every consequent parameter (a
    /// rule no sample fires, fewer samples than unknowns); the default `1e-10` shrinks such
    /// parameters to zero and changes well-determined ones by about that relative amount.
    pub ridge: f64,
    /// Stop once the training RMSE reaches this value (0: run every epoch).
    pub target_rmse: f64,
}

impl Default for AnfisOptions {
    fn default() -> Self {
        Self {
            epochs: 100,
            initial_step: 0.01,
            step_increase: 1.1,
            step_decrease: 0.9,
            ridge: 1e-10,
            target_rmse: 0.0,
        }
    }
}

impl AnfisOptions {
    /// Checks the options as [`Anfis::new`] does, before any data are read or systems built.
    pub fn validate(&self) -> Result<(), FuzzyError> {
        if !(1..=MAX_EPOCHS).contains(&self.epochs) {
            return Err(LearningProblem::CountOutOfRange {
                name: "epochs",
                count: self.epochs,
                max: MAX_EPOCHS,
            }
            .into());
        }
        let finite_at_least = |name: &'static str, value: f64, min: f64| {
            if value.is_finite() && value >= min {
                Ok(())
            } else {
                Err(LearningProblem::BelowMinimum { name, min, value })
            }
        };
        finite_at_least("the initial step", self.initial_step, 0.0)?;
        finite_at_least("the step increase", self.step_increase, 1.0)?;
        finite_at_least("the ridge", self.ridge, 0.0)?;
        if self.ridge > MAX_RIDGE {
            return Err(LearningProblem::AboveMaximum {
                name: "the ridge",
                max: MAX_RIDGE,
                value: self.ridge,
            }
            .into());
        }
        finite_at_least("the target RMSE", self.target_rmse, 0.0)?;
        if !(self.step_decrease > 0.0 && self.step_decrease <= 1.0) {
            return Err(LearningProblem::OutsideUnitInterval {
                name: "the step decrease",
                value: self.step_decrease,
            }
            .into());
        }
        Ok(())
    }
}

/// The errors of one epoch, measured on the system as it was at the start of the epoch's
/// gradient step (premises of the epoch, consequents just fitted).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochReport {
    /// 1-based.
    pub epoch: usize,
    /// Root-mean-square error on the training data.
    pub training_rmse: f64,
    /// Root-mean-square error on the check data, if any.
    pub check_rmse: Option<f64>,
    /// The step size `kappa` used for this epoch's premise step.
    pub step: f64,
}

/// The result of [`anfis`]: the kept system and every epoch's errors.
#[derive(Debug, Clone, PartialEq)]
pub struct Trained {
    /// The system of the epoch with the smallest check error (or training error without check
    /// data).
    pub system: FuzzySystem,
    /// The epoch `system` comes from (1-based).
    pub best_epoch: usize,
    /// One report per epoch run.
    pub history: Vec<EpochReport>,
}

/// Trains `system` on output `output` of `train` for `options.epochs` epochs (fewer if the
/// target RMSE is reached) and returns the kept system; see [`Anfis`].
pub fn anfis(
    system: FuzzySystem,
    train: &TrainingData,
    check: Option<&TrainingData>,
    output: usize,
    options: &AnfisOptions,
) -> Result<Trained, FuzzyError> {
    let mut trainer = Anfis::new(system, train, check, output, *options)?;
    let mut history = Vec::with_capacity(options.epochs);
    while history.len() < options.epochs {
        let report = trainer.epoch()?;
        history.push(report);
        if report.training_rmse <= options.target_rmse {
            break;
        }
    }
    Ok(Trained {
        system: trainer.best_system()?,
        best_epoch: trainer.best_epoch(),
        history,
    })
}

/// An ANFIS trainer: the system being trained in flat form, the data, and every buffer an epoch
/// needs.
///
/// The system must have one output, product AND, the weighted-average defuzzifier and AND
/// rules whose antecedents are sets or "don't care" (no negation), each rule concluding on a
/// constant or linear term (terms may be shared by rules); every membership type trains (a
/// `constant` degree stays fixed). Inputs are taken as given, even outside their ranges, as
/// MATLAB's `anfis` and the default [`Evaluator`](crate::Evaluator) take them, so the errors
/// reported are the evaluator's; a sample on
/// which no rule fires is predicted as the middle of the output range and does not move any
/// parameter.
///
/// ```
/// use fuzzy_sugeno::learn::{Anfis, AnfisOptions, genfis_grid, GridPartition, TrainingData};
///
/// let values: Vec<f64> = (0..50).flat_map(|k| {
///     let x = k as f64 / 49.0;
///     [x, (3.0 * x).sin()]
/// }).collect();
/// let data = TrainingData::new(1, 1, values)?;
/// let mut trainer = Anfis::new(genfis_grid(&data, 0, &GridPartition::default())?, &data, None, 0, AnfisOptions::default())?;
/// let first = trainer.epoch()?;
/// for _ in 0..30 {
///     trainer.epoch()?;
/// }
/// assert!(trainer.epoch()?.training_rmse < first.training_rmse);
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Anfis {
    template: FuzzySystem,
    options: AnfisOptions,
    net: Network,
    buf: Buffers,
    /// Every input set, inputs in order (the premise parameters).
    mfs: Vec<MembershipFn>,
    /// Offset of each set's parameters in `grad`.
    mf_offset: Vec<usize>,
    /// The width of each set's input range (for [`repair`]).
    mf_span: Vec<f64>,
    /// Offset of each output term's parameters in `theta`, and whether it is linear.
    terms: Vec<(usize, bool)>,
    train_x: Vec<f64>,
    train_y: Vec<f64>,
    check_x: Vec<f64>,
    check_y: Vec<f64>,
    has_check: bool,
    least_squares: LeastSquares,
    /// `dE / d alpha` for every premise parameter.
    grad: Vec<f64>,
    best_mfs: Vec<MembershipFn>,
    best_theta: Vec<f64>,
    best_error: f64,
    best_epoch: usize,
    step: f64,
    /// The last five training errors, oldest first (NaN before there are five).
    recent: [f64; 5],
    epoch: usize,
}

impl Anfis {
    /// Checks the system, the data and the options and sizes every buffer.
    pub fn new(
        system: FuzzySystem,
        train: &TrainingData,
        check: Option<&TrainingData>,
        output: usize,
        options: AnfisOptions,
    ) -> Result<Self, FuzzyError> {
        options.validate()?;
        check_structure(&system)?;
        let n_inputs = system.inputs().len();
        for (what, data) in [("training", Some(train)), ("check", check)] {
            let Some(data) = data else { continue };
            if data.n_inputs() != n_inputs {
                return Err(LearningProblem::DataInputs {
                    data: what,
                    expected: n_inputs,
                    found: data.n_inputs(),
                }
                .into());
            }
            data.check_output(output)?;
        }
        let mut mfs = Vec::new();
        let mut mf_input = Vec::new();
        let mut mf_offset = Vec::new();
        let mut mf_span = Vec::new();
        let mut set_start = Vec::with_capacity(n_inputs);
        let mut n_premise = 0;
        for (i, input) in system.inputs().iter().enumerate() {
            set_start.push(mfs.len());
            for set in &input.sets {
                mfs.push(set.membership);
                mf_input.push(i);
                mf_offset.push(n_premise);
                mf_span.push(input.range[1] - input.range[0]);
                n_premise += set.membership.param_array().1;
            }
        }
        let compiled = mfs
            .iter()
            .map(MembershipFn::compile)
            .collect::<Result<Vec<_>, _>>()?;
        let output_variable = &system.outputs()[0];
        let mut terms = Vec::with_capacity(output_variable.terms.len());
        let mut theta = Vec::new();
        for term in &output_variable.terms {
            terms.push((
                theta.len(),
                matches!(term.function, OutputFn::Linear { .. }),
            ));
            match &term.function {
                OutputFn::Constant(c) => theta.push(*c),
                OutputFn::Linear {
                    coefficients,
                    constant,
                } => {
                    theta.extend_from_slice(coefficients);
                    theta.push(*constant);
                }
            }
        }
        let rules = system.rules();
        let mut antecedents = Vec::with_capacity(rules.len() * n_inputs);
        let mut rule_theta = Vec::with_capacity(rules.len());
        let mut rule_linear = Vec::with_capacity(rules.len());
        for rule in rules {
            for (i, antecedent) in rule.antecedents.iter().enumerate() {
                antecedents.push(match *antecedent {
                    Antecedent::Is(k) => {
                        u32::try_from(set_start[i] + k).map_err(|_| LearningProblem::TooManySets)?
                    }
                    _ => ANY,
                });
            }
            let (offset, linear) = terms[rule.consequents[0].unwrap_or_default()];
            rule_theta.push(offset);
            rule_linear.push(linear);
        }
        let rows = train.rows();
        let unknowns = theta.len();
        // The solver's matrix holds a ridge row per unknown below the samples' rows.
        let entries = rows.saturating_add(unknowns).saturating_mul(unknowns);
        if entries > MAX_LEAST_SQUARES_ENTRIES {
            return Err(LearningProblem::LeastSquaresTooLarge {
                samples: rows,
                unknowns,
                limit: MAX_LEAST_SQUARES_ENTRIES,
            }
            .into());
        }
        if entries.saturating_mul(unknowns) > MAX_LEAST_SQUARES_WORK {
            return Err(LearningProblem::LeastSquaresTooSlow {
                samples: rows,
                unknowns,
                limit: MAX_LEAST_SQUARES_WORK,
            }
            .into());
        }
        // An epoch evaluates every training and check row through every rule (and takes the
        // premise gradient over the training rows) besides its least-squares solve.
        let evaluated = rows.saturating_add(check.map_or(0, TrainingData::rows));
        let evaluation = evaluated
            .saturating_mul(rules.len())
            .saturating_mul(n_inputs + 1)
            .saturating_mul(EVALUATION_COST);
        let per_epoch = entries.saturating_mul(unknowns).saturating_add(evaluation);
        if per_epoch.saturating_mul(options.epochs) > MAX_TRAINING_WORK {
            return Err(LearningProblem::TrainingTooSlow {
                epochs: options.epochs,
                per_epoch,
                limit: MAX_TRAINING_WORK,
            }
            .into());
        }
        let columns = |data: &TrainingData| {
            let mut x = Vec::with_capacity(data.rows() * n_inputs);
            let mut y = Vec::with_capacity(data.rows());
            for r in 0..data.rows() {
                x.extend_from_slice(data.inputs(r));
                y.push(data.target(r, output));
            }
            (x, y)
        };
        let (train_x, train_y) = columns(train);
        let (check_x, check_y) = check.map(columns).unwrap_or_default();
        let [lo, hi] = output_variable.range;
        let (n_mf, n_rules) = (mfs.len(), rules.len());
        let net = Network {
            n_inputs,
            compiled,
            mf_input,
            antecedents,
            rule_weight: rules.iter().map(|r| r.weight).collect(),
            rule_theta,
            rule_linear,
            theta,
            fallback: 0.5 * (lo + hi),
        };
        let buf = Buffers {
            mu: vec![0.0; n_mf],
            dmu: vec![[0.0; 4]; n_mf],
            strengths: vec![0.0; n_rules],
            rule_outputs: vec![0.0; n_rules],
            de_dmu: vec![0.0; n_mf],
        };
        Ok(Self {
            options,
            best_theta: net.theta.clone(),
            net,
            buf,
            best_mfs: mfs.clone(),
            mfs,
            mf_offset,
            mf_span,
            terms,
            train_x,
            train_y,
            check_x,
            check_y,
            has_check: check.is_some(),
            least_squares: LeastSquares::new(rows, unknowns),
            grad: vec![0.0; n_premise],
            best_error: f64::INFINITY,
            best_epoch: 0,
            step: options.initial_step,
            recent: [f64::NAN; 5],
            epoch: 0,
            template: system,
        })
    }

    /// Runs one epoch: fits the consequents by least squares, measures the errors, keeps the
    /// system if it is the best so far, adapts the step size and takes the premise step.
    /// Allocates nothing.
    pub fn epoch(&mut self) -> Result<EpochReport, FuzzyError> {
        self.fit_consequents()?;
        let training_sse = self.backward();
        let training_rmse = (training_sse / self.train_y.len() as f64).sqrt();
        let check_rmse = self.has_check.then(|| {
            let n = self.net.n_inputs;
            let sse = self
                .check_x
                .chunks_exact(n)
                .zip(&self.check_y)
                .fold(0.0, |sse, (x, y)| {
                    let e = self.net.forward(x, &mut self.buf).0 - y;
                    sse + e * e
                });
            (sse / self.check_y.len() as f64).sqrt()
        });
        self.epoch += 1;
        let kept = check_rmse.unwrap_or(training_rmse);
        if kept < self.best_error {
            self.best_error = kept;
            self.best_epoch = self.epoch;
            self.best_mfs.copy_from_slice(&self.mfs);
            self.best_theta.copy_from_slice(&self.net.theta);
        }
        self.adapt_step(training_rmse);
        let report = EpochReport {
            epoch: self.epoch,
            training_rmse,
            check_rmse,
            step: self.step,
        };
        self.premise_step()?;
        Ok(report)
    }

    /// The kept system (see [`Trained::system`]); before the first epoch, the initial one.
    pub fn best_system(&self) -> Result<FuzzySystem, FuzzyError> {
        self.system_with(&self.best_mfs, &self.best_theta)
    }

    /// The epoch [`best_system`](Self::best_system) comes from (0 before the first epoch).
    pub fn best_epoch(&self) -> usize {
        self.best_epoch
    }

    /// The system with the current premises and the consequents fitted to them by least
    /// squares (what `genfis` returns).
    pub(crate) fn fitted_system(mut self) -> Result<FuzzySystem, FuzzyError> {
        self.fit_consequents()?;
        self.system_with(&self.mfs, &self.net.theta)
    }

    /// The forward pass over the training data, filling and solving eq 15 for `theta`.
    fn fit_consequents(&mut self) -> Result<(), FuzzyError> {
        let n = self.net.n_inputs;
        for (r, (x, &y)) in self.train_x.chunks_exact(n).zip(&self.train_y).enumerate() {
            let total = self.net.fire(x, &mut self.buf);
            if total <= 0.0 {
                self.least_squares.clear_row(r, 0.0);
                continue;
            }
            self.least_squares.clear_row(r, y);
            for (rule, &w) in self.buf.strengths.iter().enumerate() {
                let normalized = w / total;
                let offset = self.net.rule_theta[rule];
                if self.net.rule_linear[rule] {
                    for (i, xi) in x.iter().enumerate() {
                        self.least_squares.add(r, offset + i, normalized * xi);
                    }
                    self.least_squares.add(r, offset + n, normalized);
                } else {
                    self.least_squares.add(r, offset, normalized);
                }
            }
        }
        match self.least_squares.solve(self.options.ridge) {
            Ok(solution) => {
                self.net.theta.copy_from_slice(solution);
                Ok(())
            }
            Err(LeastSquaresError::RankDeficient { column }) => {
                Err(self.rank_deficiency(column).into())
            }
            // `NonFinite`, and any failure a later version adds: the fit came out non-finite.
            Err(_) => Err(LearningProblem::NonFiniteLeastSquares.into()),
        }
    }

    /// Names the consequent parameter that the data do not determine.
    fn rank_deficiency(&self, column: usize) -> LearningProblem {
        let term = self
            .terms
            .iter()
            .rposition(|&(offset, _)| offset <= column)
            .unwrap_or(0);
        let (offset, linear) = self.terms[term];
        let n = self.net.n_inputs;
        let parameter = match column - offset {
            k if !linear || k == n => ConsequentParameter::Constant,
            k => ConsequentParameter::Coefficient {
                input: k,
                name: self.template.inputs()[k].name.clone(),
            },
        };
        LearningProblem::RankDeficient {
            term,
            name: self.template.outputs()[0].terms[term].name.clone(),
            parameter,
        }
    }

    /// The backward pass: returns the training SSE and accumulates `dE / d alpha` into `grad`.
    fn backward(&mut self) -> f64 {
        let n = self.net.n_inputs;
        let (net, buf) = (&self.net, &mut self.buf);
        self.grad.fill(0.0);
        let mut sse = 0.0;
        for (x, &target) in self.train_x.chunks_exact(n).zip(&self.train_y) {
            let (y, total) = net.forward(x, buf);
            let e = y - target;
            sse += e * e;
            if total <= 0.0 {
                continue;
            }
            buf.de_dmu.fill(0.0);
            for (rule, &f) in buf.rule_outputs.iter().enumerate() {
                // dE/dw_r = 2 e (f_r - y) / W: eqs 5-8 through the normalising layer 3.
                let de_dw = 2.0 * e * (f - y) / total;
                let row = &net.antecedents[rule * n..(rule + 1) * n];
                for (i, &a) in row.iter().enumerate() {
                    if a == ANY {
                        continue;
                    }
                    // dw_r/dmu: the rule's weight times its other antecedents' degrees.
                    let others = row
                        .iter()
                        .enumerate()
                        .filter(|&(j, &b)| j != i && b != ANY)
                        .fold(net.rule_weight[rule], |acc, (_, &b)| {
                            acc * buf.mu[b as usize]
                        });
                    buf.de_dmu[a as usize] += de_dw * others;
                }
            }
            for (m, mf) in self.mfs.iter().enumerate() {
                if buf.de_dmu[m] == 0.0 {
                    continue;
                }
                gradient(mf, x[net.mf_input[m]], buf.mu[m], &mut buf.dmu[m]);
                let offset = self.mf_offset[m];
                let count = mf.param_array().1;
                for (g, d) in self.grad[offset..offset + count]
                    .iter_mut()
                    .zip(&buf.dmu[m])
                {
                    *g += buf.de_dmu[m] * d;
                }
            }
        }
        sse
    }

    /// Jang's heuristic rules 1 and 2 (section IV-C) on the last five training errors.
    fn adapt_step(&mut self, error: f64) {
        self.recent.rotate_left(1);
        self.recent[4] = error;
        let e = self.recent;
        if e.iter().any(|v| v.is_nan()) {
            return;
        }
        let down = |k: usize| e[k + 1] < e[k];
        let up = |k: usize| e[k + 1] > e[k];
        if (0..4).all(down) {
            self.step *= self.options.step_increase;
        } else if up(0) && down(1) && up(2) && down(3) {
            self.step *= self.options.step_decrease;
        }
    }

    /// `alpha -= kappa g / |g|` (eqs 9-10), then each set is repaired and recompiled.
    fn premise_step(&mut self) -> Result<(), FuzzyError> {
        let norm = self.grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        if norm == 0.0 || self.step == 0.0 {
            return Ok(());
        }
        if !norm.is_finite() {
            return Err(LearningProblem::NonFiniteGradient { epoch: self.epoch }.into());
        }
        let eta = self.step / norm;
        for (m, mf) in self.mfs.iter_mut().enumerate() {
            let (mut params, count) = mf.param_array();
            let offset = self.mf_offset[m];
            for (p, g) in params[..count].iter_mut().zip(&self.grad[offset..]) {
                *p -= eta * g;
            }
            if !params[..count].iter().all(|p| p.is_finite()) {
                return Err(LearningProblem::StepOverflow {
                    epoch: self.epoch,
                    step: self.step,
                }
                .into());
            }
            let before = *mf;
            *mf = mf.with_params(&params[..count]);
            repair(mf, &before, self.mf_span[m]);
            self.net.compiled[m] = mf.compile()?;
        }
        Ok(())
    }

    /// The template with the given sets and consequent parameters.
    fn system_with(&self, mfs: &[MembershipFn], theta: &[f64]) -> Result<FuzzySystem, FuzzyError> {
        let n = self.net.n_inputs;
        let mut inputs = self.template.inputs().to_vec();
        for (set, mf) in inputs.iter_mut().flat_map(|v| v.sets.iter_mut()).zip(mfs) {
            set.membership = *mf;
        }
        let mut outputs = self.template.outputs().to_vec();
        for (term, &(offset, linear)) in outputs[0].terms.iter_mut().zip(&self.terms) {
            term.function = if linear {
                OutputFn::Linear {
                    coefficients: theta[offset..offset + n].to_vec(),
                    constant: theta[offset + n],
                }
            } else {
                OutputFn::Constant(theta[offset])
            };
        }
        FuzzySystem::new(
            self.template.name().to_string(),
            inputs,
            outputs,
            self.template.rules().to_vec(),
            self.template.methods(),
        )
    }
}

/// The adaptive network (Jang's Figure 2(b)) in flat form: what a forward pass reads.
#[derive(Debug, Clone)]
struct Network {
    n_inputs: usize,
    compiled: Vec<CompiledMf>,
    mf_input: Vec<usize>,
    /// Rule-major, one entry per input: the index in `compiled`, or [`ANY`].
    antecedents: Vec<u32>,
    rule_weight: Vec<f64>,
    /// Offset of each rule's consequent parameters in `theta`.
    rule_theta: Vec<usize>,
    /// Whether each rule's consequent is linear (`n_inputs + 1` parameters) or constant (1).
    rule_linear: Vec<bool>,
    /// The consequent parameters, term by term.
    theta: Vec<f64>,
    /// The output when no rule fires.
    fallback: f64,
}

/// Per-sample values, sized once.
#[derive(Debug, Clone)]
struct Buffers {
    /// Layer 1: every set's degree.
    mu: Vec<f64>,
    /// Every set's `d mu / d alpha`.
    dmu: Vec<[f64; 4]>,
    /// Layer 2: every rule's strength `w_r`.
    strengths: Vec<f64>,
    /// Every rule's consequent value `f_r`.
    rule_outputs: Vec<f64>,
    /// `dE / d mu` of every set.
    de_dmu: Vec<f64>,
}

impl Network {
    /// Layers 1-2: degrees into `buf.mu`, strengths into `buf.strengths`; returns their sum.
    fn fire(&self, x: &[f64], buf: &mut Buffers) -> f64 {
        for ((mu, mf), &i) in buf.mu.iter_mut().zip(&self.compiled).zip(&self.mf_input) {
            *mu = mf.eval(x[i]);
        }
        let n = self.n_inputs;
        let mut total = 0.0;
        for (rule, strength) in buf.strengths.iter_mut().enumerate() {
            let row = &self.antecedents[rule * n..(rule + 1) * n];
            *strength = row
                .iter()
                .filter(|&&a| a != ANY)
                .fold(self.rule_weight[rule], |w, &a| w * buf.mu[a as usize]);
            total += *strength;
        }
        total
    }

    /// Layers 1-5: returns the output and the total strength; `buf.rule_outputs` gets each
    /// rule's `f_r`.
    fn forward(&self, x: &[f64], buf: &mut Buffers) -> (f64, f64) {
        let n = self.n_inputs;
        let total = self.fire(x, buf);
        let mut weighted = 0.0;
        for (rule, (f, &w)) in buf.rule_outputs.iter_mut().zip(&buf.strengths).enumerate() {
            let p = &self.theta[self.rule_theta[rule]..];
            *f = if self.rule_linear[rule] {
                affine(&p[..n], p[n], x)
            } else {
                p[0]
            };
            weighted += w * *f;
        }
        if total > 0.0 {
            (weighted / total, total)
        } else {
            (self.fallback, total)
        }
    }
}

/// Refuses a system ANFIS cannot train, saying why.
fn check_structure(system: &FuzzySystem) -> Result<(), FuzzyError> {
    if system.outputs().len() != 1 {
        return Err(LearningProblem::NotSingleOutput {
            outputs: system.outputs().len(),
        }
        .into());
    }
    let methods = system.methods();
    if methods.and != AndMethod::Product {
        return Err(LearningProblem::NotProductAnd.into());
    }
    if methods.defuzzification != Defuzzification::WeightedAverage {
        return Err(LearningProblem::NotWeightedAverage.into());
    }
    if system.rules().is_empty() {
        return Err(LearningProblem::NoRules.into());
    }
    for (r, rule) in system.rules().iter().enumerate() {
        if rule.connective != Connective::And {
            return Err(LearningProblem::OrRule { rule: r }.into());
        }
        if rule
            .antecedents
            .iter()
            .any(|a| matches!(a, Antecedent::IsNot(_)))
        {
            return Err(LearningProblem::NegatedAntecedent { rule: r }.into());
        }
        if rule.consequents[0].is_none() {
            return Err(LearningProblem::NoConsequent { rule: r }.into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MembershipFn as Mf;
    use lane_math::Classify;

    /// Two inputs with sets of several types (pimf and zmf among them), a shared term, a
    /// don't-care and a rule weight.
    fn mixed_system() -> FuzzySystem {
        let linear = |p: [f64; 3]| OutputFn::Linear {
            coefficients: vec![p[0], p[1]],
            constant: p[2],
        };
        FuzzySystem::builder("mixed")
            .input(
                "x",
                [-1.0, 1.0],
                [
                    ("a", Mf::bell(0.7, 1.7, -0.6)),
                    ("b", Mf::gaussian(0.5, 0.3)),
                    (
                        "c",
                        Mf::SigmoidProduct {
                            slope1: 3.0,
                            center1: 0.1,
                            slope2: -4.0,
                            center2: 0.9,
                        },
                    ),
                    (
                        "d",
                        Mf::PiShape {
                            left_foot: -0.8,
                            left_shoulder: -0.2,
                            right_shoulder: 0.25,
                            right_foot: 0.75,
                        },
                    ),
                ],
            )
            .input(
                "y",
                [0.0, 2.0],
                [
                    (
                        "p",
                        Mf::Gaussian2 {
                            sigma1: 0.4,
                            center1: 0.5,
                            sigma2: 0.6,
                            center2: 0.9,
                        },
                    ),
                    ("q", Mf::sigmoid(2.5, 1.2)),
                    ("r", Mf::trapezoid(0.8, 1.3, 1.6, 2.6)),
                    (
                        "s",
                        Mf::ZShape {
                            start: 0.3,
                            end: 1.7,
                        },
                    ),
                ],
            )
            .output(
                "z",
                [-5.0, 5.0],
                [
                    ("u", linear([1.0, -0.5, 0.2])),
                    ("v", OutputFn::Constant(0.7)),
                    ("w", linear([0.3, 0.8, -1.0])),
                ],
            )
            .rule(["a", "p"], ["u"])
            .rule(["b", "q"], ["v"])
            .rule(["c", "-"], ["w"])
            .weighted_rule(["a", "r"], ["v"], 0.6, Connective::And)
            .rule(["b", "r"], ["u"])
            .rule(["d", "s"], ["w"])
            .build()
            .unwrap()
    }

    fn data() -> TrainingData {
        let values = (0..40)
            .flat_map(|k| {
                // Away from every kink of the sets above.
                let (x, y) = (
                    -0.95 + 0.047 * k as f64,
                    2.0 * (((k * 7) % 40) as f64 + 0.37) / 40.0,
                );
                [x, y, (2.0 * x).sin() + 0.3 * y * y]
            })
            .collect();
        TrainingData::new(2, 1, values).unwrap()
    }

    fn sse(trainer: &mut Anfis) -> f64 {
        let n = trainer.net.n_inputs;
        let (net, buf) = (&trainer.net, &mut trainer.buf);
        trainer
            .train_x
            .chunks_exact(n)
            .zip(&trainer.train_y)
            .map(|(x, y)| (net.forward(x, buf).0 - y).powi(2))
            .sum()
    }

    #[test]
    fn backward_pass_is_the_gradient_of_the_error() {
        let mut trainer =
            Anfis::new(mixed_system(), &data(), None, 0, AnfisOptions::default()).unwrap();
        trainer.fit_consequents().unwrap();
        let base = trainer.backward();
        assert!((base - sse(&mut trainer)).abs() < 1e-12);
        let analytic = trainer.grad.clone();
        let mut checked = 0;
        for m in 0..trainer.mfs.len() {
            let (params, count) = trainer.mfs[m].param_array();
            for k in 0..count {
                let h = 1e-6;
                let mut at = |delta: f64| {
                    let mut p = params;
                    p[k] += delta;
                    let mf = trainer.mfs[m].with_params(&p[..count]);
                    trainer.net.compiled[m] = mf.compile().unwrap();
                    let e = sse(&mut trainer);
                    trainer.net.compiled[m] = trainer.mfs[m].compile().unwrap();
                    e
                };
                let numeric = (at(h) - at(-h)) / (2.0 * h);
                let g = analytic[trainer.mf_offset[m] + k];
                assert!(
                    (numeric - g).abs() < 1e-6 * (1.0 + g.abs()),
                    "set {m} parameter {k}: numeric {numeric}, analytic {g}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 3 + 2 + 4 + 4 + 4 + 2 + 4 + 2);
    }

    #[test]
    fn least_squares_consequents_minimise_the_error() {
        // At the least-squares consequents, the error's gradient in every consequent parameter
        // vanishes: perturbing any of them does not lower the error.
        let mut trainer = Anfis::new(
            mixed_system(),
            &data(),
            None,
            0,
            AnfisOptions {
                ridge: 0.0,
                ..AnfisOptions::default()
            },
        )
        .unwrap();
        trainer.fit_consequents().unwrap();
        let best = sse(&mut trainer);
        for j in 0..trainer.net.theta.len() {
            for delta in [-1e-4, 1e-4] {
                trainer.net.theta[j] += delta;
                assert!(sse(&mut trainer) >= best, "parameter {j}");
                trainer.net.theta[j] -= delta;
            }
        }
    }

    #[test]
    fn step_size_follows_jangs_two_rules() {
        let mut trainer =
            Anfis::new(mixed_system(), &data(), None, 0, AnfisOptions::default()).unwrap();
        for e in [5.0, 4.0, 3.0, 2.0] {
            trainer.adapt_step(e);
        }
        assert_eq!(trainer.step, 0.01, "no rule before five errors");
        trainer.adapt_step(1.0);
        assert!(
            (trainer.step - 0.011).abs() < 1e-15,
            "four decreases: +10 %"
        );
        for e in [2.0, 1.5, 2.5, 2.0] {
            trainer.adapt_step(e);
        }
        // 1 -> 2 up, 2 -> 1.5 down, 1.5 -> 2.5 up, 2.5 -> 2 down.
        assert!(
            (trainer.step - 0.0099).abs() < 1e-15,
            "two up-down pairs: -10 %"
        );
    }

    #[test]
    fn systems_anfis_cannot_train_are_refused_by_reason() {
        let refuse = |system: FuzzySystem| {
            let error = Anfis::new(system, &data(), None, 0, AnfisOptions::default()).unwrap_err();
            assert!(error.is_invalid_input() && !error.is_numerical(), "{error}");
            match error {
                FuzzyError::Learning(problem) => problem,
                other => panic!("not a learning error: {other}"),
            }
        };
        let message = |problem: LearningProblem| FuzzyError::from(problem).to_string();
        let two_outputs = refuse(crate::paper_controller());
        assert_eq!(two_outputs, LearningProblem::NotSingleOutput { outputs: 2 });
        assert!(message(two_outputs).contains("single-output systems; this one has 2 outputs"));
        let sets = [
            ("lo", Mf::gaussian(0.5, -1.0)),
            ("hi", Mf::gaussian(0.5, 1.0)),
        ];
        let base = || {
            FuzzySystem::builder("s")
                .input("x", [-1.0, 1.0], sets)
                .input("y", [0.0, 2.0], sets)
                .output("z", [0.0, 1.0], [("c", OutputFn::Constant(0.5))])
        };
        let minimum = refuse(
            base()
                .and_method(AndMethod::Minimum)
                .rule(["lo", "lo"], ["c"])
                .build()
                .unwrap(),
        );
        assert_eq!(minimum, LearningProblem::NotProductAnd);
        assert_eq!(
            message(minimum),
            "learning: ANFIS needs the product AND (AndMethod='prod')"
        );
        let sum = refuse(
            base()
                .defuzzification(Defuzzification::WeightedSum)
                .rule(["lo", "lo"], ["c"])
                .build()
                .unwrap(),
        );
        assert_eq!(sum, LearningProblem::NotWeightedAverage);
        assert_eq!(
            message(sum),
            "learning: ANFIS needs the weighted-average defuzzifier (DefuzzMethod='wtaver')"
        );
        let negated = refuse(
            base()
                .rule(["lo", "hi"], ["c"])
                .rule(["not lo", "lo"], ["c"])
                .build()
                .unwrap(),
        );
        assert_eq!(negated, LearningProblem::NegatedAntecedent { rule: 1 });
        assert_eq!(
            message(negated),
            "learning: rule 2 negates an antecedent; ANFIS needs plain sets"
        );
        let or = refuse(
            base()
                .weighted_rule(["lo", "hi"], ["c"], 1.0, Connective::Or)
                .build()
                .unwrap(),
        );
        assert_eq!(or, LearningProblem::OrRule { rule: 0 });
        assert_eq!(
            message(or),
            "learning: rule 1 is an OR rule; ANFIS needs AND rules"
        );
    }

    #[test]
    fn bad_options_and_data_are_refused_by_name() {
        let refuse = |options: AnfisOptions, check: Option<&TrainingData>| {
            Anfis::new(mixed_system(), &data(), check, 0, options).unwrap_err()
        };
        let with = |f: fn(&mut AnfisOptions)| {
            let mut options = AnfisOptions::default();
            f(&mut options);
            refuse(options, None)
        };
        let epochs = with(|o| o.epochs = 0);
        assert_eq!(
            epochs,
            FuzzyError::Learning(LearningProblem::CountOutOfRange {
                name: "epochs",
                count: 0,
                max: MAX_EPOCHS
            })
        );
        assert_eq!(
            epochs.to_string(),
            "learning: epochs must lie in 1..=1000000, got 0"
        );
        let ridge = with(|o| o.ridge = -1.0);
        assert_eq!(
            ridge,
            FuzzyError::Learning(LearningProblem::BelowMinimum {
                name: "the ridge",
                min: 0.0,
                value: -1.0
            })
        );
        assert_eq!(
            ridge.to_string(),
            "learning: the ridge must be finite and at least 0, got -1"
        );
        // A ridge that overwhelms the data (1e308 overflowed and was reported as a rank
        // deficiency, "use a ridge > 0").
        assert_eq!(
            with(|o| o.ridge = 1e308).to_string(),
            "learning: the ridge must be at most 1e6, got 1e308"
        );
        assert!(matches!(
            with(|o| o.step_increase = f64::NAN),
            FuzzyError::Learning(LearningProblem::BelowMinimum {
                name: "the step increase",
                min: 1.0,
                value,
            }) if value.is_nan()
        ));
        let decrease = with(|o| o.step_decrease = 1.5);
        assert_eq!(
            decrease,
            FuzzyError::Learning(LearningProblem::OutsideUnitInterval {
                name: "the step decrease",
                value: 1.5
            })
        );
        assert_eq!(
            decrease.to_string(),
            "learning: the step decrease must lie in (0, 1], got 1.5"
        );
        let narrow = TrainingData::new(1, 1, vec![0.0, 1.0]).unwrap();
        let inputs = refuse(AnfisOptions::default(), Some(&narrow));
        assert_eq!(
            inputs,
            FuzzyError::Learning(LearningProblem::DataInputs {
                data: "check",
                expected: 2,
                found: 1
            })
        );
        assert_eq!(
            inputs.to_string(),
            "learning: the check data have 1 inputs, the system 2"
        );
        for error in [epochs, ridge, decrease, inputs] {
            assert!(error.is_invalid_input() && !error.is_numerical(), "{error}");
        }
    }
}
