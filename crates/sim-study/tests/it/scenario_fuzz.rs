//! Fuzzing the scenario loader: arbitrary text, and the shipped scenarios with lines deleted or
//! duplicated, values set to 0, negative, NaN, infinite, huge or of the wrong type, unknown keys
//! and sections added.
//!
//! Properties: `from_toml` never panics and refuses with a message; an accepted scenario writes
//! and reads back equal (`to_toml`); `build` refuses with a message naming the setting or yields
//! a simulation; a cheap accepted case (duration capped to at most 20 controller periods) runs
//! to a finite summary or stops with a `RunFailure`, never a panic.

use proptest::prelude::*;
use sim_study::{IntegratorSpec, Scenario};

const SHIPPED: &[&str] = &[
    include_str!("../../scenarios/paper-tracking.toml"),
    include_str!("../../scenarios/paper-responses-step.toml"),
    include_str!("../../scenarios/paper-responses-sine.toml"),
    include_str!("../../scenarios/paper-responses-noise.toml"),
];

/// Values a mutation may give any `key = value` line.
const VALUES: &[&str] = &[
    "0",
    "-0.0",
    "-1",
    "-1e-3",
    "1e-300",
    "1e300",
    "1e308",
    "-1e308",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "1000000000000",
    "9223372036854775807",
    "-9223372036854775808",
    "0.00003",
    "0.0002",
    "0.5",
    "3",
    "\"fuzzy\"",
    "\"pd\"",
    "\"computed-torque\"",
    "\"fuzzy-gc\"",
    "\"dopri5\"",
    "\"rk4\"",
    "\"step\"",
    "\"sinusoid\"",
    "\"path\"",
    "\"constant\"",
    "\"negative\"",
    "\"nope\"",
    "\"\"",
    "true",
    "[]",
    "[0.0]",
    "[0.0, 0.0]",
    "[nan, 0.0]",
    "[inf, -inf]",
    "[1e300, -1e300]",
    "[-1.0, -1.0]",
    "[0.1, 0.2, 0.3]",
    "[[0.1, 0.5], [0.2, 0.5]]",
    "[[0.1, 0.5]]",
    "[[nan, 0.5], [0.2, 0.5]]",
    "{}",
    "{ a = 1 }",
    "1979-05-27",
];

/// Lines a mutation may insert (sections, unknown keys, extreme settings).
const LINES: &[&str] = &[
    "",
    "[arm]",
    "[noise]",
    "[limits]",
    "[initial]",
    "[unknown]",
    "[controller]",
    "[integrator]",
    "[reference.sine]",
    "links = 0",
    "links = 1",
    "links = 2",
    "links = 1000000000000",
    "links = -1",
    "lengths = [0.1, 0.1, 0.1]",
    "masses = [0.1, -0.1, 0.1]",
    "inertias = [0.0, 0.001, nan]",
    "gravity = nan",
    "dt = 0",
    "dt = 1e-300",
    "period = 0.00005",
    "duration = 1e300",
    "duration = 0",
    "record_period = 1e300",
    "record_period = 0.00001",
    "rtol = 0",
    "rtol = -1",
    "rtol = 1e-320",
    "gravity = 1e308",
    "pitch = 1e300",
    "atol = 0",
    "h_max = 0",
    "max_steps = 0",
    "reference_std = [-0.1, 0.0]",
    "sensor_a_std = [nan, 0.0]",
    "sensor_a_dot_std = [inf, 0.0]",
    "max_modal_error = 0",
    "joint_torque_nm = -1",
    "joint_torque_nm = [1.0, 2.0]",
    "a = [0.1, 0.2]",
    "a = [nan, 0.2]",
    "a_dot = [1e300, 0]",
    "fis = \"/nonexistent/file.fis\"",
    "kp = [-1.0, 0.0]",
    "kd = [nan, 0.0]",
    "unknown_key = 1",
    "seed = -1",
    "time = -1",
    "travel_time = 0",
    "points = [[0.1, 0.5]]",
    "points = [[5.0, 5.0], [6.0, 6.0]]",
    "x_end = 0.08",
    "amplitude = [1e300, 0.0]",
    "frequency_hz = [1e300, 0.0]",
    "= 1",
    "[[arm]]",
    "key = ",
    "\"quoted\" = 1",
];

