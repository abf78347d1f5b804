//! The arm description shared by `hrm eval` requests: `{"links": 10, "link_length": 0.1,
//! "link_mass": 0.1, "gravity": 9.81}` with optional per-link `lengths`, `masses`, `inertias`.

use manip_dyn::{ChainModel, Link};
use serde::Deserialize;

/// The paper's arm: 10 links of 0.1 m and 0.1 kg under 9.81 m/s^2.
const DEFAULT_LINKS: usize = 10;
const DEFAULT_LINK_LENGTH: f64 = 0.1;
const DEFAULT_LINK_MASS: f64 = 0.1;
const DEFAULT_GRAVITY: f64 = 9.81;

/// An arm as a request gives it; every field is optional and defaults to the paper's arm.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmSpec {
    links: Option<usize>,
    link_length: Option<f64>,
    link_mass: Option<f64>,
    gravity: Option<f64>,
    lengths: Option<Vec<f64>>,
    masses: Option<Vec<f64>>,
    inertias: Option<Vec<f64>>,
}

impl ArmSpec {
    /// Builds the chain; per-link arrays override the scalars, and all given sizes must agree.
    pub fn to_chain(&self) -> Result<ChainModel, String> {
        let n = self.link_count()?;
        let per_link = |array: &Option<Vec<f64>>, scalar: f64| match array {
            Some(values) => values.clone(),
            None => vec![scalar; n],
        };
        let lengths = per_link(
            &self.lengths,
            self.link_length.unwrap_or(DEFAULT_LINK_LENGTH),
        );
        let masses = per_link(&self.masses, self.link_mass.unwrap_or(DEFAULT_LINK_MASS));
        let mut links = Vec::with_capacity(n);
        for i in 0..n {
            let mut link = Link::uniform_beam(lengths[i], masses[i]).map_err(|e| at_link(e, i))?;
            if let Some(inertias) = &self.inertias {
                link = Link::new(lengths[i], masses[i], link.com, inertias[i])
                    .map_err(|e| at_link(e, i))?;
            }
            links.push(link);
        }
        ChainModel::new(links, self.gravity.unwrap_or(DEFAULT_GRAVITY)).map_err(|e| e.to_string())
    }

    /// The number of links, checked against every per-link array.
    fn link_count(&self) -> Result<usize, String> {
        let mut n = self.links;
        for (name, array) in [
            ("lengths", &self.lengths),
            ("masses", &self.masses),
            ("inertias", &self.inertias),
        ] {
            if let Some(values) = array {
                match n {
                    Some(k) if k != values.len() => {
                        return Err(format!(
                            "arm: {name} has {} entries but the arm has {k} links",
                            values.len()
                        ));
                    }
                    _ => n = Some(values.len()),
                }
            }
        }
        match n.unwrap_or(DEFAULT_LINKS) {
            0 => Err("arm: links must be at least 1".to_string()),
            n => Ok(n),
        }
    }
}

/// Re-anchors a single-link validation error at link `index`.
fn at_link(error: manip_dyn::DynError, index: usize) -> String {
    match error {
        manip_dyn::DynError::InvalidLink {
            quantity,
            requirement,
            value,
            ..
        } => manip_dyn::DynError::InvalidLink {
            index,
            quantity,
            requirement,
            value,
        }
        .to_string(),
        other => other.to_string(),
    }
}
