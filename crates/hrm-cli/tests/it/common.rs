//! Helpers of the command-line tests: running the built `hrm` binary, scratch folders.

use std::path::PathBuf;
use std::process::{Command, Output};

/// A fresh, empty scratch folder for one test (`name` unique across the binary's tests).
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hrm-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `hrm args...` run to completion, with no standard input.
pub fn hrm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hrm"))
        .args(args)
        .output()
        .expect("the hrm binary runs")
}