#[derive(Debug, Clone)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Insert(usize, &'static str),
    /// Replaces the value of a `key = value` line (modulo the number of such lines).
    Value(usize, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let index = any::<usize>();
    prop_oneof![
        1 => index.prop_map(Mutation::Delete),
        1 => index.prop_map(Mutation::Duplicate),
        2 => (index, prop::sample::select(LINES)).prop_map(|(i, l)| Mutation::Insert(i, l)),
        4 => (index, prop::sample::select(VALUES)).prop_map(|(i, v)| Mutation::Value(i, v)),
    ]
}

fn mutate(text: &str, mutations: &[Mutation]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for m in mutations {
        let n = lines.len().max(1);
        match *m {
            Mutation::Delete(i) if !lines.is_empty() => {
                lines.remove(i % n);
            }
            Mutation::Duplicate(i) if !lines.is_empty() => {
                let line = lines[i % n].clone();
                lines.insert(i % n, line);
            }
            Mutation::Insert(i, line) => lines.insert(i % (lines.len() + 1), line.to_string()),
            Mutation::Value(i, value) => {
                let keyed: Vec<usize> = (0..lines.len())
                    .filter(|&k| !lines[k].starts_with('#') && lines[k].contains(" = "))
                    .collect();
                if !keyed.is_empty() {
                    let line = &mut lines[keyed[i % keyed.len()]];
                    let key = line.split(" = ").next().unwrap_or_default().to_string();
                    *line = format!("{key} = {value}");
                }
            }
            _ => {}
        }
    }
    lines.join("\n")
}

/// The controller period a scenario asks for (`None` if it has none).
fn period(scenario: &Scenario) -> Option<f64> {
    match (scenario.controller.period, scenario.integrator) {
        (Some(p), _) => Some(p),
        (None, IntegratorSpec::Rk4 { dt }) => Some(dt),
        (None, IntegratorSpec::Dopri5 { .. }) => None,
    }
}

/// A copy cheap enough to run: at most 20 controller periods of at most 100 RK4 steps, or of
/// at most 10,000 Dormand-Prince steps, recorded every period.
fn cheap(scenario: &Scenario) -> Option<Scenario> {
    let period = period(scenario)?;
    let mut cheap = scenario.clone();
    cheap.duration = period * (scenario.duration / period).round().clamp(1.0, 20.0);
    cheap.record_period = None;
    match &mut cheap.integrator {
        IntegratorSpec::Rk4 { dt } => (period / *dt <= 100.0).then_some(())?,
        IntegratorSpec::Dopri5 { max_steps, .. } => {
            *max_steps = Some(max_steps.unwrap_or(10_000).min(10_000));
        }
    }
    Some(cheap)
}

/// The property for one text.
fn check(text: &str) -> Result<(), TestCaseError> {
    let scenario = match Scenario::from_toml(text) {
        Err(error) => {
            let message = error.to_string();
            prop_assert!(
                message.starts_with("scenario text is malformed: ") && message.len() > 30,
                "unhelpful error `{}`",
                message
            );
            return Ok(());
        }
        Ok(scenario) => scenario,
    };
    // Writing never fails; an accepted scenario without NaN reads back equal.
    let written = scenario.to_toml();
    let read = Scenario::from_toml(&written).map_err(|e| {
        TestCaseError::fail(format!(
            "written scenario does not read back: {e}\n{written}"
        ))
    })?;
    let copy = scenario.clone();
    if copy == scenario {
        prop_assert_eq!(
            &read,
            &scenario,
            "round trip changed the scenario\n{}",
            written
        );
    }
    if let Err(error) = scenario.build() {
        let message = error.to_string();
        prop_assert!(message.len() > 10, "unhelpful error `{}`", message);
        return Ok(());
    }
    let Some(cheap) = cheap(&scenario) else {
        return Ok(());
    };
    let mut simulation = match cheap.build() {
        Ok(simulation) => simulation,
        // Capping the duration may make it a non-multiple of the recording period: refused.
        Err(_) => return Ok(()),
    };
    match simulation.run() {
        Ok(run) => {
            let s = &run.summary;
            let numbers = [
                s.simulated_s,
                s.tip_error_rms_m,
                s.tip_error_max_m,
                s.peak_joint_torque_nm,
                s.control_effort_n2m2s,
            ];
            let all = numbers
                .iter()
                .chain(&s.modal_error_rms_rad)
                .chain(&s.modal_error_max_rad)
                .chain(&s.peak_modal_torques_nm)
                .chain(&s.peak_joint_torques_nm);
            for x in all {
                prop_assert!(x.is_finite(), "non-finite summary {:?}\n{}", s, text);
            }
        }
        Err(failure) => {
            prop_assert!(failure.to_string().len() > 10);
        }
    }
    Ok(())
}

