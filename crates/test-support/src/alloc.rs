//! A counting global allocator whose counter is thread-local.
//!
//! A process-wide counter sees the allocations of every thread: the test harness's main thread
//! (which allocates at moments of its own while it waits) and the other tests of the same binary,
//! which run in parallel. Counting per thread makes a measurement on the test's own thread exact
//! however many tests share the binary. Work a test hands to other threads (rayon, a spawned
//! thread) is not counted; measure on the thread that does the work.
//!
//! Every call that can hand out new memory counts: `alloc`, `alloc_zeroed` and `realloc`. The
//! bytes are counted too: those requested ([`bytes_allocated_during`]) and those held, with their
//! peak ([`memory_during`]), for the tests that bound a workspace's size.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    /// Allocations made by the current thread so far. `const`-initialised with no destructor,
    /// so that touching it from inside the allocator never allocates or registers anything.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Bytes requested by the current thread so far (`alloc`, `alloc_zeroed`, `realloc`'s new size).
    static REQUESTED: Cell<usize> = const { Cell::new(0) };
    /// Bytes the current thread holds: allocated here minus freed here.
    static LIVE: Cell<isize> = const { Cell::new(0) };
    /// The largest `LIVE` since [`memory_during`] last reset it.
    static PEAK: Cell<isize> = const { Cell::new(0) };
}

/// The system allocator, counting the allocations of each thread. Install it once per test
/// binary with `#[global_allocator]`.
pub struct CountingAllocator;

/// Counts one allocation of `bytes` bytes on the current thread.
fn count(bytes: usize) {
    // `try_with`: during thread teardown the slot may be gone; those allocations are not ours.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
    let _ = REQUESTED.try_with(|n| n.set(n.get().wrapping_add(bytes)));
    let _ = LIVE.try_with(|live| {
        live.set(live.get().wrapping_add(bytes as isize));
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(live.get())));
    });
}

/// Counts `bytes` bytes freed on the current thread.
fn free(bytes: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get().wrapping_sub(bytes as isize)));
}

// SAFETY: every method forwards to the system allocator with the caller's arguments; counting
// touches only a plain thread-local cell and never allocates.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        // SAFETY: the caller upholds `GlobalAlloc::alloc`'s contract, which `System` shares.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        // SAFETY: as for `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        free(layout.size());
        // SAFETY: `ptr` came from this allocator, hence from `System`, with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        free(layout.size());
        count(new_size);
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

/// What `f` returns and how many bytes it requested on the current thread (freed or not).
pub fn bytes_allocated_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = REQUESTED.with(Cell::get);
    let value = f();
    (value, REQUESTED.with(Cell::get).wrapping_sub(before))
}

/// What `f` returns, the bytes the current thread holds after it above what it held before, and
/// the peak above that while `f` ran.
pub fn memory_during<T>(f: impl FnOnce() -> T) -> (T, usize, usize) {
    let before = LIVE.with(Cell::get);
    PEAK.with(|peak| peak.set(before));
    let value = f();
    let held = LIVE.with(Cell::get) - before;
    let peak = PEAK.with(Cell::get) - before;
    (value, held.max(0) as usize, peak.max(0) as usize)
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
    fn bytes_requested_held_and_peak_are_counted() {
        let (kept, requested) = bytes_allocated_during(|| std::hint::black_box(vec![0u8; 4096]));
        assert_eq!(requested, 4096);
        let ((), held, peak) = memory_during(|| {
            drop(std::hint::black_box(vec![0u8; 1 << 20]));
            drop(kept);
        });
        // The megabyte was held at the peak, then freed; the 4096 bytes freed here count as
        // nothing held (never negative).
        assert!(peak >= 1 << 20, "{peak}");
        assert_eq!(held, 0);
        let (kept, held, _) = memory_during(|| std::hint::black_box(vec![0u64; 1000]));
        assert_eq!(held, 8000);
        drop(kept);
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
