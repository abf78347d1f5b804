//! What the planner asks of a modal arm: place its chain, differentiate, bound its motion.

use crate::error::PlanError;
use clearance::{ClearanceData, ClearanceModel};

/// A chain whose joint angles follow a constant modal map, placed in the world for the
/// clearance computations. Implemented by [`PlanarArm`](crate::PlanarArm) and
/// later spatial arms.
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
    /// `theta` (`n_joints` entries) receives the joint angles. Allocation-free.
    fn place(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        theta: &mut [f64],
        a: &[f64],
    ) -> Result<(), PlanError>;
    /// After [`place`](Self::place) and [`clearance::distances`]: every pair's modal gradient
    /// (into `data`) and the tip's Jacobian `d tip / d a` (`3 x m`, row-major, into
    /// `tip_jacobian`). Allocation-free.
    fn gradients(
        &self,
        clearance: &ClearanceModel,
        data: &mut ClearanceData,
        theta: &[f64],
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
