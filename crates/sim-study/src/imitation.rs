//! Controllers learned by imitation: a teacher controller (computed torque by default) is run
//! on training scenarios, the pairs (what the controller saw, the torque the teacher chose) are
//! recorded at the controller samples, and a first-order Sugeno system is trained on them with
//! ANFIS (`fuzzy_sugeno::learn`), one system per modal torque merged into one `m`-output
//! system. The result is an ordinary [`FuzzySystem`]: written as a `.fis` file, any scenario
//! with the same modal coordinates uses it as its fuzzy controller (`controller.fis`).
//!
//! **Inputs.** The `4m` inputs of [`FuzzyController`](sim_core::controller::FuzzyController)'s
//! scheduled layout, per coordinate the error `da_i = a_i - a_i_ref`, the error rate
//! `da_i_dot = a_i_dot - a_i_ref_dot`, the coordinate `a_i` and the reference acceleration
//! `a_i_ref_ddot`. Computed torque, `tau* = M*(a) (a_ref_ddot - kp da - kd da_dot) + C*(a,
//! a_dot) + G*(a)` (eq 15), is linear in the errors and the reference acceleration with
//! coefficients that depend on the configuration `a` (the mass matrix, the gravity torque and
//! its slope), so the rules partition the coordinates `a` only (bell sets, [`genfis_grid_over`])
//! and each rule's linear consequent takes all `4m` inputs: a gain-scheduled local linear model
//! of the teacher. The errors alone (the paper's inputs) cannot carry the gravity torque, which
//! depends on where the arm is, not on how far it is from the reference.
//!
//! **Training data.** One row per `stride`-th controller sample of each training scenario run
//! with the teacher, with the noise of the scenario (the inputs are what the teacher measured).
//! The teacher's step responses supply large errors and rates, its tracking of sinusoids the
//! accelerations. A response demonstrates only the configurations it passes through, so
//! [`shifted_grid`] repeats responses about a grid of operating points (the reference shifted),
//! the way a gain-scheduled controller is designed at several operating points.
//!
//! Everything is deterministic: the same scenarios and options give the same system, bit for bit.
//!
//! ```no_run
//! use sim_study::imitation::{ImitationOptions, imitate, paper_demonstrations};
//!
//! let learned = imitate(&paper_demonstrations()?, &ImitationOptions::default(), |_, _| {})?;
//! std::fs::write("learned.fis", learned.system.to_fis())?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::scenario::{ControllerKind, ReferenceSpec, Scenario};
use fuzzy_sugeno::learn::{
    Anfis, AnfisOptions, ConsequentOrder, EpochReport, GridPartition, MAX_INPUTS, MAX_ROWS,
    SetShape, TrainingData, genfis_grid_over, merge_outputs,
};
use fuzzy_sugeno::{Evaluator, FuzzyError, FuzzySystem, LearningProblem};
use sim_core::SimError;
use sim_core::controller::{SCHEDULED_INPUTS_PER_COORDINATE, scheduled_inputs};

/// The scenarios the main job's learned controller is trained on: the paper's step and sine
/// responses (Figure 9), never the tracking path it is compared on; they are repeated about the
/// operating points [`PAPER_OFFSETS`] ([`paper_demonstrations`]).
pub const PAPER_TRAINING_SCENARIOS: [&str; 2] = ["paper-responses-step", "paper-responses-sine"];

/// The operating points of the main job's demonstrations, as offsets of `a1` and of `a2` (rad;
/// every combination): the paper's responses move the arm within 0.3 rad of the straight
/// configuration, so repeated about these points they cover `|a1| <= 1.8`, `|a2| <= 0.75` rad.
pub const PAPER_OFFSETS: [&[f64]; 2] = [&[-1.5, -0.75, 0.0, 0.75, 1.5], &[-0.5, 0.0, 0.5]];

/// The most demonstrations [`shifted_grid`] makes.
pub const MAX_DEMONSTRATIONS: usize = 10_000;

/// The largest stride ([`ImitationOptions::stride`]).
pub const MAX_STRIDE: usize = 1_000_000;
/// The most bell sets per coordinate ([`ImitationOptions::sets`]).
pub const MAX_SETS: usize = 9;
/// The most ANFIS epochs per output ([`ImitationOptions::epochs`]).
pub const MAX_EPOCHS: usize = 10_000;
/// The largest range margin ([`ImitationOptions::margin`]).
pub const MAX_MARGIN: f64 = 100.0;

