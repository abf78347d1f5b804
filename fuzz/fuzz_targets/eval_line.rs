//! `hrm eval` on arbitrary bytes: never panics, one JSON answer with `ok` per non-blank line.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)] // run_stdio is the binary's entry point, unused here
#[path = "../../crates/hrm-cli/src/eval.rs"]
mod eval;

fuzz_target!(|data: &[u8]| {
    let mut out = Vec::new();
    eval::serve(data, &mut out).expect("writing to a Vec cannot fail");
    let requests = data
        .split(|&b| b == b'\n')
        .filter(|l| !l.iter().all(u8::is_ascii_whitespace))
        .count();
    let answers: Vec<serde_json::Value> = out
        .split(|&b| b == b'\n')
        .filter(|l| !l.is_empty())
        .map(|l| serde_json::from_slice(l).expect("answers are JSON"))
        .collect();
    assert_eq!(answers.len(), requests);
    assert!(answers.iter().all(|a| a["ok"].is_boolean()));
});
