//! Discrete-time dynamics for trajectory optimisation: the [`DiscreteDynamics`] interface of
//! [`Ilqr`](super::Ilqr), and the reduced model (eq 15) discretised by semi-implicit Euler with
//! its exact Jacobians from the analytic derivatives.

use modal_reduce::{
    MAX_BATCH_COORDS, Plant, PlantData, PlantDerivatives, ReducedDerivativesBatch,
    reduced_derivatives_batch,
};

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

    /// Whether [`linearise_trajectory`](Self::linearise_trajectory) takes a trajectory's
    /// Jacobians faster than [`linearise`](Self::linearise) node by node: a solver then rolls
    /// out with [`step`](Self::step) and linearises the trajectory it keeps, instead of
    /// linearising on its way (which a rejected rollout wastes).
    fn linearises_trajectories(&self) -> bool {
        false
    }

    /// The Jacobians of the steps from the states `x` (`N x n_x`, row-major) under the controls
    /// `u` (`N x n_u`): `A_k` into block `k` of `a` (`N` blocks of `n_x x n_x`) and `B_k` into
    /// `b` (`N` blocks of `n_x x n_u`), with `next` (`n_x`) as scratch. By default
    /// [`linearise`](Self::linearise) node by node.
    ///
    /// # Errors
    /// As [`step`](Self::step); [`OptimalError::Dimension`] for slices that do not hold the
    /// same number of whole nodes.
    fn linearise_trajectory(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<(), OptimalError> {
        linearise_node_by_node(self, x, u, next, (a, b))
    }
}

/// Checks the slices of [`DiscreteDynamics::linearise_trajectory`]: `N = u.len() / n_u` nodes,
/// `x` of `N` states, `a` and `b` of `N` blocks each, `next` of one state.
fn check_trajectory(
    (nx, nu): (usize, usize),
    (x, u, next): (&[f64], &[f64], &[f64]),
    (a, b): (&[f64], &[f64]),
) -> Result<(), OptimalError> {
    let nodes = u.len() / nu.max(1);
    for (name, expected, found) in [
        ("controls (whole nodes of n_u values)", nodes * nu, u.len()),
        ("states (one a node)", nodes * nx, x.len()),
        ("next", nx, next.len()),
        ("state Jacobians (one a node)", nodes * nx * nx, a.len()),
        ("control Jacobians (one a node)", nodes * nx * nu, b.len()),
    ] {
        if expected != found {
            return Err(OptimalError::Dimension {
                name,
                expected,
                found,
            });
        }
    }
    Ok(())
}

/// [`DiscreteDynamics::linearise_trajectory`] by [`DiscreteDynamics::linearise`] of each node.
fn linearise_node_by_node<D: DiscreteDynamics + ?Sized>(
    dynamics: &mut D,
    x: &[f64],
    u: &[f64],
    next: &mut [f64],
    (a, b): (&mut [f64], &mut [f64]),
) -> Result<(), OptimalError> {
    let (nx, nu) = (dynamics.state_dim(), dynamics.control_dim());
    check_trajectory((nx, nu), (x, u, next), (a, b))?;
    let nodes = x.chunks_exact(nx).zip(u.chunks_exact(nu));
    let jacobians = a.chunks_exact_mut(nx * nx).zip(b.chunks_exact_mut(nx * nu));
    for ((x, u), (a, b)) in nodes.zip(jacobians) {
        dynamics.linearise(x, u, next, a, b)?;
    }
    Ok(())
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
/// the model (planar or spatial) and a workspace (`PlantData`, `PlantDerivatives`) for one solve;
/// with a batch workspace ([`with_batch`](Self::with_batch)), a planar model's trajectories are
/// linearised SIMD across nodes.
#[derive(Debug)]
pub struct ReducedEuler<'a> {
    model: Plant<'a>,
    data: &'a mut PlantData,
    derivatives: &'a mut PlantDerivatives,
    batch: Option<&'a mut ReducedDerivativesBatch>,
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
            batch: None,
            step,
        })
    }

    /// The same map, whose trajectories [`linearise_trajectory`] linearises with
    /// `modal_reduce::reduced_derivatives_batch` (SIMD across nodes, each node the same bits as
    /// alone) when the model is planar, of at most [`MAX_BATCH_COORDS`] coordinates, and `work`
    /// was built for it; node by node otherwise.
    ///
    /// [`linearise_trajectory`]: DiscreteDynamics::linearise_trajectory
    pub fn with_batch(mut self, work: &'a mut ReducedDerivativesBatch) -> Self {
        self.batch = Some(work);
        self
    }
}

/// The nodes a batch of [`ReducedEuler::linearise_trajectory`] linearises at once: a SIMD
/// group of the widest instruction set.
const BATCH_NODES: usize = 8;

