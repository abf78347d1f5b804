//! Evaluation, and an ANFIS epoch, allocate nothing once the evaluator or the trainer exists:
//! the binary's counting allocator (which counts this test's thread only) watches.

use fuzzy_sugeno::learn::{
    Anfis, AnfisOptions, GridPartition, SetShape, TrainingData, genfis_grid,
};
use fuzzy_sugeno::{Evaluator, paper_controller};
use test_support::alloc::{allocations_during, is_counting};

#[test]
fn eval_fire_and_batch_do_not_allocate() {
    assert!(is_counting());
    let mut evaluator = Evaluator::new(paper_controller());
    let inputs: Vec<f64> = (0..40).map(|k| (k as f64 * 0.37).sin()).collect();
    let mut outputs = vec![0.0; 20];
    let mut single = [0.0; 2];
    let count = allocations_during(|| {
        for x in inputs.chunks(4) {
            evaluator.eval(x, &mut single).unwrap();
            evaluator.fire(x).unwrap();
        }
        evaluator.eval_batch(&inputs, &mut outputs).unwrap();
    });
    assert_eq!(count, 0, "evaluation allocated {count} times");
    assert_eq!(&outputs[18..], &single[..]);
}

#[test]
fn an_epoch_does_not_allocate() {
    let values: Vec<f64> = (0..60)
        .flat_map(|k| {
            let (x1, x2) = ((k as f64 * 0.37).sin(), (k as f64 * 0.11).cos());
            [x1, x2, x1 * x2 + x2]
        })
        .collect();
    let data = TrainingData::new(2, 1, values).unwrap();
    let grid = GridPartition {
        shape: SetShape::Trapezoid,
        ..GridPartition::default()
    };
    let initial = genfis_grid(&data, 0, &grid).unwrap();
    let mut trainer = Anfis::new(initial, &data, Some(&data), 0, AnfisOptions::default()).unwrap();
    assert!(is_counting());
    let count = allocations_during(|| {
        for _ in 0..10 {
            trainer.epoch().unwrap();
        }
    });
    assert_eq!(count, 0, "10 epochs allocated {count} times");
}
