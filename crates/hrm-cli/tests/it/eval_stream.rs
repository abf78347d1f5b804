//! Fuzzing `hrm eval` through the built binary: arbitrary byte lines and structurally valid
//! requests with mutated fields, interleaved with known-good requests.
//!
//! Properties of every stream: the process exits 0 at end of input and never panics; it writes
//! exactly one answer line per non-blank request line (a blank line is empty or only ASCII
//! whitespace, see docs/eval-protocol.md); every answer is a JSON object with `"ok"` true or false
//! that echoes the request's `id` (`null` when the line is not a JSON object with one); the
//! known-good requests get the same answer as when sent alone; `ok` answers hold only finite
//! numbers (and no `null` but an absent id).

use proptest::prelude::*;
use serde_json::Value;
use std::io::Write;
use std::process::{Command, Stdio};
use std::sync::OnceLock;

/// Runs `hrm eval` on `input`; returns the answer lines.
fn run_eval(input: &[u8]) -> Vec<String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hrm"))
        .arg("eval")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hrm starts");
    let mut stdin = child.stdin.take().expect("piped stdin");
    let input = input.to_vec();
    // Write from another thread: the answers fill the stdout pipe while we write.
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let output = child.wait_with_output().expect("hrm runs");
    writer
        .join()
        .expect("writer thread")
        .expect("stdin accepts the input");
    let stdout = String::from_utf8(output.stdout).expect("answers are UTF-8");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "hrm eval exited with {}: {stderr}",
        output.status
    );
    assert!(!stderr.contains("panicked"), "hrm eval panicked: {stderr}");
    assert!(
        stdout.is_empty() || stdout.ends_with('\n'),
        "last answer unterminated"
    );
    stdout.lines().map(str::to_string).collect()
}

/// The request lines of a stream, as `hrm eval` splits them (on `\n`; the last one may lack it).
fn request_lines(input: &[u8]) -> Vec<&[u8]> {
    let mut lines: Vec<&[u8]> = input.split(|&b| b == b'\n').collect();
    if input.ends_with(b"\n") || input.is_empty() {
        lines.pop();
    }
    lines
        .into_iter()
        .filter(|l| !l.iter().all(u8::is_ascii_whitespace))
        .collect()
}

/// The `id` an answer to `line` must echo.
fn expected_id(line: &[u8]) -> Value {
    match serde_json::from_slice::<Value>(line) {
        Ok(Value::Object(mut map)) => map.remove("id").unwrap_or(Value::Null),
        _ => Value::Null,
    }
}

/// Every number finite, and no `null` (JSON's stand-in for a non-finite number) anywhere.
fn all_finite(value: &Value) -> bool {
    match value {
        Value::Null => false,
        Value::Number(n) => n.as_f64().is_some_and(f64::is_finite),
        Value::Array(items) => items.iter().all(all_finite),
        Value::Object(map) => map.values().all(all_finite),
        Value::Bool(_) | Value::String(_) => true,
    }
}

/// Checks the answers to a whole stream; returns them parsed.
fn check_stream(input: &[u8]) -> Result<Vec<Value>, TestCaseError> {
    let lines = request_lines(input);
    let answers = run_eval(input);
    prop_assert_eq!(
        answers.len(),
        lines.len(),
        "one answer per non-blank request line"
    );
    let mut parsed = Vec::with_capacity(answers.len());
    for (line, answer) in lines.iter().zip(&answers) {
        let value: Value = serde_json::from_str(answer)
            .map_err(|e| TestCaseError::fail(format!("answer is not JSON ({e}): {answer}")))?;
        let Value::Object(map) = &value else {
            return Err(TestCaseError::fail(format!(
                "answer is not an object: {answer}"
            )));
        };
        prop_assert_eq!(
            &map["id"],
            &expected_id(line),
            "id of the answer {}",
            answer
        );
        match map.get("ok") {
            Some(Value::Bool(true)) => {
                prop_assert!(
                    !map.contains_key("error"),
                    "ok answer with an error: {}",
                    answer
                );
                let mut fields = map.clone();
                fields.remove("id");
                prop_assert!(
                    all_finite(&Value::Object(fields)),
                    "ok answer with a non-finite number: {}",
                    answer
                );
            }
            Some(Value::Bool(false)) => {
                let kind = map["error"]["kind"].as_str().unwrap_or("");
                let message = map["error"]["message"].as_str().unwrap_or("");
                prop_assert!(
                    !kind.is_empty() && !message.is_empty(),
                    "bad error: {}",
                    answer
                );
            }
            _ => return Err(TestCaseError::fail(format!("no ok field: {answer}"))),
        }
        parsed.push(value);
    }
    Ok(parsed)
}

