//! Enforced joint limits: the controller's `tau*` projected each controller sample onto the
//! polytope of modal torques whose joint torques stay within `limits.joint_torque_nm` and whose
//! joint rates keep every joint within `limits.joint_angle_rad` (`docs/theory.md`, "Enforced
//! joint limits").

use crate::controller::joint_jacobian;
use crate::error::SimError;
use modal_reduce::{Plant, PlantData};
use optimal_ctl::{PolytopeProjection, ProjectionFailure};

/// The shortest time (s) in which a joint may close the gap to its angle limit: the loop keeps
/// every joint's rate `theta_dot_j` at most `(limit_j - theta_j) / T` towards its limit, with `T`
/// this or the controller period if that is longer.
pub const JOINT_ANGLE_APPROACH_S: f64 = 0.02;

/// The projection aims this far inside every limit (relative), so that rounding in the
/// projection leaves the applied torques within the limits themselves.
const INSIDE: f64 = 1e-9;

/// The limits in force and the projection's working memory for `n` joints and `m` coordinates.
/// Allocation-free per sample.
pub(super) struct LimitProjection {
    /// Joint torque limits (`n`, N m), if any.
    torque: Option<Vec<f64>>,
    /// Joint angle limits, if any.
    angle: Option<AngleLimits>,
    /// Box limits on `tau*` (`m`, N m), if any.
    tau_star: Option<Vec<f64>>,
    /// The controller period `h` (s).
    period: f64,
    projection: PolytopeProjection,
    /// Constraint rows (`m` entries each, row-major) and their bounds.
    rows: Vec<f64>,
    bounds: Vec<f64>,
    /// Joint torques and accelerations at zero modal torque, and at the torque evaluated last.
    tau_bias: Vec<f64>,
    a_ddot_bias: Vec<f64>,
    tau: Vec<f64>,
    a_ddot: Vec<f64>,
    /// A modal vector: a unit torque, or a rate.
    modal: Vec<f64>,
    projected: Vec<f64>,
}

/// Joint angle limits `|theta_j| <= limits_j` with the modal map's rows and the working memory
/// of the rate constraints.
struct AngleLimits {
    limits: Vec<f64>,
    /// The rows of `J` (`n x m`, row-major): `theta_dot = J a_dot`.
    jacobian: Vec<f64>,
    /// The approach time `T` (s).
    approach: f64,
    /// The joint angles at the sample, their rates, and the predicted rates at the next sample
    /// (at the candidate torque, then at zero torque).
    theta: Vec<f64>,
    rate: Vec<f64>,
    next_rate: Vec<f64>,
    column: Vec<f64>,
}

impl AngleLimits {
    /// `1 + h / (2T)`: the factor of the next rate in the constraint.
    fn scale(&self, period: f64) -> f64 {
        1.0 + period / (2.0 * self.approach)
    }

    /// The upper bound of `(1 + h / 2T) v1_j`, `(L_j - theta_j - h v0_j / 2) / T` (with
    /// `sign = 1`), or minus the lower bound (`sign = -1`): `(L_j + theta_j + h v0_j / 2) / T`.
    fn bound(&self, j: usize, sign: f64, period: f64, inside: f64) -> f64 {
        (self.limits[j] * inside - sign * (self.theta[j] + 0.5 * period * self.rate[j]))
            / self.approach
    }

    /// The predicted rates `J (a_dot + h a_ddot)` into `next_rate`.
    fn predict(&mut self, a_dot: &[f64], a_ddot: &[f64], period: f64, modal: &mut [f64]) {
        for ((v, a), dd) in modal.iter_mut().zip(a_dot).zip(a_ddot) {
            *v = a + period * dd;
        }
        map_rows(&self.jacobian, modal, &mut self.next_rate);
    }
}

/// `J x` into `out` (`J` row-major with `x.len()` columns).
fn map_rows(jacobian: &[f64], x: &[f64], out: &mut [f64]) {
    for (row, o) in jacobian.chunks_exact(x.len()).zip(out) {
        *o = row.iter().zip(x).map(|(j, x)| j * x).sum();
    }
}

