//! The separable form of a complete grid of product rules: the tables of
//! [`kernel::separable_sums`](crate::kernel::separable_sums).
//!
//! When the rules are every combination of one set per input (a complete grid), combined by the
//! product and weighted 1, with bells of one integer exponent as sets and constant conclusions
//! that depend on a subset `S_o` of the inputs only (the paper's `tau1* = f(da1, a1_dot)`), the
//! centre average of eq 21 factorises: the sum over the grid of the strengths
//! `prod_i mu_{i k_i}` is `prod_i s_i` with `s_i = sum_k mu_{ik}`, and the factors of the inputs
//! outside `S_o` cancel between numerator and denominator,
//!
//! `y_o = sum_{k in grid(S_o)} z_o(k) prod_{i in S_o} mu_{i k_i} / prod_{i in S_o} s_i`.
//!
//! With the bell `mu_{ik} = 1 / A_{ik}`, `A_{ik} = 1 + |(x_i - c_{ik}) / a_{ik}|^(2b)`, numerator
//! and denominator are multiplied by `prod_{i in S_o} prod_k A_{ik}`: the *grade*
//! `P_{ik} = prod_{j != k} A_{ij}` replaces `mu_{ik}` and `S_i = sum_k P_{ik}` replaces `s_i`,
//! so that an output costs one division (the paper's controller: 2 divisions a point instead of
//! 18, 16 products of the grid instead of 28 nodes and 48 sums).
//!
//! The result is the centre average in another order of operations: not the same bits as the
//! general kernel, but within 8 `f64::EPSILON` of it times the largest magnitude of the output's
//! conclusions (tested on random points within and five times beyond the ranges, and on other
//! grids: at most 4.5 for the paper's controller, whose outputs move by at most 6.4e-14 N m). The form is taken at a point
//! only while every `A_{ik}` stays at most [`Separable::limit`], so that no product overflows and
//! the general kernel's strengths cannot underflow to "no rule fired"; beyond (inputs far
//! outside their ranges) the point is evaluated by the general kernel.

use crate::compiled_mf::CompiledMf;
use crate::rules::{AndMethod, Antecedent, Connective, Defuzzification, Methods, Rule};

/// The most sets an input may have for the separable form (its grades are products of the
/// others' `A`).
pub(crate) const MAX_SEPARABLE_SETS: usize = 4;

/// The tables of the separable form (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Separable {
    /// Every set's centre `c` and inverse width `1 / a`, input by input (the order of
    /// [`Compiled::mfs`](crate::system::Compiled::mfs)).
    pub sets: Vec<[f64; 2]>,
    /// The exponent `2 b`, the same for every set.
    pub exponent: u32,
    /// Input `i`'s sets are `sets[set_offsets[i]..set_offsets[i + 1]]`.
    pub set_offsets: Vec<usize>,
    /// The number of sets of every input when all inputs have the same (the paper's 2), which
    /// lets the kernel take the inputs' sets in arrays of that length.
    pub sets_per_input: Option<usize>,
    /// One grid per output.
    pub outputs: Vec<OutputGrid>,
    /// The largest `A_{ik}` for which a point takes the separable form.
    pub limit: f64,
}

/// The conclusions of one output over the inputs it depends on.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OutputGrid {
    /// The inputs `S_o` the conclusions depend on, in input order.
    pub inputs: Vec<usize>,
    /// The conclusion of every combination of sets of `inputs` (the last input's set varying
    /// fastest).
    pub terms: Vec<f64>,
    /// For every entry of `terms`, the grade slot (a set's index) of each of `inputs`.
    pub factors: Vec<u32>,
}

impl Separable {
    /// The number of grade slots: one per set (`P_{ik}`), then one per input (`S_i`).
    pub(crate) fn grade_count(&self) -> usize {
        self.sets.len() + self.set_offsets.len() - 1
    }

