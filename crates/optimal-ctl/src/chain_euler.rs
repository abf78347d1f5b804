//! A full chain in joint space as a discrete system for trajectory optimisation: the
//! articulated-body forward dynamics of a [`SpatialModel`] (any joints, prismatic included)
//! discretised by semi-implicit Euler, with its exact Jacobians from the analytic ABA
//! derivatives.

use manip_dyn::spatial::{SpatialData, SpatialDerivativeData, SpatialModel, aba, aba_derivatives};

use super::OptimalError;
use super::discrete::{DiscreteDynamics, check_step};

/// `M(q) q_dd + C(q, v) v + G(q) = tau` of a spatial chain as a discrete system over a step `h`
/// with `tau` held, by the same semi-implicit Euler as [`ReducedEuler`](crate::ReducedEuler):
///
/// ```text
/// v_{k+1} = v_k + h ABA(q_k, v_k, tau_k),   q_{k+1} = q_k + h v_{k+1},
/// ```
///
/// `x = (q, v)` (`2n` entries), `u = tau` (`n`, N m for a revolute joint, N for a prismatic
/// one). Its Jacobians are exact for this map, from
/// [`aba_derivatives`](manip_dyn::spatial::aba_derivatives) (`F_q = d q_dd / d q`,
/// `F_v = d q_dd / d v`, `F_u = M^-1`):
///
/// ```text
/// A = [[I + h^2 F_q, h I + h^2 F_v], [h F_q, I + h F_v]],   B = [[h^2 F_u], [h F_u]].
/// ```
///
/// It borrows the model and a workspace for one solve and allocates nothing.
#[derive(Debug)]
pub struct ChainEuler<'a> {
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
    derivatives: &'a mut SpatialDerivativeData,
    step: f64,
}

impl<'a> ChainEuler<'a> {
    /// The semi-implicit Euler map of `model` over `step` seconds, with a workspace built for
    /// `model`.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] unless `step` is positive and finite (at most 10 s).
    pub fn new(
        model: &'a SpatialModel,
        data: &'a mut SpatialData,
        derivatives: &'a mut SpatialDerivativeData,
        step: f64,
    ) -> Result<Self, OptimalError> {
        check_step(step)?;
        Ok(Self {
            model,
            data,
            derivatives,
            step,
        })
    }
}

impl DiscreteDynamics for ChainEuler<'_> {
    fn state_dim(&self) -> usize {
        2 * self.model.n_links()
    }

    fn control_dim(&self) -> usize {
        self.model.n_links()
    }

    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError> {
        let (n, h) = (self.model.n_links(), self.step);
        let (q, v) = x.split_at(n);
        let (q_next, v_next) = next.split_at_mut(n);
        aba(self.model, self.data, q, v, u, v_next)?;
        for i in 0..n {
            v_next[i] = v[i] + h * v_next[i];
            q_next[i] = q[i] + h * v_next[i];
        }
        Ok(())
    }

    fn linearise(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a_mat: &mut [f64],
        b_mat: &mut [f64],
    ) -> Result<(), OptimalError> {
        let (n, h) = (self.model.n_links(), self.step);
        let nx = 2 * n;
        let (q, v) = x.split_at(n);
        aba_derivatives(self.model, self.data, self.derivatives, q, v, u)?;
        let d = &*self.derivatives;
        let (f_q, f_v, f_u, qdd) = (d.d_q(), d.d_v(), d.d_input(), d.value());
        for i in 0..n {
            let v_next = v[i] + h * qdd[i];
            next[n + i] = v_next;
            next[i] = q[i] + h * v_next;
            for j in 0..n {
                let identity = if i == j { 1.0 } else { 0.0 };
                a_mat[(n + i) * nx + j] = h * f_q[(i, j)];
                a_mat[(n + i) * nx + n + j] = identity + h * f_v[(i, j)];
                b_mat[(n + i) * n + j] = h * f_u[(i, j)];
                a_mat[i * nx + j] = identity + h * h * f_q[(i, j)];
                a_mat[i * nx + n + j] = h * (identity + h * f_v[(i, j)]);
                b_mat[i * n + j] = h * h * f_u[(i, j)];
            }
        }
        Ok(())
    }
}
