//! Evaluation allocates nothing once the evaluator exists: a counting global allocator watches.

use fuzzy_sugeno::{Evaluator, paper_controller};
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

#[test]
fn eval_fire_and_batch_do_not_allocate() {
    let mut evaluator = Evaluator::new(paper_controller());
    let inputs: Vec<f64> = (0..40).map(|k| (k as f64 * 0.37).sin()).collect();
    let mut outputs = vec![0.0; 20];
    let mut single = [0.0; 2];
    let before = ALLOCATIONS.with(Cell::get);
    for x in inputs.chunks(4) {
        evaluator.eval(x, &mut single).unwrap();
        evaluator.fire(x).unwrap();
    }
    evaluator.eval_batch(&inputs, &mut outputs).unwrap();
    let after = ALLOCATIONS.with(Cell::get);
    assert_eq!(
        after - before,
        0,
        "evaluation allocated {} times",
        after - before
    );
    assert_eq!(&outputs[18..], &single[..]);
}
