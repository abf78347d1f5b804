//! The joint-torque polytope as step constraints: at a modal state the joint torques that
//! realise a modal torque are affine in it, `tau = A tau* + b` (eqs 13 and 15), so
//! `|tau_j| <= limit_j` is `2n` linear rows on `tau*` ([`StepConstraints`]), with their state
//! Jacobian in closed form on a planar arm.

use crate::OptimalError;
use crate::step_constraints::StepConstraints;
use faer::MatRef;
use lane_math::dense::{cholesky, cholesky_solve};
use manip_dyn::{ChainData, DerivativeData, rnea_derivatives};
use modal_reduce::{
    Plant, PlantData, ReduceError, ReducedDerivatives, ReducedModel, reduced_derivatives,
};

/// The most joints of a planar arm whose rows get their state Jacobian in closed form: it
/// costs `O(n^2 m)` against the forward differences' `O(n m^3)`, and its workspace `O(n^2)`.
const CLOSED_FORM_MAX_JOINTS: usize = 64;

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
    /// The closed-form state Jacobian's workspace (a planar arm of at most
    /// [`CLOSED_FORM_MAX_JOINTS`] joints).
    derivatives: Option<TorqueDerivatives>,
}

/// The workspace of [`JointTorqueLimits::state_jacobian`] on a planar arm.
#[derive(Debug, Clone)]
struct TorqueDerivatives {
    reduced: ReducedDerivatives,
    chain: ChainData,
    rnea: DerivativeData,
    /// The joint angles, rates and accelerations (`n` each).
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    theta_ddot: Vec<f64>,
    /// `d theta_ddot / dx = J [d a_ddot/d a | d a_ddot/d a_dot]` (`n x 2m`, row-major).
    accel: Vec<f64>,
}

impl TorqueDerivatives {
    fn new(model: &ReducedModel) -> Self {
        let (n, m) = (model.n_links(), model.n_coords());
        Self {
            reduced: ReducedDerivatives::new(model),
            chain: ChainData::new(model.chain()),
            rnea: DerivativeData::new(model.chain()),
            theta: vec![0.0; n],
            theta_dot: vec![0.0; n],
            theta_ddot: vec![0.0; n],
            accel: vec![0.0; n * 2 * m],
        }
    }
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
            derivatives: plant
                .planar()
                .filter(|model| model.n_links() <= CLOSED_FORM_MAX_JOINTS)
                .map(TorqueDerivatives::new),
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

