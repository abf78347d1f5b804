//! The reduced plant of the closed loop, planar or spatial: one type for what a simulation and
//! its controllers ask of a modal arm (`M*`, `C*`, `G*`, forward dynamics, joint torques and
//! the analytic derivatives), so that every controller runs on either. Each call is one `match`
//! onto the family's own allocation-free function: the planar path computes the same bits as
//! calling [`reduced_terms`], [`forward_dynamics`], [`joint_torques`] and
//! [`reduced_derivatives`] directly (tested).

use faer::MatRef;

use crate::spatial::{
    SpatialReducedBatchData, SpatialReducedData, SpatialReducedDerivatives, SpatialReducedModel,
    spatial_batch_lanes, spatial_forward_dynamics, spatial_forward_dynamics_batch,
    spatial_joint_torques, spatial_project_torques, spatial_reduced_derivatives,
    spatial_reduced_terms,
};
use crate::{
    BatchError, ReduceError, ReducedBatchData, ReducedData, ReducedDerivatives, ReducedModel,
    batch_lanes, forward_dynamics, forward_dynamics_batch, joint_torques, project_torques,
    reduced_derivatives, reduced_terms,
};

/// A modal arm owned (what a simulation holds), planar or spatial; [`PlantModel::plant`] lends it
/// as a [`Plant`].
#[derive(Debug, Clone)]
pub enum PlantModel {
    /// A planar modal arm.
    Planar(ReducedModel),
    /// A spatial modal arm.
    Spatial(SpatialReducedModel),
}

impl PlantModel {
    /// The arm, borrowed.
    pub fn plant(&self) -> Plant<'_> {
        match self {
            PlantModel::Planar(model) => Plant::Planar(model),
            PlantModel::Spatial(model) => Plant::Spatial(model),
        }
    }
}

impl From<ReducedModel> for PlantModel {
    fn from(model: ReducedModel) -> Self {
        PlantModel::Planar(model)
    }
}

impl From<SpatialReducedModel> for PlantModel {
    fn from(model: SpatialReducedModel) -> Self {
        PlantModel::Spatial(model)
    }
}

impl<'a> From<&'a PlantModel> for Plant<'a> {
    fn from(model: &'a PlantModel) -> Self {
        model.plant()
    }
}

/// A modal arm as the loop sees it, borrowed: the planar arm of the paper (eqs 7-18) or a
/// spatial universal-joint arm (`docs/theory.md`, section 8).
#[derive(Debug, Clone, Copy)]
pub enum Plant<'a> {
    /// A planar modal arm (`n` joints).
    Planar(&'a ReducedModel),
    /// A spatial modal arm (`2n` joints, `m = 4K`).
    Spatial(&'a SpatialReducedModel),
}

impl<'a> From<&'a ReducedModel> for Plant<'a> {
    fn from(model: &'a ReducedModel) -> Self {
        Plant::Planar(model)
    }
}

impl<'a> From<&'a SpatialReducedModel> for Plant<'a> {
    fn from(model: &'a SpatialReducedModel) -> Self {
        Plant::Spatial(model)
    }
}

impl<'a> Plant<'a> {
    /// The number of modal coordinates `m`.
    pub fn n_coords(self) -> usize {
        match self {
            Plant::Planar(model) => model.n_coords(),
            Plant::Spatial(model) => model.n_coords(),
        }
    }

    /// The number of links `n`.
    pub fn n_links(self) -> usize {
        match self {
            Plant::Planar(model) => model.n_links(),
            Plant::Spatial(model) => model.n_links(),
        }
    }

    /// The number of joints: `n` planar, `2n` spatial.
    pub fn n_joints(self) -> usize {
        match self {
            Plant::Planar(model) => model.n_links(),
            Plant::Spatial(model) => 2 * model.n_links(),
        }
    }