/// How a controller is learned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImitationOptions {
    /// The controller imitated (default computed torque with the scenario's gains).
    pub teacher: ControllerKind,
    /// One row every `stride` controller samples (default 50: every 5 ms at the paper's 0.1 ms
    /// period); 1 to [`MAX_STRIDE`].
    pub stride: usize,
    /// Bell sets per coordinate `a_i` (default 3: `3^m` rules); 1 to [`MAX_SETS`].
    pub sets: usize,
    /// ANFIS epochs per output (default 20); 1 to [`MAX_EPOCHS`]. The epoch with the smallest
    /// training error is kept.
    pub epochs: usize,
    /// ANFIS's initial premise step `kappa` (default 0.01); 0 fits the consequents only.
    pub step: f64,
    /// How far the learned system's input ranges reach beyond the data, as a fraction of each
    /// input's range in the data on either side (default 1: three times the width). Beyond the
    /// data the outermost rules' linear models extrapolate; an input beyond these ranges is
    /// evaluated as given by default (a scenario's `out_of_range = "clamp"` clamps it to them).
    /// 0 to [`MAX_MARGIN`].
    pub margin: f64,
}

impl Default for ImitationOptions {
    fn default() -> Self {
        Self {
            teacher: ControllerKind::ComputedTorque,
            stride: 50,
            sets: 3,
            epochs: 20,
            step: 0.01,
            margin: 1.0,
        }
    }
}

impl ImitationOptions {
    /// Checks every option against its bounds; the error names the option.
    pub fn validate(&self) -> Result<(), SimError> {
        let count = |name: &str, value: usize, max: usize| {
            if (1..=max).contains(&value) {
                Ok(())
            } else {
                Err(SimError::setting(
                    name,
                    format!("must be at least 1 and at most {max}, got {value}"),
                ))
            }
        };
        count("imitation.stride", self.stride, MAX_STRIDE)?;
        count("imitation.sets", self.sets, MAX_SETS)?;
        count("imitation.epochs", self.epochs, MAX_EPOCHS)?;
        if !(self.step.is_finite() && self.step >= 0.0) {
            return Err(SimError::setting(
                "imitation.step",
                format!("must be finite and at least 0, got {}", self.step),
            ));
        }
        if !(self.margin.is_finite() && (0.0..=MAX_MARGIN).contains(&self.margin)) {
            return Err(SimError::setting(
                "imitation.margin",
                format!("must lie in [0, {MAX_MARGIN}], got {}", self.margin),
            ));
        }
        Ok(())
    }
}

/// A learned controller and how it was learned.
#[derive(Debug, Clone, PartialEq)]
pub struct Imitation {
    /// The learned system: `4m` inputs, `m` outputs (see the module documentation).
    pub system: FuzzySystem,
    /// The training pairs recorded from the teacher.
    pub data: TrainingData,
    /// Per output, every epoch's report.
    pub history: Vec<Vec<EpochReport>>,
    /// Per output, the epoch kept (1-based).
    pub best_epoch: Vec<usize>,
    /// Per output, the RMSE of the learned system against the teacher on the training pairs
    /// (N m).
    pub training_rmse: Vec<f64>,
}

/// The names of the learned system's inputs for the modal coordinates `coordinates` (e.g.
/// `["a1", "a2"]`): `da1, da2, da1_dot, da2_dot, a1, a2, a1_ref_ddot, a2_ref_ddot`.
pub fn input_names(coordinates: &[String]) -> Vec<String> {
    let block = |f: &dyn Fn(&str) -> String| coordinates.iter().map(|c| f(c)).collect::<Vec<_>>();
    [
        block(&|c| format!("d{c}")),
        block(&|c| format!("d{c}_dot")),
        block(&|c| c.to_string()),
        block(&|c| format!("{c}_ref_ddot")),
    ]
    .concat()
}

/// The names of the learned system's outputs: `tau_a1, tau_a2, ...`.
pub fn output_names(coordinates: &[String]) -> Vec<String> {
    coordinates.iter().map(|c| format!("tau_{c}")).collect()
}