    /// The separable form of a system, if it has one: `mfs` input by input as `mf_inputs`
    /// says, `terms[o]` output `o`'s terms' values (`None` for a first-order term).
    pub(crate) fn new(
        mfs: &[CompiledMf],
        mf_inputs: &[usize],
        terms: &[Vec<Option<f64>>],
        rules: &[Rule],
        methods: Methods,
    ) -> Option<Self> {
        if methods.and != AndMethod::Product
            || methods.defuzzification != Defuzzification::WeightedAverage
        {
            return None;
        }
        let n_in = mf_inputs.last()? + 1;
        let mut counts = vec![0usize; n_in];
        for &j in mf_inputs {
            counts[j] += 1;
        }
        let mut set_offsets = vec![0];
        for (i, &count) in counts.iter().enumerate() {
            if count == 0 || count > MAX_SEPARABLE_SETS {
                return None;
            }
            set_offsets.push(set_offsets[i] + count);
        }
        let mut exponent = None;
        let mut sets = Vec::with_capacity(mfs.len());
        for mf in mfs {
            let (center, width, e) = match *mf {
                CompiledMf::BellSquare { center, width } => (center, width, 2),
                CompiledMf::BellQuartic { center, width } => (center, width, 4),
                CompiledMf::BellInteger {
                    center,
                    width,
                    exponent,
                } => (center, width, exponent),
                _ => return None,
            };
            if *exponent.get_or_insert(e) != e {
                return None;
            }
            sets.push([center, 1.0 / width]);
        }
        let counts: Vec<usize> = set_offsets.windows(2).map(|w| w[1] - w[0]).collect();
        // A complete grid: every combination of one set per input exactly once, every rule a
        // weighted-1 AND concluding on every output.
        let cells: usize = counts.iter().product();
        let mut cell_rule = vec![usize::MAX; cells];
        for (r, rule) in rules.iter().enumerate() {
            if rule.weight != 1.0
                || rule.connective != Connective::And
                || rule.consequents.iter().any(Option::is_none)
            {
                return None;
            }
            let mut cell = 0;
            for (antecedent, &count) in rule.antecedents.iter().zip(&counts) {
                let Antecedent::Is(k) = *antecedent else {
                    return None;
                };
                cell = cell * count + k;
            }
            if cell_rule[cell] != usize::MAX {
                return None;
            }
            cell_rule[cell] = r;
        }
        if cell_rule.contains(&usize::MAX) {
            return None;
        }
        // The sets of cell `cell`, input by input.
        let sets_of = |mut cell: usize| {
            let mut k = vec![0; n_in];
            for i in (0..n_in).rev() {
                k[i] = cell % counts[i];
                cell /= counts[i];
            }
            k
        };
        let cell_of = |k: &[usize]| k.iter().zip(&counts).fold(0, |c, (&k, &n)| c * n + k);
        let mut outputs = Vec::with_capacity(terms.len());
        let mut largest = 0.0_f64;
        let mut exponent_sum = 0;
        for (o, values) in terms.iter().enumerate() {
            let value = |cell: usize| values[rules[cell_rule[cell]].consequents[o]?];
            // Input `i` matters to the output if changing its set alone changes a conclusion.
            let mut inputs = Vec::new();
            for i in 0..n_in {
                let mut matters = false;
                for cell in 0..cells {
                    let z = value(cell)?;
                    let mut k = sets_of(cell);
                    for other in 0..counts[i] {
                        k[i] = other;
                        matters |= value(cell_of(&k))? != z;
                    }
                }
                if matters {
                    inputs.push(i);
                }
            }
            let grid: usize = inputs.iter().map(|&i| counts[i]).product();
            let (mut grid_terms, mut factors) = (Vec::with_capacity(grid), Vec::new());
            for entry in 0..grid {
                // The sets of `inputs` of this entry; the other inputs' sets at 0.
                let mut k = vec![0; n_in];
                let mut rest = entry;
                for &i in inputs.iter().rev() {
                    k[i] = rest % counts[i];
                    rest /= counts[i];
                }
                let z = value(cell_of(&k))?;
                largest = largest.max(z.abs());
                grid_terms.push(z);
                factors.extend(inputs.iter().map(|&i| (set_offsets[i] + k[i]) as u32));
            }
            exponent_sum = inputs
                .iter()
                .map(|&i| counts[i] - 1)
                .sum::<usize>()
                .max(exponent_sum);
            outputs.push(OutputGrid {
                inputs,
                terms: grid_terms,
                factors,
            });
        }
        // Every product of the form stays below 2^1000: a term `z prod P` is at most
        // `|z| limit^exponent_sum`, summed over at most `cells` terms; the general kernel's
        // strengths, products of `n_in` degrees of at least `1 / limit`, stay normal.
        let headroom = 1000.0 - largest.max(1.0).log2().ceil() - (cells as f64).log2().ceil();
        let per_factor = (headroom / exponent_sum.max(1) as f64)
            .min(900.0 / n_in as f64)
            .min(64.0)
            .floor();
        if per_factor < 8.0 {
            return None;
        }
        let sets_per_input = Some(counts[0]).filter(|&c| counts.iter().all(|&k| k == c));
        Some(Self {
            sets,
            exponent: exponent?,
            set_offsets,
            sets_per_input,
            outputs,
            limit: per_factor.exp2(),
        })
    }

