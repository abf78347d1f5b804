//! The planner's working memory, sized once from an arm and its clearance model.

use crate::arm::{Arm, ArmScratch};
use crate::error::PlanError;
use clearance::{ClearanceData, ClearanceModel};
use optimal_ctl::LinearQp;

/// What [`solve_shape`](crate::solve_shape), [`check_segment`](crate::check_segment) and
/// [`Planner`](crate::Planner) write; holds no algorithm. Only [`Planner::plan`]'s result (the
/// path it returns) allocates after this is built.
///
/// [`Planner::plan`]: crate::Planner::plan
#[derive(Debug, Clone)]
pub struct PlanData {
    /// The clearance data of the current iterate (distances and modal gradients).
    pub(crate) current: ClearanceData,
    /// The clearance data of a trial step or a check point (distances only).
    pub(crate) trial: ClearanceData,
    /// Joint angles, points and axes of the last placed shape.
    pub(crate) scratch: ArmScratch,
    /// Every pair's modal gradient at the current iterate, `pairs x m`.
    pub(crate) gradients: Vec<f64>,
    /// `d tip / d a` of the current iterate, `3 x m`.
    pub(crate) tip_jacobian: Vec<f64>,
    /// A trial point or check point in modal coordinates.
    pub(crate) point: Vec<f64>,
    /// The step of the quadratic program.
    pub(crate) step: Vec<f64>,
    /// `H = T^T T + mu I`, `m x m`.
    pub(crate) hessian: Vec<f64>,
    /// `q = T^T e`.
    pub(crate) linear: Vec<f64>,
    /// The linearised constraints `G` (`(pairs + 2m) x m`) and their bounds `g`.
    pub(crate) rows: Vec<f64>,
    pub(crate) bounds: Vec<f64>,
    pub(crate) qp: LinearQp,
}

impl PlanData {
    /// Working memory for `arm` among the obstacles of `clearance`.
    pub fn new<A: Arm>(arm: &A, clearance: &ClearanceModel) -> Result<Self, PlanError> {
        lane_math::check_len("clearance model links", clearance.n_links(), arm.n_links())?;
        let m = arm.n_coords();
        let data = ClearanceData::new(clearance, m)?;
        let rows = clearance.pairs().len() + 2 * m;
        Ok(Self {
            current: data.clone(),
            trial: data,
            scratch: ArmScratch::new(arm),
            gradients: vec![0.0; clearance.pairs().len() * m],
            tip_jacobian: vec![0.0; 3 * m],
            point: vec![0.0; m],
            step: vec![0.0; m],
            hessian: vec![0.0; m * m],
            linear: vec![0.0; m],
            rows: vec![0.0; rows * m],
            bounds: vec![0.0; rows],
            qp: LinearQp::new(m, rows),
        })
    }

    /// The joint points of the last shape solved or checked, base to tip.
    pub fn points(&self) -> &[[f64; 3]] {
        self.current.points()
    }
}
