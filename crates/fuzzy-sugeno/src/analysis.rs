//! Static analysis of a rule base after Li-Xin Wang (*A Course in Fuzzy Systems and Control*,
//! the paper's reference \[18\], which claims its rule base is "complete, continuous and
//! consistent"):
//!
//! - **completeness**: every point of the input domain fires, for every output, some rule with
//!   strength at least the threshold. The threshold is Wang's ε-completeness lifted to rules:
//!   the strength a rule reaches when each of its antecedents holds to degree ε (default 0.5),
//!   i.e. `ε^n` under product AND and `ε` under minimum AND, for `n` inputs. It is checked on a
//!   grid made of evenly spaced samples, the landmarks of every set (centres, feet, shoulders,
//!   half-power points) and the midpoints between landmarks; the weakest point is reported.
//! - **consistency**: no two rules with the same premise (same antecedents and connective)
//!   conclude on the same output with different functions.
//! - **continuity**: neighbouring rules (premises that differ in exactly one input, by sets
//!   adjacent along that input's axis) do not jump. Wang's definition asks that the THEN-part
//!   sets of neighbours intersect; singleton consequents never intersect, so the jump is
//!   measured instead, relative to the output's range, and fails when it reaches
//!   [`AnalysisOptions::max_relative_jump`] (default 1: neighbours demanding opposite ends of
//!   the output range). First-order consequents are compared at the point between the two
//!   neighbouring cells.

use crate::error::FuzzyError;
use crate::eval::Evaluator;
use crate::membership::MembershipFn;
use crate::options::{EvalOptions, OutOfRange};
use crate::system::{AndMethod, Antecedent, FuzzySystem, InputVariable};
use lane_math::Compact;
use std::fmt;

/// The relative rounding allowance of the completeness check: a weakest strength within
/// `threshold * COVERAGE_ROUNDING` below the threshold passes (a set evaluated at its own
/// half-power point gives `0.49999999999999994`, not `0.5`), and the report says so.
pub const COVERAGE_ROUNDING: f64 = 1e-12;

/// The most evenly spaced samples per input a front end asks [`FuzzySystem::analyze`] for
/// (`hrm fis check --samples`, Python's `System.check(samples=...)`): the grid holds at most
/// [`AnalysisOptions::max_grid_points`] points anyway, and takes at least 2 a input.
pub const MAX_SAMPLES_PER_INPUT: usize = 1_000_000;

/// The thresholds and resolution of [`FuzzySystem::analyze`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisOptions {
    /// ε: the degree to which every antecedent of some rule must hold at every point.
    pub coverage: f64,
    /// Evenly spaced samples per input (landmarks and midpoints are added).
    pub samples_per_input: usize,
    /// The largest grid; the even samples are thinned to fit, and the analysis fails if even
    /// two per input plus the landmarks do not.
    pub max_grid_points: usize,
    /// Continuity fails when neighbouring consequents jump by this fraction of the output range
    /// or more.
    pub max_relative_jump: f64,
    /// The most work the analysis does: grid points times rules (completeness) plus rule pairs
    /// (consistency and continuity). The even samples are thinned to fit, and the analysis fails
    /// with [`FuzzyError::AnalysisWork`] if the pairs and the smallest grid do not.
    pub max_work: u64,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        Self {
            coverage: 0.5,
            samples_per_input: 21,
            max_grid_points: 1_000_000,
            max_relative_jump: 1.0,
            max_work: 100_000_000,
        }
    }
}

/// The result of [`FuzzySystem::analyze`]; its `Display` is a readable report.
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisReport {
    /// Wang's completeness.
    pub completeness: Completeness,
    /// Wang's consistency.
    pub consistency: Consistency,
    /// Wang's continuity.
    pub continuity: Continuity,
    names: Names,
}

/// Completeness: per output, the weakest coverage found on the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Completeness {
    /// The strength every point must reach (`coverage` combined over all inputs by the AND).
    pub threshold: f64,
    /// The number of grid points along each input.
    pub grid: Vec<usize>,
    /// One entry per output.
    pub outputs: Vec<Coverage>,
}