/// Known-good requests, one per op, each with its answer when sent alone.
fn good_requests() -> &'static [(String, Value)] {
    static GOOD: OnceLock<Vec<(String, Value)>> = OnceLock::new();
    GOOD.get_or_init(|| {
        let fis = serde_json::to_string(include_str!("../../../fuzzy-sugeno/data/paper.fis")).unwrap();
        let requests = [
            r#"{"id":"good-fk","op":"fk","a":[0.3,-0.2],"alpha0":1.2}"#.to_string(),
            r#"{"id":"good-ik","op":"ik","target":[0.3,0.5],"alpha0":1.5707963267948966}"#.to_string(),
            r#"{"id":"good-joints","op":"joints","arm":{"links":5},"a":[0.1,0.2,0.3]}"#.to_string(),
            r#"{"id":"good-dynamics","op":"dynamics","arm":{"links":3,"gravity":9.81},"theta":[0.1,0.2,0.3],"theta_dot":[1,-1,0.5]}"#.to_string(),
            r#"{"id":"good-reduced","op":"reduced","a":[0.4,-0.3],"alpha0":1.2,"a_dot":[0.5,1],"tau_star":[0.3,-0.1]}"#.to_string(),
            r#"{"id":"good-fuzzy","op":"fuzzy","controller":"paper","inputs":[0.1,-0.2,0.3,0.5]}"#.to_string(),
            format!(r#"{{"id":"good-fis","op":"fuzzy","fis":{fis},"inputs":[0.1,-0.2,0.3,0.5]}}"#),
        ];
        requests
            .into_iter()
            .map(|request| {
                let answers = run_eval(format!("{request}\n").as_bytes());
                assert_eq!(answers.len(), 1);
                let answer: Value = serde_json::from_str(&answers[0]).unwrap();
                assert_eq!(answer["ok"], true, "{request} -> {answer}");
                (request, answer)
            })
            .collect()
    })
}

/// A line of the stream: a known-good request (by index) or anything else.
#[derive(Debug, Clone)]
enum Line {
    Good(usize),
    Other(Vec<u8>),
}

/// Builds the stream, checks it, and checks each good request's answer against its solo answer.
fn check_mixed(lines: &[Line], crlf: bool) -> Result<(), TestCaseError> {
    let good = good_requests();
    let mut input = Vec::new();
    let mut goods_at = Vec::new();
    let mut index = 0;
    for line in lines {
        let bytes: &[u8] = match line {
            Line::Good(k) => {
                goods_at.push((index, k % good.len()));
                good[k % good.len()].0.as_bytes()
            }
            Line::Other(bytes) => bytes,
        };
        if !bytes.iter().all(u8::is_ascii_whitespace) {
            index += 1;
        } else if matches!(line, Line::Good(_)) {
            unreachable!("good requests are not blank");
        }
        input.extend_from_slice(bytes);
        input.extend_from_slice(if crlf { b"\r\n" } else { b"\n" });
    }
    let answers = check_stream(&input)?;
    for (at, k) in goods_at {
        prop_assert_eq!(
            &answers[at],
            &good[k].1,
            "answer to {} changed in a stream",
            &good[k].0
        );
    }
    Ok(())
}

