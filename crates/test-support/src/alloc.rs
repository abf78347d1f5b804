//! A counting global allocator whose counter is thread-local.
//!
//! A process-wide counter sees the allocations of every thread: the test harness's main thread
//! (which allocates at moments of its own while it waits) and the other tests of the same binary,
//! which run in parallel. Counting per thread makes a measurement on the test's own thread exact
//! however many tests share the binary. Work a test hands to other threads (rayon, a spawned
//! thread) is not counted; measure on the thread that does the work.
//!
//! Every call that can hand out new memory counts: `alloc`, `alloc_zeroed` and `realloc`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Allocations made by the current thread so far. `const`-initialised with no destructor,
    /// so that touching it from inside the allocator never allocates or registers anything.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, counting the allocations of each thread. Install it once per test
/// binary with `#[global_allocator]`.
pub struct CountingAllocator;

fn count() {
    // `try_with`: during thread teardown the slot may be gone; those allocations are not ours.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

// SAFETY: every method forwards to the system allocator with the caller's arguments; counting
// touches only a plain thread-local cell and never allocates.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract, which `System` shares.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: as for `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from this allocator, hence from `System`, with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: as for `dealloc`, and the caller upholds `realloc`'s size contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations the current thread has made so far (0 forever if [`CountingAllocator`] is not the
/// binary's global allocator: check with [`is_counting`]).
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// How many allocations `f` makes on the current thread.
pub fn allocations_during(f: impl FnOnce()) -> usize {
    let before = allocations();
    f();
    allocations() - before
}

/// Whether the counter works: the binary installed [`CountingAllocator`] and a fresh `Box` is
/// counted. Allocation tests assert it, so that "zero allocations" cannot mean "not counting".
pub fn is_counting() -> bool {
    allocations_during(|| drop(std::hint::black_box(Box::new(1u64)))) == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[global_allocator]
    static ALLOCATOR: CountingAllocator = CountingAllocator;

    #[test]
    fn every_kind_of_allocation_is_counted() {
        assert!(is_counting());
        // alloc_zeroed (a zeroed vector), then realloc (growth past the capacity).
        let mut grown = Vec::new();
        let zeroed = allocations_during(|| grown = std::hint::black_box(vec![0u8; 64]));
        assert_eq!(zeroed, 1);
        let regrown = allocations_during(|| grown.extend_from_slice(&[1u8; 1000]));
        assert_eq!(regrown, 1);
        // Freeing is not allocating.
        assert_eq!(allocations_during(|| drop(grown)), 0);
    }

    #[test]
    fn other_threads_are_not_counted() {
        let count = allocations_during(|| {
            std::thread::scope(|scope| {
                scope.spawn(|| {
                    let on_the_other_thread = allocations_during(|| {
                        drop(std::hint::black_box(vec![1.0f64; 1000]));
                    });
                    assert_eq!(on_the_other_thread, 1);
                });
            });
        });
        // Spawning allocates on this thread (the thread's bookkeeping), but the other thread's
        // vectors are not counted here: a thousand of them would show.
        let many = allocations_during(|| {
            std::thread::scope(|scope| {
                scope.spawn(|| {
                    for _ in 0..1000 {
                        drop(std::hint::black_box(vec![1.0f64; 10]));
                    }
                });
            });
        });
        assert!(many < count + 100, "{many} vs {count}");
    }
}