/// Runs each scenario with `options.teacher` and records one row every `options.stride`
/// controller samples: the `4m` scheduled inputs of what the teacher measured and was commanded
/// (noise included), then the `m` torques it chose. Every scenario must have the same modal
/// coordinates. Fails if a scenario cannot be built, if its run fails or a tracking error exceeds
/// its runaway bound, or if the rows would exceed [`MAX_ROWS`] or the runs' estimated work
/// ([`Simulation::work`](sim_core::Simulation::work)) [`MAX_RUN_WORK`](sim_core::MAX_RUN_WORK)
/// (checked before any is recorded).
pub fn record(
    scenarios: &[Scenario],
    options: &ImitationOptions,
) -> Result<TrainingData, SimError> {
    options.validate()?;
    let Some(first) = scenarios.first() else {
        return Err(SimError::setting(
            "imitation.scenarios",
            "must name at least one training scenario",
        ));
    };
    // Counted (saturating) before any name is made: a file may ask for absurdly many.
    let m = first.n_coords();
    if SCHEDULED_INPUTS_PER_COORDINATE.saturating_mul(m) > MAX_INPUTS {
        return Err(SimError::setting(
            "imitation.scenarios",
            format!(
                "have {m} modal coordinates; a learned controller takes {} inputs per \
                 coordinate and at most {MAX_INPUTS} in all",
                SCHEDULED_INPUTS_PER_COORDINATE
            ),
        ));
    }
    let mut simulations = Vec::with_capacity(scenarios.len());
    let mut rows = 0usize;
    let mut work = 0.0;
    let coordinates = first.coordinate_names();
    for scenario in scenarios {
        // The same names: the same family (planar or spatial), harmonics and alpha0 freedom.
        if scenario.n_coords() != m || scenario.coordinate_names() != coordinates {
            return Err(SimError::setting(
                "imitation.scenarios",
                format!(
                    "must share their modal coordinates: '{}' has {m} ({}), '{}' has {} ({})",
                    first.name,
                    coordinates.join(", "),
                    scenario.name,
                    scenario.n_coords(),
                    scenario.coordinate_names().join(", ")
                ),
            ));
        }
        let mut teacher = scenario.clone();
        teacher.controller.kind = options.teacher;
        let simulation = teacher.build()?;
        // Bounded as one run is, before any runs.
        work += simulation.work();
        if work > sim_core::MAX_RUN_WORK {
            return Err(SimError::setting(
                "imitation.scenarios",
                format!(
                    "make {} teacher runs, whose first {} already take an estimated {work:.2e} \
                     operations, more than the {:e} the runs of one imitation may take (about \
                     ten minutes): fewer or shorter scenarios, or fewer offsets",
                    scenarios.len(),
                    simulations.len() + 1,
                    sim_core::MAX_RUN_WORK
                ),
            ));
        }
        let s = simulation.settings();
        // A whole number of periods, checked when the simulation was built.
        let samples = (s.duration / s.controller_period).round() as usize;
        rows = rows.saturating_add(samples.div_ceil(options.stride));
        simulations.push((simulation, samples));
    }
    if rows > MAX_ROWS {
        return Err(SimError::setting(
            "imitation.stride",
            format!(
                "= {} records {rows} rows from these scenarios, more than {MAX_ROWS}; use a \
                 larger stride",
                options.stride
            ),
        ));
    }
    let width = SCHEDULED_INPUTS_PER_COORDINATE * m + m;
    let mut values = Vec::with_capacity(rows * width);
    let mut inputs = vec![0.0; SCHEDULED_INPUTS_PER_COORDINATE * m];
    for (simulation, samples) in &mut simulations {
        let bound = simulation.settings().max_modal_error;
        for k in 0..*samples {
            let sample = simulation.step()?;
            if let Some((i, error)) = (0..m)
                .map(|i| (i, (sample.state.a[i] - sample.reference.a[i]).abs()))
                .find(|&(_, e)| e > bound)
            {
                return Err(SimError::RunawayError {
                    t: sample.t,
                    coordinate: i + 1,
                    error,
                    bound,
                });
            }
            if k % options.stride == 0 {
                scheduled_inputs(&sample.measured, &sample.command, &mut inputs);
                values.extend_from_slice(&inputs);
                values.extend_from_slice(&sample.tau_star);
            }
        }
    }
    let mut names = input_names(&coordinates);
    names.extend(output_names(&coordinates));
    Ok(TrainingData::new(width - m, m, values)?.with_names(names)?)
}

