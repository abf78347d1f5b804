//! Evaluation allocates nothing once the evaluator exists: a counting global allocator watches.

use fuzzy_sugeno::{Evaluator, paper_controller};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
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
fn eval_fire_and_batch_do_not_allocate() {
    let mut evaluator = Evaluator::new(paper_controller());
    let inputs: Vec<f64> = (0..40).map(|k| (k as f64 * 0.37).sin()).collect();
    let mut outputs = vec![0.0; 20];
    let mut single = [0.0; 2];
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for x in inputs.chunks(4) {
        evaluator.eval(x, &mut single).unwrap();
        evaluator.fire(x).unwrap();
    }
    evaluator.eval_batch(&inputs, &mut outputs).unwrap();
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert_eq!(
        after - before,
        0,
        "evaluation allocated {} times",
        after - before
    );
    assert_eq!(&outputs[18..], &single[..]);
}