/// Raw JSON texts for a number field: edge numbers, wrong types, nesting, long digit strings.
fn raw_number() -> impl Strategy<Value = String> {
    let edge = prop::sample::select(vec![
        "0",
        "-0",
        "-0.0",
        "1",
        "-1",
        "0.5",
        "1.5",
        "3",
        "1e308",
        "-1e308",
        "1.7976931348623157e308",
        "1e400",
        "-1e400",
        "1e-400",
        "5e-324",
        "1e-320",
        "1000000000",
        "1000000000000",
        "18446744073709551616",
        "-9223372036854775809",
        "123456789012345678901234567890",
        "NaN",
        "nan",
        "Infinity",
        "-Infinity",
        "\"NaN\"",
        "\"inf\"",
        "\"1.0\"",
        "true",
        "false",
        "null",
        "{}",
        "[]",
        "[1]",
        "\"\"",
        "01",
        "1.",
        ".5",
        "+1",
        "0x10",
        "1e",
        "--1",
    ])
    .prop_map(str::to_string);
    prop_oneof![
        4 => edge,
        4 => (-4.0f64..4.0).prop_map(|x| format!("{x}")),
        1 => (1usize..40).prop_map(|n| "9".repeat(n * 100)),
        1 => (1usize..400).prop_map(|d| format!("{}1{}", "[".repeat(d), "]".repeat(d))),
        1 => (1usize..400).prop_map(|d| format!("{}1{}", "{\"a\":".repeat(d), "}".repeat(d))),
    ]
}

/// A raw JSON array of `raw_number`s, of a random (often wrong) length.
fn raw_array() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => prop::collection::vec(raw_number(), 0..12).prop_map(|v| format!("[{}]", v.join(","))),
        3 => prop::collection::vec((-2.0f64..2.0).prop_map(|x| format!("{x}")), 0..12)
            .prop_map(|v| format!("[{}]", v.join(","))),
        1 => raw_number(),
    ]
}

/// A raw JSON arm: the scalar or per-link fields, each mutated.
fn raw_arm() -> impl Strategy<Value = String> {
    let links = prop_oneof![
        3 => (0usize..8).prop_map(|n| n.to_string()),
        1 => prop::sample::select(vec![
            "1000000000", "1000000000000", "18446744073709551615", "18446744073709551616", "-1",
            "1.5", "1001", "\"10\"", "null",
        ])
        .prop_map(str::to_string),
    ];
    (
        prop::option::of(links),
        prop::option::of(raw_number()),
        prop::option::of(raw_number()),
        prop::option::of(raw_number()),
        prop::option::of(raw_array()),
        prop::option::of(raw_array()),
        prop::option::of(raw_array()),
        prop::option::of(Just("\"extra\":1")),
    )
        .prop_map(
            |(links, length, mass, gravity, lengths, masses, inertias, extra)| {
                let mut fields = Vec::new();
                for (key, value) in [
                    ("links", links),
                    ("link_length", length),
                    ("link_mass", mass),
                    ("gravity", gravity),
                    ("lengths", lengths),
                    ("masses", masses),
                    ("inertias", inertias),
                ] {
                    if let Some(value) = value {
                        fields.push(format!("\"{key}\":{value}"));
                    }
                }
                fields.extend(extra.map(str::to_string));
                format!("{{{}}}", fields.join(","))
            },
        )
}

/// A request of a known op, every field possibly mutated, dropped, or joined by an unknown one.
fn mutated_request() -> impl Strategy<Value = String> {
    let op = prop::sample::select(vec!["fk", "ik", "joints", "dynamics", "reduced", "fuzzy"]);
    let field = prop_oneof![
        Just(None),
        raw_array().prop_map(Some),
        raw_number().prop_map(Some),
    ];
    (
        op,
        any::<u32>(),
        prop::option::of(raw_arm()),
        prop::collection::vec(field, 6),
        prop::option::of(Just("\"bogus\":0")),
        prop::sample::select(vec![None, Some("paper"), Some("other")]),
    )
        .prop_map(|(op, id, arm, values, extra, controller)| {
            let keys: &[&str] = match op {
                "fk" => &["a", "alpha0"],
                "ik" => &["target", "alpha0"],
                "joints" => &["a", "alpha0"],
                "dynamics" => &["theta", "theta_dot"],
                "reduced" => &["a", "a_dot", "tau_star", "alpha0"],
                _ => &["inputs", "fis"],
            };
            let mut fields = vec![format!("\"id\":{id}"), format!("\"op\":\"{op}\"")];
            if let Some(arm) = arm {
                fields.push(format!("\"arm\":{arm}"));
            }
            for (key, value) in keys.iter().zip(values) {
                if let Some(value) = value {
                    fields.push(format!("\"{key}\":{value}"));
                }
            }
            if let (Some(controller), "fuzzy") = (controller, op) {
                fields.push(format!("\"controller\":\"{controller}\""));
            }
            fields.extend(extra.map(str::to_string));
            format!("{{{}}}", fields.join(","))
        })
}

