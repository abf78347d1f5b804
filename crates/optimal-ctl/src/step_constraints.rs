//! General linear constraints on the control of every step of [`Ilqr`](crate::Ilqr): the box
//! QP of control-limited iLQR grown into a QP with linear constraints ([`LinearQp`]).
//!
//! A step's constraints are rows `G u_k <= g` given at the step's state `x_k` (and the control
//! `u_k` and the Jacobian `B_k = dF/du` around which they may be linearised): the joint-torque
//! polytope at `x_k` (exactly affine in `u_k`), or a state constraint on the next state
//! linearised through `x_{k+1} ~ F(x_k, u_k) + B_k (u - u_k)` (joint limits, clearance).

use crate::OptimalError;
use crate::linear_qp::{LinearQp, LinearQpFailure};
use crate::polytope::{PolytopeProjection, ProjectionFailure};
use lane_math::dense::{cholesky, cholesky_solve};

/// The constraints `G u_k <= g` of every step of a constrained [`Ilqr`](crate::Ilqr) solve.
pub trait StepConstraints {
    /// The most rows a step may have.
    fn max_rows(&self) -> usize;

    /// Writes the rows of step `k` at state `x` (`n_x`), around control `u` (`n_u`) with
    /// `b = dF/du` there (`n_x x n_u`, row-major): `rows` (`r x n_u`, row-major) and `bounds`
    /// (`r`), and returns `r <= max_rows()`. Called along the nominal trajectory before every
    /// backward pass (and, with [`state_jacobian`](Self::state_jacobian), at `n_x` states a
    /// small step from each nominal state: the same rows in the same order), and at every state
    /// of a forward pass (with the nominal `b`); see also
    /// [`rows_of_state_and_control`](Self::rows_of_state_and_control).
    ///
    /// # Errors
    /// Whatever the model refuses at `x`.
    fn rows(
        &mut self,
        k: usize,
        x: &[f64],
        u: &[f64],
        b: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError>;

    /// Whether the feedback gain takes in the rows' state dependence: their state Jacobian
    /// `D = d(G u - g)/dx` ([`analytic_state_jacobian`](Self::analytic_state_jacobian), or by
    /// forward differences, `n_x` more calls of [`rows`](Self::rows) at each node of every
    /// iteration). Without it the gain keeps the active rows active only
    /// where their bounds do not move with the state, and where they do, a forward pass's
    /// projection undoes the feedback and the line search may find no decrease. `true`
    /// unless said otherwise, for rows too costly to evaluate `n_x + 1` times a node.
    fn state_jacobian(&self) -> bool {
        true
    }

    /// Writes the state Jacobian `D = d(G u - g)/dx` (`r x n_x`, row-major) of the `r` rows
    /// that [`rows`](Self::rows) last wrote, at the same `(k, x, u, b)`, in closed form and
    /// returns `true`; or returns `false`, writing nothing, for rows without one (the solve
    /// then takes forward differences). `false` unless said otherwise.
    ///
    /// # Errors
    /// Whatever the model refuses at `x`.
    fn analytic_state_jacobian(
        &mut self,
        _k: usize,
        _x: &[f64],
        _u: &[f64],
        _b: &[f64],
        _jacobian: &mut [f64],
    ) -> Result<bool, OptimalError> {
        Ok(false)
    }

    /// Whether a step's rows, and their [`analytic_state_jacobian`](Self::analytic_state_jacobian),
    /// are a function of `(k, x, u)` alone: not of `b`, nor of the calls before. The solve then
    /// keeps the rows each forward pass wrote at each node and, once the pass is accepted,
    /// takes them as the rows of the nodes whose control they did not move (the same `x` and
    /// `u`, to the bit) instead of evaluating them again. `false` unless said otherwise.
    fn rows_of_state_and_control(&self) -> bool {
        false
    }

    /// Whether the rows are moreover a function of `(k, x)` alone (not of `u`; their state
    /// Jacobian may depend on `u`): the solve then takes a forward pass's rows at a node whose
    /// control they moved, too. `false` unless said otherwise.
    fn rows_of_state(&self) -> bool {
        false
    }
}

/// Rows this far inside their bound count as active for the feedback gain (relative).
const ACTIVE: f64 = 1e-9;
/// The forward-difference step of the rows' state Jacobian (relative to `1 + |x_i|`).
const STATE_STEP: f64 = 1e-7;
/// A perturbed row whose coefficients differ from the nominal row's by more than this (relative
/// to its largest) is another row.
const SAME_ROW: f64 = 1e-3;

/// The per-step working memory of a constrained solve: the rows of every step along the
/// nominal trajectory, and the QP, projection and gain of one step. Allocation-free per use.
#[derive(Debug, Clone)]
pub(crate) struct ConstrainedWork {
    nx: usize,
    nu: usize,
    max_rows: usize,
    /// Per step: the rows (`max_rows x n_u`), bounds (`max_rows`) and their number.
    pub(crate) rows: Vec<f64>,
    pub(crate) bounds: Vec<f64>,
    pub(crate) counts: Vec<usize>,
    /// Per step: `D = d(G u - g)/dx` of each row at the nominal `(x, u)` (`max_rows x n_x`), in
    /// closed form or by forward differences; zero where a perturbed state gave another number
    /// of rows or another row in a row's place.
    state_jacobians: Vec<f64>,
    /// A perturbed state and its rows.
    perturbed: Vec<f64>,
    perturbed_rows: Vec<f64>,
    perturbed_bounds: Vec<f64>,
    /// Which of the QP's rows are active: the step row's index, or `None` for a box row.
    active_rows: Vec<Option<usize>>,
    /// One step's rows with the box appended (`max_rows + 2 n_u`), in the step `d` or in `u`.
    qp_rows: Vec<f64>,
    qp_bounds: Vec<f64>,
    qp: LinearQp,
    projection: PolytopeProjection,
    projected: Vec<f64>,
    /// Per step: the rows at the last forward pass's state (the nominal ones stay for the next
    /// backward pass), their number (`None` where the pass wrote none), the `(x, u)` they
    /// were evaluated at (`n_x + n_u`), and whether their projection found them and the box
    /// empty.
    forward_rows: Vec<f64>,
    forward_bounds: Vec<f64>,
    forward_counts: Vec<Option<usize>>,
    forward_at: Vec<f64>,
    forward_empty: Vec<bool>,
    /// Per step: whether the nominal rows admit no control within the box, where known (they
    /// are a forward pass's rows, whose projection found out).
    empty: Vec<Option<bool>>,
    /// The gain's linear algebra: `H`'s factor, `X = H^-1 Q_ux`, the active rows `A`,
    /// `Y = H^-1 A^T`, `S = A Y` and `A X`.
    factor: Vec<f64>,
    x_mat: Vec<f64>,
    active: Vec<f64>,
    y_mat: Vec<f64>,
    s_mat: Vec<f64>,
    ax: Vec<f64>,
    /// The solve's warm start: the plan's states it follows (`(N + 1) n_x`) and its controls
    /// (`N n_u`), for a second start without the rows.
    pub(crate) warm_states: Vec<f64>,
    pub(crate) warm_controls: Vec<f64>,
}

impl ConstrainedWork {
    pub(crate) fn new(nx: usize, nu: usize, horizon: usize, max_rows: usize) -> Self {
        let total = max_rows + 2 * nu;
        Self {
            nx,
            nu,
            max_rows,
            rows: vec![0.0; horizon * max_rows * nu],
            bounds: vec![0.0; horizon * max_rows],
            counts: vec![0; horizon],
            state_jacobians: vec![0.0; horizon * max_rows * nx],
            perturbed: vec![0.0; nx],
            perturbed_rows: vec![0.0; max_rows * nu],
            perturbed_bounds: vec![0.0; max_rows],
            active_rows: vec![None; nu],
            qp_rows: vec![0.0; total * nu],
            qp_bounds: vec![0.0; total],
            qp: LinearQp::new(nu, total),
            projection: PolytopeProjection::new(nu, total),
            projected: vec![0.0; nu],
            forward_rows: vec![0.0; horizon * max_rows * nu],
            forward_bounds: vec![0.0; horizon * max_rows],
            forward_counts: vec![None; horizon],
            forward_at: vec![0.0; horizon * (nx + nu)],
            forward_empty: vec![false; horizon],
            empty: vec![None; horizon],
            factor: vec![0.0; nu * nu],
            x_mat: vec![0.0; nu * nx],
            active: vec![0.0; nu * nu],
            y_mat: vec![0.0; nu * nu],
            s_mat: vec![0.0; nu * nu],
            ax: vec![0.0; nu * nx],
            warm_states: vec![0.0; (horizon + 1) * nx],
            warm_controls: vec![0.0; horizon * nu],
        }
    }

