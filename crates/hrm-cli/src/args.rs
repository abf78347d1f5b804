//! Numbers from the command line checked against their bounds before they reach an allocation
//! or a loop. Counts are parsed as wide signed integers (with negative numbers allowed), so that
//! `--seeds -1` gets the option's own message rather than a parse error. Controller names come
//! from the one controller table, `sim_study::CONTROLLERS`.

use sim_study::{CONTROLLERS, ControllerKind};
use std::sync::LazyLock;

/// Every controller's name, comma-separated: the default of list options.
pub static ALL_CONTROLLERS: LazyLock<String> = LazyLock::new(|| ControllerKind::names(","));

/// The help of `simulate --controller`: every controller's name.
pub static CONTROLLER_HELP: LazyLock<String> = LazyLock::new(|| {
    format!(
        "Override the scenario's controller: {}",
        ControllerKind::names(", ")
    )
});

/// The long help (`--help`) of `simulate --controller`: every controller with its description.
pub static CONTROLLER_LONG_HELP: LazyLock<String> = LazyLock::new(|| {
    let mut help = String::from("Override the scenario's controller, one of:");
    for entry in CONTROLLERS {
        help += &format!("\n- {}: {}", entry.name, entry.description);
    }
    help
});

/// `message` with the library's name of a setting at its start (`learning: the ridge`,
/// `imitation.margin`) replaced by the option the user gave it with (`--ridge`, `--margin`):
/// the first of `names` (library name, option) that starts it.
pub fn as_option(message: String, names: &[(&str, &str)]) -> String {
    names
        .iter()
        .find_map(|(library, option)| {
            message
                .strip_prefix(library)
                .map(|rest| format!("{option}{rest}"))
        })
        .unwrap_or(message)
}

/// `value` of option `option` as a count from `min` to `max`, or the one-line message
/// "`option` must be at least `min` and at most `max`, got `value`".
pub fn count(option: &str, value: i128, min: usize, max: usize) -> Result<usize, String> {
    usize::try_from(value)
        .ok()
        .filter(|v| (min..=max).contains(v))
        .ok_or_else(|| format!("{option} must be at least {min} and at most {max}, got {value}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_bounded_with_the_option_named() {
        assert_eq!(count("--seeds", 3, 1, 10), Ok(3));
        assert_eq!(
            count("--seeds", -1, 1, 10).unwrap_err(),
            "--seeds must be at least 1 and at most 10, got -1"
        );
        assert!(count("--samples", 1_000_000_000_000, 2, 1_000_000).is_err());
        assert!(count("--seeds", i128::MAX, 1, usize::MAX).is_err());
    }
}