impl LimitProjection {
    /// The projection for `plant` under the given limits (checked by the loop's settings), or
    /// `None` when there are neither joint torque nor joint angle limits.
    pub(super) fn new(
        plant: Plant<'_>,
        torque: Option<&[f64]>,
        angle: Option<&[f64]>,
        tau_star: Option<&[f64]>,
        period: f64,
    ) -> Result<Option<Self>, SimError> {
        if torque.is_none() && angle.is_none() {
            return Ok(None);
        }
        let (n, m) = (plant.n_joints(), plant.n_coords());
        let angle = match angle {
            None => None,
            Some(limits) => Some(AngleLimits {
                limits: limits.to_vec(),
                jacobian: joint_jacobian(plant)?,
                approach: JOINT_ANGLE_APPROACH_S.max(period),
                theta: vec![0.0; n],
                rate: vec![0.0; n],
                next_rate: vec![0.0; n],
                column: vec![0.0; n],
            }),
        };
        let rows = 4 * n + 2 * m;
        Ok(Some(Self {
            torque: torque.map(<[f64]>::to_vec),
            angle,
            tau_star: tau_star.map(<[f64]>::to_vec),
            period,
            projection: PolytopeProjection::new(m, rows),
            rows: vec![0.0; rows * m],
            bounds: vec![0.0; rows],
            tau_bias: vec![0.0; n],
            a_ddot_bias: vec![0.0; m],
            tau: vec![0.0; n],
            a_ddot: vec![0.0; m],
            modal: vec![0.0; m],
            projected: vec![0.0; m],
        }))
    }

