//! Initial Sugeno systems from data, like MATLAB's `genfis`: a grid partition of the input space
//! (`genfis1`) or one rule per cluster found by subtractive clustering (`genfis2`, Chiu 1994),
//! with zero- or first-order consequents fitted by least squares.

use super::anfis::{Anfis, AnfisOptions};
use super::data::TrainingData;
use crate::membership::MembershipFn;
use crate::system::{
    Antecedent, Connective, FuzzySet, FuzzySystem, InputVariable, Methods, OutputFn, OutputTerm,
    OutputVariable, Rule,
};
use crate::{FuzzyError, LearningProblem};

/// The most rules `genfis` builds (sets per input to the power of the inputs, or clusters).
pub const MAX_RULES: usize = 4096;
/// The narrowest range of an input a partition is built over: the premise gradients divide by
/// the sets' widths, a fraction of it.
pub const MIN_INPUT_RANGE: f64 = 1e-100;
/// The most rows subtractive clustering accepts (its cost grows as the square of the rows).
pub const MAX_CLUSTER_ROWS: usize = 10_000;
/// The most sets per input of a grid partition.
pub const MAX_SETS_PER_INPUT: usize = 64;

/// The consequents' order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConsequentOrder {
    /// Constant consequents (MATLAB `'constant'`).
    Zero,
    /// Linear consequents in every input (MATLAB `'linear'`).
    #[default]
    First,
}

/// The shape of the sets of a grid partition, by MATLAB type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SetShape {
    /// `gbellmf`: `a` = half the spacing, `b = 2` (MATLAB's `genfis1`).
    #[default]
    Bell,
    /// `gaussmf`, crossing its neighbours at 1/2.
    Gaussian,
    /// `gauss2mf`: a flat top over the middle half of the spacing, crossing at 1/2.
    Gaussian2,
    /// `trimf`: feet on the neighbouring centres.
    Triangle,
    /// `trapmf`: shoulders a quarter spacing from the centre, feet three quarters.
    Trapezoid,
    /// `sigmf`: exactly two sets, one open to each side, crossing in the middle of the range.
    Sigmoid,
    /// `dsigmf`: a difference of sigmoids half a spacing either side of the centre.
    SigmoidDifference,
    /// `psigmf`: a product of the same sigmoids.
    SigmoidProduct,
    /// `pimf`: the trapezoid's corners joined by MATLAB's quadratic splines, so neighbours
    /// cross at 1/2 and sum to 1. (`smf` and `zmf`, open to one side, partition no range and
    /// are not offered.)
    PiShape,
}

impl SetShape {
    /// The shape of MATLAB type `name` (`"gbellmf"`, ...), or an error listing the choices.
    pub fn from_matlab_name(name: &str) -> Result<Self, FuzzyError> {
        Ok(match name {
            "gbellmf" => Self::Bell,
            "gaussmf" => Self::Gaussian,
            "gauss2mf" => Self::Gaussian2,
            "trimf" => Self::Triangle,
            "trapmf" => Self::Trapezoid,
            "sigmf" => Self::Sigmoid,
            "dsigmf" => Self::SigmoidDifference,
            "psigmf" => Self::SigmoidProduct,
            "pimf" => Self::PiShape,
            _ => {
                return Err(LearningProblem::UnknownSetShape {
                    name: name.to_string(),
                }
                .into());
            }
        })
    }