/// The weakest point of one output's coverage.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// The minimum over the grid of the strongest firing among the output's rules.
    pub weakest_strength: f64,
    /// Where it occurs (one value per input).
    pub weakest_point: Vec<f64>,
    /// The rules (0-based) that reach that strength there.
    pub strongest_rules: Vec<usize>,
}

/// Consistency: the conflicting rule pairs.
#[derive(Debug, Clone, PartialEq)]
pub struct Consistency {
    /// Every pair of rules with the same premise and different consequents, per output.
    pub conflicts: Vec<Conflict>,
}

/// Two rules with the same premise that conclude differently on one output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conflict {
    /// The two rules (0-based).
    pub rules: [usize; 2],
    /// The output (0-based).
    pub output: usize,
}

/// Continuity: per output, the largest jump between neighbouring rules.
#[derive(Debug, Clone, PartialEq)]
pub struct Continuity {
    /// The relative jump at which continuity fails.
    pub max_relative_jump: f64,
    /// One entry per output; `None` when no two neighbouring rules conclude on it.
    pub outputs: Vec<Option<Jump>>,
}

/// The jump between two neighbouring rules on one output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// The two rules (0-based).
    pub rules: [usize; 2],
    /// The input (0-based) in which their premises differ.
    pub input: usize,
    /// The two adjacent sets (0-based) of that input, in rule order.
    pub sets: [usize; 2],
    /// `|z_1 - z_2|`.
    pub jump: f64,
    /// The jump divided by the width of the output's range (0 for no jump, infinite for a jump
    /// on an output whose range is a point).
    pub relative: f64,
}

/// Names and ranges kept for the report's text.
#[derive(Debug, Clone, PartialEq)]
struct Names {
    inputs: Vec<String>,
    sets: Vec<Vec<String>>,
    outputs: Vec<(String, [f64; 2])>,
}

impl Completeness {
    /// Whether every output reaches the threshold everywhere on the grid (up to the relative
    /// rounding allowance [`COVERAGE_ROUNDING`]).
    pub fn passed(&self) -> bool {
        self.outputs
            .iter()
            .all(|c| self.covered(c.weakest_strength))
    }

    /// Whether `strength` reaches the threshold up to the rounding allowance.
    fn covered(&self, strength: f64) -> bool {
        strength >= self.threshold * (1.0 - COVERAGE_ROUNDING)
    }
}

impl Consistency {
    /// Whether no rules conflict.
    pub fn passed(&self) -> bool {
        self.conflicts.is_empty()
    }
}

impl Continuity {
    /// Whether every neighbouring jump stays below the limit.
    pub fn passed(&self) -> bool {
        self.outputs
            .iter()
            .flatten()
            .all(|j| j.relative < self.max_relative_jump)
    }
}

impl AnalysisReport {
    /// Whether all three properties hold.
    pub fn passed(&self) -> bool {
        self.completeness.passed() && self.consistency.passed() && self.continuity.passed()
    }
}

impl FuzzySystem {
    /// Checks Wang's completeness, consistency and continuity of the rule base (see the
    /// [module documentation](crate::analysis)).
    ///
    /// ```
    /// use fuzzy_sugeno::{paper_controller, AnalysisOptions};
    /// let report = paper_controller().analyze(&AnalysisOptions::default())?;
    /// assert!(report.passed(), "{report}");
    /// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
    /// ```
    pub fn analyze(&self, options: &AnalysisOptions) -> Result<AnalysisReport, FuzzyError> {
        if !(options.coverage > 0.0 && options.coverage <= 1.0) {
            return Err(FuzzyError::AnalysisOption {
                name: "coverage",
                requirement: "lie in (0, 1]",
                value: options.coverage,
            });
        }
        if !(options.max_relative_jump > 0.0 && options.max_relative_jump.is_finite()) {
            return Err(FuzzyError::AnalysisOption {
                name: "max_relative_jump",
                requirement: "be positive and finite",
                value: options.max_relative_jump,
            });
        }
        let names = Names {
            inputs: self.inputs().iter().map(|i| i.name.clone()).collect(),
            sets: self
                .inputs()
                .iter()
                .map(|i| i.sets.iter().map(|s| s.name.clone()).collect())
                .collect(),
            outputs: self
                .outputs()
                .iter()
                .map(|o| (o.name.clone(), o.range))
                .collect(),
        };
        Ok(AnalysisReport {
            completeness: self.completeness(options)?,
            consistency: self.consistency(),
            continuity: self.continuity(options.max_relative_jump)?,
            names,
        })
    }

