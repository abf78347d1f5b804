//! Every error path: bad models, wrong sizes, non-finite inputs, a workspace of another chain,
//! overflow, and a mass matrix that is not numerically positive definite.

use faer::Mat;
use manip_dyn::{
    ChainData, ChainModel, DynError, Link, aba, coriolis, coriolis_matrix, forward_dynamics,
    gravity, kinetic_energy, mass_matrix, nonlinear_effects, potential_energy, rnea,
};

/// Arguments of one call; `third` is `qdd` for RNEA and `tau` for forward dynamics.
struct Args {
    q: Vec<f64>,
    v: Vec<f64>,
    third: Vec<f64>,
    out: Vec<f64>,
    matrix: Mat<f64>,
}

impl Args {
    fn new(n: usize) -> Self {
        Args {
            q: vec![0.3; n],
            v: vec![0.5; n],
            third: vec![0.7; n],
            out: vec![0.0; n],
            matrix: Mat::zeros(n, n),
        }
    }

    fn input(&mut self, name: &str) -> &mut Vec<f64> {
        match name {
            "q" => &mut self.q,
            "v" => &mut self.v,
            _ => &mut self.third,
        }
    }
}

type Call = fn(&ChainModel, &mut ChainData, &mut Args) -> Result<(), DynError>;

/// One public algorithm: its name, a call, the names of its vector inputs, and the name of its
/// vector output (`None` for matrix or scalar results).
struct Algorithm {
    name: &'static str,
    call: Call,
    inputs: &'static [&'static str],
    output: Option<&'static str>,
    matrix_output: bool,
}

const ALGORITHMS: [Algorithm; 10] = [
    Algorithm {
        name: "rnea",
        call: |m, d, x| rnea(m, d, &x.q, &x.v, &x.third, &mut x.out),
        inputs: &["q", "v", "qdd"],
        output: Some("tau"),
        matrix_output: false,
    },
    Algorithm {
        name: "coriolis",
        call: |m, d, x| coriolis(m, d, &x.q, &x.v, &mut x.out),
        inputs: &["q", "v"],
        output: Some("out"),
        matrix_output: false,
    },
    Algorithm {
        name: "gravity",
        call: |m, d, x| gravity(m, d, &x.q, &mut x.out),
        inputs: &["q"],
        output: Some("out"),
        matrix_output: false,
    },
    Algorithm {
        name: "nonlinear_effects",
        call: |m, d, x| nonlinear_effects(m, d, &x.q, &x.v, &mut x.out),
        inputs: &["q", "v"],
        output: Some("out"),
        matrix_output: false,
    },
    Algorithm {
        name: "mass_matrix",
        call: |m, d, x| mass_matrix(m, d, &x.q, x.matrix.as_mut()),
        inputs: &["q"],
        output: None,
        matrix_output: true,
    },
    Algorithm {
        name: "coriolis_matrix",
        call: |m, d, x| coriolis_matrix(m, d, &x.q, &x.v, x.matrix.as_mut()),
        inputs: &["q", "v"],
        output: None,
        matrix_output: true,
    },
    Algorithm {
        name: "aba",
        call: |m, d, x| aba(m, d, &x.q, &x.v, &x.third, &mut x.out),
        inputs: &["q", "v", "tau"],
        output: Some("qdd"),
        matrix_output: false,
    },
    Algorithm {
        name: "forward_dynamics",
        call: |m, d, x| forward_dynamics(m, d, &x.q, &x.v, &x.third, &mut x.out),
        inputs: &["q", "v", "tau"],
        output: Some("qdd"),
        matrix_output: false,
    },
    Algorithm {
        name: "kinetic_energy",
        call: |m, d, x| kinetic_energy(m, d, &x.q, &x.v).map(drop),
        inputs: &["q", "v"],
        output: None,
        matrix_output: false,
    },
    Algorithm {
        name: "potential_energy",
        call: |m, d, x| potential_energy(m, d, &x.q).map(drop),
        inputs: &["q"],
        output: None,
        matrix_output: false,
    },
];

const N: usize = 4;

fn arm() -> ChainModel {
    ChainModel::uniform(N, 0.25, 0.5, 9.81).unwrap()
}

#[test]
fn valid_calls_succeed() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    for algorithm in &ALGORITHMS {
        let mut args = Args::new(N);
        assert_eq!(
            (algorithm.call)(&arm, &mut data, &mut args),
            Ok(()),
            "{}",
            algorithm.name
        );
    }
}

