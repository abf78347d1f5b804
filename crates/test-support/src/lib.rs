//! What the workspace's integration tests share, in the spirit of Pinocchio's sample models:
//!
//! - [`alloc`]: a counting global allocator with a thread-local counter, so that allocation
//!   tests can share a test binary with tests running on other threads;
//! - [`config`]: the proptest configurations (expensive properties on a fraction of the cases);
//! - [`numeric`]: small vector helpers and Ridders' finite differences, written independently of
//!   the crates under test;
//! - [`refusal`]: table-driven tests of refusals (a row per bad input: the error expected, what
//!   its message says, outputs left untouched);
//! - [`sample`]: the arms the tests use again and again, and random-arm strategies (those that
//!   build a `ChainModel` with the feature `arms`, reduced models with `reduced`).
//!
//! Each crate's integration tests are one binary, `tests/it/main.rs`, which installs the
//! allocator once:
//!
//! ```ignore
//! #[global_allocator]
//! static ALLOCATOR: test_support::alloc::CountingAllocator = test_support::alloc::CountingAllocator;
//! ```
//!
//! This crate is a dev-dependency only (`publish = false`).
#![deny(missing_docs)]

pub mod alloc;
pub mod config;
pub mod numeric;
pub mod refusal;
pub mod sample;
