//! Several single-output systems over the same inputs as one multi-output system: how data with
//! several outputs, learned one system per output, becomes one `.fis` (for example a controller
//! with two torques).

use crate::system::{FuzzySet, FuzzySystem, InputVariable, Rule};
use crate::{FuzzyError, LearningProblem};

/// Merges single-output systems over the same inputs (same names and ranges, same inference
/// methods) into one system named `name` with their outputs in order. Each input gets the sets
/// of every system, renamed `<output>_<set>`; each rule concludes on its own system's output
/// only, so every output of the merged system evaluates exactly as its system alone (the other
/// systems' rules do not enter its weighted average).
///
/// ```
/// use fuzzy_sugeno::learn::{genfis_grid, merge_outputs, GridPartition, TrainingData};
/// // Two outputs, x + y and x - y, of the same two inputs.
/// let values = (0..25).flat_map(|k| {
///     let (x, y) = ((k % 5) as f64, (k / 5) as f64);
///     [x, y, x + y, x - y]
/// }).collect();
/// let data = TrainingData::new(2, 2, values)?;
/// let systems = [0, 1].map(|o| genfis_grid(&data, o, &GridPartition::default()));
/// let [sum, difference] = systems;
/// let both = merge_outputs("both", &[sum?, difference?])?;
/// assert_eq!(both.outputs().len(), 2);
/// assert_eq!(both.rules().len(), 8);
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
pub fn merge_outputs(name: &str, systems: &[FuzzySystem]) -> Result<FuzzySystem, FuzzyError> {
    let Some(first) = systems.first() else {
        return Err(LearningProblem::NothingToMerge.into());
    };
    let n_inputs = first.inputs().len();
    for (k, system) in systems.iter().enumerate() {
        let name = || system.name().to_string();
        if system.outputs().len() != 1 {
            return Err(LearningProblem::MergeOutputs {
                system: k,
                name: name(),
                outputs: system.outputs().len(),
            }
            .into());
        }
        if system.methods() != first.methods() {
            return Err(LearningProblem::MergeMethods {
                system: k,
                name: name(),
            }
            .into());
        }
        let same_inputs = system.inputs().len() == n_inputs
            && system
                .inputs()
                .iter()
                .zip(first.inputs())
                .all(|(a, b)| a.name == b.name && a.range == b.range);
        if !same_inputs {
            return Err(LearningProblem::MergeInputs {
                system: k,
                name: name(),
            }
            .into());
        }
    }
    let mut inputs: Vec<InputVariable> = first
        .inputs()
        .iter()
        .map(|v| InputVariable {
            name: v.name.clone(),
            range: v.range,
            sets: Vec::new(),
        })
        .collect();
    let mut outputs = Vec::with_capacity(systems.len());
    let mut rules = Vec::new();
    for (k, system) in systems.iter().enumerate() {
        let output = &system.outputs()[0];
        let offsets: Vec<usize> = inputs.iter().map(|v| v.sets.len()).collect();
        for (merged, input) in inputs.iter_mut().zip(system.inputs()) {
            merged.sets.extend(input.sets.iter().map(|s| FuzzySet {
                name: format!("{}_{}", output.name, s.name),
                membership: s.membership,
            }));
        }
        for rule in system.rules() {
            let mut consequents = vec![None; systems.len()];
            consequents[k] = rule.consequents[0];
            rules.push(Rule {
                antecedents: rule
                    .antecedents
                    .iter()
                    .zip(&offsets)
                    .map(|(a, &offset)| match *a {
                        crate::Antecedent::Any => crate::Antecedent::Any,
                        crate::Antecedent::Is(s) => crate::Antecedent::Is(offset + s),
                        crate::Antecedent::IsNot(s) => crate::Antecedent::IsNot(offset + s),
                    })
                    .collect(),
                consequents,
                weight: rule.weight,
                connective: rule.connective,
            });
        }
        outputs.push(output.clone());
    }
    FuzzySystem::new(name.to_string(), inputs, outputs, rules, first.methods())
}