    /// Writes the state Jacobian `D = d(G u - g)/dx` of the rows of [`rows`](Self::rows) at
    /// `x = (a, a_dot)` under the modal torque `u`, `2n x 2m` row-major (joint `j`'s upper row
    /// `d tau_j/dx`, its lower row `-d tau_j/dx`), and returns `true`; `false`, writing nothing,
    /// on a spatial arm or a planar one of more than 64 joints.
    ///
    /// `tau(x, u)` is the inverse dynamics (eq 13) at `theta = J a + theta_0`,
    /// `theta_dot = J a_dot` and `theta_ddot = J a_ddot(x, u)` (eqs 8, 10, 11, 15), so
    /// `d tau/d a = d_q tau J + M J d a_ddot/d a` and
    /// `d tau/d a_dot = d_v tau J + M J d a_ddot/d a_dot`, from the chain's inverse-dynamics
    /// derivatives ([`manip_dyn::rnea_derivatives`]: `d_q tau`, `d_v tau`, `M`) and the reduced
    /// forward dynamics' ([`modal_reduce::reduced_derivatives`]).
    ///
    /// # Errors
    /// [`OptimalError::Dynamics`] or [`OptimalError::ChainDynamics`] when `plant` refuses the
    /// state or the torque or is not the arm these limits were made for.
    pub fn state_jacobian(
        &mut self,
        plant: Plant<'_>,
        x: &[f64],
        u: &[f64],
        jacobian: &mut [f64],
    ) -> Result<bool, OptimalError> {
        let (Plant::Planar(model), PlantData::Planar(data), Some(work)) =
            (plant, &mut self.data, self.derivatives.as_mut())
        else {
            return Ok(false);
        };
        let m = self.a_ddot.len();
        let nx = 2 * m;
        let (a, a_dot) = (&x[..m], &x[m..nx]);
        reduced_derivatives(model, data, &mut work.reduced, a, a_dot, u)?;
        let map = model.map();
        map.joint_angles(a, &mut work.theta)
            .map_err(ReduceError::from)?;
        map.joint_rates(a_dot, &mut work.theta_dot)
            .map_err(ReduceError::from)?;
        map.joint_rates(work.reduced.a_ddot(), &mut work.theta_ddot)
            .map_err(ReduceError::from)?;
        rnea_derivatives(
            model.chain(),
            &mut work.chain,
            &mut work.rnea,
            &work.theta,
            &work.theta_dot,
            &work.theta_ddot,
        )?;
        let (d_a, d_a_dot) = (work.reduced.d_a(), work.reduced.d_a_dot());
        let jac = map.jacobian();
        for (row, accel) in jac.chunks_exact(m).zip(work.accel.chunks_exact_mut(nx)) {
            for c in 0..m {
                accel[c] = (0..m).map(|i| row[i] * d_a[(i, c)]).sum();
                accel[m + c] = (0..m).map(|i| row[i] * d_a_dot[(i, c)]).sum();
            }
        }
        let chain = (work.rnea.d_q(), work.rnea.d_v(), work.rnea.d_input());
        let products = (jac, &work.accel[..]);
        match m {
            2 => chain_rows::<2>(2, chain, products, jacobian),
            3 => chain_rows::<3>(3, chain, products, jacobian),
            _ => chain_rows::<0>(m, chain, products, jacobian),
        }
        Ok(true)
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

/// The rows of [`JointTorqueLimits::state_jacobian`] from the chain's derivatives
/// `(d_q tau, d_v tau, M)` and `(J, J d a_ddot/dx)` (`n x m` and `n x 2m`, row-major): joint
/// `j`'s upper row `d_q tau_j J | d_v tau_j J + (M J d a_ddot/dx)_j`, its lower row the
/// negation; for `m = M` known at compile time (the loops over the coordinates unrolled), or
/// any `m` when `M` is 0.
#[inline(always)]
fn chain_rows<const M: usize>(
    m: usize,
    (d_q, d_v, mass): (MatRef<'_, f64>, MatRef<'_, f64>, MatRef<'_, f64>),
    (jac, accel): (&[f64], &[f64]),
    jacobian: &mut [f64],
) {
    let m = if M == 0 { m } else { M };
    let nx = 2 * m;
    let joints = jacobian.chunks_exact_mut(2 * nx).take(d_q.nrows());
    for (j, rows) in joints.enumerate() {
        let (upper, lower) = rows.split_at_mut(nx);
        upper.fill(0.0);
        let entries = d_q
            .row(j)
            .iter()
            .zip(d_v.row(j).iter())
            .zip(mass.row(j).iter());
        for (((dq, dv), mk), (row, accel)) in
            entries.zip(jac.chunks_exact(m).zip(accel.chunks_exact(nx)))
        {
            // d_q tau J and d_v tau J, then M J d a_ddot/dx.
            for c in 0..m {
                upper[c] += dq * row[c];
                upper[m + c] += dv * row[c];
            }
            for (d, a) in upper.iter_mut().zip(accel) {
                *d += mk * a;
            }
        }
        for (l, u) in lower.iter_mut().zip(upper.iter()) {
            *l = -u;
        }
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

    fn analytic_state_jacobian(
        &mut self,
        _k: usize,
        x: &[f64],
        u: &[f64],
        _b: &[f64],
        jacobian: &mut [f64],
    ) -> Result<bool, OptimalError> {
        self.limits.state_jacobian(self.plant, x, u, jacobian)
    }

    /// The rows are those of the state `x`, the state Jacobian that of `(x, u)`.
    fn rows_of_state_and_control(&self) -> bool {
        true
    }

    fn rows_of_state(&self) -> bool {
        true
    }
}
