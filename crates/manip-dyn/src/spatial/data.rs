//! The reusable workspace of the spatial algorithms (the "Data" of the Model/Data split).

use lane_math::try_filled;
use pulp::Arch;

use super::algebra::{Force, Mat3, Motion, Symmetric6, Transform, Vec3};
use super::model::SpatialModel;
use crate::error::DynError;

/// Scratch space for one [`SpatialModel`]: build it once with [`SpatialData::new`], then pass it
/// to every algorithm of [`spatial`](crate::spatial); after construction none of them allocates.
/// Its memory is `O(n)` (under a kilobyte a link).
///
/// After [`forward_kinematics`](super::forward_kinematics()) (and every algorithm that runs it:
/// all but the articulated-body ones) it holds each link's pose, read with
/// [`link_pose`](Self::link_pose); its other contents between calls are unspecified.
#[derive(Clone)]
pub struct SpatialData {
    /// `q`, then `sin q_i`, `cos q_i` (revolute joints; unused for prismatic ones).
    pub(crate) angle: Vec<f64>,
    pub(crate) sin: Vec<f64>,
    pub(crate) cos: Vec<f64>,
    /// Link `i`'s frame in link `i - 1`'s frame at `q`.
    pub(crate) placements: Vec<Transform>,
    /// Link `i`'s frame in the base frame at `q`.
    pub(crate) poses: Vec<Transform>,
    /// Spatial velocity and acceleration of each link, in its own frame.
    pub(crate) velocities: Vec<Motion>,
    pub(crate) accelerations: Vec<Motion>,
    /// The force each link receives from its parent, in its own frame.
    pub(crate) forces: Vec<Force>,
    /// Composite inertia of links `i..n` in link `i`'s frame (CRBA).
    pub(crate) composites: Vec<Symmetric6>,
    /// The articulated-body quantities of each joint (ABA).
    pub(crate) articulated: Vec<AbaLink<f64>>,
    /// The instruction set found at construction, for the sines and cosines.
    pub(crate) arch: Arch,
}

impl SpatialData {
    /// Allocates the workspace for `model`.
    ///
    /// ```
    /// use manip_dyn::ChainModel;
    /// use manip_dyn::spatial::{SpatialData, SpatialModel};
    /// let arm = SpatialModel::from_planar(&ChainModel::uniform(10, 0.1, 0.1, 9.81)?);
    /// assert_eq!(SpatialData::new(&arm).n_links(), 10);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    ///
    /// # Panics
    /// When the system refuses the memory; [`SpatialData::try_new`] returns the error.
    pub fn new(model: &SpatialModel) -> SpatialData {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`SpatialData::new`], or [`DynError::OutOfMemory`] when the system refuses the memory.
    pub fn try_new(model: &SpatialModel) -> Result<SpatialData, DynError> {
        const WHAT: &str = "the workspace of the spatial recursive algorithms";
        let n = model.n_links();
        Ok(SpatialData {
            angle: try_filled(n, 0.0, WHAT)?,
            sin: try_filled(n, 0.0, WHAT)?,
            cos: try_filled(n, 0.0, WHAT)?,
            placements: try_filled(n, Transform::IDENTITY, WHAT)?,
            poses: try_filled(n, Transform::IDENTITY, WHAT)?,
            velocities: try_filled(n, Motion::default(), WHAT)?,
            accelerations: try_filled(n, Motion::default(), WHAT)?,
            forces: try_filled(n, Force::default(), WHAT)?,
            composites: try_filled(n, Symmetric6::default(), WHAT)?,
            articulated: try_filled(n, AbaLink::default(), WHAT)?,
            arch: Arch::new(),
        })
    }

    /// Number of links of the chain this workspace was built for.
    pub fn n_links(&self) -> usize {
        self.poses.len()
    }

    /// Link `index`'s frame in the base frame as of the last forward kinematics, or `None` for
    /// an index past the chain.
    pub fn link_pose(&self, index: usize) -> Option<&Transform> {
        self.poses.get(index)
    }
}

impl std::fmt::Debug for SpatialData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpatialData")
            .field("n_links", &self.n_links())
            .finish_non_exhaustive()
    }
}

/// What the later sweeps need of joint `i`, for one state (`T = f64`) or the lanes of a batch
/// (`T` a slot of lanes).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct AbaLink<T> {
    /// `X_i`: link `i`'s frame in its parent's.
    pub(crate) rotation: Mat3<T>,
    pub(crate) translation: Vec3<T>,
    /// `c_i` (linear, angular).
    pub(crate) bias: [Vec3<T>; 2],
    /// `p_i`, the rigid bias force (linear, angular).
    pub(crate) force: [Vec3<T>; 2],
    /// `U_i` (linear, angular).
    pub(crate) coupling: [Vec3<T>; 2],
    /// `1 / D_i`.
    pub(crate) inverse: T,
    /// `u_i`.
    pub(crate) residual: T,
}
