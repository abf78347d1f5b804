//! The integration tests of fuzzy-sugeno, one binary: a module per `src` module it tests
//! (`evaluator`, `fcl` (and `fuzzylite`, against the real program), `export_c`, `anfis`; `fis_files`, `fis_fuzz` and `fis_interop` for the
//! `.fis` reader and writer), `batch` for the SIMD batch against one point at a time, `bad_input` for every refusal, `allocation` for the allocation-free
//! evaluation and training, and `common` for random systems and the independent reference
//! evaluator.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod anfis;
mod bad_input;
mod batch;
mod common;
mod evaluator;
mod export_c;
mod fcl;
mod fis_files;
mod fis_fuzz;
mod fis_interop;
mod fuzzylite;