    /// Whether every grade and factor slot is within [`grade_count`](Self::grade_count): the
    /// condition under which the kernel reads them without bounds checks.
    pub(crate) fn slots_in_bounds(&self) -> bool {
        let n_sets = self.sets.len();
        let n_in = self.set_offsets.len() - 1;
        self.set_offsets.first() == Some(&0)
            && (self.set_offsets.windows(2))
                .all(|w| w[0] < w[1] && w[1] - w[0] <= MAX_SEPARABLE_SETS)
            && self.set_offsets.last() == Some(&n_sets)
            && self.sets_per_input.is_none_or(|c| {
                c * n_in == n_sets
                    && (self.outputs.iter())
                        .all(|g| Some(g.terms.len()) == c.checked_pow(g.inputs.len() as u32))
            })
            && self.outputs.iter().all(|g| {
                g.inputs.iter().all(|&i| i < n_in)
                    && g.factors.len() == g.terms.len() * g.inputs.len()
                    && g.factors.iter().all(|&s| (s as usize) < n_sets)
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        Evaluator, FuzzySet, FuzzySystem, MembershipFn, OutputFn, PaperController, paper_controller,
    };

    /// The bound of the separable form against the general kernel, in units of `f64::EPSILON`
    /// times the largest magnitude of a conclusion of the output.
    const BOUND_EPS: f64 = 8.0;

    /// A uniform draw in `[-1, 1)` from a 64-bit linear congruential generator.
    fn draw(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// The largest difference between the separable form and the general kernel over `points`
    /// random points within `spread` times each input's range, in units of `f64::EPSILON` times
    /// the output's largest conclusion; asserts every point within [`BOUND_EPS`] and that the
    /// separable form was taken.
    fn worst_difference(system: &FuzzySystem, spread: f64, points: usize) -> f64 {
        assert!(system.compiled().separable.is_some());
        let mut fast = Evaluator::new(system.clone());
        let mut general = Evaluator::new(system.clone().without_separable_form());
        let n_out = system.outputs().len();
        let largest: Vec<f64> = (system.outputs().iter())
            .map(|o| {
                (o.terms.iter())
                    .map(|t| match t.function {
                        OutputFn::Constant(c) => c.abs(),
                        OutputFn::Linear { .. } => unreachable!("zero-order"),
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        let (mut y, mut y_ref) = (vec![0.0; n_out], vec![0.0; n_out]);
        let mut state = 7;
        let mut worst = 0.0_f64;
        for _ in 0..points {
            let x: Vec<f64> = (system.inputs().iter())
                .map(|v| {
                    let [lo, hi] = v.range;
                    0.5 * (lo + hi) + spread * 0.5 * (hi - lo) * draw(&mut state)
                })
                .collect();
            fast.eval(&x, &mut y).unwrap();
            general.eval(&x, &mut y_ref).unwrap();
            for o in 0..n_out {
                let units = (y[o] - y_ref[o]).abs() / (f64::EPSILON * largest[o]);
                assert!(
                    units <= BOUND_EPS,
                    "output {o} at {x:?}: {} against {}",
                    y[o],
                    y_ref[o]
                );
                worst = worst.max(units);
            }
        }
        worst
    }

    #[test]
    fn the_paper_controller_separates_into_two_grids_of_two_inputs() {
        let s = paper_controller().compiled().separable.clone().unwrap();
        assert_eq!(s.exponent, 4);
        assert_eq!(s.outputs[0].inputs, [0, 2]);
        assert_eq!(s.outputs[1].inputs, [1, 3]);
        // tau1*: (N, N) -> VP, (N, P) -> P, (P, N) -> N, (P, P) -> VN.
        assert_eq!(s.outputs[0].terms, [100.0, 80.0, -80.0, -100.0]);
        assert_eq!(s.outputs[0].factors, [0, 4, 0, 5, 1, 4, 1, 5]);
        assert_eq!(s.limit, 2f64.powi(64));
    }

    /// Within the ranges and well outside them (five times, as the `AsGiven` policy evaluates
    /// them), the separable form stays within its bound of the general kernel.
    #[test]
    fn the_paper_controller_stays_within_the_bound_of_the_general_kernel() {
        let system = paper_controller();
        let inside = worst_difference(&system, 1.0, 20_000);
        let outside = worst_difference(&system, 5.0, 20_000);
        eprintln!("worst: {inside:.2} eps inside the ranges, {outside:.2} eps within 5 times");
        // Other bell exponents and widths.
        for slope in [1.0, 1.5, 3.0] {
            let system = PaperController {
                slope,
                width_fraction: 0.7,
                ..PaperController::default()
            }
            .build()
            .unwrap();
            worst_difference(&system, 3.0, 5_000);
        }
    }

    /// A complete grid of three inputs with three sets each whose one output depends on all
    /// three (27 distinct conclusions), and a second that depends on none.
    #[test]
    fn a_grid_of_27_conclusions_stays_within_the_bound() {
        let sets = |name: &str| {
            let sets = (0..3).map(|k| {
                (
                    format!("{name}{k}"),
                    MembershipFn::bell(0.6, 1.0, k as f64 - 1.0),
                )
            });
            sets.collect::<Vec<_>>()
        };
        let terms = (0..27).map(|k| (format!("z{k}"), OutputFn::Constant(k as f64 * 3.7 - 50.0)));
        let mut builder = FuzzySystem::builder("grid27")
            .input("x", [-1.0, 1.0], sets("x"))
            .input("y", [-1.0, 1.0], sets("y"))
            .input("w", [-1.0, 1.0], sets("w"))
            .output("z", [-50.0, 50.0], terms.collect::<Vec<_>>())
            .output("c", [0.0, 10.0], [("c", OutputFn::Constant(4.0))]);
        for k in 0..27 {
            let rule = Rule {
                antecedents: vec![
                    Antecedent::Is(k / 9),
                    Antecedent::Is(k / 3 % 3),
                    Antecedent::Is(k % 3),
                ],
                consequents: vec![Some(26 - k), Some(0)],
                weight: 1.0,
                connective: Connective::And,
            };
            builder = builder.indexed_rule(rule);
        }
        let system = builder.build().unwrap();
        let s = system.compiled().separable.clone().unwrap();
        assert_eq!(s.outputs[0].inputs, [0, 1, 2]);
        assert!(s.outputs[1].inputs.is_empty());
        worst_difference(&system, 2.0, 5_000);
        let mut out = [0.0; 2];
        Evaluator::new(system)
            .eval(&[0.3, -0.2, 0.9], &mut out)
            .unwrap();
        assert_eq!(out[1], 4.0);
    }

    /// A complete grid of `n_in` inputs with `c` bells each (`b = 2`) over `[-1, 1]` and one
    /// output per entry of `depends`, whose conclusions are distinct for every combination of
    /// the sets of the inputs it lists.
    fn uniform_grid(n_in: usize, c: usize, depends: &[&[usize]]) -> FuzzySystem {
        let step = 2.0 / (c - 1).max(1) as f64;
        let sets: Vec<_> = (0..c)
            .map(|k| {
                (
                    format!("S{k}"),
                    MembershipFn::bell(0.4 * step, 2.0, k as f64 * step - 1.0),
                )
            })
            .collect();
        let cells = c.pow(n_in as u32);
        let mut builder = FuzzySystem::builder("uniform");
        for i in 0..n_in {
            builder = builder.input(format!("x{i}"), [-1.0, 1.0], sets.clone());
        }
        for o in 0..depends.len() {
            let terms = (0..cells).map(|k| {
                (
                    format!("z{k}"),
                    OutputFn::Constant(3.1 * k as f64 - 7.0 * o as f64),
                )
            });
            builder = builder.output(format!("y{o}"), [-500.0, 500.0], terms.collect::<Vec<_>>());
        }
        for cell in 0..cells {
            let digits: Vec<usize> = (0..n_in)
                .map(|i| cell / c.pow((n_in - 1 - i) as u32) % c)
                .collect();
            let consequents = depends
                .iter()
                .map(|inputs| Some(inputs.iter().fold(0, |t, &i| t * c + digits[i])))
                .collect();
            builder = builder.indexed_rule(Rule {
                antecedents: digits.iter().map(|&k| Antecedent::Is(k)).collect(),
                consequents,
                weight: 1.0,
                connective: Connective::And,
            });
        }
        builder.build().unwrap()
    }

    /// Inputs with the same number of sets take the unrolled grids of the kernel: the same bits
    /// as the factor tables, alone and in a batch, for every count of sets and inputs it unrolls
    /// and beyond.
    #[test]
    fn uniform_sets_give_the_bits_of_the_factor_tables() {
        let systems = [
            paper_controller(),
            uniform_grid(3, 2, &[&[0], &[0, 2], &[2, 0, 1], &[]]),
            uniform_grid(3, 3, &[&[1], &[2, 0], &[0, 1, 2]]),
            uniform_grid(2, 4, &[&[0, 1], &[1]]),
            uniform_grid(4, 2, &[&[0, 1, 2, 3]]),
        ];
        let bits = |y: &[f64]| y.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let mut state = 11;
        for system in systems {
            let s = system.compiled().separable.clone().unwrap();
            assert!(s.sets_per_input.is_some(), "{}", system.name());
            let (n_in, n_out) = (system.inputs().len(), system.outputs().len());
            let mut uniform = Evaluator::new(system.clone());
            let mut tables = Evaluator::new(system.without_uniform_sets());
            let rows: Vec<f64> = (0..n_in * 37).map(|_| 1.5 * draw(&mut state)).collect();
            let (mut y, mut y_ref) = (vec![0.0; n_out * 37], vec![0.0; n_out * 37]);
            uniform.eval_batch(&rows, &mut y).unwrap();
            tables.eval_batch(&rows, &mut y_ref).unwrap();
            assert_eq!(bits(&y), bits(&y_ref));
            for (x, y_ref) in rows.chunks_exact(n_in).zip(y_ref.chunks_exact(n_out)) {
                let mut alone = vec![0.0; n_out];
                uniform.eval(x, &mut alone).unwrap();
                assert_eq!(bits(&alone), bits(y_ref));
            }
        }
    }

    /// Far outside the ranges, where an `A` exceeds the limit, the point goes to the general
    /// kernel: the same bits as without the separable form, alone and in a batch.
    #[test]
    fn points_beyond_the_limit_take_the_general_kernel() {
        let system = paper_controller();
        let mut fast = Evaluator::new(system.clone());
        let mut general = Evaluator::new(system.without_separable_form());
        let far = [0.1, 1e7, -0.2, 1e300];
        let (mut y, mut y_ref) = ([0.0; 2], [0.0; 2]);
        fast.eval(&far, &mut y).unwrap();
        general.eval(&far, &mut y_ref).unwrap();
        assert_eq!(y.map(f64::to_bits), y_ref.map(f64::to_bits));
        // One far row among near ones: every row as alone.
        let mut rows: Vec<f64> = (0..16 * 4).map(|k| 0.05 * (k as f64).sin()).collect();
        rows[4 * 5..4 * 6].copy_from_slice(&far);
        let mut batch = vec![0.0; 16 * 2];
        fast.eval_batch(&rows, &mut batch).unwrap();
        for (x, y) in rows.chunks_exact(4).zip(batch.chunks_exact(2)) {
            let mut alone = [0.0; 2];
            fast.eval(x, &mut alone).unwrap();
            assert_eq!(y[0].to_bits(), alone[0].to_bits());
            assert_eq!(y[1].to_bits(), alone[1].to_bits());
        }
    }

    /// What has no separable form: a rule missing from the grid, a weight below 1, a "don't
    /// care", another kind of set, bells of two exponents, the minimum as AND.
    #[test]
    fn other_rule_bases_have_no_separable_form() {
        type Edit<'a> = &'a dyn Fn(&mut Vec<FuzzySet>, &mut Vec<Rule>);
        let separable = |and: AndMethod, edit: Edit| {
            let system = paper_controller();
            let mut rules = system.rules().to_vec();
            let mut first_sets = system.inputs()[0].sets.clone();
            edit(&mut first_sets, &mut rules);
            let mut builder = FuzzySystem::builder("edited").and_method(and);
            for (i, input) in system.inputs().iter().enumerate() {
                let sets = if i == 0 { &first_sets } else { &input.sets };
                let sets: Vec<_> = (sets.iter())
                    .map(|s| (s.name.clone(), s.membership))
                    .collect();
                builder = builder.input(&input.name, input.range, sets);
            }
            for output in system.outputs() {
                let terms: Vec<_> = (output.terms.iter())
                    .map(|t| (t.name.clone(), t.function.clone()))
                    .collect();
                builder = builder.output(&output.name, output.range, terms);
            }
            for rule in rules {
                builder = builder.indexed_rule(rule);
            }
            builder.build().unwrap().compiled().separable.is_some()
        };
        let product = AndMethod::Product;
        assert!(separable(product, &|_, _| {}));
        assert!(!separable(AndMethod::Minimum, &|_, _| {}));
        assert!(!separable(product, &|_, rules| {
            rules.pop();
        }));
        assert!(!separable(product, &|_, rules| rules[3].weight = 0.5));
        assert!(!separable(product, &|_, rules| {
            rules[3].antecedents[1] = Antecedent::Any
        }));
        assert!(!separable(product, &|sets, _| {
            sets[0].membership = MembershipFn::Gaussian {
                sigma: 0.1,
                center: -0.3,
            }
        }));
        assert!(!separable(product, &|sets, _| {
            sets[0].membership = MembershipFn::bell(0.3, 1.0, -0.3)
        }));
    }
}