/// Checks an integration step of the discrete model (s).
pub(crate) fn check_step(step: f64) -> Result<(), OptimalError> {
    if (1e-9..=10.0).contains(&step) {
        Ok(())
    } else {
        Err(OptimalError::InvalidSetting {
            name: "step",
            requirement: "between 1e-9 s and 10 s",
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
        let state = a_next
            .iter_mut()
            .zip(v_next.iter_mut())
            .zip(a.iter().zip(v));
        for ((a_next, v_next), (&a, &v)) in state {
            *v_next = v + h * *v_next;
            *a_next = a + h * *v_next;
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
        assemble_any(m, (d.a_ddot(), d.jacobians()), euler);
        Ok(())
    }

    fn linearises_trajectories(&self) -> bool {
        matches!(self.model, Plant::Planar(_))
            && self.batch.is_some()
            && self.model.n_coords() <= MAX_BATCH_COORDS
            && self.model.batch_lanes() > 1
    }

    fn linearise_trajectory(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a_mat: &mut [f64],
        b_mat: &mut [f64],
    ) -> Result<(), OptimalError> {
        let batched = self.linearises_trajectories();
        let (Plant::Planar(model), Some(work), true) =
            (self.model, self.batch.as_deref_mut(), batched)
        else {
            return linearise_node_by_node(self, x, u, next, (a_mat, b_mat));
        };
        let (m, h) = (model.n_coords(), self.step);
        let (nx, nu) = (2 * m, m);
        check_trajectory((nx, nu), (x, u, next), (a_mat, b_mat))?;
        // Each group of nodes gathered into the batch's layout (`a`, `a_dot`, `tau*` state after
        // state) on the stack, its accelerations and Jacobians assembled node by node.
        let mut inputs = [[0.0; BATCH_NODES * MAX_BATCH_COORDS]; 3];
        let mut a_ddot = [0.0; BATCH_NODES * MAX_BATCH_COORDS];
        let mut jacobians = [0.0; BATCH_NODES * 3 * MAX_BATCH_COORDS * MAX_BATCH_COORDS];
        let groups = x
            .chunks(BATCH_NODES * nx)
            .zip(u.chunks(BATCH_NODES * nu))
            .zip(a_mat.chunks_mut(BATCH_NODES * nx * nx))
            .zip(b_mat.chunks_mut(BATCH_NODES * nx * nu));
        for (((x, u), a_mat), b_mat) in groups {
            let [a, a_dot, tau_star] = &mut inputs;
            // A last group of fewer nodes is filled up with its last node, so that every group
            // runs SIMD; the copies' results are not read.
            let (x_last, u_last) = (&x[x.len() - nx..], &u[u.len() - nu..]);
            for k in 0..BATCH_NODES {
                let state = x.get(k * nx..(k + 1) * nx).unwrap_or(x_last);
                let control = u.get(k * nu..(k + 1) * nu).unwrap_or(u_last);
                a[k * m..(k + 1) * m].copy_from_slice(&state[..m]);
                a_dot[k * m..(k + 1) * m].copy_from_slice(&state[m..]);
                tau_star[k * m..(k + 1) * m].copy_from_slice(control);
            }
            let values = BATCH_NODES * m;
            reduced_derivatives_batch(
                model,
                work,
                &a[..values],
                &a_dot[..values],
                &tau_star[..values],
                &mut a_ddot[..values],
                &mut jacobians[..values * 3 * m],
            )
            .map_err(modal_reduce::BatchError::into_reduce_error)?;
            let per_node = x
                .chunks_exact(nx)
                .zip(a_mat.chunks_exact_mut(nx * nx))
                .zip(b_mat.chunks_exact_mut(nx * nu))
                .enumerate();
            for (k, ((x, a_mat), b_mat)) in per_node {
                let derivatives = (
                    &a_ddot[k * m..(k + 1) * m],
                    &jacobians[k * 3 * m * m..(k + 1) * 3 * m * m],
                );
                assemble_any(m, derivatives, (h, x, next, a_mat, b_mat));
            }
        }
        Ok(())
    }
}

/// [`assemble`] for `m` coordinates: unrolled for the reduced model's `m = 2` and `3`.
#[inline(always)]
fn assemble_any(
    m: usize,
    derivatives: (&[f64], &[f64]),
    euler: (f64, &[f64], &mut [f64], &mut [f64], &mut [f64]),
) {
    match m {
        2 => assemble::<2>(derivatives, euler),
        3 => assemble::<3>(derivatives, euler),
        _ => assemble::<0>(derivatives, euler),
    }
}

/// The Euler map's next state and Jacobians `(A, B)` from the plant's accelerations and
/// Jacobians at `x` (row `i` of the latter `[F_a row i | F_v row i | F_u row i]`), as
/// `(h, x, next, A, B)`, for `m = M` known at compile time, or any `m` when `M` is 0.
#[inline(always)]
fn assemble<const M: usize>(
    (a_ddot, jacobians): (&[f64], &[f64]),
    (h, x, next, a_mat, b_mat): (f64, &[f64], &mut [f64], &mut [f64], &mut [f64]),
) {
    let m = if M == 0 { a_ddot.len() } else { M };
    let n = 2 * m;
    let (a, v) = (&x[..m], &x[m..n]);
    let (next, a_mat, b_mat) = (&mut next[..n], &mut a_mat[..n * n], &mut b_mat[..n * m]);
    let jacobians = &jacobians[..3 * m * m];
    let a_ddot = &a_ddot[..m];
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