    /// The planar model, if the plant is planar.
    pub fn planar(self) -> Option<&'a ReducedModel> {
        match self {
            Plant::Planar(model) => Some(model),
            Plant::Spatial(_) => None,
        }
    }

    /// The spatial model, if the plant is spatial.
    pub fn spatial(self) -> Option<&'a SpatialReducedModel> {
        match self {
            Plant::Spatial(model) => Some(model),
            Plant::Planar(_) => None,
        }
    }

    /// `M*`, `C*`, `G*` at `(a, a_dot)` into `data` ([`reduced_terms`] or
    /// [`spatial_reduced_terms`]).
    ///
    /// Errors: as those, and a workspace of the other family ([`ReduceError::WrongFamily`]).
    pub fn terms(self, data: &mut PlantData, a: &[f64], a_dot: &[f64]) -> Result<(), ReduceError> {
        match (self, data) {
            (Plant::Planar(model), PlantData::Planar(data)) => reduced_terms(model, data, a, a_dot),
            (Plant::Spatial(model), PlantData::Spatial(data)) => {
                spatial_reduced_terms(model, data, a, a_dot)
            }
            _ => Err(other_family(self)),
        }
    }

    /// The modal accelerations under `tau_star` (eq 15: [`forward_dynamics`] or
    /// [`spatial_forward_dynamics`]).
    ///
    /// Errors: as those, and a workspace of the other family.
    pub fn forward_dynamics(
        self,
        data: &mut PlantData,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        a_ddot: &mut [f64],
    ) -> Result<(), ReduceError> {
        match (self, data) {
            (Plant::Planar(model), PlantData::Planar(data)) => {
                forward_dynamics(model, data, a, a_dot, tau_star, a_ddot)
            }
            (Plant::Spatial(model), PlantData::Spatial(data)) => {
                spatial_forward_dynamics(model, data, a, a_dot, tau_star, a_ddot)
            }
            _ => Err(other_family(self)),
        }
    }

    /// The modal accelerations of a batch of states, SIMD across states, each state's the bits
    /// of [`forward_dynamics`](Self::forward_dynamics) ([`forward_dynamics_batch`] or
    /// [`spatial_forward_dynamics_batch`]; the slices hold states of `m` values one after the
    /// other).
    ///
    /// Errors: as those, and a workspace of the other family (as [`BatchError::Shape`]).
    pub fn forward_dynamics_batch(
        self,
        data: &mut PlantBatchData,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        a_ddot: &mut [f64],
    ) -> Result<(), BatchError> {
        match (self, data) {
            (Plant::Planar(model), PlantBatchData::Planar(data)) => {
                forward_dynamics_batch(model, data, a, a_dot, tau_star, a_ddot)
            }
            (Plant::Spatial(model), PlantBatchData::Spatial(data)) => {
                spatial_forward_dynamics_batch(model, data, a, a_dot, tau_star, a_ddot)
            }
            _ => Err(BatchError::Shape(other_family(self))),
        }
    }

    /// The states one SIMD group of [`forward_dynamics_batch`](Self::forward_dynamics_batch)
    /// evaluates on this processor ([`batch_lanes`] or [`spatial_batch_lanes`]; 1 when the
    /// states go one at a time).
    pub fn batch_lanes(self) -> usize {
        match self {
            Plant::Planar(model) => batch_lanes(model),
            Plant::Spatial(model) => spatial_batch_lanes(model),
        }
    }

    /// The joint torques that realise the modal motion (`n` planar, `2n` spatial:
    /// [`joint_torques`] or [`spatial_joint_torques`]).
    ///
    /// Errors: as those, and a workspace of the other family.
    pub fn joint_torques(
        self,
        data: &mut PlantData,
        a: &[f64],
        a_dot: &[f64],
        a_ddot: &[f64],
        tau: &mut [f64],
    ) -> Result<(), ReduceError> {
        match (self, data) {
            (Plant::Planar(model), PlantData::Planar(data)) => {
                joint_torques(model, data, a, a_dot, a_ddot, tau)
            }
            (Plant::Spatial(model), PlantData::Spatial(data)) => {
                spatial_joint_torques(model, data, a, a_dot, a_ddot, tau)
            }
            _ => Err(other_family(self)),
        }
    }

    /// The modal forces of joint torques, `tau_star = J^T tau` ([`project_torques`] or
    /// [`spatial_project_torques`]).
    ///
    /// Errors: as those.
    pub fn project_torques(self, tau: &[f64], tau_star: &mut [f64]) -> Result<(), ReduceError> {
        match self {
            Plant::Planar(model) => project_torques(model, tau, tau_star),
            Plant::Spatial(model) => spatial_project_torques(model, tau, tau_star),
        }
    }

    /// The forward dynamics and its analytic derivatives ([`reduced_derivatives`] or
    /// [`spatial_reduced_derivatives`]) into `derivatives`.
    ///
    /// Errors: as those, and workspaces of the other family.
    pub fn derivatives(
        self,
        data: &mut PlantData,
        derivatives: &mut PlantDerivatives,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
    ) -> Result<(), ReduceError> {
        match (self, data, derivatives) {
            (Plant::Planar(model), PlantData::Planar(data), PlantDerivatives::Planar(d)) => {
                reduced_derivatives(model, data, d, a, a_dot, tau_star)
            }
            (Plant::Spatial(model), PlantData::Spatial(data), PlantDerivatives::Spatial(d)) => {
                spatial_reduced_derivatives(model, data, d, a, a_dot, tau_star)
            }
            _ => Err(other_family(self)),
        }
    }
}

impl Plant<'_> {
    /// `"planar"` or `"spatial"`.
    pub fn family(self) -> &'static str {
        match self {
            Plant::Planar(_) => "planar",
            Plant::Spatial(_) => "spatial",
        }
    }
}

/// The error of a workspace of the other family than `plant`'s.
fn other_family(plant: Plant<'_>) -> ReduceError {
    let (given, built) = match plant {
        Plant::Planar(_) => ("planar", "spatial"),
        Plant::Spatial(_) => ("spatial", "planar"),
    };
    ReduceError::WrongFamily { built, given }
}

/// The workspace of a [`Plant`]'s computations, built once for it.
#[derive(Debug, Clone)]
#[allow(
    clippy::large_enum_variant,
    reason = "built once per loop or controller and never moved per step"
)]
pub enum PlantData {
    /// For a planar plant.
    Planar(ReducedData),
    /// For a spatial plant.
    Spatial(SpatialReducedData),
}

