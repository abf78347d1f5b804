//! An ANFIS epoch allocates nothing once the trainer exists: a counting global allocator
//! watches.

use fuzzy_sugeno::learn::{
    Anfis, AnfisOptions, GridPartition, SetShape, TrainingData, genfis_grid,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations of the current thread only: the test harness's main thread allocates at
    /// moments of its own while it waits for the test.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

// The only test in this binary, so no other test thread allocates meanwhile.
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
    let before = ALLOCATIONS.with(Cell::get);
    for _ in 0..10 {
        trainer.epoch().unwrap();
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert_eq!(
        after - before,
        0,
        "10 epochs allocated {} times",
        after - before
    );
}
