//! What a sweep's results depend on besides its settings: the SHA-256 of the scenario's
//! canonical content and of every file the scenario references (the `.fis` of the fuzzy
//! controller), so that shards run with different contents are never merged; and the check
//! that every scenario setting survives the JSON of a shard file.

use crate::Scenario;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The name of the scenario's own entry in [`SweepConfig::inputs`](super::SweepConfig::inputs).
pub const SCENARIO_INPUT: &str = "scenario";

/// The SHA-256 of one input of a sweep.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputDigest {
    /// [`SCENARIO_INPUT`] for the scenario's canonical content (its compact JSON), else the
    /// setting that names a file (`controller.fis`).
    pub input: String,
    /// The file, for a file input.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathBuf>,
    /// The SHA-256 of the content, 64 lower-case hexadecimal digits.
    pub sha256: String,
}

impl InputDigest {
    /// What the digest is of, for messages: `scenario` or `controller.fis (path)`.
    pub fn describe(&self) -> String {
        match &self.path {
            Some(path) => format!("{} ({})", self.input, path.display()),
            None => self.input.clone(),
        }
    }
}

/// The files `scenario` references, by the setting that names them.
fn referenced_files(scenario: &Scenario) -> Vec<(&'static str, &Path)> {
    scenario
        .controller
        .fis
        .as_deref()
        .map(|fis| ("controller.fis", fis))
        .into_iter()
        .collect()
}

/// The SHA-256 of `bytes` in lower-case hexadecimal.
fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .fold(String::with_capacity(64), |mut hex, byte| {
            let _ = write!(hex, "{byte:02x}");
            hex
        })
}

/// The digest of the scenario's canonical content: its compact JSON, fields in declaration
/// order (what a shard file stores).
fn scenario_digest(scenario: &Scenario) -> Result<InputDigest, String> {
    let json = serde_json::to_string(scenario)
        .map_err(|e| format!("the scenario cannot be written as JSON: {e}"))?;
    Ok(InputDigest {
        input: SCENARIO_INPUT.into(),
        path: None,
        sha256: sha256_hex(json.as_bytes()),
    })
}

/// The digests of `scenario` and of every file it references, scenario first. Reads the files
/// (at most [`MAX_INPUT_FILE_BYTES`](crate::MAX_INPUT_FILE_BYTES) each, as a run does).
pub fn input_digests(scenario: &Scenario) -> Result<Vec<InputDigest>, String> {
    let mut digests = vec![scenario_digest(scenario)?];
    for (input, path) in referenced_files(scenario) {
        let text = crate::read_text_file(path, crate::MAX_INPUT_FILE_BYTES)
            .map_err(|e| format!("{input} cannot be read from {}: {e}", path.display()))?;
        digests.push(InputDigest {
            input: input.into(),
            path: Some(path.to_path_buf()),
            sha256: sha256_hex(text.as_bytes()),
        });
    }
    Ok(digests)
}