    /// Set `j` of `k` evenly spaced over `[lo, hi]`.
    fn set(self, j: usize, k: usize, [lo, hi]: [f64; 2]) -> MembershipFn {
        let spacing = (hi - lo) / (k.max(2) - 1) as f64;
        let c = if k == 1 {
            0.5 * (lo + hi)
        } else {
            lo + spacing * j as f64
        };
        // sigma of a Gaussian that is 1/2 at distance `d` from its centre.
        let half_at = |d: f64| d / (2.0 * std::f64::consts::LN_2).sqrt();
        // A sigmoid slope that reaches 1 - 1/(1 + e^4) = 0.982 half a spacing in.
        let slope = 8.0 / spacing;
        match self {
            Self::Bell => MembershipFn::bell(0.5 * spacing, 2.0, c),
            Self::Gaussian => MembershipFn::gaussian(half_at(0.5 * spacing), c),
            Self::Gaussian2 => MembershipFn::Gaussian2 {
                sigma1: half_at(0.25 * spacing),
                center1: c - 0.25 * spacing,
                sigma2: half_at(0.25 * spacing),
                center2: c + 0.25 * spacing,
            },
            Self::Triangle => MembershipFn::triangle(c - spacing, c, c + spacing),
            Self::Trapezoid => MembershipFn::trapezoid(
                c - 0.75 * spacing,
                c - 0.25 * spacing,
                c + 0.25 * spacing,
                c + 0.75 * spacing,
            ),
            Self::Sigmoid => {
                // 0.9 at the ends of the range.
                let slope = 2.0 * 9f64.ln() / (hi - lo);
                let sign = if j == 0 { -1.0 } else { 1.0 };
                MembershipFn::sigmoid(sign * slope, 0.5 * (lo + hi))
            }
            Self::SigmoidDifference => MembershipFn::SigmoidDifference {
                slope1: slope,
                center1: c - 0.5 * spacing,
                slope2: slope,
                center2: c + 0.5 * spacing,
            },
            Self::SigmoidProduct => MembershipFn::SigmoidProduct {
                slope1: slope,
                center1: c - 0.5 * spacing,
                slope2: -slope,
                center2: c + 0.5 * spacing,
            },
            Self::PiShape => MembershipFn::PiShape {
                left_foot: c - 0.75 * spacing,
                left_shoulder: c - 0.25 * spacing,
                right_shoulder: c + 0.25 * spacing,
                right_foot: c + 0.75 * spacing,
            },
        }
    }
}

/// A grid partition: `sets_per_input` sets of one shape evenly spread over each input's range
/// in the data, one rule per combination of sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridPartition {
    /// Sets per input (1 to 64; the rule count, this to the power of the inputs, at most
    /// [`MAX_RULES`]).
    pub sets_per_input: usize,
    /// Their shape.
    pub shape: SetShape,
    /// The consequents' order.
    pub order: ConsequentOrder,
}

impl Default for GridPartition {
    /// Two bell sets per input, first-order consequents (MATLAB's `genfis1` defaults).
    fn default() -> Self {
        Self {
            sets_per_input: 2,
            shape: SetShape::Bell,
            order: ConsequentOrder::First,
        }
    }
}

/// Subtractive clustering (Chiu 1994) of the joint input-output space, each column scaled to
/// `[0, 1]`, with MATLAB's `subclust` defaults: squash factor 1.25, accept ratio 0.5, reject
/// ratio 0.15.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubtractiveClustering {
    /// The cluster radius `r_a` in scaled units, in `(0, 1]` (typically 0.2 to 0.5; smaller
    /// radii give more clusters).
    pub radius: f64,
    /// The consequents' order.
    pub order: ConsequentOrder,
}

impl Default for SubtractiveClustering {
    fn default() -> Self {
        Self {
            radius: 0.5,
            order: ConsequentOrder::First,
        }
    }
}

/// `subclust`'s squash factor `r_b / r_a`.
const SQUASH: f64 = 1.25;
/// A candidate above this fraction of the first potential is always accepted.
const ACCEPT_RATIO: f64 = 0.5;
/// A candidate below this fraction of the first potential ends the search.
const REJECT_RATIO: f64 = 0.15;

/// A grid-partition system for output `output` of `data` (MATLAB's `genfis1`), named `"genfis"`:
/// variables named after the data's columns ([`TrainingData::column_name`]), sets `in1mf1 ...`,
/// one output term `out1mf1 ...` per rule, rules in MATLAB's order (the last input's set varies
/// fastest), consequents fitted by least squares.
pub fn genfis_grid(
    data: &TrainingData,
    output: usize,
    grid: &GridPartition,
) -> Result<FuzzySystem, FuzzyError> {
    let every: Vec<usize> = (0..data.n_inputs()).collect();
    genfis_grid_over(data, output, grid, &every)
}