fn fuzz_config() -> ProptestConfig {
    // Cheap: an accepted case builds a model and runs at most 20 short controller periods.
    ProptestConfig::default()
}

proptest! {
    #![proptest_config(fuzz_config())]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        check(&text)?;
    }

    #[test]
    fn toml_like_text_never_panics(text in "[\\[\\]a-z_0-9=\". \n#-]{0,300}") {
        check(&text)?;
    }

    #[test]
    fn mutated_shipped_scenarios_are_refused_or_sound(
        which in 0..SHIPPED.len(),
        mutations in prop::collection::vec(mutation(), 1..5),
    ) {
        check(&mutate(SHIPPED[which], &mutations))?;
    }
}

/// Minimal reproducers of what the fuzzer found, and the edge cases the brief names.
mod regressions {
    use super::*;

    const HOLD: &str = "name = \"hold\"\nduration = 0.01\nalpha0 = 1.0\n\
        reference = { kind = \"constant\", a = [0.3, -0.2] }\n\
        integrator = { method = \"rk4\", dt = 1e-3 }\n";

    fn build_error(extra: &str) -> String {
        let text = format!("{HOLD}{extra}");
        let scenario = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        match scenario.build() {
            Ok(_) => panic!("accepted\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn the_shipped_scenarios_are_sound() {
        for text in SHIPPED {
            check(text).unwrap();
        }
        check(HOLD).unwrap();
    }

    #[test]
    fn a_huge_link_count_is_refused_before_allocating() {
        assert_eq!(
            build_error("arm = { links = 1000000000000 }"),
            "arm.links must be at most 1000000, got 1000000000000"
        );
    }

    #[test]
    fn a_duration_of_1e300_is_refused() {
        // It once overflowed the recorded-sample count in `Simulation::new` (debug panic).
        let text = HOLD.replace("duration = 0.01", "duration = 1e300");
        let message = Scenario::from_toml(&text)
            .unwrap()
            .build()
            .err()
            .unwrap()
            .to_string();
        assert_eq!(
            message,
            "duration must be at most 1e9 controller periods (controller.period = 0.001 s), got 1e300 s"
        );
    }

    #[test]
    fn seeds_above_i64_max_are_written_and_read_back() {
        // `to_toml` once panicked on a seed TOML integers cannot hold (sweeps draw full-range seeds).
        for seed in [0, 1 << 62, i64::MAX as u64, (i64::MAX as u64) + 1, u64::MAX] {
            let mut scenario = Scenario::from_toml(HOLD).unwrap();
            scenario.seed = seed;
            assert_eq!(Scenario::from_toml(&scenario.to_toml()).unwrap(), scenario);
        }
        let negative = Scenario::from_toml(&format!("{HOLD}seed = -1"))
            .unwrap_err()
            .to_string();
        assert!(
            negative.contains("seed must not be negative, got -1"),
            "{negative}"
        );
        let text = Scenario::from_toml(&format!("{HOLD}seed = \"x\""))
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("seed must be an integer from 0 to 18446744073709551615"),
            "{text}"
        );
    }

    #[test]
    fn edge_settings_are_refused_with_the_setting_named() {
        for (extra, setting) in [
            ("arm = { links = 0 }", "arm.links"),
            ("record_period = 0.0", "record_period"),
            ("controller = { period = 0.0005 }", "controller.period"),
            (
                "noise = { reference_std = [-0.1, 0.0] }",
                "noise.reference_std",
            ),
            (
                "noise = { sensor_a_std = [nan, 0.0] }",
                "noise.sensor_a_std[0]",
            ),
            (
                "limits = { max_modal_error = 0.0 }",
                "limits.max_modal_error",
            ),
        ] {
            let message = build_error(extra);
            assert!(message.contains(setting), "{extra}: {message}");
        }
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_refused_with_the_line() {
        for text in [
            format!("{HOLD}bogus = 1"),
            HOLD.replace("duration = 0.01", "duration = \"long\""),
            HOLD.replace("alpha0 = 1.0", "alpha0 = [1.0]"),
        ] {
            let message = Scenario::from_toml(&text).unwrap_err().to_string();
            assert!(message.contains("line "), "{message}");
            assert!(!message.contains('\n'), "one line: {message}");
        }
    }
}