    /// The most rows a step may have.
    pub(crate) fn max_rows(&self) -> usize {
        self.max_rows
    }

    /// Evaluates the rows of step `k` at `(x, u)` with `b` into the step's storage, and their
    /// state Jacobian `D = d(G u - g)/dx` when the constraints ask for it (zero otherwise): in
    /// closed form where they have it, by forward differences (`n_x` more evaluations)
    /// otherwise. Rows of `(k, x, u)` alone
    /// ([`rows_of_state_and_control`](StepConstraints::rows_of_state_and_control)) that the
    /// last forward pass wrote at this `(x, u)` (at this `x`, for rows of `(k, x)` alone) are
    /// copied, not evaluated again.
    pub(crate) fn evaluate(
        &mut self,
        constraints: &mut dyn StepConstraints,
        k: usize,
        (x, u, b): (&[f64], &[f64], &[f64]),
    ) -> Result<(), OptimalError> {
        let (nx, nu, max) = (self.nx, self.nu, self.max_rows);
        let rows = &mut self.rows[k * max * nu..(k + 1) * max * nu];
        let bounds = &mut self.bounds[k * max..(k + 1) * max];
        let at = &self.forward_at[k * (nx + nu)..(k + 1) * (nx + nu)];
        let count = match self.forward_counts[k] {
            Some(count)
                if constraints.rows_of_state_and_control()
                    && same_bits(&at[..nx], x)
                    && (constraints.rows_of_state() || same_bits(&at[nx..], u)) =>
            {
                rows[..count * nu]
                    .copy_from_slice(&self.forward_rows[k * max * nu..(k * max + count) * nu]);
                bounds[..count].copy_from_slice(&self.forward_bounds[k * max..k * max + count]);
                self.empty[k] = Some(self.forward_empty[k]);
                count
            }
            _ => {
                self.empty[k] = None;
                constraints.rows(k, x, u, b, rows, bounds)?
            }
        };
        if count > max {
            return Err(OptimalError::Dimension {
                name: "step constraint rows",
                expected: max,
                found: count,
            });
        }
        self.counts[k] = count;
        let jacobian = &mut self.state_jacobians[k * max * nx..(k + 1) * max * nx];
        jacobian.fill(0.0);
        if !constraints.state_jacobian()
            || constraints.analytic_state_jacobian(k, x, u, b, &mut jacobian[..count * nx])?
        {
            return Ok(());
        }
        let residual = |rows: &[f64], bounds: &[f64], r: usize| -> f64 {
            let g: f64 = rows[r * nu..(r + 1) * nu]
                .iter()
                .zip(u)
                .map(|(g, u)| g * u)
                .sum();
            g - bounds[r]
        };
        for i in 0..nx {
            self.perturbed.copy_from_slice(x);
            let step = STATE_STEP * (1.0 + x[i].abs());
            self.perturbed[i] += step;
            let step = self.perturbed[i] - x[i];
            let perturbed_count = constraints.rows(
                k,
                &self.perturbed,
                u,
                b,
                &mut self.perturbed_rows,
                &mut self.perturbed_bounds,
            )?;
            if perturbed_count != count {
                jacobian.fill(0.0);
                return Ok(());
            }
            for r in 0..count {
                // A row that is not its nominal one (rows selected by rank, reordered by the
                // step) keeps `D = 0`.
                let (nominal, moved) = (
                    &rows[r * nu..(r + 1) * nu],
                    &self.perturbed_rows[r * nu..(r + 1) * nu],
                );
                let size = nominal.iter().fold(1.0f64, |s, g| s.max(g.abs()));
                if nominal
                    .iter()
                    .zip(moved)
                    .any(|(g, h)| (g - h).abs() > SAME_ROW * size)
                {
                    continue;
                }
                jacobian[r * nx + i] = (residual(&self.perturbed_rows, &self.perturbed_bounds, r)
                    - residual(rows, bounds, r))
                    / step;
            }
        }
        Ok(())
    }

