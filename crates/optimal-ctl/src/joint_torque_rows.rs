//! The joint-torque polytope as step constraints: at a modal state the joint torques that
//! realise a modal torque are affine in it, `tau = A tau* + b` (eqs 13 and 15), so
//! `|tau_j| <= limit_j` is `2n` linear rows on `tau*` ([`StepConstraints`]).

use crate::OptimalError;
use crate::step_constraints::StepConstraints;
use lane_math::dense::{cholesky, cholesky_solve};
use modal_reduce::{Plant, PlantData, ReduceError};

/// The limits `|tau_j| <= limit_j` of a modal arm and the working memory that writes their rows
/// at a state, without the arm: [`rows`](Self::rows) takes it at each call, so a controller that
/// is handed the arm at every sample (as the loop's controllers are) can own this.
/// [`JointTorqueRows`] is the same with the arm borrowed, as [`StepConstraints`].
/// Allocation-free per use.
#[derive(Debug, Clone)]
pub struct JointTorqueLimits {
    data: PlantData,
    limits: Vec<f64>,
    /// `M*`'s Cholesky factor (`m x m`) and `M*^-1 [I, -(C* + G*)]` (`m x (m + 1)`).
    factor: Vec<f64>,
    solves: Vec<f64>,
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
            factor: vec![0.0; m * m],
            solves: vec![0.0; m * (m + 1)],
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
    /// at the state `x = (a, a_dot)`; `rows` is `2n x m` row-major (joint `j`'s upper bound,
    /// then its lower one), `bounds` `2n`. Returns `2n`.
    ///
    /// With `a_ddot = M*^-1 (tau* - C* - G*)` (eq 15) and the joint torques
    /// `tau = M J a_ddot + C + G` (eq 13) affine in `a_ddot`: one evaluation of `M*`, `C*`, `G*`
    /// and one factorisation of `M*` give `a_ddot_0 = -M*^-1 (C* + G*)` and the columns
    /// `y_i = M*^-1 e_i`; `b = tau(a_ddot_0)` and `A`'s column `i` is
    /// `tau(a_ddot_0 + y_i) - b` (`m + 1` evaluations of eq 13).
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
        let m = self.a_ddot.len();
        let (a, a_dot) = (&x[..m], &x[m..2 * m]);
        self.solve_accelerations(plant, a, a_dot)?;
        // `solves` is `m x (m + 1)` row-major: the columns `y_i`, then `a_ddot_0`.
        for (r, acc) in self.a_ddot.iter_mut().enumerate() {
            *acc = self.solves[r * (m + 1) + m];
        }
        plant.joint_torques(&mut self.data, a, a_dot, &self.a_ddot, &mut self.bias)?;
        for i in 0..m {
            for (r, acc) in self.a_ddot.iter_mut().enumerate() {
                *acc = self.solves[r * (m + 1) + m] + self.solves[r * (m + 1) + i];
            }
            plant.joint_torques(&mut self.data, a, a_dot, &self.a_ddot, &mut self.tau)?;
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

    /// `M*^-1 [e_1 ... e_m, -(C* + G*)]` at `(a, a_dot)` into `self.solves` (eq 15).
    fn solve_accelerations(
        &mut self,
        plant: Plant<'_>,
        a: &[f64],
        a_dot: &[f64],
    ) -> Result<(), OptimalError> {
        let m = a.len();
        plant.terms(&mut self.data, a, a_dot)?;
        let mass = self.data.mass_matrix();
        for r in 0..m {
            for c in 0..m {
                self.factor[r * m + c] = mass[(r, c)];
            }
        }
        if !cholesky(&mut self.factor, m) {
            return Err(ReduceError::NotPositiveDefinite.into());
        }
        let (coriolis, gravity) = (self.data.coriolis(), self.data.gravity());
        for r in 0..m {
            let row = &mut self.solves[r * (m + 1)..(r + 1) * (m + 1)];
            row.fill(0.0);
            row[r] = 1.0;
            row[m] = -(coriolis[r] + gravity[r]);
        }
        cholesky_solve(&self.factor, m, &mut self.solves, m + 1);
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
