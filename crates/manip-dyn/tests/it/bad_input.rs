//! Every refusal of manip-dyn: bad models in one table of rows (each a call on bad input, the
//! [`DynError`] expected and what its message says), and every public algorithm crossed with
//! every bad argument (wrong sizes, non-finite entries, a workspace of another chain, overflow).
//! The rows named in `docs/bad-input.md` (`manip-dyn/tests/it/bad_input.rs::<row>`) are rows or
//! tests here. Refused calls leave their outputs untouched and the workspace usable.

use faer::Mat;
use lane_math::Classify;
use manip_dyn::{
    ChainData, ChainModel, DynError, Link, MAX_LINKS, aba, coriolis, coriolis_matrix,
    forward_dynamics, gravity, kinetic_energy, mass_matrix, nonlinear_effects, potential_energy,
    rnea,
};
use test_support::refusal::{Row, SENTINEL, check, exactly, row, untouched, words};

/// Every refusal of a bad model or a bad link.
fn model_rows() -> Vec<Row<DynError>> {
    let good = Link::uniform_beam(0.1, 0.1).unwrap();
    let mut rows = vec![
        row(
            "zero_links",
            ChainModel::uniform(0, 0.1, 0.1, 9.81).unwrap_err(),
            |e| *e == DynError::NoLinks,
        ),
        exactly(
            "zero_links",
            ChainModel::new(vec![], 9.81).unwrap_err(),
            |e| *e == DynError::NoLinks,
            "a chain needs at least one link",
        ),
        row(
            "huge_link_count",
            ChainModel::new(vec![good; MAX_LINKS + 1], 9.81).unwrap_err(),
            |e| matches!(e, DynError::TooManyLinks { .. }),
        ),
        // Valid links whose sums overflow: the total mass, M's bound, the gravity torques.
        exactly(
            "total_mass_overflows",
            ChainModel::uniform(8, 0.125, 1e308, 9.81).unwrap_err(),
            |e| matches!(e, DynError::ChainOverflows { .. }),
            "the chain's total mass inf kg over its length 1 m under gravity 9.81 m/s^2 \
             overflows double precision (total mass, mass x length^2 and mass x g x length must \
             be finite)",
        ),
        row(
            "gravity_torque_overflows",
            ChainModel::uniform(2, 1.0, 1e300, 1e10).unwrap_err(),
            |e| matches!(e, DynError::ChainOverflows { .. }),
        ),
        // A point mass on the joint axis: the joint would drive nothing, M would be singular.
        words(
            "point_mass_on_the_joint",
            Link::new(0.1, 0.1, 0.0, 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "inertia about the joint (inertia + mass * com^2)",
                        ..
                    }
                )
            },
            &["point mass must sit off the joint"],
        ),
        // The inertia m L^2 / 12 underflows to 0 (or overflows): named as the length or mass.
        words(
            "tiny_beam_length",
            Link::uniform_beam(1e-300, 1.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "length",
                        ..
                    }
                )
            },
            // Compactly: `1e-300`, not 302 characters.
            &["link length must be such that", "got 1e-300"],
        ),
        words(
            "huge_beam_length",
            Link::uniform_beam(1e300, 1.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "length",
                        ..
                    }
                )
            },
            &["link length must be such that", "got 1e300"],
        ),
        words(
            "tiny_beam_mass",
            Link::uniform_beam(0.1, 5e-324).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "mass",
                        ..
                    }
                )
            },
            &["link mass must be such that", "got 5e-324"],
        ),
        // Below the smallest link scale, the articulated inertias' products underflow.
        words(
            "mass_below_the_link_scale",
            Link::new(1.0, 1e-160, 0.5, 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "mass",
                        ..
                    }
                )
            },
            &["link mass must be at least 1e-150", "got 1e-160"],
        ),
        words(
            "first_moment_below_the_link_scale",
            Link::uniform_beam(1e-60, 1e-100).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "mass * length",
                        ..
                    }
                )
            },
            &["link mass * length must be at least 1e-150", "got 1e-160"],
        ),
        row(
            "non_finite_centre_of_mass",
            ChainModel::new(
                vec![
                    good,
                    Link {
                        com: f64::NAN,
                        ..good
                    },
                ],
                9.81,
            )
            .unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLink {
                        index: 1,
                        quantity: "centre of mass",
                        ..
                    }
                )
            },
        ),
        exactly(
            "non_finite_gravity",
            ChainModel::uniform(2, 0.1, 0.1, f64::INFINITY).unwrap_err(),
            |e| matches!(e, DynError::InvalidGravity(g) if g.is_infinite()),
            "gravity must be finite, got inf",
        ),
        row(
            "non_finite_gravity",
            ChainModel::new(vec![good; 2], f64::NAN).unwrap_err(),
            |e| matches!(e, DynError::InvalidGravity(g) if g.is_nan()),
        ),
        // A lone link has no index, so its message claims none; a chain names the link where it
        // sits.
        exactly(
            "a_bad_link_is_named_by_its_real_index_or_by_none",
            Link::new(0.1, -1.0, 0.05, 0.0).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "mass",
                        ..
                    }
                )
            },
            "link mass must be positive and finite, got -1",
        ),
        exactly(
            "a_bad_link_is_named_by_its_real_index_or_by_none",
            ChainModel::new(vec![good, good, Link { mass: -1.0, ..good }], 9.81).unwrap_err(),
            |e| *e == Link::new(0.1, -1.0, 0.05, 0.0).unwrap_err().at_link(2),
            "link 2: mass must be positive and finite, got -1",
        ),
    ];
    for n in [MAX_LINKS + 1, 1_000_000_000, usize::MAX] {
        let error = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap_err();
        assert!(
            matches!(error, DynError::TooManyLinks { got, max: MAX_LINKS, .. } if got == n),
            "{error:?}"
        );
        rows.push(words(
            "huge_link_count",
            error,
            |e| matches!(e, DynError::TooManyLinks { .. }),
            &["a chain may have at most 1000000 links"],
        ));
    }
    for length in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        rows.push(row(
            "non_positive_or_non_finite_length",
            ChainModel::uniform(2, length, 0.1, 9.81).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLink {
                        quantity: "length",
                        ..
                    } | DynError::InvalidLinkParameter {
                        quantity: "length",
                        ..
                    }
                )
            },
        ));
    }
    for mass in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        rows.push(row(
            "non_positive_or_non_finite_mass",
            Link::new(0.1, mass, 0.05, 1e-4).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "mass",
                        ..
                    }
                )
            },
        ));
    }
    for inertia in [-1e-6, f64::NAN, f64::INFINITY] {
        rows.push(row(
            "negative_or_non_finite_inertia",
            Link::new(0.1, 0.1, 0.05, inertia).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLinkParameter {
                        quantity: "inertia",
                        requirement: "non-negative and finite",
                        ..
                    }
                )
            },
        ));
    }
    // Each bad parameter of the second link of a chain, named by its index; the same link alone
    // is refused too.
    let bad_links = [
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
    for (bad, quantity) in bad_links {
        let error = ChainModel::new(vec![good, bad], 9.81).unwrap_err();
        assert!(
            matches!(error, DynError::InvalidLink { index: 1, quantity: q, .. } if q == quantity),
            "{bad:?}: {error:?}"
        );
        rows.push(row("invalid_link_in_a_chain", error, |e| {
            matches!(e, DynError::InvalidLink { index: 1, .. })
        }));
        rows.push(row(
            "invalid_link_in_a_chain",
            Link::new(bad.length, bad.mass, bad.com, bad.inertia).unwrap_err(),
            |e| matches!(e, DynError::InvalidLinkParameter { .. }),
        ));
    }
    rows
}