#[test]
fn wrong_input_lengths_are_refused() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    for algorithm in &ALGORITHMS {
        for &input in algorithm.inputs {
            for found in [0, N - 1, N + 1] {
                let mut args = Args::new(N);
                args.input(input).resize(found, 0.1);
                let expected = DynError::Dimension {
                    name: input,
                    expected: N,
                    found,
                };
                assert_eq!(
                    (algorithm.call)(&arm, &mut data, &mut args),
                    Err(expected),
                    "{}",
                    algorithm.name
                );
            }
        }
    }
}

#[test]
fn non_finite_inputs_are_refused() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    for algorithm in &ALGORITHMS {
        for &input in algorithm.inputs {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut args = Args::new(N);
                args.input(input)[2] = bad;
                match (algorithm.call)(&arm, &mut data, &mut args) {
                    Err(DynError::NonFinite {
                        name,
                        index: 2,
                        value,
                    }) => {
                        assert_eq!(name, input, "{}", algorithm.name);
                        assert_eq!(value.to_bits(), bad.to_bits());
                    }
                    other => panic!("{} with {input}[2] = {bad}: {other:?}", algorithm.name),
                }
            }
        }
    }
}

#[test]
fn wrong_output_sizes_are_refused() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    for algorithm in &ALGORITHMS {
        if let Some(output) = algorithm.output {
            for found in [0, N + 1] {
                let mut args = Args::new(N);
                args.out.resize(found, 0.0);
                let expected = DynError::Dimension {
                    name: output,
                    expected: N,
                    found,
                };
                assert_eq!(
                    (algorithm.call)(&arm, &mut data, &mut args),
                    Err(expected),
                    "{}",
                    algorithm.name
                );
            }
        }
        if algorithm.matrix_output {
            let cases = [
                (
                    N + 1,
                    N,
                    DynError::Dimension {
                        name: "out (rows)",
                        expected: N,
                        found: N + 1,
                    },
                ),
                (
                    N,
                    N - 1,
                    DynError::Dimension {
                        name: "out (columns)",
                        expected: N,
                        found: N - 1,
                    },
                ),
            ];
            for (rows, cols, expected) in cases {
                let mut args = Args::new(N);
                args.matrix = Mat::zeros(rows, cols);
                assert_eq!(
                    (algorithm.call)(&arm, &mut data, &mut args),
                    Err(expected),
                    "{}",
                    algorithm.name
                );
            }
        }
    }
}

#[test]
fn a_workspace_of_another_chain_is_refused() {
    let arm = arm();
    let mut data = ChainData::new(&ChainModel::uniform(N + 2, 0.25, 0.5, 9.81).unwrap());
    for algorithm in &ALGORITHMS {
        let mut args = Args::new(N);
        match (algorithm.call)(&arm, &mut data, &mut args) {
            Err(DynError::Dimension {
                name,
                expected: N,
                found,
            }) => {
                assert!(name.starts_with("data"), "{}: {name}", algorithm.name);
                assert_eq!(found, N + 2);
            }
            other => panic!("{}: {other:?}", algorithm.name),
        }
    }
}

#[test]
fn overflow_is_reported_not_returned() {
    // Finite but huge rates: omega^2 overflows in every velocity-dependent result.
    let arm = arm();
    let mut data = ChainData::new(&arm);
    for algorithm in ALGORITHMS.iter().filter(|a| a.inputs.contains(&"v")) {
        if algorithm.name == "coriolis_matrix" {
            continue; // linear in v: checked below with a heavier arm
        }
        let mut args = Args::new(N);
        args.v = vec![1e200; N];
        match (algorithm.call)(&arm, &mut data, &mut args) {
            Err(DynError::NonFiniteResult { .. }) => {}
            other => panic!("{}: {other:?}", algorithm.name),
        }
    }
    // A link of 1e300 kg whose centre of mass lies 1e10 m out: M, G, V, C overflow.
    let heavy = ChainModel::new(vec![Link::new(1.0, 1e300, 1e10, 1.0).unwrap(); 2], 9.81).unwrap();
    let mut data = ChainData::new(&heavy);
    let all = [
        "gravity",
        "mass_matrix",
        "potential_energy",
        "coriolis_matrix",
        "rnea",
        "aba",
        "forward_dynamics",
    ];
    for name in all {
        let algorithm = ALGORITHMS.iter().find(|a| a.name == name).unwrap();
        let mut args = Args::new(2);
        args.v = vec![1e10; 2];
        let result = (algorithm.call)(&heavy, &mut data, &mut args);
        assert!(
            matches!(result, Err(DynError::NonFiniteResult { .. })),
            "{name}: {result:?}"
        );
        let error = result.unwrap_err();
        assert!(error.is_numerical() && !error.is_invalid_input(), "{name}");
    }
    let mut args = Args::new(2);
    assert_eq!(
        (ALGORITHMS[2].call)(&heavy, &mut data, &mut args),
        Err(DynError::NonFiniteResult { name: "gravity" })
    );
}