    /// Copies step `k`'s rows (or `rows`/`bounds` given) and the box into the QP's rows, shifted
    /// to the step `d = u' - u` when `u` is given; returns the number of rows.
    fn assemble(
        &mut self,
        (rows, bounds): (&[f64], &[f64]),
        u: Option<&[f64]>,
        (lower, upper): (&[f64], &[f64]),
    ) -> usize {
        let nu = self.nu;
        let count = bounds.len();
        self.qp_rows[..count * nu].copy_from_slice(rows);
        for r in 0..count {
            let shift = u.map_or(0.0, |u| {
                rows[r * nu..(r + 1) * nu]
                    .iter()
                    .zip(u)
                    .map(|(g, u)| g * u)
                    .sum()
            });
            self.qp_bounds[r] = bounds[r] - shift;
        }
        let mut n = count;
        for j in 0..nu {
            let uj = u.map_or(0.0, |u| u[j]);
            for (sign, bound) in [(1.0, upper[j] - uj), (-1.0, uj - lower[j])] {
                if bound.is_finite() {
                    let row = &mut self.qp_rows[n * nu..(n + 1) * nu];
                    row.fill(0.0);
                    row[j] = sign;
                    self.qp_bounds[n] = bound;
                    n += 1;
                }
            }
        }
        n
    }