/// Refusals of single calls, with their outputs untouched.
fn call_rows() -> Vec<Row<DynError>> {
    let arm = ChainModel::uniform(3, 0.2, 0.4, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let mut other = ChainData::new(&ChainModel::uniform(5, 0.1, 0.1, 9.81).unwrap());
    vec![
        exactly(
            "input_of_wrong_length",
            untouched([SENTINEL; 3], |tau| {
                rnea(&arm, &mut data, &[0.1; 2], &[0.0; 3], &[0.0; 3], tau)
            }),
            |e| {
                *e == DynError::Dimension {
                    name: "q",
                    expected: 3,
                    found: 2,
                }
            },
            "q has 2 entries, expected 3",
        ),
        row(
            "output_of_wrong_length",
            untouched([SENTINEL; 4], |qdd| {
                aba(&arm, &mut data, &[0.1; 3], &[0.0; 3], &[0.0; 3], qdd)
            }),
            |e| {
                *e == DynError::Dimension {
                    name: "qdd",
                    expected: 3,
                    found: 4,
                }
            },
        ),
        exactly(
            "non_finite_input_leaves_output_and_workspace_usable",
            untouched([SENTINEL; 3], |qdd| {
                forward_dynamics(
                    &arm,
                    &mut data,
                    &[0.1; 3],
                    &[0.0, f64::NAN, 0.0],
                    &[0.0; 3],
                    qdd,
                )
            }),
            |e| matches!(e, DynError::NonFinite { name: "v", index: Some(1), value } if value.is_nan()),
            "v[1] must be finite, got NaN",
        ),
        words(
            "workspace_of_another_chain",
            untouched([SENTINEL; 3], |out| {
                gravity(&arm, &mut other, &[0.0; 3], out)
            }),
            |e| {
                matches!(
                    e,
                    DynError::Dimension {
                        expected: 3,
                        found: 5,
                        ..
                    }
                )
            },
            &["ChainData built for another model"],
        ),
        words(
            "overflowing_result",
            kinetic_energy(&arm, &mut data, &[0.0; 3], &[1e200; 3]).unwrap_err(),
            |e| matches!(e, DynError::NonFiniteResult { .. }),
            &["too large for double precision"],
        ),
        words(
            "overflowing_result",
            DynError::NonFiniteResult { name: "tau" },
            |_| true,
            &["tau", "too large"],
        ),
    ]
}

#[test]
fn bad_models_and_links_are_refused() {
    check(&model_rows());
}

#[test]
fn bad_calls_are_refused_and_write_nothing() {
    check(&call_rows());
}

#[test]
fn matrix_output_of_wrong_shape() {
    let arm = ChainModel::uniform(3, 0.2, 0.4, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let mut m = Mat::from_fn(3, 4, |_, _| SENTINEL);
    let err = mass_matrix(&arm, &mut data, &[0.1; 3], m.as_mut()).unwrap_err();
    assert_eq!(
        err,
        DynError::Dimension {
            name: "out (columns)",
            expected: 3,
            found: 4
        }
    );
    assert!((0..3).all(|i| (0..4).all(|j| m[(i, j)] == SENTINEL)));
}

#[test]
fn a_refused_call_leaves_the_workspace_usable() {
    let arm = ChainModel::uniform(3, 0.2, 0.4, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let mut qdd = [0.0; 3];
    let nan = [0.0, f64::NAN, 0.0];
    assert!(forward_dynamics(&arm, &mut data, &[0.1; 3], &nan, &[0.0; 3], &mut qdd).is_err());
    // The workspace that saw the error gives what a fresh one gives.
    let (q, v, tau) = ([0.3, -0.2, 0.5], [0.4, 0.1, -0.3], [0.2, 0.0, -0.1]);
    forward_dynamics(&arm, &mut data, &q, &v, &tau, &mut qdd).unwrap();
    let mut fresh = [0.0; 3];
    forward_dynamics(&arm, &mut ChainData::new(&arm), &q, &v, &tau, &mut fresh).unwrap();
    assert_eq!(qdd, fresh);
}

#[test]
fn point_mass_link_is_allowed() {
    // Zero inertia about the centre of mass is a point mass: a simple pendulum of length c,
    // whose exact acceleration from rest is -g cos(q) / c.
    let (c, g, q) = (0.7, 9.81, 0.4);
    let pendulum = ChainModel::new(vec![Link::new(1.0, 2.0, c, 0.0).unwrap()], g).unwrap();
    let mut data = ChainData::new(&pendulum);
    let mut qdd = [0.0];
    aba(&pendulum, &mut data, &[q], &[0.0], &[0.0], &mut qdd).unwrap();
    assert!((qdd[0] + g * q.cos() / c).abs() < 1e-12, "{qdd:?}");
    forward_dynamics(&pendulum, &mut data, &[q], &[0.0], &[0.0], &mut qdd).unwrap();
    assert!((qdd[0] + g * q.cos() / c).abs() < 1e-12, "{qdd:?}");
}

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
            out: vec![SENTINEL; n],
            matrix: Mat::from_fn(n, n, |_, _| SENTINEL),
        }
    }

    /// After a refused call: the outputs still hold the sentinel.
    fn assert_untouched(&self, algorithm: &str) {
        assert!(
            self.out.iter().all(|&x| x == SENTINEL),
            "{algorithm} wrote out"
        );
        let matrix = &self.matrix;
        let untouched =
            (0..matrix.nrows()).all(|i| (0..matrix.ncols()).all(|j| matrix[(i, j)] == SENTINEL));
        assert!(untouched, "{algorithm} wrote its matrix");
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
                args.assert_untouched(algorithm.name);
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
                        index: Some(2),
                        value,
                    }) => {
                        assert_eq!(name, input, "{}", algorithm.name);
                        assert_eq!(value.to_bits(), bad.to_bits());
                    }
                    other => panic!("{} with {input}[2] = {bad}: {other:?}", algorithm.name),
                }
                args.assert_untouched(algorithm.name);
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
                args.out.resize(found, SENTINEL);
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
                args.assert_untouched(algorithm.name);
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
                args.matrix = Mat::from_fn(rows, cols, |_, _| SENTINEL);
                assert_eq!(
                    (algorithm.call)(&arm, &mut data, &mut args),
                    Err(expected),
                    "{}",
                    algorithm.name
                );
                args.assert_untouched(algorithm.name);
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
        args.assert_untouched(algorithm.name);
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
fn an_overflowing_pivot_names_the_factor_it_belongs_to() {
    // Links of 1e200 kg: the mass matrix is finite (about 3e200), but the articulated inertias
    // of ABA pass through U U^T, beyond double precision. The error names what overflowed.
    let arm = ChainModel::uniform(10, 0.1, 1e200, 9.81).unwrap();
    let mut data = ChainData::new(&arm);
    let (q, mut qdd) = ([0.1; 10], [0.0; 10]);
    let mut m = Mat::zeros(10, 10);
    assert_eq!(mass_matrix(&arm, &mut data, &q, m.as_mut()), Ok(()));
    assert_eq!(
        aba(&arm, &mut data, &q, &q, &q, &mut qdd),
        Err(DynError::NonFiniteResult {
            name: "articulated inertia"
        })
    );
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

/// Every refusal of a bad spatial model, joint or link, and of a bad spatial call.
/// The error of `arm`'s ABA at rest alone, checked to be the first state's error in a batch of
/// eight states (`q = 0.1`) as well.
fn aba_error_alone_and_in_a_batch(arm: &manip_dyn::spatial::SpatialModel) -> DynError {
    use manip_dyn::spatial::SpatialData;
    let n = arm.n_links();
    let error = manip_dyn::spatial::aba(
        arm,
        &mut SpatialData::new(arm),
        &vec![0.0; n],
        &vec![0.0; n],
        &vec![0.0; n],
        &mut vec![0.0; n],
    )
    .unwrap_err();
    let batch = manip_dyn::spatial::aba_batch(
        arm,
        &mut manip_dyn::spatial::SpatialBatchData::new(arm),
        &vec![0.1; 8 * n],
        &vec![0.0; 8 * n],
        &vec![0.0; 8 * n],
        &mut vec![0.0; 8 * n],
    )
    .unwrap_err();
    assert_eq!(
        batch,
        manip_dyn::BatchError::State {
            state: 0,
            error: error.clone()
        }
    );
    error
}

fn spatial_rows() -> Vec<Row<DynError>> {
    use manip_dyn::spatial::{
        SpatialData, SpatialDerivativeData, SpatialJoint, SpatialLink, SpatialModel, Transform,
        aba_derivatives, jacobian,
    };
    let link = SpatialLink::cuboid(0.1, [0.1, 0.01, 0.01], [0.05, 0.0, 0.0]);
    let joint = SpatialJoint::revolute([0.0, 0.0, 1.0], Transform::IDENTITY);
    let model = |joints: Vec<SpatialJoint>, links: Vec<SpatialLink>, g: [f64; 3]| {
        SpatialModel::new(joints, links, g).unwrap_err()
    };
    let one = |joint: SpatialJoint, link: SpatialLink| model(vec![joint], vec![link], [0.0; 3]);
    let good = SpatialModel::new(vec![joint; 2], vec![link; 2], [0.0, 0.0, -9.81]).unwrap();
    let mut data = SpatialData::new(&good);
    let mut j = Mat::<f64>::zeros(6, 2);
    vec![
        exactly(
            "spatial_zero_joints",
            model(vec![], vec![], [0.0; 3]),
            |e| *e == DynError::NoLinks,
            "a chain needs at least one link",
        ),
        words(
            "spatial_link_count_differs",
            model(vec![joint; 2], vec![link], [0.0; 3]),
            |e| matches!(e, DynError::Dimension { .. }),
            &["links (one per joint) has 1 entries, expected 2"],
        ),
        words(
            "spatial_zero_axis",
            one(
                SpatialJoint {
                    axis: [0.0; 3],
                    ..joint
                },
                link,
            ),
            |e| matches!(e, DynError::InvalidJoint { index: 0, .. }),
            &["joint 0: axis (its norm) must be 1", "got 0"],
        ),
        words(
            "spatial_non_finite_axis",
            one(
                SpatialJoint {
                    axis: [f64::NAN, 0.0, 1.0],
                    ..joint
                },
                link,
            ),
            |e| {
                matches!(
                    e,
                    DynError::InvalidJoint {
                        quantity: "axis",
                        ..
                    }
                )
            },
            &["joint 0: axis must be finite, got NaN"],
        ),
        words(
            "spatial_non_rigid_origin",
            one(
                SpatialJoint {
                    origin: Transform {
                        rotation: [[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                        translation: [0.0; 3],
                    },
                    ..joint
                },
                link,
            ),
            |e| matches!(e, DynError::InvalidJoint { .. }),
            &["origin rotation", "a rotation matrix"],
        ),
        words(
            "spatial_reflected_origin",
            one(
                SpatialJoint {
                    origin: Transform {
                        rotation: [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                        translation: [0.0; 3],
                    },
                    ..joint
                },
                link,
            ),
            |e| matches!(e, DynError::InvalidJoint { .. }),
            &["not a reflection"],
        ),
        words(
            "spatial_non_finite_origin",
            one(
                SpatialJoint {
                    origin: Transform::translation([0.0, f64::INFINITY, 0.0]),
                    ..joint
                },
                link,
            ),
            |e| {
                matches!(
                    e,
                    DynError::InvalidJoint {
                        quantity: "origin",
                        ..
                    }
                )
            },
            &["joint 0: origin must be finite, got inf"],
        ),
        words(
            "spatial_negative_mass",
            one(joint, SpatialLink { mass: -1.0, ..link }),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLink {
                        index: 0,
                        quantity: "mass",
                        ..
                    }
                )
            },
            &["link 0: mass must be non-negative and finite, got -1"],
        ),
        words(
            "spatial_nan_mass",
            one(
                joint,
                SpatialLink {
                    mass: f64::NAN,
                    ..link
                },
            ),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLink {
                        quantity: "mass",
                        ..
                    }
                )
            },
            &["got NaN"],
        ),
        words(
            "spatial_non_finite_inertia",
            one(
                joint,
                SpatialLink {
                    com: [0.0, f64::NAN, 0.0],
                    ..link
                },
            ),
            |e| {
                matches!(
                    e,
                    DynError::InvalidLink {
                        quantity: "centre of mass",
                        ..
                    }
                )
            },
            &["centre of mass must be finite"],
        ),
        words(
            "spatial_asymmetric_inertia",
            one(
                joint,
                SpatialLink {
                    inertia: [[1e-3, 1e-4, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]],
                    ..link
                },
            ),
            |e| matches!(e, DynError::InvalidLink { .. }),
            &["symmetric"],
        ),
        words(
            "spatial_triangle_inequality",
            one(
                joint,
                SpatialLink {
                    inertia: [[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 3e-3]],
                    ..link
                },
            ),
            |e| matches!(e, DynError::InvalidLink { .. }),
            &["triangle inequalities", "got -0.0005"],
        ),
        words(
            "spatial_negative_inertia",
            one(
                joint,
                SpatialLink {
                    inertia: [[-1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]],
                    ..link
                },
            ),
            |e| matches!(e, DynError::InvalidLink { .. }),
            &["triangle inequalities"],
        ),
        words(
            "spatial_non_finite_gravity",
            model(vec![joint], vec![link], [0.0, f64::NAN, 0.0]),
            |e| matches!(e, DynError::InvalidGravity(_)),
            &["gravity must be finite, got NaN"],
        ),
        words(
            "spatial_no_such_link",
            jacobian(&good, &mut data, &[0.0; 2], 2, [0.0; 3], j.as_mut()).unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::NoSuchLink {
                        index: 2,
                        n_links: 2
                    }
                )
            },
            &["link index 2 is out of range: the chain has 2 links"],
        ),
        words(
            "spatial_non_finite_point",
            jacobian(
                &good,
                &mut data,
                &[0.0; 2],
                1,
                [0.0, f64::NAN, 0.0],
                j.as_mut(),
            )
            .unwrap_err(),
            |e| matches!(e, DynError::NonFinite { name: "point", .. }),
            &["point[1] must be finite, got NaN"],
        ),
        words(
            "spatial_jacobian_of_wrong_shape",
            jacobian(
                &good,
                &mut data,
                &[0.0; 2],
                1,
                [0.0; 3],
                Mat::<f64>::zeros(3, 2).as_mut(),
            )
            .unwrap_err(),
            |e| matches!(e, DynError::Dimension { .. }),
            &["out (rows) has 3 entries, expected 6"],
        ),
        words(
            "spatial_workspace_of_another_chain",
            aba_derivatives(
                &good,
                &mut SpatialData::new(
                    &SpatialModel::new(vec![joint], vec![link], [0.0; 3]).unwrap(),
                ),
                &mut SpatialDerivativeData::new(&good),
                &[0.0; 2],
                &[0.0; 2],
                &[0.0; 2],
            )
            .unwrap_err(),
            |e| matches!(e, DynError::Dimension { .. }),
            &["data (a SpatialData built for another model) has 1 entries, expected 2"],
        ),
        words(
            "spatial_non_finite_input",
            manip_dyn::spatial::aba(
                &good,
                &mut data,
                &[0.0; 2],
                &[0.0, f64::INFINITY],
                &[0.0; 2],
                &mut [0.0; 2],
            )
            .unwrap_err(),
            |e| {
                matches!(
                    e,
                    DynError::NonFinite {
                        name: "v",
                        index: Some(1),
                        ..
                    }
                )
            },
            &["v[1] must be finite, got inf"],
        ),
        // A point mass on the joint's axis at the tip: nothing resists that joint.
        words(
            "spatial_massless_joint",
            {
                let point = SpatialLink {
                    mass: 1.0,
                    com: [0.0; 3],
                    inertia: [[0.0; 3]; 3],
                };
                let arm = SpatialModel::new(vec![joint; 2], vec![link, point], [0.0; 3]).unwrap();
                manip_dyn::spatial::aba(
                    &arm,
                    &mut SpatialData::new(&arm),
                    &[0.0; 2],
                    &[0.0; 2],
                    &[0.0; 2],
                    &mut [0.0; 2],
                )
                .unwrap_err()
            },
            |e| *e == DynError::SingularJoint { index: 1 },
            &["joint 1: the articulated inertia about its axis is not positive"],
        ),
        // A massless link at the tip: its joint moves nothing, in the batch as alone.
        words(
            "spatial_massless_tip",
            {
                let massless = SpatialLink {
                    mass: 0.0,
                    com: [0.0; 3],
                    inertia: [[0.0; 3]; 3],
                };
                let arm = SpatialModel::new(vec![joint; 3], vec![link, link, massless], [0.0; 3])
                    .unwrap();
                aba_error_alone_and_in_a_batch(&arm)
            },
            |e| *e == DynError::SingularJoint { index: 2 } && e.is_numerical(),
            &["joint 2: the articulated inertia about its axis is not positive"],
        ),
        // A subnormal inertia about the tip joint's axis (its mass on the axis): a pivot whose
        // reciprocal overflows, alone and in a batch (it gave an infinite acceleration).
        words(
            "spatial_massless_joint",
            {
                let tiny = SpatialLink {
                    mass: 1.0,
                    com: [0.0; 3],
                    inertia: [[1e-320, 0.0, 0.0], [0.0, 1e-320, 0.0], [0.0, 0.0, 1e-320]],
                };
                let arm = SpatialModel::new(vec![joint; 2], vec![link, tiny], [0.0; 3]).unwrap();
                aba_error_alone_and_in_a_batch(&arm)
            },
            |e| *e == DynError::SingularJoint { index: 1 },
            &["joint 1: the articulated inertia about its axis is not positive"],
        ),
    ]
}

#[test]
fn bad_spatial_models_and_calls_are_refused() {
    check(&spatial_rows());
}
