//! What the planner asks of a modal arm: place its chain, differentiate, bound its motion.

use crate::error::PlanError;
use clearance::{ClearanceData, ClearanceModel};

/// An arm's working memory for placing its chain: joint angles, joint points and joint axes.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmScratch {
    /// The joint angles (`n_joints`).
    pub theta: Vec<f64>,
    /// The joint points (`n_links + 1`), base first.
    pub points: Vec<[f64; 3]>,
    /// The joint axes in world coordinates (`n_joints`).
    pub axes: Vec<[f64; 3]>,
    /// Each link's first joint axis (`n_links`), what `clearance::place` records.
    pub link_axes: Vec<[f64; 3]>,
    /// Prefix sums of the modal gradients' formula (`2 n_links n_coords`), for arms that
    /// compute them here.
    pub prefix: Vec<[f64; 3]>,
}

impl ArmScratch {
    /// Scratch sized for `arm`.
    pub fn new<A: Arm + ?Sized>(arm: &A) -> Self {
        Self {
            theta: vec![0.0; arm.n_joints()],
            points: vec![[0.0; 3]; arm.n_links() + 1],
            axes: vec![[0.0, 0.0, 1.0]; arm.n_joints()],
            link_axes: vec![[0.0, 0.0, 1.0]; arm.n_links()],
            prefix: vec![[0.0; 3]; 2 * arm.n_links() * arm.n_coords()],
        }
    }
}

/// A chain whose joint angles follow a constant modal map, placed in the world for the
/// clearance computations. Implemented by [`PlanarArm`](crate::PlanarArm) and
/// [`SpatialArm`](crate::SpatialArm).
pub trait Arm {
    /// The dimension of the workspace the tip moves in: 2 (the plane `z = 0`) or 3.
    fn dimension(&self) -> usize;
    /// The number of links `n`.
    fn n_links(&self) -> usize;
    /// The number of joint angles (the rows of the modal map).
    fn n_joints(&self) -> usize;
    /// The number of modal coordinates `m`.
    fn n_coords(&self) -> usize;
    /// The chain's length (the sum of its links), m.
    fn length(&self) -> f64;
    /// The base point (the first joint), world frame.
    fn base(&self) -> [f64; 3];
    /// Places the chain of modal coordinates `a` into `data` (joint points and axes);
    /// `scratch` receives the joint angles, points and axes. Allocation-free.
    fn place(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        scratch: &mut ArmScratch,
        a: &[f64],
    ) -> Result<(), PlanError>;
    /// After [`place`](Self::place) and [`clearance::distances`]: every pair's modal gradient
    /// (`pairs x m`, row-major, into `gradients`) and the tip's Jacobian `d tip / d a` (`3 x m`,
    /// row-major, into `tip_jacobian`). Allocation-free.
    fn gradients(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        scratch: &mut ArmScratch,
        gradients: &mut [f64],
        tip_jacobian: &mut [f64],
    ) -> Result<(), PlanError>;
    /// A Lipschitz constant `Lambda` of every point of every link's axis in the modal
    /// coordinates: `|x(a) - x(b)| <= Lambda |a - b|` (Euclidean norms).
    fn lipschitz(&self) -> f64;
    /// Starts from the free-space inverse kinematics of `target` (the shapes that reach it
    /// ignoring obstacles), best first; `initial` supplies any coordinate the inverse
    /// kinematics does not solve for.
    fn free_space_starts(&self, target: [f64; 3], initial: &[f64]) -> Vec<Vec<f64>>;
}