/// Trains the learned controller on `data` (from [`record`]): per output, a first-order system
/// with `options.sets` bell sets on each coordinate input `a_i` and none on the others
/// ([`genfis_grid_over`]), trained by ANFIS for `options.epochs` epochs (`progress` is called
/// with the output's index and each epoch's report); the systems are merged into one named
/// `learned`, and its input ranges widened by `options.margin`.
pub fn train(
    data: &TrainingData,
    options: &ImitationOptions,
    mut progress: impl FnMut(usize, &EpochReport),
) -> Result<Imitation, SimError> {
    options.validate()?;
    let m = data.n_outputs();
    if data.n_inputs() != SCHEDULED_INPUTS_PER_COORDINATE * m {
        return Err(SimError::setting(
            "imitation data",
            format!(
                "must have {} inputs for {m} outputs (the scheduled layout), got {}",
                SCHEDULED_INPUTS_PER_COORDINATE * m,
                data.n_inputs()
            ),
        ));
    }
    let grid = GridPartition {
        sets_per_input: options.sets,
        shape: SetShape::Bell,
        order: ConsequentOrder::First,
    };
    let coordinates: Vec<usize> = (2 * m..3 * m).collect();
    let anfis = AnfisOptions {
        epochs: options.epochs,
        initial_step: options.step,
        ..AnfisOptions::default()
    };
    let (mut systems, mut history, mut best_epoch) = (Vec::new(), Vec::new(), Vec::new());
    // A constant column is named (the library counts inputs from 1, which says little here).
    let named = |error: FuzzyError| match error {
        FuzzyError::Learning(LearningProblem::ConstantInput { input, value }) => SimError::setting(
            "imitation data",
            format!(
                "input '{}' is constant ({value}) over the demonstrations: the teacher's runs \
                 never vary it, so no partition of it can be learned; add scenarios (or \
                 imitation.offsets) that move it",
                data.column_name(input)
            ),
        ),
        other => other.into(),
    };
    for output in 0..m {
        let initial = genfis_grid_over(data, output, &grid, &coordinates).map_err(named)?;
        let mut trainer = Anfis::new(initial, data, None, output, anfis)?;
        let mut reports = Vec::with_capacity(options.epochs);
        for _ in 0..options.epochs {
            let report = trainer.epoch()?;
            progress(output, &report);
            reports.push(report);
        }
        systems.push(trainer.best_system()?);
        best_epoch.push(trainer.best_epoch());
        history.push(reports);
    }
    let merged = merge_outputs("learned", &systems)?;
    let system = widen_inputs(&merged, options.margin)?;
    let training_rmse = rmse(&system, data)?;
    Ok(Imitation {
        system,
        data: data.clone(),
        history,
        best_epoch,
        training_rmse,
    })
}

/// Every scenario of `scenarios` repeated about every operating point of the grid `offsets`
/// (one list of offsets per modal coordinate, rad; every combination, the first scenario
/// first and, within a scenario, the last coordinate's offset varying fastest): the reference
/// (constant, step or sinusoid) and a given initial state shifted by the offsets, so the
/// same response is demonstrated in another configuration of the arm. Refuses a path reference
/// (a tip path fixes its configurations), a grid of another number of coordinates, a non-finite
/// offset, an empty list and more than [`MAX_DEMONSTRATIONS`] scenarios (counted before any is
/// made).
///
/// ```
/// use sim_study::imitation::shifted_grid;
/// use sim_study::Scenario;
///
/// let step = Scenario::builtin("paper-responses-step")?;
/// let shifted = shifted_grid(&[step], &[vec![0.0, 1.0], vec![-0.5]])?;
/// assert_eq!(shifted.len(), 2);
/// assert!(shifted[1].build().is_ok());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn shifted_grid(
    scenarios: &[Scenario],
    offsets: &[Vec<f64>],
) -> Result<Vec<Scenario>, SimError> {
    let name = "imitation.offsets";
    let points = offsets
        .iter()
        .try_fold(1usize, |n, list| n.checked_mul(list.len()))
        .unwrap_or(usize::MAX);
    let total = points.saturating_mul(scenarios.len());
    if points == 0 {
        return Err(SimError::setting(
            name,
            "must give at least one offset per coordinate, got an empty list",
        ));
    }
    if total > MAX_DEMONSTRATIONS {
        let sizes: Vec<String> = offsets.iter().map(|l| l.len().to_string()).collect();
        return Err(SimError::setting(
            name,
            format!(
                "must make at most {MAX_DEMONSTRATIONS} scenarios, got a grid of {} offsets \
                 for {} scenarios ({} in all)",
                sizes.join(" x "),
                scenarios.len(),
                if total == usize::MAX {
                    "beyond counting".to_string()
                } else {
                    total.to_string()
                }
            ),
        ));
    }
    for list in offsets {
        lane_math::check_all_finite(name, list)?;
    }
    let m = offsets.len();
    let mut shifted = Vec::with_capacity(total);
    for scenario in scenarios {
        if scenario.n_coords() != m {
            return Err(SimError::setting(
                name,
                format!(
                    "has {m} lists, '{}' has {} modal coordinates (one list each)",
                    scenario.name,
                    scenario.n_coords()
                ),
            ));
        }
        let mut offset = vec![0.0; m];
        for k in 0..points {
            let mut rest = k;
            for i in (0..m).rev() {
                offset[i] = offsets[i][rest % offsets[i].len()];
                rest /= offsets[i].len();
            }
            shifted.push(shift(scenario, &offset)?);
        }
    }
    Ok(shifted)
}

