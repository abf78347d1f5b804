//! The integration tests of modal-reduce, one binary: `closed_form` (the two-link arm by hand),
//! `properties` (the fast path against `J^T M J` and brute-force energies over random models),
//! `derivatives`, `spatial` and `spatial_derivatives` (spatial modal arms), `jacobi` (the eq-18
//! iteration), `batch` (the SIMD batch against one state at a time), `continuum` (convergence as `n` grows at fixed length and mass), `large_chains` (`O(n m)`
//! memory up to `MAX_LINKS`), `bad_input` for every refusal, `allocation` for the allocation-free
//! per-step functions and `common` for random models and references.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod bad_input;
mod batch;
mod closed_form;
mod common;
mod continuum;
mod derivatives;
mod jacobi;
mod large_chains;
mod plant;
mod properties;
mod spatial;
mod spatial_derivatives;
