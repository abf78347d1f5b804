//! After construction, the inverse-kinematics solvers and the per-step maps allocate nothing
//! (checked with a counting global allocator; this file holds a single test so nothing else runs
//! concurrently).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use backbone_kin::{BaseAngle, Branch, ChainIk, HarmonicIk, ModalMap, tip_position};

struct Counting;

thread_local! {
    /// Allocations of the current thread only: the test harness's main thread allocates at
    /// moments of its own while it waits for the test.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn solvers_and_maps_do_not_allocate() {
    let lengths: Vec<f64> = (0..20)
        .map(|i| 0.075 - 0.05 * f64::from(i) / 19.0)
        .collect();
    let alpha0 = std::f64::consts::FRAC_PI_2;
    let mut chain_ik = ChainIk::new(&lengths, 2, alpha0).unwrap();
    let mut harmonic_ik = HarmonicIk::new(1.0, 2, alpha0).unwrap();
    let map = ModalMap::new(&lengths, 2, BaseAngle::Fixed(alpha0)).unwrap();
    let (mut a, mut b, mut theta) = ([0.0; 4], [0.0; 4], vec![0.0; 20]);
    let before = ALLOCATIONS.with(Cell::get);
    for target in [[0.3, 0.5], [-0.2, 0.6], [0.1, 0.9]] {
        chain_ik
            .solve_from_closed_form(target, Branch::Positive, &mut a)
            .unwrap();
        b.copy_from_slice(&a);
        harmonic_ik.solve(target, &mut b).unwrap();
        map.joint_angles(&a, &mut theta).unwrap();
        let tip = tip_position(&lengths, &theta).unwrap();
        assert!((tip[0] - target[0]).hypot(tip[1] - target[1]) < 1e-13);
    }
    assert_eq!(ALLOCATIONS.with(Cell::get), before);
}
