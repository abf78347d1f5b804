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

/// The most bytes of an existing file read to tell whether hrm wrote it as a fuzzy system
/// ([`sim_study::MAX_INPUT_FILE_BYTES`], what the readers take).
pub(crate) const RECOGNISED_BYTES: usize = sim_study::MAX_INPUT_FILE_BYTES as usize;

/// The first line of the `.fis` files `hrm fis train` and `hrm fis imitate` write: a comment,
/// which MATLAB, fuzzylite and hrm skip, by which hrm knows its own file.
pub(crate) const FIS_SIGNATURE: &str = "% written by hrm\n";

/// The `.fis` text of `system` as `hrm fis train` and `hrm fis imitate` write it: hrm's
/// signature, then the system.
pub(crate) fn signed_fis(system: &FuzzySystem) -> String {
    format!("{FIS_SIGNATURE}{}", system.to_fis())
}

/// The first line of the FCL files `hrm fis export --format fcl` writes (a comment fuzzylite
/// and hrm skip).
pub(crate) const FCL_SIGNATURE: &str = "// written by hrm\n";

/// Whether `text` is a fuzzy system file hrm wrote: a `.fis` or FCL text that opens with hrm's
/// signature ([`FIS_SIGNATURE`], [`FCL_SIGNATURE`]) and whose system, written back by hrm's
/// writer, is the rest of the text byte for byte (a copy of the shipped `paper.fis`, which the
/// canonical writer reproduces, is the user's), or the C that `hrm fis export` writes (its
/// opening comment says so).
pub(crate) fn written_by_hrm(text: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(text) else {
        return false;
    };
    let opening = &text[..text.floor_char_boundary(512)];
    opening.contains("exported by hrm (fuzzy-sugeno) as C99")
        || text.strip_prefix(FIS_SIGNATURE).is_some_and(|fis| {
            FuzzySystem::from_fis(fis).is_ok_and(|system| system.to_fis() == fis)
        })
        || text.strip_prefix(FCL_SIGNATURE).is_some_and(|fcl| {
            FuzzySystem::from_fcl(fcl)
                .is_ok_and(|system| system.to_fcl().is_ok_and(|text| text == fcl))
        })
}
