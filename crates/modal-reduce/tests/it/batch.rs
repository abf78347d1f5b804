//! `forward_dynamics_batch` against `forward_dynamics` state by state, over random arms, maps and
//! batches: equal bit for bit (the kernel is shared), errors named by the lowest failing state,
//! and no allocation.

use crate::common::*;
use modal_reduce::{
    BatchError, ReduceError, ReducedBatchData, ReducedData, ReducedModel, forward_dynamics,
    forward_dynamics_batch,
};
use proptest::prelude::*;

/// `forward_dynamics` of each state of a batch, in order.
fn one_at_a_time(
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
) -> Result<Vec<f64>, BatchError> {
    let m = model.n_coords();
    let mut data = ReducedData::new(model);
    let mut out = vec![0.0; a.len()];
    for (state, out) in out.chunks_exact_mut(m).enumerate() {
        let range = state * m..(state + 1) * m;
        forward_dynamics(
            model,
            &mut data,
            &a[range.clone()],
            &a_dot[range.clone()],
            &tau_star[range],
            out,
        )
        .map_err(|error| BatchError::State { state, error })?;
    }
    Ok(out)
}

fn batch(
    model: &ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
) -> Result<Vec<f64>, BatchError> {
    let mut out = vec![0.0; a.len()];
    forward_dynamics_batch(
        model,
        &mut ReducedBatchData::new(model),
        a,
        a_dot,
        tau_star,
        &mut out,
    )?;
    Ok(out)
}

/// A random model (1-3 harmonics, so `m` from 2 to 7: the SIMD sizes and beyond) and a batch of
/// 0-40 random states.
fn model_and_batch() -> impl Strategy<Value = (ReducedModel, Vec<f64>, Vec<f64>, Vec<f64>)> {
    (model_with_harmonics(1..=40, 3), 0usize..40).prop_flat_map(|(model, states)| {
        let values = model.n_coords() * states;
        (
            Just(model),
            prop::collection::vec(-1.5..1.5f64, values),
            prop::collection::vec(-2.0..2.0f64, values),
            prop::collection::vec(-3.0..3.0f64, values),
        )
    })
}

proptest! {
    #[test]
    fn batch_equals_one_at_a_time((model, a, a_dot, tau_star) in model_and_batch()) {
        let expected = one_at_a_time(&model, &a, &a_dot, &tau_star).unwrap();
        let got = batch(&model, &a, &a_dot, &tau_star).unwrap();
        prop_assert_eq!(got.len(), expected.len());
        // The kernel is shared, with the same operations in the same order for every state, so
        // a batch gives each state's own bits.
        for (i, (x, y)) in got.iter().zip(&expected).enumerate() {
            prop_assert_eq!(x.to_bits(), y.to_bits(), "value {}: {} vs {}", i, x, y);
        }
    }

    #[test]
    fn the_lowest_failing_state_is_named(
        (model, mut a, a_dot, tau_star) in model_and_batch(),
        bad in prop::collection::vec(any::<prop::sample::Index>(), 1..3),
    ) {
        prop_assume!(!a.is_empty());
        let len = a.len();
        for index in &bad {
            a[index.index(len)] = f64::INFINITY;
        }
        let expected = one_at_a_time(&model, &a, &a_dot, &tau_star).unwrap_err();
        prop_assert_eq!(batch(&model, &a, &a_dot, &tau_star).unwrap_err(), expected);
    }
}

/// Absolute angles near and beyond the sine and cosine's reduction (`2^19 pi`, about 1.6e6 rad):
/// a group whose angles might pass half of it runs one state at a time, and every state still
/// gets its own bits, whether its angles are reduced or go to `libm`.
#[test]
fn huge_angles_give_each_state_its_own_bits() {
    let model = paper_arm();
    // Four groups of 8 (or eight of 4): ordinary; one lane at 6e5 (within the group bound);
    // one at 1e6 (beyond the bound, within the reduction); one at 3e6 (beyond both).
    let base_angle = |state: usize| match state {
        13 => 6e5,
        18 => -1e6,
        29 => 3e6,
        _ => 0.1 * state as f64,
    };
    let states = 32;
    let a: Vec<f64> = (0..states)
        .flat_map(|s| [0.3 - 0.01 * s as f64, -0.2, base_angle(s)])
        .collect();
    let a_dot: Vec<f64> = (0..states)
        .flat_map(|s| [0.5, -0.1 * s as f64, 0.2])
        .collect();
    let tau_star = vec![0.4; 3 * states];
    let expected = one_at_a_time(&model, &a, &a_dot, &tau_star).unwrap();
    let got = batch(&model, &a, &a_dot, &tau_star).unwrap();
    for (i, (x, y)) in got.iter().zip(&expected).enumerate() {
        assert_eq!(x.to_bits(), y.to_bits(), "value {i}: {x} vs {y}");
    }
    // The huge base angle only turns the arm: the same accelerations as at its remainder mod
    // 2 pi, to the rounding of the angles (1e6 rad carries about 1e-10 rad of it).
    let mut near = a.clone();
    for s in [13, 18, 29] {
        near[3 * s + 2] = base_angle(s).rem_euclid(std::f64::consts::TAU);
    }
    let reference = one_at_a_time(&model, &near, &a_dot, &tau_star).unwrap();
    for (i, (x, y)) in got.iter().zip(&reference).enumerate() {
        assert!(
            (x - y).abs() <= 1e-6 * (1.0 + y.abs()),
            "value {i}: {x} vs {y}"
        );
    }
}

#[test]
fn partial_states_are_refused() {
    let model = paper_arm();
    let mut data = ReducedBatchData::new(&model);
    let mut out = vec![0.0; 6];
    let err = forward_dynamics_batch(
        &model,
        &mut data,
        &[0.0; 7],
        &[0.0; 7],
        &[0.0; 7],
        &mut out[..],
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "a (whole states of m values) has 7 entries, expected 6"
    );
    let err = forward_dynamics_batch(&model, &mut data, &[0.0; 6], &[0.0; 3], &[0.0; 6], &mut out)
        .unwrap_err();
    assert!(matches!(
        err,
        BatchError::Shape(ReduceError::Dimension {
            expected: 6,
            found: 3,
            ..
        })
    ));
}

#[test]
fn a_batch_allocates_nothing() {
    let model = paper_arm();
    let states = 37;
    let a: Vec<f64> = (0..3 * states).map(|i| 0.1 * (i as f64).sin()).collect();
    let a_dot: Vec<f64> = (0..3 * states).map(|i| (i as f64).cos()).collect();
    let tau_star = vec![0.2; 3 * states];
    let mut out = vec![0.0; 3 * states];
    let mut data = ReducedBatchData::new(&model);
    assert!(test_support::alloc::is_counting());
    let allocations = test_support::alloc::allocations_during(|| {
        forward_dynamics_batch(&model, &mut data, &a, &a_dot, &tau_star, &mut out).unwrap();
    });
    assert_eq!(allocations, 0);
}