    fn completeness(&self, options: &AnalysisOptions) -> Result<Completeness, FuzzyError> {
        let n = self.inputs().len();
        let threshold = match self.methods().and {
            AndMethod::Product => options.coverage.powi(n as i32),
            AndMethod::Minimum => options.coverage,
        };
        // A threshold that underflows would pass every point (`1e-320` over two inputs is 0).
        if threshold < f64::MIN_POSITIVE {
            return Err(FuzzyError::AnalysisOption {
                name: "coverage",
                requirement: "give a threshold (coverage, raised to the number of inputs under \
                              the product) of at least 2.2e-308",
                value: options.coverage,
            });
        }
        // Work left for the grid once the rule pairs are counted (bounds every loop here).
        let rules = self.rules().len() as u64;
        let pairs = rules * rules.saturating_sub(1) / 2;
        let work_points = options.max_work.saturating_sub(pairs) / rules.max(1);
        let max_points = options
            .max_grid_points
            .min(usize::try_from(work_points).unwrap_or(usize::MAX));
        let axes =
            grid_axes(self.inputs(), options.samples_per_input, max_points).map_err(|e| {
                if max_points < options.max_grid_points {
                    FuzzyError::AnalysisWork {
                        rules: self.rules().len(),
                        max_work: options.max_work,
                    }
                } else {
                    e
                }
            })?;
        let options_as_given = EvalOptions {
            out_of_range: OutOfRange::AsGiven,
            ..EvalOptions::default()
        };
        let mut evaluator = Evaluator::with_options(self.clone(), options_as_given)?;
        let n_out = self.outputs().len();
        let mut weakest = vec![(f64::INFINITY, Vec::new()); n_out];
        let mut index = vec![0usize; n];
        let mut point = vec![0.0; n];
        loop {
            for ((x, axis), &k) in point.iter_mut().zip(&axes).zip(&index) {
                *x = axis[k];
            }
            let strengths = evaluator.fire(&point)?;
            for (o, (strength, at)) in weakest.iter_mut().enumerate() {
                let best = self.rules_of(o).map(|r| strengths[r]).fold(0.0, f64::max);
                if best < *strength {
                    *strength = best;
                    at.clone_from(&point);
                }
            }
            // The next grid point, odometer style.
            let Some(i) = (0..n).find(|&i| index[i] + 1 < axes[i].len()) else {
                break;
            };
            index[i] += 1;
            index[..i].fill(0);
        }
        let mut outputs = Vec::with_capacity(n_out);
        for (o, (strength, at)) in weakest.into_iter().enumerate() {
            let strengths = evaluator.fire(&at)?;
            let strongest_rules = self
                .rules_of(o)
                .filter(|&r| strengths[r] >= strength && strength > 0.0)
                .collect();
            outputs.push(Coverage {
                weakest_strength: strength,
                weakest_point: at,
                strongest_rules,
            });
        }
        Ok(Completeness {
            threshold,
            grid: axes.iter().map(Vec::len).collect(),
            outputs,
        })
    }

