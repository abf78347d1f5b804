//! Discrete-time dynamics for trajectory optimisation: the [`DiscreteDynamics`] interface of
//! [`Ilqr`](super::Ilqr), and the reduced model (eq 15) discretised by semi-implicit Euler with
//! its exact Jacobians from the analytic derivatives.

use modal_reduce::{Plant, PlantData, PlantDerivatives};

use super::OptimalError;

/// A discrete-time system `x_{k+1} = F(x_k, u_k)` with `n_x` states and `n_u` controls, and its
/// Jacobians. Implementations fill caller-owned buffers and allocate nothing.
pub trait DiscreteDynamics {
    /// The number of states `n_x`.
    fn state_dim(&self) -> usize;

    /// The number of controls `n_u`.
    fn control_dim(&self) -> usize;

    /// `next = F(x, u)`.
    ///
    /// # Errors
    /// Whatever the model refuses (a state it cannot evaluate).
    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError>;

    /// `next = F(x, u)` and the Jacobians `a = dF/dx` (`n_x x n_x`) and `b = dF/du`
    /// (`n_x x n_u`), row-major.
    ///
    /// # Errors
    /// As [`step`](Self::step).
    fn linearise(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<(), OptimalError>;
}

/// The reduced dynamics `M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau*` (eq 15) as a discrete
/// system over a step `h` with `tau*` held, by semi-implicit (symplectic) Euler:
///
/// ```text
/// a_dot_{k+1} = a_dot_k + h f(a_k, a_dot_k, tau*_k),   a_{k+1} = a_k + h a_dot_{k+1},
/// ```
///
/// `x = (a, a_dot)` (`2m` entries), `u = tau*` (`m`), `f` the forward dynamics. Its Jacobians are
/// exact for this map, from the plant's analytic derivatives (`modal_reduce::Plant::derivatives`) (`F_a = d a_ddot / d a`,
/// `F_v = d a_ddot / d a_dot`, `F_u = M*^-1`):
///
/// ```text
/// A = [[I + h^2 F_a, h I + h^2 F_v], [h F_a, I + h F_v]],   B = [[h^2 F_u], [h F_u]].
/// ```
///
/// One dynamics evaluation per step (RK4 would take four, each with its own derivatives);
/// symplectic Euler keeps the energy of the unforced arm bounded instead of letting it drift,
/// and its local error `O(h^2)` is corrected at every re-plan of a receding horizon. It borrows
/// the model (planar or spatial) and a workspace (`PlantData`, `PlantDerivatives`) for one solve.
#[derive(Debug)]
pub struct ReducedEuler<'a> {
    model: Plant<'a>,
    data: &'a mut PlantData,
    derivatives: &'a mut PlantDerivatives,
    step: f64,
}

impl<'a> ReducedEuler<'a> {
    /// The semi-implicit Euler map of `model` over `step` seconds, with a workspace built for
    /// `model`.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] unless `step` is positive and finite (at most 10 s).
    pub fn new(
        model: impl Into<Plant<'a>>,
        data: &'a mut PlantData,
        derivatives: &'a mut PlantDerivatives,
        step: f64,
    ) -> Result<Self, OptimalError> {
        check_step(step)?;
        Ok(Self {
            model: model.into(),
            data,
            derivatives,
            step,
        })
    }
}

/// Checks an integration step of the discrete model (s).
pub(crate) fn check_step(step: f64) -> Result<(), OptimalError> {
    if step.is_finite() && step > 0.0 && step <= 10.0 {
        Ok(())
    } else {
        Err(OptimalError::InvalidSetting {
            name: "step",
            requirement: "positive and at most 10 s",
            value: step,
        })
    }
}

impl DiscreteDynamics for ReducedEuler<'_> {
    fn state_dim(&self) -> usize {
        2 * self.model.n_coords()
    }

    fn control_dim(&self) -> usize {
        self.model.n_coords()
    }

    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError> {
        let (m, h) = (self.model.n_coords(), self.step);
        let (a, v) = x.split_at(m);
        let (a_next, v_next) = next.split_at_mut(m);
        self.model.forward_dynamics(self.data, a, v, u, v_next)?;
        for i in 0..m {
            v_next[i] = v[i] + h * v_next[i];
            a_next[i] = a[i] + h * v_next[i];
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
        let m = self.model.n_coords();
        let (a, v) = x.split_at(m);
        self.model
            .derivatives(self.data, self.derivatives, a, v, u)?;
        let d = &*self.derivatives;
        let euler = (self.step, x, next, a_mat, b_mat);
        match m {
            2 => assemble::<2>(d, euler),
            3 => assemble::<3>(d, euler),
            _ => assemble::<0>(d, euler),
        }
        Ok(())
    }
}

/// The Euler map's next state and Jacobians `(A, B)` from the plant's derivatives `d` at `x`
/// (`(h, x, next, A, B)`), for `m = M` known at compile time, or any `m` when `M` is 0.
#[inline(always)]
fn assemble<const M: usize>(
    d: &PlantDerivatives,
    (h, x, next, a_mat, b_mat): (f64, &[f64], &mut [f64], &mut [f64], &mut [f64]),
) {
    let m = if M == 0 { d.a_ddot().len() } else { M };
    let n = 2 * m;
    let (a, v) = (&x[..m], &x[m..n]);
    let (next, a_mat, b_mat) = (&mut next[..n], &mut a_mat[..n * n], &mut b_mat[..n * m]);
    // Row i of the plant's Jacobians: [F_a row i | F_v row i | F_u row i].
    let jacobians = &d.jacobians()[..3 * m * m];
    let a_ddot = &d.a_ddot()[..m];
    for (i, row) in jacobians.chunks_exact(3 * m).enumerate() {
        let v_next = v[i] + h * a_ddot[i];
        next[m + i] = v_next;
        next[i] = a[i] + h * v_next;
        for j in 0..m {
            let identity = if i == j { 1.0 } else { 0.0 };
            let (f_a, f_v, f_u) = (row[j], row[m + j], row[2 * m + j]);
            // Velocity rows: d v_next = h F d(.) + identity on v.
            a_mat[(m + i) * n + j] = h * f_a;
            a_mat[(m + i) * n + m + j] = identity + h * f_v;
            b_mat[(m + i) * m + j] = h * f_u;
            // Position rows: d a_next = d a + h d v_next.
            a_mat[i * n + j] = identity + h * h * f_a;
            a_mat[i * n + m + j] = h * (identity + h * f_v);
            b_mat[i * m + j] = h * h * f_u;
        }
    }
}
