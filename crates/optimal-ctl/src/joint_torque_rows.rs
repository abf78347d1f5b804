//! The joint-torque polytope as step constraints: at a modal state the joint torques that
//! realise a modal torque are affine in it, `tau = A tau* + b` (eqs 13 and 15), so
//! `|tau_j| <= limit_j` is `2n` linear rows on `tau*` ([`StepConstraints`]).

use crate::OptimalError;
use crate::step_constraints::StepConstraints;
use modal_reduce::{Plant, PlantData};

/// The limits `|tau_j| <= limit_j` of a modal arm and the working memory that writes their rows
/// at a state, without the arm: [`rows`](Self::rows) takes it at each call, so a controller that
/// is handed the arm at every sample (as the loop's controllers are) can own this.
/// [`JointTorqueRows`] is the same with the arm borrowed, as [`StepConstraints`].
/// Allocation-free per use.
#[derive(Debug, Clone)]
pub struct JointTorqueLimits {
    data: PlantData,
    limits: Vec<f64>,
    unit: Vec<f64>,
    a_ddot: Vec<f64>,
    bias: Vec<f64>,
    tau: Vec<f64>,
}

impl JointTorqueLimits {
    /// The limits of `model` (one per joint, positive and finite).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for limits of another length than the joints,
    /// [`OptimalError::InvalidSetting`] for a limit that is not positive and finite.
    pub fn new<'p>(model: impl Into<Plant<'p>>, limits: &[f64]) -> Result<Self, OptimalError> {
        let plant = model.into();
        let (n, m) = (plant.n_joints(), plant.n_coords());
        if limits.len() != n {
            return Err(OptimalError::Dimension {
                name: "joint torque limits",
                expected: n,
                found: limits.len(),
            });
        }
        if let Some(&l) = limits.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
            return Err(OptimalError::InvalidSetting {
                name: "joint torque limit",
                requirement: "positive and finite",
                value: l,
            });
        }
        Ok(Self {
            data: PlantData::new(plant),
            limits: limits.to_vec(),
            unit: vec![0.0; m],
            a_ddot: vec![0.0; m],
            bias: vec![0.0; n],
            tau: vec![0.0; n],
        })
    }

    /// The number of rows, `2n`.
    pub fn max_rows(&self) -> usize {
        2 * self.limits.len()
    }

    /// Writes the rows `|A tau* + b| <= limits` of `plant` (the arm these limits were made for)
    /// at the state `x = (a, a_dot)`: `b` the joint torques of zero modal torque, `A`'s columns
    /// those of each unit modal torque less `b`, exactly (`m + 1` evaluations of the forward
    /// dynamics and the joint torques); `rows` is `2n x m` row-major (joint `j`'s upper bound,
    /// then its lower one), `bounds` `2n`. Returns `2n`.
    ///
    /// # Errors
    /// [`OptimalError::Dynamics`] when `plant` refuses the state or is not the arm these limits
    /// were made for (another size).
    pub fn rows(
        &mut self,
        plant: Plant<'_>,
        x: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        let m = self.unit.len();
        let state = (&x[..m], &x[m..2 * m]);
        self.unit.fill(0.0);
        self.realise(plant, state, true)?;
        for i in 0..m {
            self.unit.fill(0.0);
            self.unit[i] = 1.0;
            self.realise(plant, state, false)?;
            for (j, (tau, bias)) in self.tau.iter().zip(&self.bias).enumerate() {
                rows[2 * j * m + i] = tau - bias;
                rows[(2 * j + 1) * m + i] = bias - tau;
            }
        }
        for (j, (limit, bias)) in self.limits.iter().zip(&self.bias).enumerate() {
            bounds[2 * j] = limit - bias;
            bounds[2 * j + 1] = limit + bias;
        }
        Ok(self.max_rows())
    }

    /// The joint torques of the unit torque in `self.unit` at `(a, a_dot)` into `self.bias`
    /// (`bias`) or `self.tau`.
    fn realise(
        &mut self,
        plant: Plant<'_>,
        (a, a_dot): (&[f64], &[f64]),
        bias: bool,
    ) -> Result<(), OptimalError> {
        plant.forward_dynamics(&mut self.data, a, a_dot, &self.unit, &mut self.a_ddot)?;
        let out = if bias { &mut self.bias } else { &mut self.tau };
        plant.joint_torques(&mut self.data, a, a_dot, &self.a_ddot, out)?;
        Ok(())
    }
}

/// The rows `|A tau* + b| <= limits` of a modal arm at each step's state `x = (a, a_dot)`
/// ([`JointTorqueLimits::rows`]) as [`StepConstraints`], for
/// [`Ilqr::solve_constrained`](crate::Ilqr::solve_constrained) and
/// [`Mpc::solve_constrained`](crate::Mpc::solve_constrained). Allocation-free per step.
#[derive(Debug, Clone)]
pub struct JointTorqueRows<'p> {
    plant: Plant<'p>,
    limits: JointTorqueLimits,
}

impl<'p> JointTorqueRows<'p> {
    /// The rows of `model` under `limits` (one per joint, positive and finite).
    ///
    /// # Errors
    /// As [`JointTorqueLimits::new`].
    pub fn new(model: impl Into<Plant<'p>>, limits: &[f64]) -> Result<Self, OptimalError> {
        let plant = model.into();
        Ok(Self {
            plant,
            limits: JointTorqueLimits::new(plant, limits)?,
        })
    }
}

impl StepConstraints for JointTorqueRows<'_> {
    fn max_rows(&self) -> usize {
        self.limits.max_rows()
    }

    fn rows(
        &mut self,
        _k: usize,
        x: &[f64],
        _u: &[f64],
        _b: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        self.limits.rows(self.plant, x, rows, bounds)
    }
}
