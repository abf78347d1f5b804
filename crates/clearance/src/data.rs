//! What the clearance algorithms write: the chain's placement, distances, closest points and
//! modal gradients, sized once from a model.

use crate::closest::{Closest, Segment};
use crate::error::ClearanceError;
use crate::model::ClearanceModel;
use crate::vector::V3;

/// The coordinates of a block of the planar prefix sums: an AVX2 register of `f64`.
pub(crate) const LANES: usize = 4;

/// [`LANES`] coordinates of the planar prefix sums, coordinate by coordinate.
pub(crate) type Block = [[f64; LANES]; 3];

/// The most modal gradient entries (pairs times coordinates) a [`ClearanceData`] holds: `2^25`.
pub const MAX_GRADIENT_ENTRIES: usize = 1 << 25;

/// The working memory of [`ClearanceModel`]'s algorithms for a chain with `m` modal coordinates
/// (`m` may be zero when only joint gradients are wanted). Holds no algorithm.
#[derive(Debug, Clone, PartialEq)]
pub struct ClearanceData {
    /// `n + 1` joint points, base to tip: link `i` runs from `points[i]` to `points[i + 1]`.
    pub(crate) points: Vec<V3>,
    /// `n` unit joint axes in world coordinates (`z` for a planar chain).
    pub(crate) axes: Vec<V3>,
    /// `n` links' segments, prepared once per [`distances`](crate::distances) call.
    pub(crate) segments: Vec<Segment<3>>,
    /// The same in the plane, for a chain placed by [`place_planar`](crate::place_planar).
    pub(crate) planar_segments: Vec<Segment<2>>,
    /// The planar chain's points, from `backbone_kin::joint_positions`.
    pub(crate) planar: Vec<[f64; 2]>,
    /// Per pair: the signed clearance (distance between the surfaces, negative in contact).
    pub(crate) distances: Vec<f64>,
    /// Per pair: the closest points and the normal.
    pub(crate) closest: Vec<Closest>,
    /// Per self pair: the parameters of its closest points, between the two passes of
    /// [`distances`](crate::distances).
    pub(crate) self_parameters: Vec<(f64, f64)>,
    /// The number of modal coordinates `m`.
    pub(crate) n_coords: usize,
    /// `pairs x m` modal gradients, row-major.
    pub(crate) modal_gradient: Vec<f64>,
    /// Prefix sums `W_il = sum_{j <= i} J_jl w_j` (`n x m`).
    pub(crate) prefix_axes: Vec<V3>,
    /// Prefix sums `U_il = sum_{j <= i} J_jl (w_j x p_j)` (`n x m`).
    pub(crate) prefix_moments: Vec<V3>,
    /// Whether every joint turns about `z` (placed by [`place_planar`](crate::place_planar)).
    pub(crate) turns_about_z: bool,
    /// A planar chain's prefix sums `T_il = sum_{j <= i} J_jl (p_jy, -p_jx, 1)`, in blocks of
    /// [`LANES`] coordinates (`[x; LANES], [y; LANES], [s; LANES]`, zero past `m`): `n` rows of
    /// `ceil(m / LANES)` blocks.
    pub(crate) prefix_planar: Vec<Block>,
}

impl ClearanceData {
    /// Data for `model` and modal maps of `n_coords` coordinates; refused when the modal
    /// gradients (pairs times coordinates) would exceed [`MAX_GRADIENT_ENTRIES`].
    pub fn new(model: &ClearanceModel, n_coords: usize) -> Result<Self, ClearanceError> {
        let n = model.n_links();
        let pairs = model.pairs().len();
        let entries = pairs.max(n).saturating_mul(n_coords);
        if entries > MAX_GRADIENT_ENTRIES {
            return Err(ClearanceError::TooMany {
                what: "modal gradient entries (pairs x coordinates)",
                got: entries,
                max: MAX_GRADIENT_ENTRIES,
            });
        }
        let empty = Closest {
            t: 0.0,
            point: [0.0; 3],
            other: [0.0; 3],
            distance: 0.0,
            normal: [0.0; 3],
        };
        Ok(Self {
            points: vec![[0.0; 3]; n + 1],
            axes: vec![[0.0, 0.0, 1.0]; n],
            segments: vec![Segment::new([0.0; 3], [0.0; 3]); n],
            planar_segments: vec![Segment::new([0.0; 2], [0.0; 2]); n],
            planar: vec![[0.0; 2]; n + 1],
            distances: vec![f64::INFINITY; pairs],
            closest: vec![empty; pairs],
            self_parameters: vec![(0.0, 0.0); pairs - model.n_obstacle_pairs()],
            n_coords,
            modal_gradient: vec![0.0; pairs * n_coords],
            prefix_axes: vec![[0.0; 3]; n * n_coords],
            prefix_moments: vec![[0.0; 3]; n * n_coords],
            turns_about_z: true,
            prefix_planar: vec![[[0.0; LANES]; 3]; n * n_coords.div_ceil(LANES)],
        })
    }

