//! The integration tests of manip-dyn, one binary: `closed_form` (one- and two-link arms by
//! hand), `properties` (each algorithm against an independent one over random arms),
//! `derivatives` (the analytic derivatives against finite differences), `bad_input` for every
//! refusal, `allocation` for the allocation-free algorithms and `common` for shared helpers.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod bad_input;
mod closed_form;
mod common;
mod derivatives;
mod properties;