/// [`genfis_grid`] with the grid over the inputs `partitioned` only (0-based, increasing): the
/// other inputs get no sets, every rule says "don't care" for them, and with first-order
/// consequents they enter each rule's linear function. The result is a set of local linear
/// models of all inputs scheduled on the partitioned ones (Takagi-Sugeno gain scheduling), with
/// `k^p` rules for `p` partitioned inputs instead of `k^n`. Refuses an empty, unordered or
/// out-of-range list, and an input (partitioned or not) that is constant over the data.
///
/// ```
/// use fuzzy_sugeno::learn::{genfis_grid_over, GridPartition, TrainingData};
/// use fuzzy_sugeno::Evaluator;
///
/// // z = (1 + x^2) y: linear in y with a slope scheduled on x.
/// let values = (0..121).flat_map(|k| {
///     let (x, y) = (-1.0 + 0.2 * (k % 11) as f64, -1.0 + 0.2 * (k / 11) as f64);
///     [x, y, (1.0 + x * x) * y]
/// }).collect();
/// let data = TrainingData::new(2, 1, values)?;
/// let grid = GridPartition { sets_per_input: 5, ..GridPartition::default() };
/// let system = genfis_grid_over(&data, 0, &grid, &[0])?;
/// assert_eq!(system.rules().len(), 5);
/// assert!(system.inputs()[1].sets.is_empty());
/// let mut z = [0.0];
/// Evaluator::new(system).eval(&[0.5, 0.8], &mut z)?;
/// assert!((z[0] - 1.25 * 0.8).abs() < 0.02, "{}", z[0]);
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
pub fn genfis_grid_over(
    data: &TrainingData,
    output: usize,
    grid: &GridPartition,
    partitioned: &[usize],
) -> Result<FuzzySystem, FuzzyError> {
    data.check_output(output)?;
    let (n, k) = (data.n_inputs(), grid.sets_per_input);
    if partitioned.is_empty()
        || partitioned.windows(2).any(|w| w[0] >= w[1])
        || partitioned.last().is_some_and(|&i| i >= n)
    {
        return Err(LearningProblem::PartitionedInputs {
            partitioned: partitioned.to_vec(),
            inputs: n,
        }
        .into());
    }
    if !(1..=MAX_SETS_PER_INPUT).contains(&k) {
        return Err(LearningProblem::CountOutOfRange {
            name: "sets per input",
            count: k,
            max: MAX_SETS_PER_INPUT,
        }
        .into());
    }
    if grid.shape == SetShape::Sigmoid && k != 2 {
        return Err(LearningProblem::SigmoidSets { sets: k }.into());
    }
    let p = partitioned.len();
    let rules = u32::try_from(p)
        .ok()
        .and_then(|p| k.checked_pow(p))
        .filter(|&r| r <= MAX_RULES)
        .ok_or(LearningProblem::TooManyRules {
            sets: k,
            inputs: p,
            limit: MAX_RULES,
        })?;
    let mut inputs = Vec::with_capacity(n);
    for i in 0..n {
        let range = input_range(data, i)?;
        let sets = if partitioned.contains(&i) {
            (0..k)
                .map(|j| FuzzySet {
                    name: format!("in{}mf{}", i + 1, j + 1),
                    membership: grid.shape.set(j, k, range),
                })
                .collect()
        } else {
            Vec::new()
        };
        inputs.push(InputVariable {
            name: data.column_name(i),
            range,
            sets,
        });
    }
    let antecedents = (0..rules).map(|r| {
        // Mixed-radix digits of r over the partitioned inputs, the last one least significant.
        (0..n)
            .map(|i| match partitioned.iter().position(|&q| q == i) {
                Some(d) => Antecedent::Is(r / k.pow((p - 1 - d) as u32) % k),
                None => Antecedent::Any,
            })
            .collect()
    });
    assemble(data, output, inputs, antecedents.collect(), grid.order)
}