#[test]
fn a_numerically_singular_mass_matrix_is_reported() {
    // A nearly massless link followed by one whose own inertia is lost in m c^2: straight out,
    // M is singular to double precision (its pivots are ~1e-21 of its diagonal).
    let arm = ChainModel::new(
        vec![
            Link::new(0.5, 1e-30, 0.5, 1e-33).unwrap(),
            Link::new(0.5, 1e-10, 0.3, 1e-43).unwrap(),
        ],
        9.81,
    )
    .unwrap();
    let mut data = ChainData::new(&arm);
    let zero = [0.0; 2];
    let mut qdd = [0.0; 2];
    assert_eq!(
        aba(&arm, &mut data, &zero, &zero, &zero, &mut qdd),
        Err(DynError::NotPositiveDefinite)
    );
    assert_eq!(
        forward_dynamics(&arm, &mut data, &zero, &zero, &zero, &mut qdd),
        Err(DynError::NotPositiveDefinite)
    );
    assert!(DynError::NotPositiveDefinite.is_numerical());
    // The same arm still has a well-defined mass matrix and inverse dynamics.
    let mut m = Mat::zeros(2, 2);
    assert_eq!(mass_matrix(&arm, &mut data, &zero, m.as_mut()), Ok(()));
    assert_eq!(rnea(&arm, &mut data, &zero, &zero, &zero, &mut qdd), Ok(()));
}

#[test]
fn invalid_models_are_refused() {
    assert_eq!(ChainModel::new(vec![], 9.81), Err(DynError::NoLinks));
    assert_eq!(
        ChainModel::uniform(0, 0.1, 0.1, 9.81),
        Err(DynError::NoLinks)
    );
    let good = Link::uniform_beam(0.1, 0.1).unwrap();
    assert!(matches!(
        ChainModel::new(vec![good; 2], f64::NAN),
        Err(DynError::InvalidGravity(g)) if g.is_nan()
    ));
    let cases = [
        (
            Link {
                length: 0.0,
                ..good
            },
            "length",
        ),
        (
            Link {
                length: f64::INFINITY,
                ..good
            },
            "length",
        ),
        (Link { mass: -1.0, ..good }, "mass"),
        (
            Link {
                mass: f64::NAN,
                ..good
            },
            "mass",
        ),
        (
            Link {
                inertia: -1.0,
                ..good
            },
            "inertia",
        ),
        (
            Link {
                com: f64::NAN,
                ..good
            },
            "centre of mass",
        ),
    ];
    for (bad, quantity) in cases {
        match ChainModel::new(vec![good, bad], 9.81) {
            Err(DynError::InvalidLink {
                index: 1,
                quantity: q,
                ..
            }) => assert_eq!(q, quantity),
            other => panic!("{bad:?}: {other:?}"),
        }
        assert!(Link::new(bad.length, bad.mass, bad.com, bad.inertia).is_err());
    }
}

#[test]
fn messages_say_what_failed() {
    let arm = arm();
    let mut data = ChainData::new(&arm);
    let mut args = Args::new(N);
    args.v[1] = f64::NAN;
    let message = (ALGORITHMS[0].call)(&arm, &mut data, &mut args)
        .unwrap_err()
        .to_string();
    assert_eq!(message, "v[1] must be finite, got NaN");
    let mut args = Args::new(N);
    args.q.pop();
    let message = (ALGORITHMS[6].call)(&arm, &mut data, &mut args)
        .unwrap_err()
        .to_string();
    assert_eq!(message, "q has 3 entries, expected 4");
    let message = DynError::NonFiniteResult { name: "tau" }.to_string();
    assert!(message.contains("tau") && message.contains("too large"));
}