impl PlantData {
    /// A workspace for `plant`.
    ///
    /// # Panics
    /// When the system refuses the memory; [`PlantData::try_new`] returns the error.
    pub fn new(plant: Plant<'_>) -> Self {
        Self::try_new(plant).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`PlantData::new`], or [`ReduceError::OutOfMemory`] when the system refuses the memory.
    pub fn try_new(plant: Plant<'_>) -> Result<Self, ReduceError> {
        Ok(match plant {
            Plant::Planar(model) => PlantData::Planar(ReducedData::try_new(model)?),
            Plant::Spatial(model) => PlantData::Spatial(SpatialReducedData::try_new(model)?),
        })
    }

    /// `M*` (`m x m`) of the last computation.
    pub fn mass_matrix(&self) -> MatRef<'_, f64> {
        match self {
            PlantData::Planar(data) => data.mass_matrix(),
            PlantData::Spatial(data) => {
                let m = data.coriolis().len();
                MatRef::from_row_major_slice(data.mass_matrix(), m, m)
            }
        }
    }

    /// `C*` (`m`) of the last computation.
    pub fn coriolis(&self) -> &[f64] {
        match self {
            PlantData::Planar(data) => data.coriolis(),
            PlantData::Spatial(data) => data.coriolis(),
        }
    }

    /// `G*` (`m`) of the last computation.
    pub fn gravity(&self) -> &[f64] {
        match self {
            PlantData::Planar(data) => data.gravity(),
            PlantData::Spatial(data) => data.gravity(),
        }
    }
}

/// The workspace of [`Plant::forward_dynamics_batch`], built once for the plant.
#[derive(Debug, Clone)]
#[allow(
    clippy::large_enum_variant,
    reason = "built once per lock-step group and never moved per step"
)]
pub enum PlantBatchData {
    /// For a planar plant.
    Planar(ReducedBatchData),
    /// For a spatial plant.
    Spatial(SpatialReducedBatchData),
}

impl PlantBatchData {
    /// A workspace for `plant`.
    ///
    /// # Panics
    /// When the system refuses the memory; [`PlantBatchData::try_new`] returns the error.
    pub fn new(plant: Plant<'_>) -> Self {
        Self::try_new(plant).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`PlantBatchData::new`], or [`ReduceError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_new(plant: Plant<'_>) -> Result<Self, ReduceError> {
        Ok(match plant {
            Plant::Planar(model) => PlantBatchData::Planar(ReducedBatchData::try_new(model)?),
            Plant::Spatial(model) => {
                PlantBatchData::Spatial(SpatialReducedBatchData::try_new(model)?)
            }
        })
    }
}

/// The results and workspace of [`Plant::derivatives`], built once for the plant.
#[derive(Debug, Clone)]
#[allow(
    clippy::large_enum_variant,
    reason = "built once per loop or controller and never moved per step"
)]
pub enum PlantDerivatives {
    /// For a planar plant.
    Planar(ReducedDerivatives),
    /// For a spatial plant.
    Spatial(SpatialReducedDerivatives),
}

impl PlantDerivatives {
    /// A workspace for `plant`.
    pub fn new(plant: Plant<'_>) -> Self {
        match plant {
            Plant::Planar(model) => PlantDerivatives::Planar(ReducedDerivatives::new(model)),
            Plant::Spatial(model) => {
                PlantDerivatives::Spatial(SpatialReducedDerivatives::new(model))
            }
        }
    }

    /// The modal accelerations of the last call.
    #[inline]
    pub fn a_ddot(&self) -> &[f64] {
        match self {
            PlantDerivatives::Planar(d) => d.a_ddot(),
            PlantDerivatives::Spatial(d) => d.a_ddot(),
        }
    }

    /// The three Jacobians side by side, row-major `m x 3m`: row `i` is
    /// `[d_a row i | d_a_dot row i | d_tau_star row i]`.
    #[inline]
    pub fn jacobians(&self) -> &[f64] {
        match self {
            PlantDerivatives::Planar(d) => d.jacobians(),
            PlantDerivatives::Spatial(d) => d.jacobians(),
        }
    }

    /// `d a_ddot / d a` (`m x m`).
    #[inline]
    pub fn d_a(&self) -> MatRef<'_, f64> {
        match self {
            PlantDerivatives::Planar(d) => d.d_a(),
            PlantDerivatives::Spatial(d) => d.d_a(),
        }
    }

    /// `d a_ddot / d a_dot` (`m x m`).
    #[inline]
    pub fn d_a_dot(&self) -> MatRef<'_, f64> {
        match self {
            PlantDerivatives::Planar(d) => d.d_a_dot(),
            PlantDerivatives::Spatial(d) => d.d_a_dot(),
        }
    }

    /// `d a_ddot / d tau* = M*^-1` (`m x m`).
    #[inline]
    pub fn d_tau_star(&self) -> MatRef<'_, f64> {
        match self {
            PlantDerivatives::Planar(d) => d.d_tau_star(),
            PlantDerivatives::Spatial(d) => d.d_tau_star(),
        }
    }
}