    /// The rules (0-based) that conclude on output `o`.
    fn rules_of(&self, o: usize) -> impl Iterator<Item = usize> + '_ {
        self.rules()
            .iter()
            .enumerate()
            .filter(move |(_, r)| r.consequents[o].is_some())
            .map(|(i, _)| i)
    }

    fn consistency(&self) -> Consistency {
        let rules = self.rules();
        let mut conflicts = Vec::new();
        for (i, a) in rules.iter().enumerate() {
            for (j, b) in rules.iter().enumerate().skip(i + 1) {
                if a.antecedents != b.antecedents || a.connective != b.connective {
                    continue;
                }
                for (o, output) in self.outputs().iter().enumerate() {
                    if let (Some(ta), Some(tb)) = (a.consequents[o], b.consequents[o])
                        && output.terms[ta].function != output.terms[tb].function
                    {
                        conflicts.push(Conflict {
                            rules: [i, j],
                            output: o,
                        });
                    }
                }
            }
        }
        Consistency { conflicts }
    }

    fn continuity(&self, max_relative_jump: f64) -> Result<Continuity, FuzzyError> {
        let positions: Vec<Vec<f64>> = self.inputs().iter().map(set_positions).collect();
        let ranks: Vec<Vec<usize>> = positions.iter().map(|p| ranks(p)).collect();
        let rules = self.rules();
        let mut largest: Vec<Option<Jump>> = vec![None; self.outputs().len()];
        for (i, a) in rules.iter().enumerate() {
            for (j, b) in rules.iter().enumerate().skip(i + 1) {
                if a.connective != b.connective {
                    continue;
                }
                let mut differing = a
                    .antecedents
                    .iter()
                    .zip(&b.antecedents)
                    .enumerate()
                    .filter(|(_, (x, y))| x != y);
                let (Some((input, (&Antecedent::Is(sa), &Antecedent::Is(sb)))), None) =
                    (differing.next(), differing.next())
                else {
                    continue;
                };
                if ranks[input][sa].abs_diff(ranks[input][sb]) != 1 {
                    continue;
                }
                // Where the two cells meet: set positions, the midpoint along the differing input.
                let point: Vec<f64> = a
                    .antecedents
                    .iter()
                    .zip(self.inputs())
                    .enumerate()
                    .map(|(k, (antecedent, variable))| match *antecedent {
                        _ if k == input => 0.5 * (positions[k][sa] + positions[k][sb]),
                        Antecedent::Is(s) => positions[k][s],
                        Antecedent::Any | Antecedent::IsNot(_) => {
                            0.5 * (variable.range[0] + variable.range[1])
                        }
                    })
                    .collect();
                for (o, output) in self.outputs().iter().enumerate() {
                    let (Some(ta), Some(tb)) = (a.consequents[o], b.consequents[o]) else {
                        continue;
                    };
                    let jump = (output.terms[ta].function.value(&point)?
                        - output.terms[tb].function.value(&point)?)
                    .abs();
                    if !jump.is_finite() {
                        return Err(FuzzyError::JumpOverflow {
                            index: o,
                            name: output.name.clone(),
                            rules: [i, j],
                        });
                    }
                    // A point range ([0 0] in some MATLAB files) makes any jump infinite.
                    let relative = if jump == 0.0 {
                        0.0
                    } else {
                        jump / (output.range[1] - output.range[0])
                    };
                    if largest[o].is_none_or(|l| jump > l.jump) {
                        largest[o] = Some(Jump {
                            rules: [i, j],
                            input,
                            sets: [sa, sb],
                            jump,
                            relative,
                        });
                    }
                }
            }
        }
        Ok(Continuity {
            max_relative_jump,
            outputs: largest,
        })
    }
}

/// Points along each input: even samples, the sets' landmarks and the midpoints between
/// landmarks, all within the range; the even samples are thinned until the grid fits. An axis
/// holds at least its even samples, so more than `max_points` of them never fit and are not
/// built; the largest count that fits is found by bisection (the grid grows with the count),
/// so a huge `samples` costs a few dozen axis constructions, not one per count.
fn grid_axes(
    inputs: &[InputVariable],
    samples: usize,
    max_points: usize,
) -> Result<Vec<Vec<f64>>, FuzzyError> {
    let build = |samples: usize| -> Vec<Vec<f64>> {
        inputs.iter().map(|input| axis(input, samples)).collect()
    };
    let fits = |axes: &[Vec<f64>]| {
        axes.iter()
            .try_fold(1usize, |acc, a| acc.checked_mul(a.len()))
            .is_some_and(|total| total <= max_points)
    };
    let mut high = samples.max(2).min(max_points.max(2));
    let axes = build(high);
    if fits(&axes) {
        return Ok(axes);
    }
    let mut low = 2;
    let smallest = build(low);
    if !fits(&smallest) {
        return Err(FuzzyError::AnalysisGrid {
            max_grid_points: max_points,
            axes: smallest.iter().map(Vec::len).collect(),
        });
    }
    // `low` fits and `high` does not.
    while high - low > 1 {
        let middle = low + (high - low) / 2;
        if fits(&build(middle)) {
            low = middle;
        } else {
            high = middle;
        }
    }
    Ok(build(low))
}