/// One rule per cluster of output `output` of `data` (MATLAB's `genfis2`), named `"genfis"`:
/// Gaussian sets `in1cluster1 ...` centred on the cluster centres with `sigma = r_a (max - min)
/// / sqrt(8)` per input, one term per rule, consequents fitted by least squares. Refuses more
/// than [`MAX_CLUSTER_ROWS`] rows and radii that give more than [`MAX_RULES`] clusters.
pub fn genfis_cluster(
    data: &TrainingData,
    output: usize,
    clustering: &SubtractiveClustering,
) -> Result<FuzzySystem, FuzzyError> {
    data.check_output(output)?;
    let ra = clustering.radius;
    if !(ra > 0.0 && ra <= 1.0) {
        return Err(LearningProblem::OutsideUnitInterval {
            name: "the cluster radius",
            value: ra,
        }
        .into());
    }
    let rows = data.rows();
    if rows > MAX_CLUSTER_ROWS {
        return Err(LearningProblem::TooManyClusterRows {
            rows,
            limit: MAX_CLUSTER_ROWS,
        }
        .into());
    }
    let n = data.n_inputs();
    let ranges = (0..n)
        .map(|i| input_range(data, i))
        .collect::<Result<Vec<_>, _>>()?;
    let target_range = data.column_range(n + output);
    // Rows scaled to the unit cube: inputs, then the target (a constant column scales to 0).
    let dim = n + 1;
    let scale = |v: f64, [lo, hi]: [f64; 2]| if hi > lo { (v - lo) / (hi - lo) } else { 0.0 };
    let points: Vec<f64> = (0..rows)
        .flat_map(|r| {
            let x = data.inputs(r);
            let y = data.target(r, output);
            (0..dim).map(move |d| if d < n { (x[d], d) } else { (y, d) })
        })
        .map(|(v, d)| scale(v, if d < n { ranges[d] } else { target_range }))
        .collect();
    let centres = subtractive_clustering(&points, dim, ra)?;
    let inputs = (0..n)
        .map(|i| {
            let [lo, hi] = ranges[i];
            let sigma = ra * (hi - lo) / 8f64.sqrt();
            let sets = centres
                .iter()
                .enumerate()
                .map(|(c, &row)| FuzzySet {
                    name: format!("in{}cluster{}", i + 1, c + 1),
                    membership: MembershipFn::gaussian(
                        sigma,
                        lo + points[row * dim + i] * (hi - lo),
                    ),
                })
                .collect();
            InputVariable {
                name: data.column_name(i),
                range: ranges[i],
                sets,
            }
        })
        .collect();
    let antecedents = (0..centres.len())
        .map(|c| vec![Antecedent::Is(c); n])
        .collect();
    assemble(data, output, inputs, antecedents, clustering.order)
}

/// Chiu's subtractive clustering of `points` (rows of `dim` values in `[0, 1]`): the rows
/// chosen as cluster centres, in the order found.
fn subtractive_clustering(points: &[f64], dim: usize, ra: f64) -> Result<Vec<usize>, FuzzyError> {
    let rows = points.len() / dim;
    let (alpha, beta) = (4.0 / (ra * ra), 4.0 / (SQUASH * ra).powi(2));
    let distance_sq = |a: usize, b: usize| {
        (0..dim)
            .map(|d| (points[a * dim + d] - points[b * dim + d]).powi(2))
            .sum::<f64>()
    };
    let mut potential: Vec<f64> = (0..rows)
        .map(|i| (0..rows).map(|j| (-alpha * distance_sq(i, j)).exp()).sum())
        .collect();
    let mut centres: Vec<usize> = Vec::new();
    let mut first = f64::NAN;
    // Each pass accepts a centre (at most MAX_RULES) or zeroes a potential (at most `rows`).
    // The highest potential, the first row among equals.
    while let Some((best, &p)) = potential
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
    {
        if centres.is_empty() {
            first = p;
        } else if p < REJECT_RATIO * first || p <= 0.0 {
            break;
        } else if p <= ACCEPT_RATIO * first {
            let nearest = centres
                .iter()
                .map(|&c| distance_sq(best, c))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            if nearest / ra + p / first < 1.0 {
                potential[best] = 0.0;
                continue;
            }
        }
        if centres.len() == MAX_RULES {
            return Err(LearningProblem::TooManyClusters {
                radius: ra,
                limit: MAX_RULES,
            }
            .into());
        }
        centres.push(best);
        for (i, q) in potential.iter_mut().enumerate() {
            *q -= p * (-beta * distance_sq(i, best)).exp();
        }
    }
    Ok(centres)
}

