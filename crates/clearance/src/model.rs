//! The constant part of a clearance problem: the links' radius, the obstacles and the pairs.

use crate::cores::{Core, Cores};
use crate::error::ClearanceError;
use crate::obstacle::{MAX_OBSTACLE_EXTENT, Obstacle};
use lane_math::check_finite;

/// The most obstacles a [`ClearanceModel`] accepts.
pub const MAX_OBSTACLES: usize = 65_536;

/// The most pairs (link-obstacle and link-link) a [`ClearanceModel`] accepts: `2^22`. Its data
/// holds a few numbers per pair and a modal gradient of `m` numbers per pair, so this bounds an
/// allocation a scenario could ask for.
pub const MAX_PAIRS: usize = 1 << 22;

/// Which two bodies a pair measures: link `link` (0-based, from the base) against an obstacle or
/// against a later link that shares no joint with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pair {
    /// Link `link` against obstacle `obstacle`.
    Obstacle {
        /// The link.
        link: usize,
        /// The obstacle's index in [`ClearanceModel::obstacles`].
        obstacle: usize,
    },
    /// Link `link` against link `other > link + 1` (self collision).
    Links {
        /// The proximal link.
        link: usize,
        /// The distal link.
        other: usize,
    },
}

/// Every link is a capsule of `radius` around its segment; the obstacles are fixed in the world.
///
/// Pairs are ordered link-major, obstacles first: pair `link * n_obstacles + obstacle`, then
/// the self pairs `(i, k)`, `k >= i + 2`, in lexicographic order.
#[derive(Debug, Clone, PartialEq)]
pub struct ClearanceModel {
    n_links: usize,
    radius: f64,
    obstacles: Vec<Obstacle>,
    /// The obstacles' cores, and in two dimensions when every one lies in the plane `z = 0`.
    cores: Cores<3>,
    planar_cores: Option<Cores<2>>,
    pairs: Vec<Pair>,
}

impl ClearanceModel {
    /// A model of `n_links` capsules of `radius` among `obstacles`, with every self pair of
    /// links that share no joint.
    pub fn new(
        n_links: usize,
        radius: f64,
        obstacles: Vec<Obstacle>,
    ) -> Result<Self, ClearanceError> {
        if n_links == 0 {
            return Err(backbone_kin::KinError::NoLinks.into());
        }
        check_finite("link radius", radius)?;
        if !(0.0..=MAX_OBSTACLE_EXTENT).contains(&radius) {
            return Err(ClearanceError::OutOfRange {
                name: "link radius",
                bound: "non-negative and at most 1e15 (MAX_OBSTACLE_EXTENT)",
                value: radius,
            });
        }
        if obstacles.len() > MAX_OBSTACLES {
            return Err(ClearanceError::TooMany {
                what: "obstacles",
                got: obstacles.len(),
                max: MAX_OBSTACLES,
            });
        }
        let self_pairs = n_links
            .saturating_sub(1)
            .saturating_mul(n_links.saturating_sub(2))
            / 2;
        let total = n_links
            .saturating_mul(obstacles.len())
            .saturating_add(self_pairs);
        if total > MAX_PAIRS {
            return Err(ClearanceError::TooMany {
                what: "link pairs (links x obstacles + non-adjacent link pairs)",
                got: total,
                max: MAX_PAIRS,
            });
        }
        let mut pairs = Vec::with_capacity(total);
        for link in 0..n_links {
            for obstacle in 0..obstacles.len() {
                pairs.push(Pair::Obstacle { link, obstacle });
            }
        }
        for link in 0..n_links {
            for other in link + 2..n_links {
                pairs.push(Pair::Links { link, other });
            }
        }
        let cores = Cores::new(obstacles.iter().map(Core::of).collect());
        let planar_cores = obstacles.iter().map(Core::planar).collect::<Option<_>>();
        let planar_cores = planar_cores.map(Cores::new);
        Ok(Self {
            n_links,
            radius,
            obstacles,
            cores,
            planar_cores,
            pairs,
        })
    }

    /// Number of links.
    pub fn n_links(&self) -> usize {
        self.n_links
    }

    /// The radius of every link's capsule.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// The obstacles' cores, as [`obstacles`](Self::obstacles).
    pub(crate) fn cores(&self) -> &Cores<3> {
        &self.cores
    }

    /// The obstacles' cores in two dimensions, when every one lies in the plane `z = 0` (see
    /// [`Core::planar`]).
    pub(crate) fn planar_cores(&self) -> Option<&Cores<2>> {
        self.planar_cores.as_ref()
    }

    /// Every pair, in the order of the data's distances.
    pub fn pairs(&self) -> &[Pair] {
        &self.pairs
    }

    /// Number of link-obstacle pairs; they come first in [`pairs`](Self::pairs).
    pub fn n_obstacle_pairs(&self) -> usize {
        self.n_links * self.obstacles.len()
    }
}