    /// The feed-forward step of step `k`: `ff = argmin 1/2 d^T H d + q^T d` subject to
    /// `G (u + d) <= g` and the box, and the gain `K = -X + H^-1 A^T (A H^-1 A^T)^-1 (A X - D)`,
    /// `X = H^-1 Q_ux`, that keeps the active rows `A` active to first order as the state moves
    /// (`A K = -D`, `D` their state Jacobian; zero when they leave no freedom): the box QP's
    /// "zero gain on the clamped controls", for any rows. `false` (and `ff`, `gain` unset) when
    /// the rows and the box admit no control: known without a QP for rows that a forward
    /// pass's projection found so (the same rows and box, translated by `u`) and for a row
    /// that no control within the box meets ([`row_outside_box`]).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn feedforward(
        &mut self,
        k: usize,
        (h, q, q_ux): (&[f64], &[f64], &[f64]),
        u: &[f64],
        bounds: (&[f64], &[f64]),
        ff: &mut [f64],
        gain: &mut [f64],
    ) -> Result<bool, OptimalError> {
        let (nx, nu, max) = (self.nx, self.nu, self.max_rows);
        let count = self.counts[k];
        let empty = self.empty[k].unwrap_or_else(|| {
            row_outside_box(
                &self.rows[k * max * nu..(k * max + count) * nu],
                &self.bounds[k * max..k * max + count],
                bounds,
            )
        });
        if empty {
            return Ok(false);
        }
        let rows = std::mem::take(&mut self.rows);
        let step_bounds = std::mem::take(&mut self.bounds);
        let n = self.assemble(
            (
                &rows[k * max * nu..(k * max + count) * nu],
                &step_bounds[k * max..k * max + count],
            ),
            Some(u),
            bounds,
        );
        self.rows = rows;
        self.bounds = step_bounds;
        match self
            .qp
            .solve(h, q, &self.qp_rows[..n * nu], &self.qp_bounds[..n], ff)
        {
            Ok(_) => {}
            Err(LinearQpFailure::NotPositiveDefinite) => {
                return Err(OptimalError::NotPositiveDefinite("Q_uu + mu I"));
            }
            Err(LinearQpFailure::Projection(_)) => return Ok(false),
        }
        // The active rows.
        let mut na = 0;
        for r in 0..n {
            let row = &self.qp_rows[r * nu..(r + 1) * nu];
            let gd: f64 = row.iter().zip(ff.iter()).map(|(g, d)| g * d).sum();
            let bound = self.qp_bounds[r];
            if gd >= bound - ACTIVE * (1.0 + bound.abs()) {
                if na == nu {
                    // More active rows than controls: a vertex, no feedback freedom.
                    gain.fill(0.0);
                    return Ok(true);
                }
                self.active[na * nu..(na + 1) * nu].copy_from_slice(row);
                self.active_rows[na] = (r < count).then_some(r);
                na += 1;
            }
        }
        self.factor.copy_from_slice(h);
        if !cholesky(&mut self.factor, nu) {
            return Err(OptimalError::NotPositiveDefinite("Q_uu + mu I"));
        }
        self.x_mat.copy_from_slice(q_ux);
        cholesky_solve(&self.factor, nu, &mut self.x_mat, nx);
        gain.copy_from_slice(&self.x_mat);
        if na > 0 {
            // Y = H^-1 A^T (nu x na), S = A Y, A X.
            for i in 0..nu {
                for a in 0..na {
                    self.y_mat[i * na + a] = self.active[a * nu + i];
                }
            }
            cholesky_solve(&self.factor, nu, &mut self.y_mat[..nu * na], na);
            for a in 0..na {
                for b in 0..na {
                    self.s_mat[a * na + b] = (0..nu)
                        .map(|i| self.active[a * nu + i] * self.y_mat[i * na + b])
                        .sum();
                }
                // `A X - D`: the active rows stay active as the state moves.
                let jacobian = self.active_rows[a]
                    .map(|r| &self.state_jacobians[(k * max + r) * nx..(k * max + r + 1) * nx]);
                for c in 0..nx {
                    let ax: f64 = (0..nu)
                        .map(|i| self.active[a * nu + i] * self.x_mat[i * nx + c])
                        .sum();
                    self.ax[a * nx + c] = ax - jacobian.map_or(0.0, |d| d[c]);
                }
            }
            if !cholesky(&mut self.s_mat[..na * na], na) {
                // Dependent active rows: keep the controls where the rows hold them.
                gain.fill(0.0);
                return Ok(true);
            }
            cholesky_solve(&self.s_mat[..na * na], na, &mut self.ax[..na * nx], nx);
            for i in 0..nu {
                for c in 0..nx {
                    let correction: f64 = (0..na)
                        .map(|a| self.y_mat[i * na + a] * self.ax[a * nx + c])
                        .sum();
                    gain[i * nx + c] -= correction;
                }
            }
        }
        for g in gain.iter_mut() {
            *g = -*g;
        }
        Ok(true)
    }

