//! Host package for the workspace's Criterion benchmarks (`benches/benches/*.rs`).
//!
//! A virtual workspace root cannot own benches, so they live in this unpublished package.
//! Run them with `cargo xtask bench`, which also writes `target/bench-summary.json`.
