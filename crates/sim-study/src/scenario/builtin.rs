//! The scenarios shipped with the crate, compiled in.

use super::file::{ScenarioError, parse};
use super::schema::Scenario;
use std::path::Path;

/// The scenarios shipped with the crate, by name: the paper's experiments (section 5) with the
/// tracking task also five times faster under limits on the modal forces `tau*`, then the paper's tracking task
/// with two harmonics and with `alpha0` free, then the paper's arm reaching between obstacles on
/// a planned motion (`narrow-gap`), a spatial arm reaching a point in space among obstacles
/// on a planned motion (`spatial-clutter`), and the paper's arm deploying into a bent channel by
/// follow-the-leader on an insertion axis (`pipe-deploy`, run by [`Scenario::run_deploy`]).
const BUILTIN: &[(&str, &str)] = &[
    (
        "paper-tracking",
        include_str!("../../scenarios/paper-tracking.toml"),
    ),
    (
        "paper-tracking-fast",
        include_str!("../../scenarios/paper-tracking-fast.toml"),
    ),
    (
        "paper-responses-step",
        include_str!("../../scenarios/paper-responses-step.toml"),
    ),
    (
        "paper-responses-sine",
        include_str!("../../scenarios/paper-responses-sine.toml"),
    ),
    (
        "paper-responses-noise",
        include_str!("../../scenarios/paper-responses-noise.toml"),
    ),
    (
        "harmonic-tracking",
        include_str!("../../scenarios/harmonic-tracking.toml"),
    ),
    (
        "free-base-tracking",
        include_str!("../../scenarios/free-base-tracking.toml"),
    ),
    (
        "spatial-tracking",
        include_str!("../../scenarios/spatial-tracking.toml"),
    ),
    (
        "spatial-long",
        include_str!("../../scenarios/spatial-long.toml"),
    ),
    (
        "narrow-gap",
        include_str!("../../scenarios/narrow-gap.toml"),
    ),
    (
        "spatial-clutter",
        include_str!("../../scenarios/spatial-clutter.toml"),
    ),
    (
        "pipe-deploy",
        include_str!("../../scenarios/pipe-deploy.toml"),
    ),
];

impl Scenario {
    /// A scenario shipped with the crate, by name (see [`Scenario::builtin_names`]).
    ///
    /// ```
    /// let scenario = sim_study::Scenario::builtin("paper-tracking")?;
    /// assert_eq!(scenario.duration, 5.5);
    /// # Ok::<(), sim_study::ScenarioError>(())
    /// ```
    pub fn builtin(name: &str) -> Result<Self, ScenarioError> {
        match BUILTIN.iter().find(|(n, _)| *n == name) {
            Some((name, text)) => parse(text, name),
            None => Err(unknown(name)),
        }
    }

    /// A built-in scenario by name, or else a scenario file at that path.
    pub fn resolve(name_or_path: &str) -> Result<Self, ScenarioError> {
        if Self::builtin_text(name_or_path).is_some() {
            return Self::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        if path.exists() {
            Self::load(path)
        } else {
            Err(unknown(name_or_path))
        }
    }

    /// The names of the shipped scenarios: `paper-tracking` (Figures 10-11),
    /// `paper-tracking-fast` (the same path in 1 s under `tau*` limits), the
    /// `paper-responses-*` step, sine and noise responses (Figure 9), and the tracking task for
    /// other modal families: `harmonic-tracking` (`K = 2`, `m = 4`) and `free-base-tracking`
    /// (`alpha0` free, `m = 3`), and `narrow-gap` (a `[task]` planned between obstacles that
    /// block both closed-form `K = 1` shapes, then tracked), and `pipe-deploy` (a `[deploy]`
    /// into a bent channel, run in joint space by [`Scenario::run_deploy`]).
    pub fn builtin_names() -> impl Iterator<Item = &'static str> {
        BUILTIN.iter().map(|(name, _)| *name)
    }

    /// The TOML text of a shipped scenario.
    pub fn builtin_text(name: &str) -> Option<&'static str> {
        BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }
}

pub(super) fn unknown(name: &str) -> ScenarioError {
    ScenarioError::Unknown {
        name: name.to_string(),
        available: BUILTIN
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>()
            .join(", "),
    }
}
