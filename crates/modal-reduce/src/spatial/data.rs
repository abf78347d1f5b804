//! The workspace of a [`SpatialReducedModel`]'s algorithms (the "Data"): created once, reused by
//! every call, so that no call allocates.

use super::model::SpatialReducedModel;
use super::motion::LinkMotion;
use crate::error::ReduceError;
use lane_math::check_len;
use pulp::Arch;

/// Buffers for [`spatial_reduced_terms`](super::spatial_reduced_terms),
/// [`spatial_forward_dynamics`](super::spatial_forward_dynamics) and
/// [`spatial_joint_torques`](super::spatial_joint_torques), sized for one model: `O(n + m^2)`.
#[derive(Debug, Clone)]
pub struct SpatialReducedData {
    pub(crate) n_links: usize,
    pub(crate) n_coords: usize,
    /// Joint angles, rates and accelerations (`2n` each).
    pub(crate) theta: Vec<f64>,
    pub(crate) theta_dot: Vec<f64>,
    pub(crate) theta_ddot: Vec<f64>,
    /// Every link's joint rates (`J a_dot`) and the sines and cosines of its joint angles
    /// (`theta = J a`): the `z` joints', then the `y` joints', each padded to a multiple of
    /// [`LINK_PADDING`](crate::model::LINK_PADDING) links.
    pub(crate) link_rates: Vec<f64>,
    pub(crate) link_sin: Vec<f64>,
    pub(crate) link_cos: Vec<f64>,
    /// In the link's frame (`3 x m` each, row-major): the velocity Jacobian of the link's joint
    /// point `Jp` and the angular-velocity Jacobian `Jb`, carried link by link; the centre of
    /// mass's velocity Jacobian `Jv`, `m Jv` and `I_b Jb` of one link (`I_b` the principal
    /// moments).
    pub(crate) point_jacobian: Vec<f64>,
    pub(crate) com_jacobian: Vec<f64>,
    pub(crate) momentum_jacobian: Vec<f64>,
    pub(crate) body_jacobian: Vec<f64>,
    pub(crate) body_inertia_jacobian: Vec<f64>,
    pub(crate) mass_matrix: Vec<f64>,
    pub(crate) coriolis: Vec<f64>,
    pub(crate) gravity: Vec<f64>,
    /// `L D L^T` of `M*` and the right-hand side of a solve.
    pub(crate) factor: Vec<f64>,
    /// The solve's `a_ddot` before it is known to be finite (`m`; for `m` other than 4 and 8,
    /// which solve on the stack).
    pub(crate) solution: Vec<f64>,
    /// Every link's motion, for the backward pass of the joint torques.
    pub(crate) links: Vec<LinkMotion>,
    /// The processor's instruction set, found at construction (the terms' kernel runs on it as
    /// `terms::TermsOfOneState::run` says).
    pub(crate) arch: Arch,
}

impl SpatialReducedData {
    /// A workspace for `model`.
    ///
    /// # Panics
    /// When the system refuses the memory; [`SpatialReducedData::try_new`] returns the error.
    pub fn new(model: &SpatialReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`SpatialReducedData::new`], or [`ReduceError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_new(model: &SpatialReducedModel) -> Result<Self, ReduceError> {
        const WHAT: &str = "the workspace of the spatial reduced model";
        let zeros = |len: usize| lane_math::try_filled(len, 0.0, WHAT);
        let (n, m) = (model.n_links(), model.n_coords());
        let padded = model.padded_links();
        let zero_motion = LinkMotion {
            u_z: [0.0; 3],
            u_y: [0.0; 3],
            joint: [0.0; 3],
            rotation: [[0.0; 3]; 3],
            omega: [0.0; 3],
            omega_dot: [0.0; 3],
            com: [0.0; 3],
            com_accel: [0.0; 3],
        };
        Ok(Self {
            n_links: n,
            n_coords: m,
            theta: zeros(2 * n)?,
            theta_dot: zeros(2 * n)?,
            theta_ddot: zeros(2 * n)?,
            link_rates: zeros(2 * padded)?,
            link_sin: zeros(2 * padded)?,
            link_cos: zeros(2 * padded)?,
            point_jacobian: zeros(3 * m)?,
            com_jacobian: zeros(3 * m)?,
            momentum_jacobian: zeros(3 * m)?,
            body_jacobian: zeros(3 * m)?,
            body_inertia_jacobian: zeros(3 * m)?,
            mass_matrix: zeros(m * m)?,
            coriolis: zeros(m)?,
            gravity: zeros(m)?,
            factor: zeros(m * m)?,
            solution: zeros(m)?,
            links: lane_math::try_filled(n, zero_motion, WHAT)?,
            arch: Arch::new(),
        })
    }

    /// The reduced mass matrix `M* = J^T M J` (`m x m`, row-major) of the last computation.
    pub fn mass_matrix(&self) -> &[f64] {
        &self.mass_matrix
    }

    /// The reduced Coriolis and centrifugal vector `C* = J^T C` (`m`) of the last computation.
    pub fn coriolis(&self) -> &[f64] {
        &self.coriolis
    }

    /// The reduced gravity vector `G* = J^T G` (`m`) of the last computation.
    pub fn gravity(&self) -> &[f64] {
        &self.gravity
    }

    /// Checks that this workspace was made for `model`.
    pub(crate) fn check_model(&self, model: &SpatialReducedModel) -> Result<(), ReduceError> {
        check_len("workspace links", self.n_links, model.n_links())?;
        check_len("workspace coordinates", self.n_coords, model.n_coords())?;
        Ok(())
    }
}
