//! The integration tests of backbone-kin, one binary: a module per `src` module it tests
//! (`curve`, `chain`, `chain_ik`, `modal_map`, `inverse` for the closed form and `HarmonicIk`),
//! `map_limits` for the size limits of the modal map, `bad_input` for every refusal and `allocation` for the allocation-free solvers and maps.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod bad_input;
mod chain;
mod chain_ik;
mod curve;
mod inverse;
mod map_limits;
mod modal_map;
mod spatial;
