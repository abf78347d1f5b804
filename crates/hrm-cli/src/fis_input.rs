//! What the `hrm fis` commands read: a fuzzy system from a MATLAB `.fis` file, or from an
//! IEC 61131-7 FCL file when the name ends in `.fcl`, and the policy for inputs outside their
//! ranges as a command-line value.

use clap::ValueEnum;
use fuzzy_sugeno::{FisNote, FuzzySystem, OutOfRange};
use std::path::Path;

/// The out-of-range policies, as command-line values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(crate) enum RangePolicy {
    /// Evaluate at the nearest end of the range (saturates the action).
    Clamp,
    /// Evaluate the membership functions at the value as given (MATLAB's evalfis and
    /// Simulink's Fuzzy Logic Controller; bells fade far out).
    AsGiven,
    /// Refuse.
    Error,
}

impl RangePolicy {
    /// The library's policy.
    pub(crate) fn policy(self) -> OutOfRange {
        match self {
            RangePolicy::Clamp => OutOfRange::Clamp,
            RangePolicy::AsGiven => OutOfRange::AsGiven,
            RangePolicy::Error => OutOfRange::Error,
        }
    }
}

/// The text of `path`, read up to [`sim_study::MAX_INPUT_FILE_BYTES`].
fn read_text(path: &Path) -> Result<String, String> {
    sim_study::read_text_file(path, sim_study::MAX_INPUT_FILE_BYTES)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Reads a `.fis` file, or an FCL file if the name ends in `.fcl`.
pub(crate) fn read_system(path: &Path) -> Result<FuzzySystem, String> {
    read_system_with_notes(path).map(|(system, _)| system)
}

/// Reads a system as [`read_system`] does, with the `.fis` reader's notes of what it accepted
/// but ignored; `None` for an FCL file, whose reader keeps no such notes.
pub(crate) fn read_system_with_notes(
    path: &Path,
) -> Result<(FuzzySystem, Option<Vec<FisNote>>), String> {
    let text = read_text(path)?;
    let is_fcl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("fcl"));
    let system = if is_fcl {
        FuzzySystem::from_fcl(&text).map(|system| (system, None))
    } else {
        FuzzySystem::from_fis_with_notes(&text).map(|(system, notes)| (system, Some(notes)))
    };
    system.map_err(|e| format!("{}: {e}", path.display()))
}