fn axis(input: &InputVariable, samples: usize) -> Vec<f64> {
    let [min, max] = input.range;
    // lo (1 - t) + hi t puts the midpoint of a symmetric range exactly at 0.
    let at = |t: f64| min * (1.0 - t) + max * t;
    let mut landmarks: Vec<f64> = vec![min, max];
    for set in &input.sets {
        landmarks.extend(
            set_landmarks(&set.membership)
                .into_iter()
                .filter(|x| (min..=max).contains(x)),
        );
    }
    sort_dedup(&mut landmarks, max - min);
    let midpoints: Vec<f64> = landmarks.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let mut points: Vec<f64> = (0..samples)
        .map(|k| at(k as f64 / (samples - 1) as f64))
        .collect();
    points.extend(landmarks);
    points.extend(midpoints);
    sort_dedup(&mut points, max - min);
    points
}

fn sort_dedup(points: &mut Vec<f64>, width: f64) {
    points.sort_by(f64::total_cmp);
    points.dedup_by(|b, a| (*b - *a).abs() <= 1e-12 * width);
}

/// Where a set's membership changes character: centres, feet, shoulders, half-power points.
fn set_landmarks(mf: &MembershipFn) -> Vec<f64> {
    (mf.kind().landmarks)(&mf.param_array().0)
}

/// Each set's position along its axis: the centroid of its membership over the range (1001
/// samples), or the middle of the range for a set with no membership there.
fn set_positions(input: &InputVariable) -> Vec<f64> {
    const SAMPLES: usize = 1001;
    let [min, max] = input.range;
    input
        .sets
        .iter()
        .map(|set| {
            let (mut moment, mut mass) = (0.0, 0.0);
            for k in 0..SAMPLES {
                let t = k as f64 / (SAMPLES - 1) as f64;
                let x = min * (1.0 - t) + max * t;
                // Parameters were validated when the system was built.
                let mu = set.membership.degree(x).unwrap_or(0.0);
                moment += x * mu;
                mass += mu;
            }
            if mass > 0.0 {
                moment / mass
            } else {
                0.5 * (min + max)
            }
        })
        .collect()
}

/// The rank of each value in ascending order (ties keep their index order).
fn ranks(values: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut rank = vec![0; values.len()];
    for (r, &i) in order.iter().enumerate() {
        rank[i] = r;
    }
    rank
}

fn verdict(passed: bool) -> &'static str {
    if passed { "pass" } else { "FAIL" }
}

/// Rule numbers 1-based, like MATLAB, at most `limit` of them.
fn rule_list(rules: &[usize], limit: usize) -> String {
    let mut shown: Vec<String> = rules
        .iter()
        .take(limit)
        .map(|r| (r + 1).to_string())
        .collect();
    if rules.len() > limit {
        shown.push(format!("... ({} rules)", rules.len()));
    }
    shown.join(", ")
}