/// `scenario` with its reference and given initial state shifted by `offset` (`m` entries).
fn shift(scenario: &Scenario, offset: &[f64]) -> Result<Scenario, SimError> {
    let mut shifted = scenario.clone();
    let add = |field: &str, values: &mut Vec<f64>| {
        if values.len() != offset.len() {
            return Err(SimError::setting(
                field,
                format!(
                    "of '{}' has {} entries, the offsets {}",
                    scenario.name,
                    values.len(),
                    offset.len()
                ),
            ));
        }
        for (v, o) in values.iter_mut().zip(offset) {
            *v += o;
        }
        Ok(())
    };
    let zeros = || vec![0.0; offset.len()];
    match &mut shifted.reference {
        ReferenceSpec::Constant { a } => add("reference.a", a)?,
        ReferenceSpec::Step {
            initial, target, ..
        } => {
            add("reference.target", target)?;
            add("reference.initial", initial.get_or_insert_with(zeros))?;
        }
        ReferenceSpec::Sinusoid { offset: o, .. } => {
            add("reference.offset", o.get_or_insert_with(zeros))?;
        }
        ReferenceSpec::Path { .. } => {
            return Err(SimError::setting(
                "imitation.offsets",
                format!(
                    "cannot shift the path reference of '{}': a tip path fixes its configurations",
                    scenario.name
                ),
            ));
        }
        ReferenceSpec::Planned { .. } => {
            return Err(SimError::setting(
                "imitation.offsets",
                format!(
                    "cannot shift the planned reference of '{}': the plan fixes its \
                     configurations",
                    scenario.name
                ),
            ));
        }
    }
    if let Some(initial) = &mut shifted.initial {
        add("initial.a", &mut initial.a)?;
    }
    shifted.name = format!("{} about {offset:?}", scenario.name);
    Ok(shifted)
}

/// The main job's demonstrations: the [`PAPER_TRAINING_SCENARIOS`] about every operating point
/// of [`PAPER_OFFSETS`] (30 scenarios).
pub fn paper_demonstrations() -> Result<Vec<Scenario>, SimError> {
    let scenarios = PAPER_TRAINING_SCENARIOS
        .iter()
        .map(|name| Scenario::builtin(name))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| SimError::setting("imitation.scenarios", e.to_string()))?;
    shifted_grid(&scenarios, &PAPER_OFFSETS.map(<[f64]>::to_vec))
}

/// [`record`] then [`train`].
pub fn imitate(
    scenarios: &[Scenario],
    options: &ImitationOptions,
    progress: impl FnMut(usize, &EpochReport),
) -> Result<Imitation, SimError> {
    let data = record(scenarios, options)?;
    train(&data, options, progress)
}

/// The root-mean-square difference, per output, between `system` and the targets of `data`.
pub fn rmse(system: &FuzzySystem, data: &TrainingData) -> Result<Vec<f64>, SimError> {
    let m = data.n_outputs();
    let mut evaluator = Evaluator::new(system.clone());
    let mut out = vec![0.0; system.outputs().len()];
    let mut sse = vec![0.0; m];
    for r in 0..data.rows() {
        evaluator.eval(data.inputs(r), &mut out)?;
        for (o, sum) in sse.iter_mut().enumerate() {
            let e = out[o] - data.target(r, o);
            *sum += e * e;
        }
    }
    let rows = data.rows() as f64;
    Ok(sse.into_iter().map(|s| (s / rows).sqrt()).collect())
}

/// `system` with every input range `[lo, hi]` widened to `[lo - margin w, hi + margin w]`,
/// `w = hi - lo`; the sets, rules and consequents are unchanged, so the system's values inside
/// the old ranges are too.
fn widen_inputs(system: &FuzzySystem, margin: f64) -> Result<FuzzySystem, SimError> {
    let mut builder = FuzzySystem::builder(system.name())
        .and_method(system.methods().and)
        .or_method(system.methods().or)
        .defuzzification(system.methods().defuzzification);
    for input in system.inputs() {
        let [lo, hi] = input.range;
        let w = margin * (hi - lo);
        builder = builder.input(
            input.name.clone(),
            [lo - w, hi + w],
            input.sets.iter().map(|s| (s.name.clone(), s.membership)),
        );
    }
    for output in system.outputs() {
        builder = builder.output(
            output.name.clone(),
            output.range,
            output
                .terms
                .iter()
                .map(|t| (t.name.clone(), t.function.clone())),
        );
    }
    for rule in system.rules() {
        builder = builder.indexed_rule(rule.clone());
    }
    Ok(builder.build()?)
}
