//! Random systems and an independent, deliberately naive reference evaluator written straight
//! from MATLAB's formulas and eq 21.

use fuzzy_sugeno::{
    AndMethod, Antecedent, Connective, Defuzzification, FuzzySystem, MembershipFn, OrMethod,
    OutputFn, Rule,
};

/// SplitMix64: a small deterministic generator driven by a proptest-chosen seed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    fn name(&mut self, k: usize) -> String {
        const ALPHABET: &[u8] =
            b"abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 _-.";
        let len = 1 + self.below(6);
        let stem: String = (0..len)
            .map(|_| ALPHABET[self.below(ALPHABET.len())] as char)
            .collect();
        format!("{}{k}", stem.trim_start_matches('-'))
    }
}

fn random_membership(rng: &mut Rng, lo: f64, hi: f64) -> MembershipFn {
    let w = hi - lo;
    let mut sorted = |n: usize| {
        let mut v: Vec<f64> = (0..n)
            .map(|_| rng.range(lo - 0.2 * w, hi + 0.2 * w))
            .collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let p = sorted(4);
    match rng.below(12) {
        0 => {
            let slope = [1.0, 2.0, 3.0, 1.5, 0.5, rng.range(0.3, 5.0)][rng.below(6)];
            MembershipFn::bell(rng.range(0.05, 1.0) * w, slope, rng.range(lo, hi))
        }
        1 => MembershipFn::gaussian(rng.range(0.05, 1.0) * w, rng.range(lo, hi)),
        2 => MembershipFn::Gaussian2 {
            sigma1: rng.range(0.05, 0.5) * w,
            center1: p[1],
            sigma2: rng.range(0.05, 0.5) * w,
            center2: if rng.chance(0.8) { p[2] } else { p[0] },
        },
        3 => MembershipFn::triangle(p[0], p[1], p[2]),
        4 => MembershipFn::trapezoid(p[0], p[1], p[2], p[3]),
        5 => MembershipFn::sigmoid(rng.range(-20.0, 20.0) / w, rng.range(lo, hi)),
        6 => MembershipFn::SigmoidDifference {
            slope1: rng.range(1.0, 20.0) / w,
            center1: p[0],
            slope2: rng.range(1.0, 20.0) / w,
            center2: p[3],
        },
        7 => MembershipFn::SigmoidProduct {
            slope1: rng.range(1.0, 20.0) / w,
            center1: p[0],
            slope2: -rng.range(1.0, 20.0) / w,
            center2: p[3],
        },
        // Sometimes MATLAB's step (start >= end).
        8 if rng.chance(0.2) => MembershipFn::SShape {
            start: p[2],
            end: p[0],
        },
        8 => MembershipFn::SShape {
            start: p[0],
            end: p[2],
        },
        9 if rng.chance(0.2) => MembershipFn::ZShape {
            start: p[3],
            end: p[1],
        },
        9 => MembershipFn::ZShape {
            start: p[1],
            end: p[3],
        },
        10 => MembershipFn::PiShape {
            left_foot: p[0],
            left_shoulder: p[1],
            right_shoulder: p[2],
            right_foot: p[3],
        },
        _ => MembershipFn::Constant { value: rng.unit() },
    }
}

/// A random valid system: 1-4 inputs with 1-4 sets each (or none, as MATLAB's `NumMFs=0`, for
/// inputs after the first), set and term names that sometimes repeat (as MATLAB allows), 1-3
/// outputs, 1-12 rules with negations, don't-cares, weights and OR rules; constant consequents
/// only if `zero_order`.
pub fn random_system(seed: u64, zero_order: bool) -> FuzzySystem {
    let mut rng = Rng::new(seed);
    let n_in = 1 + rng.below(4);
    let n_out = 1 + rng.below(3);
    let mut builder = FuzzySystem::builder(rng.name(0))
        .and_method(if rng.chance(0.5) {
            AndMethod::Product
        } else {
            AndMethod::Minimum
        })
        .or_method(if rng.chance(0.5) {
            OrMethod::ProbabilisticSum
        } else {
            OrMethod::Maximum
        })
        .defuzzification(if zero_order || rng.chance(0.7) {
            Defuzzification::WeightedAverage
        } else {
            Defuzzification::WeightedSum
        });
    let mut set_counts = Vec::new();
    for i in 0..n_in {
        let lo = rng.range(-5.0, 5.0);
        let hi = lo + rng.range(0.5, 10.0);
        let n_sets = if i > 0 && rng.chance(0.15) {
            0
        } else {
            1 + rng.below(4)
        };
        set_counts.push(n_sets);
        let mut sets: Vec<(String, MembershipFn)> = Vec::new();
        for k in 0..n_sets {
            let name = match sets.last() {
                Some((previous, _)) if rng.chance(0.15) => previous.clone(),
                _ => rng.name(k),
            };
            sets.push((name, random_membership(&mut rng, lo, hi)));
        }
        builder = builder.input(format!("in{i}"), [lo, hi], sets);
    }
    let mut term_counts = Vec::new();
    for o in 0..n_out {
        let lo = rng.range(-100.0, 100.0);
        let hi = lo + rng.range(1.0, 100.0);
        let n_terms = 1 + rng.below(4);
        term_counts.push(n_terms);
        let terms: Vec<(String, OutputFn)> = (0..n_terms)
            .map(|k| {
                let function = if zero_order || rng.chance(0.5) {
                    OutputFn::Constant(rng.range(lo, hi))
                } else {
                    let coefficients = (0..n_in).map(|_| rng.range(-3.0, 3.0)).collect();
                    OutputFn::Linear {
                        coefficients,
                        constant: rng.range(lo, hi),
                    }
                };
                let name = if k > 0 && rng.chance(0.15) {
                    "shared".to_string()
                } else {
                    rng.name(k)
                };
                (name, function)
            })
            .collect();
        builder = builder.output(format!("out{o}"), [lo, hi], terms);
    }
    for _ in 0..1 + rng.below(12) {
        let mut antecedents: Vec<Antecedent> = set_counts
            .iter()
            .map(|&n| match rng.unit() {
                _ if n == 0 => Antecedent::Any,
                u if u < 0.25 => Antecedent::Any,
                u if u < 0.85 => Antecedent::Is(rng.below(n)),
                _ => Antecedent::IsNot(rng.below(n)),
            })
            .collect();
        if antecedents.iter().all(|a| *a == Antecedent::Any) {
            antecedents[0] = Antecedent::Is(0);
        }
        let mut consequents: Vec<Option<usize>> = term_counts
            .iter()
            .map(|&n| {
                if rng.chance(0.2) {
                    None
                } else {
                    Some(rng.below(n))
                }
            })
            .collect();
        if consequents.iter().all(Option::is_none) {
            consequents[0] = Some(0);
        }
        let weight = if rng.chance(0.5) { 1.0 } else { rng.unit() };
        let connective = if rng.chance(0.75) {
            Connective::And
        } else {
            Connective::Or
        };
        builder = builder.indexed_rule(Rule {
            antecedents,
            consequents,
            weight,
            connective,
        });
    }
    builder
        .build()
        .expect("random systems are valid by construction")
}

/// A random input vector, 20% beyond each end of the ranges.
pub fn random_point(system: &FuzzySystem, rng: &mut Rng) -> Vec<f64> {
    system
        .inputs()
        .iter()
        .map(|v| {
            let w = v.range[1] - v.range[0];
            rng.range(v.range[0] - 0.2 * w, v.range[1] + 0.2 * w)
        })
        .collect()
}

/// MATLAB's formulas, written out independently of the crate.
pub fn reference_mu(mf: &MembershipFn, x: f64) -> f64 {
    let sig = |a: f64, c: f64| 1.0 / (1.0 + (-a * (x - c)).exp());
    let gauss = |s: f64, c: f64| (-(x - c).powi(2) / (2.0 * s * s)).exp();
    match *mf {
        MembershipFn::Bell {
            width,
            slope,
            center,
        } => 1.0 / (1.0 + ((x - center) / width).abs().powf(2.0 * slope)),
        MembershipFn::Gaussian { sigma, center } => gauss(sigma, center),
        MembershipFn::Gaussian2 {
            sigma1,
            center1,
            sigma2,
            center2,
        } => {
            let left = if x <= center1 {
                gauss(sigma1, center1)
            } else {
                1.0
            };
            let right = if x >= center2 {
                gauss(sigma2, center2)
            } else {
                1.0
            };
            left * right
        }
        // Random corners are distinct, so the closed forms need no special cases.
        MembershipFn::Triangle { left, peak, right } => ((x - left) / (peak - left))
            .min((right - x) / (right - peak))
            .max(0.0),
        MembershipFn::Trapezoid {
            left_foot: a,
            left_shoulder: b,
            right_shoulder: c,
            right_foot: d,
        } => ((x - a) / (b - a)).min(1.0).min((d - x) / (d - c)).max(0.0),
        MembershipFn::Sigmoid { slope, center } => sig(slope, center),
        MembershipFn::SigmoidDifference {
            slope1,
            center1,
            slope2,
            center2,
        } => (sig(slope1, center1) - sig(slope2, center2)).abs(),
        MembershipFn::SigmoidProduct {
            slope1,
            center1,
            slope2,
            center2,
        } => sig(slope1, center1) * sig(slope2, center2),
        MembershipFn::SShape { start, end } => reference_s(x, start, end),
        MembershipFn::ZShape { start, end } => reference_z(x, start, end),
        MembershipFn::PiShape {
            left_foot,
            left_shoulder,
            right_shoulder,
            right_foot,
        } => reference_s(x, left_foot, left_shoulder) * reference_z(x, right_shoulder, right_foot),
        MembershipFn::Constant { value } => value,
    }
}

/// MATLAB's `smf(x, [a b])`, its step for `a >= b` included.
fn reference_s(x: f64, a: f64, b: f64) -> f64 {
    if a >= b {
        return if x >= (a + b) / 2.0 { 1.0 } else { 0.0 };
    }
    let m = (a + b) / 2.0;
    if x <= a {
        0.0
    } else if x <= m {
        2.0 * ((x - a) / (b - a)).powi(2)
    } else if x < b {
        1.0 - 2.0 * ((x - b) / (b - a)).powi(2)
    } else {
        1.0
    }
}

/// MATLAB's `zmf(x, [a b])`, its step for `a >= b` included.
fn reference_z(x: f64, a: f64, b: f64) -> f64 {
    if a >= b {
        return if x <= (a + b) / 2.0 { 1.0 } else { 0.0 };
    }
    let m = (a + b) / 2.0;
    if x <= a {
        1.0
    } else if x <= m {
        1.0 - 2.0 * ((x - a) / (b - a)).powi(2)
    } else if x < b {
        2.0 * ((x - b) / (b - a)).powi(2)
    } else {
        0.0
    }
}

/// Rule strengths and outputs (`None` where no rule fired) at `x`, inputs as given (the
/// evaluator's default, MATLAB's `evalfis`), even outside their ranges.
pub fn reference_eval(system: &FuzzySystem, x: &[f64]) -> (Vec<f64>, Vec<Option<f64>>) {
    let methods = system.methods();
    let strengths: Vec<f64> = system
        .rules()
        .iter()
        .map(|rule| {
            let degrees: Vec<f64> = rule
                .antecedents
                .iter()
                .enumerate()
                .filter_map(|(i, a)| match *a {
                    Antecedent::Any => None,
                    Antecedent::Is(k) => {
                        Some(reference_mu(&system.inputs()[i].sets[k].membership, x[i]))
                    }
                    Antecedent::IsNot(k) => {
                        Some(1.0 - reference_mu(&system.inputs()[i].sets[k].membership, x[i]))
                    }
                })
                .collect();
            let combined = match (rule.connective, methods.and, methods.or) {
                (Connective::And, AndMethod::Product, _) => degrees.iter().product(),
                (Connective::And, AndMethod::Minimum, _) => {
                    degrees.iter().copied().fold(1.0, f64::min)
                }
                (Connective::Or, _, OrMethod::Maximum) => {
                    degrees.iter().copied().fold(0.0, f64::max)
                }
                // MATLAB's probor, applied pairwise: a + b - a b. (The equivalent product form
                // 1 - (1 - a)(1 - b) cancels catastrophically for tiny degrees.)
                (Connective::Or, _, OrMethod::ProbabilisticSum) => degrees
                    .iter()
                    .skip(1)
                    .fold(degrees[0], |a, &b| a + b - a * b),
            };
            rule.weight * combined
        })
        .collect();
    let outputs = system
        .outputs()
        .iter()
        .enumerate()
        .map(|(o, output)| {
            let mut weighted = 0.0;
            let mut total = 0.0;
            for (rule, w) in system.rules().iter().zip(&strengths) {
                if let Some(t) = rule.consequents[o] {
                    let z = match &output.terms[t].function {
                        OutputFn::Constant(c) => *c,
                        OutputFn::Linear {
                            coefficients,
                            constant,
                        } => constant + coefficients.iter().zip(x).map(|(p, v)| p * v).sum::<f64>(),
                    };
                    weighted += w * z;
                    total += w;
                }
            }
            (total > 0.0).then(|| match methods.defuzzification {
                Defuzzification::WeightedAverage => weighted / total,
                Defuzzification::WeightedSum => weighted,
            })
        })
        .collect();
    (strengths, outputs)
}

/// A system using what validation allows beyond MATLAB's usual files: an input `b` with no sets
/// (`NumMFs=0`) between two that have sets, and an output whose range is the single point 2
/// (so "no rule fired" falls back to 2), with a linear and a constant term, smf/zmf/pimf sets
/// and a step.
pub fn relaxed_system() -> FuzzySystem {
    let sets = |a: f64| {
        vec![
            (
                "low".to_string(),
                MembershipFn::ZShape {
                    start: a,
                    end: a + 0.6,
                },
            ),
            (
                "mid".to_string(),
                MembershipFn::PiShape {
                    left_foot: a + 0.1,
                    left_shoulder: a + 0.4,
                    right_shoulder: a + 0.6,
                    right_foot: a + 0.9,
                },
            ),
            (
                "high".to_string(),
                MembershipFn::SShape {
                    start: a + 0.7,
                    end: a + 0.3,
                },
            ),
        ]
    };
    let rule = |a: usize, c: usize, term: usize| Rule {
        antecedents: vec![Antecedent::Is(a), Antecedent::Any, Antecedent::Is(c)],
        consequents: vec![Some(term)],
        weight: 1.0,
        connective: Connective::And,
    };
    FuzzySystem::builder("relaxed")
        .input("a", [0.0, 1.0], sets(0.0))
        .input("b", [-1.0, 1.0], Vec::<(String, MembershipFn)>::new())
        .input("c", [0.0, 1.0], sets(0.0))
        .output(
            "y",
            [2.0, 2.0],
            vec![
                (
                    "slope".to_string(),
                    OutputFn::Linear {
                        coefficients: vec![1.0, 5.0, -2.0],
                        constant: 0.5,
                    },
                ),
                ("level".to_string(), OutputFn::Constant(-1.0)),
            ],
        )
        .indexed_rule(rule(0, 0, 0))
        .indexed_rule(rule(1, 2, 1))
        .indexed_rule(rule(2, 1, 0))
        .build()
        .expect("validation accepts empty inputs and point output ranges")
}

/// A system without rules (a `.fis` file may declare `NumRules=0`): one input with one set, one
/// output on `[2, 8]` (so "no rule fired" falls back to 5).
pub fn without_rules() -> FuzzySystem {
    FuzzySystem::builder("empty")
        .input(
            "x",
            [0.0, 1.0],
            [("lo", MembershipFn::triangle(0.0, 0.0, 0.5))],
        )
        .output("y", [2.0, 8.0], [("a", OutputFn::Constant(2.0))])
        .build()
        .unwrap()
}