/// Checks, without reading any file, that `digests` list the scenario and the files it
/// references, in that order, and that the scenario's digest is that of its content (a shard
/// file whose scenario was edited by hand fails here).
pub fn check_digests(scenario: &Scenario, digests: &[InputDigest]) -> Result<(), String> {
    let expected = std::iter::once((SCENARIO_INPUT, None)).chain(
        referenced_files(scenario)
            .into_iter()
            .map(|(i, p)| (i, Some(p))),
    );
    let listed = digests
        .iter()
        .map(|d| (d.input.as_str(), d.path.as_deref()));
    if !expected.eq(listed) {
        let names: Vec<String> = digests.iter().map(InputDigest::describe).collect();
        return Err(format!(
            "inputs lists [{}], but the scenario and the files it references are [{}]",
            names.join(", "),
            std::iter::once(SCENARIO_INPUT.to_string())
                .chain(
                    referenced_files(scenario)
                        .into_iter()
                        .map(|(i, p)| format!("{i} ({})", p.display()))
                )
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if let Some(bad) = digests
        .iter()
        .find(|d| d.sha256.len() != 64 || !d.sha256.bytes().all(|b| b.is_ascii_hexdigit()))
    {
        return Err(format!(
            "the SHA-256 of {} must be 64 hexadecimal digits, got '{}'",
            bad.describe(),
            bad.sha256.escape_debug()
        ));
    }
    if scenario_digest(scenario)?.sha256 != digests[0].sha256 {
        return Err(
            "the scenario's SHA-256 does not match its content (was the file edited?)".into(),
        );
    }
    Ok(())
}

/// The first input whose digest differs between two digest lists of the same scenario, as
/// `(input, sha256 here, sha256 there)`.
pub fn first_changed<'a>(
    here: &'a [InputDigest],
    there: &'a [InputDigest],
) -> Option<(&'a InputDigest, &'a str)> {
    here.iter()
        .zip(there)
        .find(|(a, b)| a.sha256 != b.sha256)
        .map(|(a, b)| (a, b.sha256.as_str()))
}

/// Checks that every setting of `scenario` can be written to JSON and read back unchanged: JSON
/// has no infinity or NaN (serde writes them as `null`) and no non-UTF-8 path. The error names
/// the first setting that cannot, e.g. `limits.max_modal_error = inf`.
pub fn check_json_safe(scenario: &Scenario) -> Result<(), String> {
    let value = toml::Value::try_from(scenario)
        .map_err(|e| format!("a scenario setting cannot be written to a shard file: {e}"))?;
    if let Some((setting, v)) = first_non_finite(&value, String::new()) {
        return Err(format!(
            "scenario setting {setting} = {v} cannot be written to a shard file (JSON has no \
             infinity or NaN): give a finite value"
        ));
    }
    let json = serde_json::to_string(scenario)
        .map_err(|e| format!("a scenario setting cannot be written to a shard file: {e}"))?;
    match serde_json::from_str::<Scenario>(&json) {
        Ok(back) if back == *scenario => Ok(()),
        Ok(_) => {
            Err("the scenario reads back from JSON changed: a setting does not round-trip".into())
        }
        Err(e) => Err(format!("the scenario does not read back from JSON: {e}")),
    }
}

/// The dotted path and value of the first non-finite float in `value`.
fn first_non_finite(value: &toml::Value, at: String) -> Option<(String, f64)> {
    match value {
        toml::Value::Float(f) if !f.is_finite() => Some((at, *f)),
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, item)| first_non_finite(item, format!("{at}[{i}]"))),
        toml::Value::Table(table) => table.iter().find_map(|(key, item)| {
            let path = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            first_non_finite(item, path)
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{IntegratorSpec, ReferenceSpec, TorqueLimit};

    #[test]
    fn sha256_matches_the_fips_180_2_vectors() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }

    /// One setting per class: a plain number, a number of a tagged table (the integrator), an
    /// optional one, a number in an array, a number in an array of arrays, a number or array
    /// of an untagged choice. Each is accepted finite and refused infinite or NaN, named.
    #[test]
    fn settings_json_cannot_hold_are_refused_by_name() {
        let base = Scenario::builtin("paper-responses-step").unwrap();
        assert_eq!(check_json_safe(&base), Ok(()));
        type Edit = fn(&mut Scenario, f64);
        let classes: [(&str, Edit); 6] = [
            ("limits.max_modal_error", |s, v| {
                s.limits.max_modal_error = v
            }),
            ("integrator.h_max", |s, v| {
                s.integrator = IntegratorSpec::Dopri5 {
                    rtol: 1e-9,
                    atol: 1e-12,
                    h_max: Some(v),
                    max_steps: None,
                }
            }),
            ("arm.gravity", |s, v| {
                s.arm.gravity = Some(crate::Gravity::Magnitude(v))
            }),
            ("reference.target[1]", |s, v| {
                s.reference = ReferenceSpec::Step {
                    initial: None,
                    target: vec![0.1, v],
                    time: 0.0,
                }
            }),
            ("reference.points[1][0]", |s, v| {
                s.reference = ReferenceSpec::Path {
                    travel_time: 1.0,
                    branch: Default::default(),
                    sine: None,
                    points: Some(vec![[0.2, 0.5], [v, 0.5]]),
                    helix: None,
                }
            }),
            ("limits.joint_torque_nm", |s, v| {
                s.limits.joint_torque_nm = Some(TorqueLimit::All(v))
            }),
        ];
        for (setting, edit) in classes {
            let mut s = base.clone();
            edit(&mut s, 0.25);
            assert_eq!(check_json_safe(&s), Ok(()), "{setting}");
            for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
                let mut s = base.clone();
                edit(&mut s, bad);
                let err = check_json_safe(&s).unwrap_err();
                assert!(
                    err.contains(&format!("scenario setting {setting} = {bad}")),
                    "{setting}: {err}"
                );
            }
        }
        let mut per_joint = base.clone();
        per_joint.limits.joint_torque_nm = Some(TorqueLimit::PerJoint(vec![1.0, f64::INFINITY]));
        let err = check_json_safe(&per_joint).unwrap_err();
        assert!(err.contains("limits.joint_torque_nm[1] = inf"), "{err}");
    }

    #[test]
    fn a_path_that_is_not_utf8_is_refused() {
        use std::os::unix::ffi::OsStrExt;
        let mut s = Scenario::builtin("paper-responses-step").unwrap();
        let name = std::ffi::OsStr::from_bytes(b"/tmp/\xff.fis");
        s.controller.fis = Some(PathBuf::from(name));
        let err = check_json_safe(&s).unwrap_err();
        assert!(err.contains("cannot be written to a shard file"), "{err}");
    }

    #[test]
    fn digests_follow_the_files_and_name_them() {
        let dir = std::env::temp_dir().join(format!("hrm-digests-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fis = dir.join("c.fis");
        std::fs::write(&fis, "one").unwrap();
        let mut s = Scenario::builtin("paper-responses-step").unwrap();
        let plain = input_digests(&s).unwrap();
        assert_eq!(plain.len(), 1);
        assert_eq!(check_digests(&s, &plain), Ok(()));
        s.controller.fis = Some(fis.clone());
        let before = input_digests(&s).unwrap();
        assert_eq!(
            before[1].describe(),
            format!("controller.fis ({})", fis.display())
        );
        assert_eq!(check_digests(&s, &before), Ok(()));
        assert!(
            check_digests(&s, &plain)
                .unwrap_err()
                .contains("controller.fis")
        );
        std::fs::write(&fis, "two").unwrap();
        let after = input_digests(&s).unwrap();
        assert_eq!(after[0], before[0]);
        let (changed, there) = first_changed(&before, &after).unwrap();
        assert_eq!(
            (changed.input.as_str(), there),
            ("controller.fis", after[1].sha256.as_str())
        );
        assert_eq!(first_changed(&after, &after.clone()), None);
        let mut edited = s.clone();
        edited.duration = 0.5;
        assert!(
            check_digests(&edited, &after)
                .unwrap_err()
                .contains("does not match")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
