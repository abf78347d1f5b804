//! Lists of a fixed length read whole. TOML's reader fills an `[f64; N]` from the first `N`
//! entries of a longer list and drops the rest without a word (`rpy = [0, 0, 0, 1]`, a
//! quaternion given for angles, read as three angles), so these fields read the whole list and
//! refuse any other length.

use serde::de::Error;
use serde::{Deserialize, Deserializer};

/// An `[f64; N]` given as exactly `N` numbers.
pub(super) fn numbers<'de, D: Deserializer<'de>, const N: usize>(
    deserializer: D,
) -> Result<[f64; N], D::Error> {
    let values = Vec::<f64>::deserialize(deserializer)?;
    let found = values.len();
    values
        .try_into()
        .map_err(|_| D::Error::invalid_length(found, &format!("{N} numbers").as_str()))
}

/// A list of points `[[x, y], ...]`, each exactly `N` numbers.
pub(super) fn optional_points<'de, D: Deserializer<'de>, const N: usize>(
    deserializer: D,
) -> Result<Option<Vec<[f64; N]>>, D::Error> {
    let rows = Vec::<Vec<f64>>::deserialize(deserializer)?;
    rows.into_iter()
        .enumerate()
        .map(|(k, row)| {
            let found = row.len();
            row.try_into().map_err(|_| {
                D::Error::custom(format!("point {k} has {found} numbers, expected {N}"))
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}