/// `[min, max]` of input `i` in the data, refused if the input is constant or spans less than
/// [`MIN_INPUT_RANGE`].
fn input_range(data: &TrainingData, i: usize) -> Result<[f64; 2], FuzzyError> {
    let [lo, hi] = data.column_range(i);
    if lo >= hi {
        Err(LearningProblem::ConstantInput {
            input: i,
            value: lo,
        }
        .into())
    } else if hi - lo < MIN_INPUT_RANGE {
        Err(LearningProblem::NarrowInput {
            input: i,
            lo,
            hi,
            min: MIN_INPUT_RANGE,
        }
        .into())
    } else {
        Ok([lo, hi])
    }
}

/// The system with the given inputs and rule premises, one output term per rule, consequents
/// fitted by least squares.
fn assemble(
    data: &TrainingData,
    output: usize,
    inputs: Vec<InputVariable>,
    antecedents: Vec<Vec<Antecedent>>,
    order: ConsequentOrder,
) -> Result<FuzzySystem, FuzzyError> {
    let n = inputs.len();
    let [lo, hi] = data.column_range(n + output);
    if lo >= hi {
        return Err(LearningProblem::ConstantOutput { output, value: lo }.into());
    }
    let terms = (0..antecedents.len())
        .map(|r| OutputTerm {
            name: format!("out1mf{}", r + 1),
            function: match order {
                ConsequentOrder::Zero => OutputFn::Constant(0.0),
                ConsequentOrder::First => OutputFn::Linear {
                    coefficients: vec![0.0; n],
                    constant: 0.0,
                },
            },
        })
        .collect();
    let rules = antecedents
        .into_iter()
        .enumerate()
        .map(|(r, antecedents)| Rule {
            antecedents,
            consequents: vec![Some(r)],
            weight: 1.0,
            connective: Connective::And,
        })
        .collect();
    let outputs = vec![OutputVariable {
        name: data.column_name(n + output),
        range: [lo, hi],
        terms,
    }];
    let system = FuzzySystem::new(
        "genfis".to_string(),
        inputs,
        outputs,
        rules,
        Methods::default(),
    )?;
    let fit = AnfisOptions {
        epochs: 1,
        ..AnfisOptions::default()
    };
    Anfis::new(system, data, None, output, fit)?.fitted_system()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::learn::MAX_ROWS;
    use lane_math::Classify;
    use proptest::prelude::*;

    fn plane(rows: usize) -> TrainingData {
        // z = 2 x - y + 0.5 on a lattice of [0, 1] x [-2, 2].
        let values = (0..rows)
            .flat_map(|k| {
                let (x, y) = (
                    (k % 7) as f64 / 6.0,
                    -2.0 + 4.0 * (k / 7) as f64 / ((rows / 7).max(2) - 1) as f64,
                );
                [x, y, 2.0 * x - y + 0.5]
            })
            .collect();
        TrainingData::new(2, 1, values).unwrap()
    }

    const SHAPES: [SetShape; 9] = [
        SetShape::Bell,
        SetShape::Gaussian,
        SetShape::Gaussian2,
        SetShape::Triangle,
        SetShape::Trapezoid,
        SetShape::Sigmoid,
        SetShape::SigmoidDifference,
        SetShape::SigmoidProduct,
        SetShape::PiShape,
    ];

    proptest! {
        /// Every point of the range belongs to some set to degree at least 1/2 (just below it
        /// for the sigmoid pairs), and the sets validate.
        #[test]
        fn grid_sets_cover_the_range(shape in 0usize..SHAPES.len(), k in 1usize..9, lo in -5.0f64..5.0, width in 0.1f64..10.0, t in 0.0f64..=1.0) {
            let shape = SHAPES[shape];
            let k = if shape == SetShape::Sigmoid { 2 } else { k };
            let range = [lo, lo + width];
            let sets: Vec<MembershipFn> = (0..k).map(|j| shape.set(j, k, range)).collect();
            for mf in &sets {
                prop_assert!(mf.validate().is_ok(), "{mf:?}");
            }
            let x = lo + t * width;
            let best = sets.iter().map(|mf| mf.degree(x).unwrap()).fold(0.0, f64::max);
            // The sigmoid pairs sit half a spacing either side of a centre with slope 8 / spacing,
            // so where neighbours meet (and at the ends of a single set's range) one sigmoid is
            // 1/2 and the other sig(8): dsigmf is sig(8) - 1/2 there, psigmf sig(8) / 2, both just
            // below 1/2. Every other shape reaches 1/2.
            let sig8 = 1.0 / (1.0 + (-8.0f64).exp());
            let floor = match shape {
                SetShape::SigmoidDifference => sig8 - 0.5,
                SetShape::SigmoidProduct => 0.5 * sig8,
                _ => 0.5,
            };
            prop_assert!(best >= floor - 1e-9, "{shape:?} k={k} at {x}: {best}");
        }
    }

    #[test]
    fn a_grid_has_matlabs_rule_order_names_and_exact_linear_fit() {
        let data = plane(49);
        let grid = GridPartition {
            sets_per_input: 3,
            shape: SetShape::Triangle,
            order: ConsequentOrder::First,
        };
        let system = genfis_grid(&data, 0, &grid).unwrap();
        assert_eq!(system.rules().len(), 9);
        assert_eq!(
            system.rules()[1].antecedents,
            [Antecedent::Is(0), Antecedent::Is(1)]
        );
        assert_eq!(
            system.rules()[3].antecedents,
            [Antecedent::Is(1), Antecedent::Is(0)]
        );
        assert_eq!(system.inputs()[1].sets[2].name, "in2mf3");
        assert_eq!(system.inputs()[1].range, [-2.0, 2.0]);
        // A plane is in the span of every first-order system: the fit is exact.
        let mut evaluator = crate::Evaluator::new(system);
        let mut z = [0.0];
        for r in 0..data.rows() {
            evaluator.eval(data.inputs(r), &mut z).unwrap();
            assert!((z[0] - data.target(r, 0)).abs() < 1e-8);
        }
    }

    #[test]
    fn a_partial_grid_schedules_linear_models_on_the_partitioned_inputs() {
        // z = 2 x - y + 0.5: exact with the grid over y only, x left to the consequents.
        let data = plane(49);
        let grid = GridPartition {
            sets_per_input: 3,
            shape: SetShape::Bell,
            order: ConsequentOrder::First,
        };
        let system = genfis_grid_over(&data, 0, &grid, &[1]).unwrap();
        assert_eq!(system.rules().len(), 3);
        assert!(system.inputs()[0].sets.is_empty());
        assert_eq!(system.inputs()[0].range, [0.0, 1.0]);
        assert_eq!(system.inputs()[1].sets.len(), 3);
        assert_eq!(
            system.rules()[2].antecedents,
            [Antecedent::Any, Antecedent::Is(2)]
        );
        let mut evaluator = crate::Evaluator::new(system);
        let mut z = [0.0];
        for r in 0..data.rows() {
            evaluator.eval(data.inputs(r), &mut z).unwrap();
            assert!((z[0] - data.target(r, 0)).abs() < 1e-8);
        }
        // The whole list is the full grid.
        assert_eq!(
            genfis_grid_over(&data, 0, &grid, &[0, 1]).unwrap(),
            genfis_grid(&data, 0, &grid).unwrap()
        );
        for bad in [&[][..], &[1, 0], &[0, 0], &[2]] {
            let error = genfis_grid_over(&data, 0, &grid, bad).unwrap_err();
            assert_eq!(
                error.to_string(),
                format!(
                    "learning: the partitioned inputs must be a non-empty increasing list of \
                     indices below 2, got {bad:?}"
                )
            );
            assert_eq!(
                error,
                FuzzyError::Learning(LearningProblem::PartitionedInputs {
                    partitioned: bad.to_vec(),
                    inputs: 2
                })
            );
        }
    }

    #[test]
    fn clustering_finds_separated_blobs() {
        // Three tight blobs in (x, y) with distinct outputs.
        let centres = [(0.0, 0.0, 1.0), (1.0, 0.0, 2.0), (0.5, 1.0, 3.0)];
        let values = (0..60)
            .flat_map(|k| {
                let (cx, cy, z) = centres[k % 3];
                let jitter = 0.01 * ((k * 37 % 11) as f64 - 5.0);
                [cx + jitter, cy - jitter, z + jitter]
            })
            .collect();
        let data = TrainingData::new(2, 1, values).unwrap();
        let system = genfis_cluster(
            &data,
            0,
            &SubtractiveClustering {
                radius: 0.3,
                order: ConsequentOrder::Zero,
            },
        )
        .unwrap();
        assert_eq!(system.rules().len(), 3);
        let mut found: Vec<f64> = system.outputs()[0]
            .terms
            .iter()
            .map(|t| match t.function {
                OutputFn::Constant(c) => c,
                OutputFn::Linear { .. } => unreachable!(),
            })
            .collect();
        found.sort_by(f64::total_cmp);
        for (c, z) in found.iter().zip([1.0, 2.0, 3.0]) {
            assert!((c - z).abs() < 0.05, "{found:?}");
        }
    }

    #[test]
    fn bad_requests_are_refused_with_a_reason() {
        // Each refusal: its problem, with the numbers and names as fields, and its message.
        fn check<T: std::fmt::Debug>(
            result: Result<T, FuzzyError>,
            expected: LearningProblem,
            message: &str,
        ) {
            let error = result.unwrap_err();
            assert_eq!(error, FuzzyError::Learning(expected));
            assert_eq!(error.to_string(), message);
            assert!(error.is_invalid_input() && !error.is_numerical(), "{error}");
        }
        let data = plane(49);
        let grid = |k, shape| GridPartition {
            sets_per_input: k,
            shape,
            order: ConsequentOrder::First,
        };
        check(
            genfis_grid(&data, 0, &grid(3, SetShape::Sigmoid)),
            LearningProblem::SigmoidSets { sets: 3 },
            "learning: sigmf partitions have exactly 2 sets per input (one open to each side), got 3",
        );
        check(
            genfis_grid(&data, 0, &grid(0, SetShape::Bell)),
            LearningProblem::CountOutOfRange {
                name: "sets per input",
                count: 0,
                max: MAX_SETS_PER_INPUT,
            },
            "learning: sets per input must lie in 1..=64, got 0",
        );
        check(
            genfis_grid(&data, 0, &grid(65, SetShape::Bell)),
            LearningProblem::CountOutOfRange {
                name: "sets per input",
                count: 65,
                max: MAX_SETS_PER_INPUT,
            },
            "learning: sets per input must lie in 1..=64, got 65",
        );
        check(
            SetShape::from_matlab_name("constant"),
            LearningProblem::UnknownSetShape {
                name: "constant".to_string(),
            },
            "learning: unknown set type 'constant' for a grid partition; expected one of gbellmf, gaussmf, gauss2mf, trimf, trapmf, sigmf, dsigmf, psigmf, pimf",
        );
        let wide = TrainingData::new(13, 1, (0..14 * 3).map(|v| (v % 5) as f64).collect()).unwrap();
        check(
            genfis_grid(&wide, 0, &GridPartition::default()),
            LearningProblem::TooManyRules {
                sets: 2,
                inputs: 13,
                limit: MAX_RULES,
            },
            "learning: 2 sets on each of 13 inputs make more than 4096 rules",
        );
        let constant = TrainingData::new(1, 1, vec![1.0, 0.0, 1.0, 1.0]).unwrap();
        check(
            genfis_grid(&constant, 0, &GridPartition::default()),
            LearningProblem::ConstantInput {
                input: 0,
                value: 1.0,
            },
            "learning: input 1 is constant (1) over the data; a fuzzy partition needs a range",
        );
        let flat = TrainingData::new(1, 2, vec![0.0, 5.0, 2.5, 1.0, 6.0, 2.5]).unwrap();
        check(
            genfis_cluster(&flat, 1, &SubtractiveClustering::default()),
            LearningProblem::ConstantOutput {
                output: 1,
                value: 2.5,
            },
            "learning: output 2 is constant (2.5) over the data; there is nothing to learn",
        );
        check(
            genfis_cluster(
                &data,
                0,
                &SubtractiveClustering {
                    radius: 0.0,
                    order: ConsequentOrder::First,
                },
            ),
            LearningProblem::OutsideUnitInterval {
                name: "the cluster radius",
                value: 0.0,
            },
            "learning: the cluster radius must lie in (0, 1], got 0",
        );
        let many = TrainingData::new(
            1,
            1,
            (0..2 * (MAX_CLUSTER_ROWS + 1)).map(|v| v as f64).collect(),
        )
        .unwrap();
        check(
            genfis_cluster(&many, 0, &SubtractiveClustering::default()),
            LearningProblem::TooManyClusterRows {
                rows: MAX_CLUSTER_ROWS + 1,
                limit: MAX_CLUSTER_ROWS,
            },
            "learning: subtractive clustering takes at most 10000 rows, got 10001",
        );
        let long = TrainingData::new(1, 1, (0..2 * MAX_ROWS).map(|v| v as f64).collect()).unwrap();
        check(
            genfis_grid(&long, 0, &grid(13, SetShape::Bell)),
            LearningProblem::LeastSquaresTooLarge {
                samples: MAX_ROWS,
                unknowns: 13 * 2,
                limit: 25_000_000,
            },
            "learning: 1000000 samples and 26 consequent parameters exceed the least-squares \
             limit of 25000000 entries ((samples + parameters) x parameters)",
        );
        // Few samples but many rules: the ridge rows count, and so does the solve's work.
        let sets = |k| GridPartition {
            sets_per_input: k,
            ..GridPartition::default()
        };
        check(
            genfis_grid(&plane(49), 0, &sets(45)),
            LearningProblem::LeastSquaresTooLarge {
                samples: 49,
                unknowns: 45 * 45 * 3,
                limit: 25_000_000,
            },
            "learning: 49 samples and 6075 consequent parameters exceed the least-squares \
             limit of 25000000 entries ((samples + parameters) x parameters)",
        );
        check(
            genfis_grid(&plane(49), 0, &sets(40)),
            LearningProblem::LeastSquaresTooSlow {
                samples: 49,
                unknowns: 40 * 40 * 3,
                limit: 40_000_000_000,
            },
            "learning: 49 samples and 4800 consequent parameters make a least-squares solve of \
             more than 40000000000 multiply-adds ((samples + parameters) x parameters^2): use \
             fewer sets per input or fewer inputs",
        );
        check(
            genfis_grid(&data, 1, &GridPartition::default()),
            LearningProblem::NoSuchOutput {
                output: 1,
                outputs: 1,
            },
            "learning: output 2 asked of data with 1 outputs",
        );
    }
}
