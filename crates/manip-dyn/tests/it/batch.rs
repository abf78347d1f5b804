//! `aba_batch` against one `aba` call per state, over random arms and batches (lengths that are
//! not a multiple of any SIMD width, failing states anywhere), and its refusals.

use manip_dyn::{AbaBatchData, BatchError, ChainData, ChainModel, DynError, aba, aba_batch};
use proptest::collection::vec;
use proptest::prelude::*;
use test_support::alloc::allocations_during;
use test_support::sample::{chain, links, values};

/// A random arm and `states` random states of it, row-major.
fn arm_and_batch(
    max_links: usize,
    max_states: usize,
) -> impl Strategy<Value = (ChainModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    (links(max_links), 0..=max_states).prop_flat_map(|(n, states)| {
        (
            chain(n),
            values(n * states, std::f64::consts::PI),
            values(n * states, 2.0),
            values(n * states, 5.0),
        )
    })
}

/// Each state by `aba` alone: its accelerations, or its error.
fn one_by_one(
    arm: &ChainModel,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Vec<Result<Vec<f64>, DynError>> {
    let n = arm.n_links();
    let mut data = ChainData::new(arm);
    (0..q.len() / n)
        .map(|s| {
            let rows = s * n..(s + 1) * n;
            let mut qdd = vec![0.0; n];
            aba(
                arm,
                &mut data,
                &q[rows.clone()],
                &v[rows.clone()],
                &tau[rows],
                &mut qdd,
            )
            .map(|()| qdd)
        })
        .collect()
}

proptest! {
    #[test]
    fn batch_equals_one_state_at_a_time((arm, q, v, tau) in arm_and_batch(24, 40)) {
        let mut qdd = vec![f64::NAN; q.len()];
        aba_batch(&arm, &mut AbaBatchData::new(&arm), &q, &v, &tau, &mut qdd).unwrap();
        let n = arm.n_links();
        for (state, expected) in one_by_one(&arm, &q, &v, &tau).into_iter().enumerate() {
            let expected = expected.unwrap();
            let got = &qdd[state * n..(state + 1) * n];
            let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for (i, (a, b)) in got.iter().zip(&expected).enumerate() {
                prop_assert!((a - b).abs() <= 1e-12 * scale,
                    "state {state}, joint {i}: batch {a}, alone {b}");
            }
        }
    }

    #[test]
    fn a_failing_state_is_named_by_its_lowest_index(
        (arm, q, v, mut tau) in arm_and_batch(12, 30),
        picks in vec((0.0..1.0f64, 0usize..3), 1..4),
    ) {
        let n = arm.n_links();
        let states = q.len() / n;
        prop_assume!(states > 0);
        let (mut q, mut v) = (q, v);
        for &(at, kind) in &picks {
            let value = (at * (q.len() as f64)) as usize;
            match kind {
                0 => q[value] = f64::NAN,
                1 => v[value] = f64::INFINITY,
                // Finite, but the accelerations overflow.
                _ => tau[value] = 1e308,
            }
        }
        let mut qdd = vec![0.0; q.len()];
        let result = aba_batch(&arm, &mut AbaBatchData::new(&arm), &q, &v, &tau, &mut qdd);
        let first_failure = one_by_one(&arm, &q, &v, &tau)
            .into_iter()
            .enumerate()
            .find_map(|(state, r)| r.err().map(|error| BatchError::State { state, error }));
        // A NaN or infinite input always fails; a large torque may or may not overflow.
        prop_assert!(first_failure.is_some() || picks.iter().all(|&(_, kind)| kind == 2));
        // Compared as text: a NaN in the error is not equal to itself.
        prop_assert_eq!(format!("{:?}", result.err()), format!("{first_failure:?}"));
    }
}

#[test]
fn shapes_are_checked() {
    let arm = ChainModel::uniform(3, 0.1, 0.1, 9.81).unwrap();
    let mut data = AbaBatchData::new(&arm);
    let six = [0.0; 6];
    let mut out = [0.0; 6];
    let error = aba_batch(&arm, &mut data, &[0.0; 5], &six, &six, &mut out).unwrap_err();
    assert_eq!(
        error.to_string(),
        "q (whole states of n values) has 5 entries, expected 3"
    );
    let error = aba_batch(&arm, &mut data, &six, &six, &six, &mut [0.0; 3]).unwrap_err();
    assert!(matches!(
        error,
        BatchError::Shape(DynError::Dimension {
            name: "qdd (as many values as q)",
            ..
        })
    ));
    let other = ChainModel::uniform(2, 0.1, 0.1, 9.81).unwrap();
    let error = aba_batch(&other, &mut data, &six, &six, &six, &mut out).unwrap_err();
    assert!(matches!(
        error,
        BatchError::Shape(DynError::Dimension { .. })
    ));
    // An empty batch is a batch of no states.
    aba_batch(&arm, &mut data, &[], &[], &[], &mut []).unwrap();
}

#[test]
fn batches_allocate_nothing() {
    for n in [1, 10, 100] {
        let arm = ChainModel::uniform(n, 0.1, 0.1, 9.81).unwrap();
        let mut data = AbaBatchData::new(&arm);
        let states = 37;
        let q: Vec<f64> = (0..n * states).map(|i| (i as f64).sin()).collect();
        let mut qdd = vec![0.0; n * states];
        let mut bad = q.clone();
        bad[n * 20] = f64::NAN;
        let count = allocations_during(|| {
            aba_batch(&arm, &mut data, &q, &q, &q, &mut qdd).unwrap();
            aba_batch(&arm, &mut data, &bad, &q, &q, &mut qdd).unwrap_err();
        });
        assert_eq!(count, 0, "n = {n}: {count} allocations");
    }
}