    /// Checks that the joints of `plant` start within `limits.joint_angle_rad` at `a`.
    pub(super) fn check_start(&mut self, plant: Plant<'_>, a: &[f64]) -> Result<(), SimError> {
        let Some(angle) = &mut self.angle else {
            return Ok(());
        };
        joint_angles(plant, a, &mut angle.theta)?;
        for (j, (&theta, &limit)) in angle.theta.iter().zip(&angle.limits).enumerate() {
            if theta.abs() > limit {
                return Err(SimError::setting(
                    "limits.joint_angle_rad",
                    format!(
                        "is {limit} rad for joint {}, which starts at {theta} rad: the initial \
                         state must be within the limits",
                        j + 1
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Keeps `tau_star` within the limits at the state `(a, a_dot)` of time `t`: unchanged when
    /// its joint torques and predicted joint rates already keep them, else replaced by the
    /// closest `tau*` (Euclidean) that does, within the `tau*` box too. Returns whether it
    /// acted.
    pub(super) fn apply(
        &mut self,
        plant: Plant<'_>,
        data: &mut PlantData,
        t: f64,
        (a, a_dot): (&[f64], &[f64]),
        tau_star: &mut [f64],
    ) -> Result<bool, SimError> {
        let (n, m, h) = (self.tau.len(), tau_star.len(), self.period);
        let dynamics = |source| SimError::Dynamics { t, source };
        realised(
            plant,
            data,
            (a, a_dot),
            tau_star,
            &mut self.a_ddot,
            &mut self.tau,
        )
        .map_err(dynamics)?;
        if let Some(angle) = &mut self.angle {
            joint_angles(plant, a, &mut angle.theta)?;
            map_rows(&angle.jacobian, a_dot, &mut angle.rate);
            angle.predict(a_dot, &self.a_ddot, h, &mut self.modal);
        }
        if self.holds() {
            return Ok(false);
        }
        // The affine maps tau* -> joint torques and tau* -> acceleration: m + 1 evaluations.
        self.modal.fill(0.0);
        realised(
            plant,
            data,
            (a, a_dot),
            &self.modal,
            &mut self.a_ddot_bias,
            &mut self.tau_bias,
        )
        .map_err(dynamics)?;
        if let Some(angle) = &mut self.angle {
            angle.predict(a_dot, &self.a_ddot_bias, h, &mut self.modal);
        }
        let torque_rows = if self.torque.is_some() { 2 * n } else { 0 };
        let angle_rows = if self.angle.is_some() { 2 * n } else { 0 };
        for i in 0..m {
            self.modal.fill(0.0);
            self.modal[i] = 1.0;
            realised(
                plant,
                data,
                (a, a_dot),
                &self.modal,
                &mut self.a_ddot,
                &mut self.tau,
            )
            .map_err(dynamics)?;
            for j in 0..torque_rows / 2 {
                let column = self.tau[j] - self.tau_bias[j];
                self.rows[2 * j * m + i] = column;
                self.rows[(2 * j + 1) * m + i] = -column;
            }
            if let Some(angle) = &mut self.angle {
                // The next sample's joint rates per unit tau*_i: h J (a_dd(e_i) - a_dd(0)).
                for (dd, bias) in self.a_ddot.iter_mut().zip(&self.a_ddot_bias) {
                    *dd = h * (*dd - bias);
                }
                map_rows(&angle.jacobian, &self.a_ddot, &mut angle.column);
                let scale = angle.scale(h);
                for j in 0..n {
                    let row = torque_rows + 2 * j;
                    self.rows[row * m + i] = scale * angle.column[j];
                    self.rows[(row + 1) * m + i] = -scale * angle.column[j];
                }
            }
        }
        let inside = 1.0 - INSIDE;
        if let Some(limits) = &self.torque {
            for (j, (limit, bias)) in limits.iter().zip(&self.tau_bias).enumerate() {
                self.bounds[2 * j] = limit * inside - bias;
                self.bounds[2 * j + 1] = limit * inside + bias;
            }
        }
        if let Some(angle) = &self.angle {
            let scale = angle.scale(h);
            for j in 0..n {
                let row = torque_rows + 2 * j;
                let at_zero = scale * angle.next_rate[j];
                self.bounds[row] = angle.bound(j, 1.0, h, inside) - at_zero;
                self.bounds[row + 1] = angle.bound(j, -1.0, h, inside) + at_zero;
            }
        }
        let mut count = torque_rows + angle_rows;
        if let Some(box_limits) = &self.tau_star {
            for (i, &limit) in box_limits.iter().enumerate() {
                for sign in [1.0, -1.0] {
                    let row = &mut self.rows[count * m..(count + 1) * m];
                    row.fill(0.0);
                    row[i] = sign;
                    self.bounds[count] = limit;
                    count += 1;
                }
            }
        }
        match self.projection.project(
            &self.rows[..count * m],
            &self.bounds[..count],
            tau_star,
            &mut self.projected,
        ) {
            Ok(acted) => {
                tau_star.copy_from_slice(&self.projected);
                Ok(acted)
            }
            Err(ProjectionFailure::Empty) => Err(SimError::JointLimits {
                t,
                reason: "no modal torque keeps every joint within limits.joint_torque_nm and \
                         limits.joint_angle_rad",
            }),
            Err(ProjectionFailure::NonFinite) => Err(SimError::JointLimits {
                t,
                reason: "the joint limits' rows or the controller's modal torque are not finite \
                         numbers",
            }),
            Err(_) => Err(SimError::JointLimits {
                t,
                reason: "the projection onto the joint limits did not converge",
            }),
        }
    }

    /// Whether the candidate (its joint torques in `tau`, its predicted rates in the angle
    /// limits' `next_rate`) keeps every limit.
    fn holds(&self) -> bool {
        if let Some(limits) = &self.torque
            && self.tau.iter().zip(limits).any(|(tau, l)| tau.abs() > *l)
        {
            return false;
        }
        match &self.angle {
            None => true,
            Some(angle) => {
                let scale = angle.scale(self.period);
                (0..angle.limits.len()).all(|j| {
                    let v = scale * angle.next_rate[j];
                    v <= angle.bound(j, 1.0, self.period, 1.0)
                        && -v <= angle.bound(j, -1.0, self.period, 1.0)
                })
            }
        }
    }
}

/// The joint torques `tau = M J a_dd + C + G` (eq 13) that `tau_star` realises at `state`, with
/// `a_dd` from the reduced dynamics (eq 15), into `tau` and `a_ddot`.
fn realised(
    plant: Plant<'_>,
    data: &mut PlantData,
    (a, a_dot): (&[f64], &[f64]),
    tau_star: &[f64],
    a_ddot: &mut [f64],
    tau: &mut [f64],
) -> Result<(), modal_reduce::ReduceError> {
    plant.forward_dynamics(data, a, a_dot, tau_star, a_ddot)?;
    plant.joint_torques(data, a, a_dot, a_ddot, tau)
}

/// The joint angles `theta = J a + theta_0` (eq 8) of either family.
fn joint_angles(plant: Plant<'_>, a: &[f64], theta: &mut [f64]) -> Result<(), SimError> {
    match plant {
        Plant::Planar(model) => model.map().joint_angles(a, theta)?,
        Plant::Spatial(model) => model.map().joint_angles(a, theta)?,
    }
    Ok(())
}
