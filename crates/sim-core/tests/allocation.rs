//! The closed loop allocates per run, never per step: the number of allocations of a run does
//! not depend on how many steps it takes.

use sim_core::{ControllerKind, Scenario};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts every allocation of this test binary.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by one run of `scenario` lasting `duration` seconds.
fn allocations_of_run(name: &str, kind: ControllerKind, duration: f64) -> usize {
    let mut scenario = Scenario::builtin(name).unwrap();
    scenario.controller.kind = kind;
    scenario.duration = duration;
    scenario.noise.sensor_a_std = [1e-3, 1e-3];
    let mut simulation = scenario.build().unwrap();
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let run = simulation.run().unwrap();
    let count = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert!(run.summary.steps > 0);
    count
}

#[test]
fn allocations_do_not_grow_with_the_number_of_steps() {
    // One test function only: the counter is global to the binary.
    for kind in ControllerKind::ALL {
        for name in ["paper-tracking", "paper-responses-noise"] {
            let short = allocations_of_run(name, kind, 0.05);
            let long = allocations_of_run(name, kind, 0.5);
            assert_eq!(
                short, long,
                "{name} with {kind}: {short} vs {long} allocations"
            );
        }
    }
    let mut adaptive = Scenario::builtin("paper-responses-step").unwrap();
    adaptive.integrator = sim_core::IntegratorSpec::Dopri5 {
        rtol: 1e-9,
        atol: 1e-12,
        h_max: None,
        max_steps: None,
    };
    let count = |duration: f64| {
        let mut s = adaptive.clone();
        s.duration = duration;
        let mut simulation = s.build().unwrap();
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        simulation.run().unwrap();
        ALLOCATIONS.load(Ordering::Relaxed) - before
    };
    assert_eq!(count(0.05), count(0.5));
}