/// Arbitrary bytes without a newline, JSON-looking fragments, blank lines.
fn arbitrary_line() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        4 => prop::collection::vec(any::<u8>().prop_filter("no newline", |&b| b != b'\n'), 0..80),
        2 => "[{}\\[\\]\":,0-9a-z .eE+-]{0,80}".prop_map(String::into_bytes),
        1 => prop::sample::select(vec!["", " ", "\t", "\r", " \r\t ", "\x0c"]).prop_map(|s| s.as_bytes().to_vec()),
        1 => prop::sample::select(vec!["{", "}", "[]", "null", "\"x\"", "{\"op\":1}", "{\"op\":\"fk\"}",
            "{\"id\":[1,2],\"op\":\"nope\"}", "{\"id\":null}", "\u{feff}{\"op\":\"fk\"}"])
            .prop_map(|s| s.as_bytes().to_vec()),
    ]
}

proptest! {
    // Each case spawns one process for a few dozen lines.
    #![proptest_config(test_support::config::scaled(4))]

    #[test]
    fn arbitrary_byte_lines_interleaved_with_good_requests(
        lines in prop::collection::vec(
            prop_oneof![1 => any::<usize>().prop_map(Line::Good), 3 => arbitrary_line().prop_map(Line::Other)],
            1..40,
        ),
        crlf in any::<bool>(),
    ) {
        check_mixed(&lines, crlf)?;
    }

    #[test]
    fn mutated_requests_interleaved_with_good_requests(
        lines in prop::collection::vec(
            prop_oneof![
                1 => any::<usize>().prop_map(Line::Good),
                4 => mutated_request().prop_map(|r| Line::Other(r.into_bytes())),
            ],
            1..40,
        ),
    ) {
        check_mixed(&lines, false)?;
    }

    #[test]
    fn a_stream_without_final_newline_is_answered(tail in arbitrary_line()) {
        let mut input = good_requests()[0].0.clone().into_bytes();
        input.push(b'\n');
        input.extend_from_slice(&tail);
        check_stream(&input)?;
    }
}