    /// Moves `u` (`n_u`) to the closest control within the rows of step `k` at the forward
    /// pass's state `x` (with the nominal `b`) and the box: whether it moved, or `None` (`u`
    /// kept) when no control is within (without a projection for a row that no control within
    /// the box meets, [`row_outside_box`]). The rows stay as step `k`'s of the pass.
    pub(crate) fn project(
        &mut self,
        constraints: &mut dyn StepConstraints,
        k: usize,
        (x, b): (&[f64], &[f64]),
        box_bounds: (&[f64], &[f64]),
        u: &mut [f64],
    ) -> Result<Option<bool>, OptimalError> {
        let (nx, nu, max) = (self.nx, self.nu, self.max_rows);
        self.forward_counts[k] = None;
        self.forward_empty[k] = false;
        let count = constraints.rows(
            k,
            x,
            u,
            b,
            &mut self.forward_rows[k * max * nu..(k + 1) * max * nu],
            &mut self.forward_bounds[k * max..(k + 1) * max],
        )?;
        if count > max {
            return Err(OptimalError::Dimension {
                name: "step constraint rows",
                expected: max,
                found: count,
            });
        }
        self.forward_counts[k] = Some(count);
        let at = &mut self.forward_at[k * (nx + nu)..(k + 1) * (nx + nu)];
        at[..nx].copy_from_slice(x);
        at[nx..].copy_from_slice(u);
        let (step_rows, step_bounds) = (
            &self.forward_rows[k * max * nu..(k * max + count) * nu],
            &self.forward_bounds[k * max..k * max + count],
        );
        if within(step_rows, step_bounds, box_bounds, u) {
            return Ok(Some(false));
        }
        if row_outside_box(step_rows, step_bounds, box_bounds) {
            self.forward_empty[k] = true;
            return Ok(None);
        }
        let rows = std::mem::take(&mut self.forward_rows);
        let bounds = std::mem::take(&mut self.forward_bounds);
        let n = self.assemble(
            (
                &rows[k * max * nu..(k * max + count) * nu],
                &bounds[k * max..k * max + count],
            ),
            None,
            box_bounds,
        );
        self.forward_rows = rows;
        self.forward_bounds = bounds;
        match self.projection.project(
            &self.qp_rows[..n * nu],
            &self.qp_bounds[..n],
            u,
            &mut self.projected,
        ) {
            Ok(moved) => {
                u.copy_from_slice(&self.projected);
                Ok(Some(moved))
            }
            Err(failure) => {
                self.forward_empty[k] = failure == ProjectionFailure::Empty;
                Ok(None)
            }
        }
    }
}

