//! The integration tests of manip-dyn, one binary: `closed_form` (one- and two-link arms by
//! hand), `properties` (each algorithm against an independent one over random arms),
//! `derivatives` (the analytic derivatives against finite differences), `dense_limit` (the `n x n`
//! algorithms refuse chains beyond `MAX_DENSE_LINKS`, no workspace holds `n x n` memory for them),
//! `batch` (`aba_batch` against one `aba` per state), `long_chains` (ABA on chains of up to
//! 10^5 links against RNEA), `bad_input` for every refusal, `allocation` for the allocation-free algorithms and `common` for shared helpers.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod bad_input;
mod batch;
mod closed_form;
mod common;
mod dense_limit;
mod derivatives;
mod long_chains;
mod properties;
mod spatial;
