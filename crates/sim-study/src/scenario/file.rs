//! Reading scenarios: TOML text and files, with one-line errors.

use super::schema::{Scenario, TaskSpec};
use std::path::{Path, PathBuf};

/// Why a scenario could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario file {path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        message: String,
    },
    /// The text is not a valid scenario; the message gives the line, column and problem.
    #[error("scenario {origin} is malformed: {message}")]
    Parse {
        /// The file or built-in name.
        origin: String,
        /// What is wrong, and where.
        message: String,
    },
    /// Neither a built-in scenario nor an existing file.
    #[error("'{name}' is neither a built-in scenario ({available}) nor a scenario file")]
    Unknown {
        /// The name asked for.
        name: String,
        /// The built-in names.
        available: String,
    },
}

impl Scenario {
    /// Parses a scenario from TOML text.
    ///
    /// ```
    /// let scenario = sim_study::Scenario::from_toml(r#"
    ///     name = "hold"
    ///     duration = 0.1
    ///     alpha0 = 1.0
    ///     reference = { kind = "constant", a = [0.3, -0.2] }
    ///     integrator = { method = "rk4", dt = 1e-3 }
    /// "#)?;
    /// let run = scenario.build()?.run()?;
    /// assert_eq!(run.summary.controller_samples, 101);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_toml(text: &str) -> Result<Self, ScenarioError> {
        parse(text, "text")
    }

    /// Reads a scenario file; a relative `controller.fis` or `arm.urdf` path is taken relative to
    /// the file, and made absolute (its links resolved where it exists), so that the scenario an
    /// output writes back
    /// ([`to_toml`](Self::to_toml)) runs again from wherever it is.
    pub fn load(path: &Path) -> Result<Self, ScenarioError> {
        let text = crate::read_text_file(path, crate::MAX_INPUT_FILE_BYTES).map_err(|e| {
            ScenarioError::Io {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })?;
        let mut scenario = parse(&text, &path.display().to_string())?;
        if let Some(dir) = path.parent() {
            let fields = [
                ("controller.fis", &mut scenario.controller.fis),
                ("arm.urdf", &mut scenario.arm.urdf),
            ];
            for (field, file) in fields {
                let Some(file) = file.as_mut().filter(|file| file.is_relative()) else {
                    continue;
                };
                let joined = dir.join(&*file);
                let absolute = std::fs::canonicalize(&joined)
                    .or_else(|_| std::path::absolute(&joined))
                    .unwrap_or_else(|_| joined.clone());
                // A folder name that is not UTF-8 above the working folder keeps the path
                // relative; one the scenario's text cannot hold is refused here, not when an
                // output writes the scenario back.
                *file = if absolute.to_str().is_some() {
                    absolute
                } else {
                    joined
                };
                if file.to_str().is_none() {
                    return Err(ScenarioError::Parse {
                        origin: path.display().to_string(),
                        message: format!(
                            "{field}: the path {} is not UTF-8, which a scenario written back as \
                             TOML cannot hold: move the scenario or the file to a UTF-8 path",
                            file.display()
                        ),
                    });
                }
            }
        }
        Ok(scenario)
    }

    /// The scenario as TOML (it parses back to an equal scenario).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a scenario serialises to TOML")
    }
}

/// Parses scenario text; a refusal is one line: `line L, column C (`<that line>`): <what is
/// wrong>` (toml's own message spans several lines around the quoted text).
pub(super) fn parse(text: &str, origin: &str) -> Result<Scenario, ScenarioError> {
    let scenario = parse_text(text, origin)?;
    // A count beyond TOML's integers (2^63 - 1) reads into a `usize` but cannot be written
    // back (nor into a shard, nor Python's dict): refused here, whatever its later bound.
    let counts = [
        ("arm.links", scenario.arm.links),
        ("modal.harmonics", Some(scenario.modal.harmonics)),
    ]
    .into_iter()
    .chain(scenario.task.iter().flat_map(|task| match task {
        TaskSpec::Reach {
            samples,
            max_iterations,
            ..
        } => [
            ("task.samples", *samples),
            ("task.max_iterations", *max_iterations),
        ],
    }));
    for (name, count) in counts {
        if let Some(count) = count
            && i64::try_from(count).is_err()
        {
            return Err(ScenarioError::Parse {
                origin: origin.to_string(),
                message: format!(
                    "{name} = {count} is beyond TOML's integers (at most 2^63 - 1, and far less \
                     where it is used)"
                ),
            });
        }
    }
    Ok(scenario)
}

/// [`parse`]'s reading of the text.
fn parse_text(text: &str, origin: &str) -> Result<Scenario, ScenarioError> {
    toml::from_str(text).map_err(|e| {
        let mut what = e.message().trim_end().replace('\n', "; ");
        // A date or time reaches serde as a map: say what the user wrote.
        let given = e.span().and_then(|span| text.get(span));
        if let (Some(rest), Some(given)) = (what.strip_prefix("invalid type: map,"), given)
            && given.trim().parse::<toml::value::Datetime>().is_ok()
        {
            what = format!("invalid type: date-time,{rest}");
        }
        let message = match e.span() {
            Some(span) => {
                let mut end = span.start.min(text.len());
                while !text.is_char_boundary(end) {
                    end -= 1;
                }
                let before = &text[..end];
                let line = before.matches('\n').count() + 1;
                let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
                let quoted: String = text
                    .lines()
                    .nth(line - 1)
                    .unwrap_or_default()
                    .trim()
                    .chars()
                    .take(80)
                    .collect();
                format!("line {line}, column {column} (`{quoted}`): {what}")
            }
            None => what,
        };
        ScenarioError::Parse {
            origin: origin.to_string(),
            message,
        }
    })
}