    /// `Ok` when this data was made for a model of `model`'s links and pairs (by
    /// [`new`](Self::new)); otherwise [`ClearanceError::Dimension`] naming what disagrees.
    pub fn check_model(&self, model: &ClearanceModel) -> Result<(), ClearanceError> {
        let pairs = model.pairs().len();
        let self_pairs = pairs - model.n_obstacle_pairs();
        // Three comparisons on the per-step path; the names only when one fails.
        if self.points.len() == model.n_links() + 1
            && self.distances.len() == pairs
            && self.self_parameters.len() == self_pairs
        {
            return Ok(());
        }
        for (name, expected, found) in [
            (
                "clearance data's joint points (made for another model)",
                model.n_links() + 1,
                self.points.len(),
            ),
            (
                "clearance data's pairs (made for another model)",
                pairs,
                self.distances.len(),
            ),
            (
                "clearance data's self pairs (made for another model)",
                self_pairs,
                self.self_parameters.len(),
            ),
        ] {
            if expected != found {
                return Err(ClearanceError::Dimension {
                    name,
                    expected,
                    found,
                });
            }
        }
        Ok(())
    }

    /// Panics with [`check_model`](Self::check_model)'s message when this data was not made for
    /// `model`: the guard of the algorithms that return no `Result`.
    pub(crate) fn assert_model(&self, model: &ClearanceModel) {
        if let Err(error) = self.check_model(model) {
            panic!("{error}");
        }
    }

    /// The joint points, base to tip.
    pub fn points(&self) -> &[V3] {
        &self.points
    }

    /// The joint axes in world coordinates.
    pub fn axes(&self) -> &[V3] {
        &self.axes
    }

    /// Each pair's clearance (distance between the capsules' surfaces; negative in contact), in
    /// the order of [`ClearanceModel::pairs`].
    pub fn distances(&self) -> &[f64] {
        &self.distances
    }

    /// Each pair's closest points and normal (`normal` is the clearance's gradient with respect
    /// to the link's point; for a self pair the link is the proximal one).
    pub fn closest(&self) -> &[Closest] {
        &self.closest
    }

    /// The gradient of pair `pair`'s clearance with respect to the modal coordinates.
    ///
    /// # Panics
    /// If `pair` is out of range, like slice indexing.
    pub fn modal_gradient(&self, pair: usize) -> &[f64] {
        &self.modal_gradient[pair * self.n_coords..(pair + 1) * self.n_coords]
    }

    /// The smallest clearance to an obstacle (`+inf` with no obstacle).
    ///
    /// # Panics
    /// If this data was not made for `model` ([`check_model`](Self::check_model)).
    pub fn min_obstacle_clearance(&self, model: &ClearanceModel) -> f64 {
        self.assert_model(model);
        min(&self.distances[..model.n_obstacle_pairs()])
    }

    /// The smallest clearance between links that share no joint (`+inf` below three links).
    ///
    /// # Panics
    /// If this data was not made for `model` ([`check_model`](Self::check_model)).
    pub fn min_self_clearance(&self, model: &ClearanceModel) -> f64 {
        self.assert_model(model);
        min(&self.distances[model.n_obstacle_pairs()..])
    }
}

fn min(values: &[f64]) -> f64 {
    values.iter().copied().fold(f64::INFINITY, f64::min)
}
