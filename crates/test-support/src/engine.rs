//! External reference engines (programs from Debian's packages such as `fuzzylite`): found on
//! `PATH`, or the test is skipped with the reason on standard error, unless the environment sets
//! `HRM_REQUIRE_ENGINES=1` (CI does), in which case a missing engine fails the test.

use std::path::PathBuf;

/// The path of `program` on `PATH`; `None` (after printing that the test is skipped) when it
/// is missing and engines are not required. `package` names what installs it.
///
/// # Panics
/// If the program is missing and `HRM_REQUIRE_ENGINES=1`.
pub fn program(program: &str, package: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|dir| dir.join(program))
            .find(|path| path.is_file())
    });
    if found.is_none() {
        let reason = format!("`{program}` is not on PATH (install the `{package}` package)");
        assert!(
            std::env::var("HRM_REQUIRE_ENGINES").as_deref() != Ok("1"),
            "HRM_REQUIRE_ENGINES=1 and {reason}"
        );
        eprintln!("skipped: {reason}");
    }
    found
}