/// Rows this far (relative) beyond their bound at their least within the box prove the box
/// and the rows empty; nearer ones are left to the projection.
const OUTSIDE: f64 = 1e-9;

/// Whether one of the rows `G u <= g` (`n_u` columns) is broken by every control within the box
/// `(lower, upper)`: its least value over the box, `sum_i min(G_i lower_i, G_i upper_i)`,
/// exceeds its bound by more than [`OUTSIDE`] of its size, so that the rows and the box
/// admit no control. A row that an unbounded side of the box lets go to `-inf`, or a NaN,
/// proves nothing.
fn row_outside_box(rows: &[f64], bounds: &[f64], (lower, upper): (&[f64], &[f64])) -> bool {
    let nu = lower.len();
    rows.chunks_exact(nu.max(1))
        .zip(bounds)
        .any(|(row, &bound)| {
            let least: f64 = row
                .iter()
                .zip(lower.iter().zip(upper))
                .map(|(&g, (&l, &h))| {
                    if g > 0.0 {
                        g * l
                    } else if g < 0.0 {
                        g * h
                    } else {
                        0.0
                    }
                })
                .sum();
            least - bound > OUTSIDE * (1.0 + bound.abs() + least.abs())
        })
}

/// Whether `u` is within the rows `G u <= g` (`g_r - G_r u` accumulated as the projection
/// does) and the box: the projection would keep it.
fn within(rows: &[f64], bounds: &[f64], (lower, upper): (&[f64], &[f64]), u: &[f64]) -> bool {
    let in_box = u
        .iter()
        .zip(lower.iter().zip(upper))
        .all(|(u, (l, h))| l <= u && u <= h);
    in_box
        && rows
            .chunks_exact(u.len().max(1))
            .zip(bounds)
            .all(|(row, &bound)| {
                let mut gu = 0.0;
                for (g, u) in row.iter().zip(u) {
                    gu += g * u;
                }
                gu <= bound
            })
}

/// Whether `x` and `y` hold the same bits.
fn same_bits(x: &[f64], y: &[f64]) -> bool {
    x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]
        /// The shortcuts of `project` agree with the projection onto the rows and the box: a
        /// control `within` them is one the projection keeps, and rows with one
        /// `row_outside_box` are ones it finds empty.
        #[test]
        fn the_shortcuts_agree_with_the_projection(
            rows in proptest::collection::vec(-1.0f64..1.0, 6),
            bounds in proptest::collection::vec(-2.0f64..1.0, 3),
            u in proptest::collection::vec(-1.0f64..1.0, 2),
        ) {
            let (lower, upper) = ([-1.0, -1.0], [1.0, 1.0]);
            let mut all_rows = rows.clone();
            let mut all_bounds = bounds.clone();
            for j in 0..2 {
                for (sign, bound) in [(1.0, upper[j]), (-1.0, -lower[j])] {
                    let mut row = [0.0; 2];
                    row[j] = sign;
                    all_rows.extend_from_slice(&row);
                    all_bounds.push(bound);
                }
            }
            let mut projection = PolytopeProjection::new(2, all_bounds.len());
            let mut x = [0.0; 2];
            let projected = projection.project(&all_rows, &all_bounds, &u, &mut x);
            if within(&rows, &bounds, (&lower, &upper), &u) {
                prop_assert_eq!(projected, Ok(false));
            } else {
                prop_assert_ne!(projected, Ok(false));
            }
            if row_outside_box(&rows, &bounds, (&lower, &upper)) {
                prop_assert_eq!(projected, Err(ProjectionFailure::Empty));
            }
        }
    }
}
