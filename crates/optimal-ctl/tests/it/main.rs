//! The integration tests of optimal-ctl, one binary: linearisation and LQR against finite
//! differences and closed forms (`optimal`); the polytope projection and the linearly
//! constrained QP against enumeration of active sets (`qp`); iLQR under linear control
//! constraints against the condensed QP of the whole horizon (`constrained_ilqr`); rollouts that
//! linearise on their way against separate linearisations (`rollouts`).

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod chain_mpc;
mod constrained_ilqr;
mod optimal;
mod qp;
mod rollouts;
