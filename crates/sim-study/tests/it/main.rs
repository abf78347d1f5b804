//! The integration tests of sim-study, one binary: the closed loop built from scenarios
//! (`closed_loop`, `replay` on the full chain, `mpc` for control-limited iLQR and MPC in the loop,
//! `imitation` for the controller learned from computed torque, `long_runs`, `paper_pinned` for
//! the paper's figures), `scenario_fuzz` for scenario files, `scenario_controller` for a scenario
//! closed by an outside controller, `lockstep` for groups of runs stepped together against the
//! runs alone, `bad_input` for every refusal and `allocation` for the allocation-free loop.

// Counts each thread's allocations; the allocation tests measure their own thread only, so the
// other tests of this binary may run in parallel.
#[global_allocator]
static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;

mod allocation;
mod bad_input;
mod closed_loop;
mod deploy;
mod imitation;
mod lockstep;
mod long_runs;
mod mpc;
mod obstacles;
mod paper_pinned;
mod replay;
mod scenario_controller;
mod scenario_fuzz;
mod spatial;
mod task;
