//! Proptest configurations.
//!
//! `ProptestConfig::default()` reads `PROPTEST_CASES` (256 cases unless set; `cargo xtask props`
//! sets 2048). Expensive properties run a fraction of that, at least 4 cases.

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// The default configuration with `cases / divisor` cases, at least 4.
///
/// Inside `proptest!`, a `PROPTEST_CASES` variable overrides the `cases` of any configuration
/// (proptest applies the environment last); [`check_scaled`] keeps the division.
pub fn scaled(divisor: u32) -> Config {
    let default = Config::default();
    Config {
        cases: (default.cases / divisor).max(4),
        ..default
    }
}

/// Properties that build and solve a model per case: one eighth of the cases.
pub fn expensive() -> Config {
    scaled(8)
}

/// Runs `test` on `cases / divisor` cases of `strategy` (at least 4), whatever `PROPTEST_CASES`
/// says; panics with proptest's report (the minimal failing input) on failure. For properties
/// that integrate seconds of motion per case, which `cargo xtask props` must not multiply.
pub fn check_scaled<S: Strategy>(
    divisor: u32,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) where
    S::Value: std::fmt::Debug,
{
    if let Err(failure) = TestRunner::new(scaled(divisor)).run(&strategy, test) {
        panic!("{failure}");
    }
}