/// Edge cases kept as named regressions, all in one stream.
#[test]
fn edge_case_lines_get_one_error_each_and_the_stream_goes_on() {
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    let deep_object = format!(
        "{{\"id\":1,\"op\":\"fk\",\"a\":{}0{}}}",
        "[".repeat(5000),
        "]".repeat(5000)
    );
    let huge_fis = serde_json::to_string(
        &include_str!("../../../fuzzy-sugeno/data/paper.fis")
            .replace("NumInputs=4", "NumInputs=1000000000000"),
    )
    .unwrap();
    let cases: Vec<(String, &str)> = vec![
        (deep, "parse"),
        (deep_object, "parse"),
        (r#"{"id":2,"op":"fk","a":[1e400,0],"alpha0":0}"#.into(), "parse"),
        (format!(r#"{{"id":3,"op":"fk","a":[{},0],"alpha0":0}}"#, "1".repeat(5000)), "parse"),
        (format!(r#"{{"id":3.5,"op":"fk","a":[0.{}1,0],"alpha0":0}}"#, "0".repeat(5000)), "ok"),
        // A 30-digit integer is read as a number, and refused as a modal coordinate.
        (format!(r#"{{"id":3.7,"op":"fk","a":[{},0],"alpha0":0}}"#, "1".repeat(30)), "invalid_input"),
        (r#"{"id":4,"op":"joints","arm":{"links":1000000000},"a":[0,0,0]}"#.into(), "invalid_input"),
        (r#"{"id":5,"op":"dynamics","arm":{"links":1000000000000},"theta":[0],"theta_dot":[0]}"#.into(), "invalid_input"),
        (r#"{"id":6,"op":"reduced","arm":{"links":18446744073709551615},"a":[0,0,0],"a_dot":[0,0,0],"tau_star":[0,0,0]}"#.into(), "invalid_input"),
        (r#"{"id":7,"op":"fk","arm":{"links":0},"a":[0,0],"alpha0":0}"#.into(), "invalid_input"),
        (r#"{"id":8,"op":"ik","arm":{"lengths":[1e308,1e308]},"target":[0.3,0.5],"alpha0":0}"#.into(), "invalid_input"),
        (r#"{"id":9,"op":"fk","a":["NaN",0],"alpha0":0}"#.into(), "invalid_request"),
        (r#"{"id":10,"op":"dynamics","theta":[],"theta_dot":[]}"#.into(), "invalid_input"),
        (format!(r#"{{"id":11,"op":"fuzzy","fis":{huge_fis},"inputs":[0,0,0,0]}}"#), "invalid_input"),
        // Modes beyond the scale of a run (theta = J a would overflow); a huge alpha0 alone
        // is answered (it is reduced modulo 2 pi).
        (r#"{"id":12,"op":"joints","harmonics":2,"a":[1.7e308,1.7e308,1.7e308,1.7e308,0]}"#.into(), "invalid_input"),
        (r#"{"id":12.5,"op":"joints","a":[0,0,1.7e308]}"#.into(), "ok"),
        // The same in `fk`, planar and spatial, is the same answer.
        (r#"{"id":12.6,"op":"fk","arm":{"links":4},"a":[1.7e308,1.7e308],"alpha0":0}"#.into(), "invalid_input"),
        (r#"{"id":12.7,"op":"fk","arm":{"kind":"spatial","links":4},"a":[1.7e308,1.7e308,1.7e308,1.7e308]}"#.into(), "invalid_input"),
        ("\u{feff}{\"id\":13,\"op\":\"fk\"}".into(), "parse"),
        (r#"{"id":-0,"op":"joints","a":[-0,-0,-0]}"#.into(), "ok"),
    ];
    let mut input = Vec::new();
    for (line, _) in &cases {
        input.extend_from_slice(line.as_bytes());
        input.extend_from_slice(b"\r\n\n \r\n");
    }
    input.extend_from_slice(b"\xff\xfe{\"id\":14}\n");
    input.extend_from_slice(good_requests()[2].0.as_bytes());
    let answers = check_stream(&input).unwrap();
    for ((line, kind), answer) in cases.iter().zip(&answers) {
        let got = answer["error"]["kind"].as_str().unwrap_or("ok");
        assert_eq!(got, *kind, "{} -> {answer}", &line[..line.len().min(200)]);
    }
    let bom = cases
        .iter()
        .position(|(line, _)| line.starts_with('\u{feff}'));
    assert!(
        answers[bom.unwrap()]["error"]["message"]
            .as_str()
            .unwrap()
            .starts_with("malformed JSON: the line starts with a byte-order mark (U+FEFF)")
    );
    assert_eq!(answers[cases.len()]["error"]["kind"], "invalid_utf8");
    assert_eq!(answers[cases.len() + 1], good_requests()[2].1);
}

/// A line over the 16 MiB limit is refused and the next line answered, through the binary.
#[test]
fn an_overlong_line_is_refused_through_the_binary() {
    let mut input = vec![b'['; (16 << 20) + 1];
    input.push(b'\n');
    input.extend_from_slice(good_requests()[0].0.as_bytes());
    input.push(b'\n');
    let answers = check_stream(&input).unwrap();
    assert_eq!(answers[0]["error"]["kind"], "line_too_long");
    assert_eq!(answers[1], good_requests()[0].1);
}