impl fmt::Display for AnalysisReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = &self.names;
        let c = &self.completeness;
        let grid: Vec<String> = c.grid.iter().map(usize::to_string).collect();
        writeln!(
            f,
            "completeness: {} (threshold {}, grid {} points)",
            verdict(c.passed()),
            Compact(c.threshold),
            grid.join(" x ")
        )?;
        for (coverage, (output, _)) in c.outputs.iter().zip(&names.outputs) {
            let at: Vec<String> = names
                .inputs
                .iter()
                .zip(&coverage.weakest_point)
                .map(|(name, x)| format!("{name} = {}", Compact(*x)))
                .collect();
            write!(
                f,
                "  {output}: weakest strength {} at ({})",
                Compact(coverage.weakest_strength),
                at.join(", ")
            )?;
            if coverage.weakest_strength < c.threshold && c.covered(coverage.weakest_strength) {
                write!(
                    f,
                    " (below the threshold {} by {:.1e}, within the relative rounding allowance \
                     {COVERAGE_ROUNDING:e})",
                    Compact(c.threshold),
                    c.threshold - coverage.weakest_strength
                )?;
            }
            if coverage.strongest_rules.is_empty() {
                writeln!(f, ", where no rule fires")?;
            } else {
                writeln!(
                    f,
                    ", reached by rule(s) {}",
                    rule_list(&coverage.strongest_rules, 8)
                )?;
            }
        }
        let conflicts = &self.consistency.conflicts;
        writeln!(
            f,
            "consistency: {} ({} conflicting rule pairs)",
            verdict(self.consistency.passed()),
            conflicts.len()
        )?;
        for conflict in conflicts {
            let [a, b] = conflict.rules;
            let output = &names.outputs[conflict.output].0;
            writeln!(
                f,
                "  rules {} and {} share a premise but conclude differently on {output}",
                a + 1,
                b + 1
            )?;
        }
        let continuity = &self.continuity;
        writeln!(
            f,
            "continuity: {} (jump / output range between neighbouring rules must stay below {})",
            verdict(continuity.passed()),
            Compact(continuity.max_relative_jump)
        )?;
        for (jump, (output, range)) in continuity.outputs.iter().zip(&names.outputs) {
            match jump {
                None => writeln!(f, "  {output}: no neighbouring rules")?,
                Some(j) => {
                    let sets = &names.sets[j.input];
                    writeln!(
                        f,
                        "  {output}: largest jump {} ({} of range [{}, {}]) between rules {} and {} ({}: {} -> {})",
                        Compact(j.jump),
                        Compact(j.relative),
                        Compact(range[0]),
                        Compact(range[1]),
                        j.rules[0] + 1,
                        j.rules[1] + 1,
                        names.inputs[j.input],
                        sets[j.sets[0]],
                        sets[j.sets[1]]
                    )?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Connective, OutputFn, PaperController, SystemBuilder, paper_controller};

    fn report(system: &FuzzySystem) -> AnalysisReport {
        system.analyze(&AnalysisOptions::default()).unwrap()
    }

    #[test]
    fn the_paper_rule_base_is_complete_consistent_and_continuous() {
        let report = report(&paper_controller());
        assert!(report.passed(), "{report}");
        // With centres at +-r and widths r, both sets hold to degree exactly 1/2 at the origin:
        // every one of the 16 rules fires 1/16 there, which is the weakest point.
        for coverage in &report.completeness.outputs {
            assert_eq!(coverage.weakest_strength, 0.0625);
            assert_eq!(coverage.weakest_point, [0.0; 4]);
            assert_eq!(coverage.strongest_rules.len(), 16);
        }
        assert_eq!(report.completeness.threshold, 0.0625);
        // The largest jumps cross the error axis: VP (100) next to N (-80) for tau1, 50 vs -40 for tau2.
        let tau1 = report.continuity.outputs[0].unwrap();
        assert_eq!((tau1.jump, tau1.relative, tau1.input), (180.0, 0.9, 0));
        assert_eq!(tau1.rules, [0, 8]);
        let tau2 = report.continuity.outputs[1].unwrap();
        assert_eq!((tau2.jump, tau2.relative, tau2.input), (90.0, 0.9, 1));
        let text = report.to_string();
        assert!(text.contains("tau1: largest jump 180 (0.9 of range [-100, 100]) between rules 1 and 9 (da1: N -> P)"), "{text}");
    }

    #[test]
    fn a_pass_within_the_rounding_allowance_says_so() {
        // A weakest strength a few ulps under the threshold passes, but is not printed as if it
        // reached it: the report names the shortfall and the allowance.
        let mut report = report(&paper_controller());
        report.completeness.threshold = 0.25;
        for coverage in &mut report.completeness.outputs {
            coverage.weakest_strength = 0.249_999_999_999_999_1;
        }
        assert!(report.completeness.passed());
        let text = report.to_string();
        assert!(
            text.contains(
                "weakest strength 0.2499999999999991 at (da1 = 0, da2 = 0, a1_dot = 0, a2_dot = 0) \
                 (below the threshold 0.25 by 8.9e-16, within the relative rounding allowance 1e-12)"
            ),
            "{text}"
        );
        // Beyond the allowance it fails.
        report.completeness.outputs[0].weakest_strength = 0.25 * (1.0 - 2e-12);
        assert!(!report.completeness.passed());
        assert!(report.to_string().starts_with("completeness: FAIL"));
    }

    #[test]
    fn narrower_bells_leave_the_origin_uncovered() {
        // Width 0.8 r: at the origin |r / 0.8 r|^4 = 2.44, so each set holds to 0.29 < 0.5.
        let narrow = PaperController {
            width_fraction: 0.8,
            ..PaperController::default()
        }
        .build()
        .unwrap();
        let report = report(&narrow);
        assert!(!report.completeness.passed());
        assert!(report.consistency.passed() && report.continuity.passed());
        let mu = 1.0 / (1.0 + 1.25f64.powi(4));
        assert!((report.completeness.outputs[0].weakest_strength - mu.powi(4)).abs() < 1e-15);
        assert!(report.to_string().starts_with("completeness: FAIL"));
    }

    fn line(sets: [(&'static str, MembershipFn); 3]) -> SystemBuilder {
        FuzzySystem::builder("line")
            .input("x", [0.0, 2.0], sets)
            .input("y", [0.0, 1.0], [("A", MembershipFn::gaussian(10.0, 0.5))])
            .output(
                "u",
                [-1.0, 1.0],
                [
                    ("neg", OutputFn::Constant(-1.0)),
                    ("zero", OutputFn::Constant(0.0)),
                    ("pos", OutputFn::Constant(1.0)),
                ],
            )
    }

    #[test]
    fn a_gap_between_triangles_is_found_and_located() {
        let sets = [
            ("lo", MembershipFn::triangle(-1.0, 0.0, 0.9)),
            ("mid", MembershipFn::triangle(1.1, 1.5, 1.6)),
            ("hi", MembershipFn::triangle(1.5, 2.0, 3.0)),
        ];
        let system = line(sets)
            .rule(["lo", "A"], ["neg"])
            .rule(["mid", "A"], ["zero"])
            .rule(["hi", "A"], ["pos"])
            .build()
            .unwrap();
        let coverage = &report(&system).completeness.outputs[0];
        assert_eq!(coverage.weakest_strength, 0.0);
        let x = coverage.weakest_point[0];
        assert!((0.9..=1.1).contains(&x), "the gap is (0.9, 1.1), found {x}");
        assert!(coverage.strongest_rules.is_empty());
    }

    #[test]
    fn conflicts_and_jumps_name_their_rules() {
        let sets = [
            ("lo", MembershipFn::triangle(-1.0, 0.0, 1.0)),
            ("mid", MembershipFn::triangle(0.0, 1.0, 2.0)),
            ("hi", MembershipFn::triangle(1.0, 2.0, 3.0)),
        ];
        // Sets declared out of axis order on purpose: adjacency follows position, not index.
        let [lo, mid, hi] = sets;
        let system = line([hi, lo, mid])
            .rule(["lo", "A"], ["neg"])
            .rule(["mid", "A"], ["pos"])
            .rule(["hi", "A"], ["neg"])
            .rule(["mid", "A"], ["zero"])
            .weighted_rule(["mid", "A"], ["neg"], 1.0, Connective::Or)
            .build()
            .unwrap();
        let report = report(&system);
        assert_eq!(
            report.consistency.conflicts,
            [Conflict {
                rules: [1, 3],
                output: 0
            }]
        );
        assert!(
            report
                .to_string()
                .contains("rules 2 and 4 share a premise but conclude differently on u")
        );
        // lo -> mid jumps from -1 to +1: the whole range, so continuity fails.
        let jump = report.continuity.outputs[0].unwrap();
        assert_eq!((jump.rules, jump.jump, jump.relative), ([0, 1], 2.0, 1.0));
        assert!(!report.continuity.passed());
        // lo and hi are not adjacent (mid lies between them), so rules 1 and 3 are not neighbours
        // even though their premises differ in one input.
        let smooth = line([hi, lo, mid])
            .rule(["lo", "A"], ["neg"])
            .rule(["hi", "A"], ["pos"])
            .rule(["mid", "A"], ["zero"]);
        let jump = self::report(&smooth.build().unwrap()).continuity.outputs[0].unwrap();
        assert_eq!((jump.jump, jump.relative), (1.0, 0.5));
    }

    #[test]
    fn a_jump_beyond_double_precision_is_an_error_not_an_infinity() {
        // Neighbours concluding 1e308 and -1e308: their jump, 2e308, is no double (the report
        // read "largest jump inf").
        let text = "[System]\nName='pm'\nType='sugeno'\nNumInputs=1\nNumOutputs=1\nNumRules=2\n\
            AndMethod='prod'\nOrMethod='probor'\nImpMethod='prod'\nAggMethod='sum'\n\
            DefuzzMethod='wtaver'\n\n[Input1]\nName='x1'\nRange=[-1 1]\nNumMFs=2\n\
            MF1='m0':'gaussmf',[0.5 0]\nMF2='m1':'gaussmf',[0.5 1]\n\n[Output1]\nName='y1'\n\
            Range=[-1 1]\nNumMFs=2\nMF1='o0':'constant',[1e308]\nMF2='o1':'constant',[-1e308]\n\n\
            [Rules]\n1, 1 (1) : 1\n2, 2 (1) : 1\n";
        let system = FuzzySystem::from_fis(text).unwrap();
        let error = system.analyze(&AnalysisOptions::default()).unwrap_err();
        assert_eq!(
            error.to_string(),
            "analysis: the consequents of rules 1 and 2 on output 1 ('y1') differ by more than \
             double precision holds"
        );
        assert!(lane_math::Classify::is_numerical(&error));
    }

    #[test]
    fn first_order_jumps_are_measured_where_the_cells_meet() {
        let sets = [
            ("N", MembershipFn::bell(1.0, 2.0, -1.0)),
            ("P", MembershipFn::bell(1.0, 2.0, 1.0)),
        ];
        let system = FuzzySystem::builder("fo")
            .input("x", [-1.0, 1.0], sets)
            .output(
                "u",
                [-10.0, 10.0],
                [
                    (
                        "a",
                        OutputFn::Linear {
                            coefficients: vec![2.0],
                            constant: 1.0,
                        },
                    ),
                    (
                        "b",
                        OutputFn::Linear {
                            coefficients: vec![-2.0],
                            constant: 1.0,
                        },
                    ),
                ],
            )
            .rule(["N"], ["a"])
            .rule(["P"], ["b"])
            .build()
            .unwrap();
        // The cells meet at x = 0 by symmetry, where both lines give 1: no jump at all.
        let jump = report(&system).continuity.outputs[0].unwrap();
        assert!(jump.jump < 1e-12, "{jump:?}");
    }

    #[test]
    fn oversized_grids_are_thinned_then_refused() {
        let sets = [("A", MembershipFn::gaussian(1.0, 0.0))];
        let mut builder = FuzzySystem::builder("wide");
        for i in 0..3 {
            builder = builder.input(format!("x{i}"), [0.0, 1.0], sets);
        }
        let system = builder
            .output("u", [0.0, 1.0], [("c", OutputFn::Constant(0.5))])
            .rule(["A", "A", "A"], ["c"])
            .build()
            .unwrap();
        let thinned = system
            .analyze(&AnalysisOptions {
                max_grid_points: 1000,
                ..AnalysisOptions::default()
            })
            .unwrap();
        assert!(thinned.completeness.grid.iter().product::<usize>() <= 1000);
        let refused = system.analyze(&AnalysisOptions {
            max_grid_points: 7,
            ..AnalysisOptions::default()
        });
        let Err(
            error @ FuzzyError::AnalysisGrid {
                max_grid_points: 7, ..
            },
        ) = refused
        else {
            panic!("{refused:?}")
        };
        // The message says what the grid needs, per input, and the limit.
        assert_eq!(
            error.to_string(),
            "analysis: the completeness grid needs 27 points (3 x 3 x 3 along its inputs, each \
             with 2 even samples, its sets' landmarks and the midpoints between them), more \
             than the 7 the check evaluates (AnalysisOptions::max_grid_points); a system with \
             fewer inputs or sets can be checked"
        );
    }

    #[test]
    fn a_huge_sample_count_is_thinned_without_allocating_it() {
        // 10^12 samples per input would be 8 TB per axis; the grid is capped at its limit.
        let report = paper_controller()
            .analyze(&AnalysisOptions {
                samples_per_input: 1_000_000_000_000,
                ..AnalysisOptions::default()
            })
            .unwrap();
        let points: usize = report.completeness.grid.iter().product();
        assert!(points <= 1_000_000 && points > 500_000, "{points}");
    }
}
