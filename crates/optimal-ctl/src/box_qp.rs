//! Box-constrained quadratic programs by projected Newton: the per-step subproblem of
//! control-limited DDP (Tassa, Mansard and Todorov 2014, section III and Algorithm 3).

use super::OptimalError;
use lane_math::dense::{cholesky, cholesky_solve};

/// Stopping rules of [`BoxQp::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxQpSettings {
    /// The most Newton iterations (at most 1e4).
    pub max_iterations: usize,
    /// Stop when the norm of the gradient on the free set is below this.
    pub gradient_tolerance: f64,
    /// Stop when an iteration lowers the objective by less than this fraction of it.
    pub relative_improvement: f64,
}

impl Default for BoxQpSettings {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            gradient_tolerance: 1e-10,
            relative_improvement: 1e-12,
        }
    }
}

impl BoxQpSettings {
    /// Checks every setting against its domain.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] naming the first setting out of its domain.
    pub fn validate(&self) -> Result<(), OptimalError> {
        if self.max_iterations == 0 || self.max_iterations > 10_000 {
            return Err(OptimalError::InvalidSetting {
                name: "box QP max_iterations",
                requirement: "between 1 and 1e4",
                value: self.max_iterations as f64,
            });
        }
        for (name, value) in [
            ("box QP gradient_tolerance", self.gradient_tolerance),
            ("box QP relative_improvement", self.relative_improvement),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(OptimalError::InvalidSetting {
                    name,
                    requirement: "non-negative and finite",
                    value,
                });
            }
        }
        Ok(())
    }
}

/// Armijo fraction of the projected line search: a step must realise this fraction of the
/// decrease its directional derivative predicts.
const ARMIJO: f64 = 0.1;
/// The line search shrinks the step by this factor.
const STEP_FACTOR: f64 = 0.6;
/// The line search gives up below this step.
const MIN_STEP: f64 = 1e-22;

/// The workspace of a box-constrained QP in `n` unknowns,
///
/// ```text
/// minimise  1/2 x^T H x + g^T x   subject to   lower <= x <= upper,
/// ```
///
/// `H` symmetric positive definite, solved by projected Newton (Bertsekas 1982, as in Tassa et
/// al. 2014): at each iterate the *clamped* set holds the coordinates at a bound whose gradient
/// pushes outwards; a Newton step on the remaining *free* coordinates (the clamped ones held) is
/// projected onto the box with an Armijo backtracking line search. The method identifies the
/// active set in a few iterations and then takes the exact Newton step. After a solve, the
/// Cholesky factor of `H` restricted to the free set of the solution is kept: DDP needs it for
/// the feedback gain ([`solve_free`](Self::solve_free)). Allocation-free after
/// [`new`](Self::new).
#[derive(Debug, Clone)]
pub struct BoxQp {
    n: usize,
    gradient: Vec<f64>,
    candidate: Vec<f64>,
    direction: Vec<f64>,
    free: Vec<bool>,
    /// The free set at the latest gradient, before it replaces `free`.
    next_free: Vec<bool>,
    /// Indices of the free coordinates (the first `n_free` entries).
    free_index: Vec<usize>,
    n_free: usize,
    /// The Cholesky factor of `H` on the free set, `n_free x n_free` row-major.
    factor: Vec<f64>,
    /// Right-hand sides on the free set.
    rhs: Vec<f64>,
}

/// What a [`BoxQp::solve`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxQpReport {
    /// Newton iterations taken.
    pub iterations: usize,
    /// Whether a stopping rule other than the iteration limit ended it.
    pub converged: bool,
    /// The objective `1/2 x^T H x + g^T x` at the solution.
    pub value: f64,
}

impl BoxQp {
    /// A workspace for `n` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            n,
            gradient: vec![0.0; n],
            candidate: vec![0.0; n],
            direction: vec![0.0; n],
            free: vec![true; n],
            next_free: vec![true; n],
            free_index: vec![0; n],
            n_free: 0,
            factor: vec![0.0; n * n],
            rhs: vec![0.0; n],
        }
    }

    /// The number of unknowns.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Solves the QP of `h` (`n x n`, row-major, symmetric positive definite), `g`, `lower` and
    /// `upper` (`n` each, `lower <= upper`, infinite bounds allowed), starting from `x` (the warm
    /// start, projected onto the box) and leaving the solution in `x`.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong sizes, [`OptimalError::InvalidSetting`] for bad
    /// settings, a number of `g` that is not finite, NaN bounds or `lower > upper`,
    /// [`OptimalError::NotPositiveDefinite`] if `H` on a free set is not (numerically) positive
    /// definite.
    pub fn solve(
        &mut self,
        h: &[f64],
        g: &[f64],
        lower: &[f64],
        upper: &[f64],
        x: &mut [f64],
        settings: &BoxQpSettings,
    ) -> Result<BoxQpReport, OptimalError> {
        match self.n {
            2 => self.solve_sized::<2>(h, g, lower, upper, x, settings),
            3 => self.solve_sized::<3>(h, g, lower, upper, x, settings),
            _ => self.solve_sized::<0>(h, g, lower, upper, x, settings),
        }
    }

    /// [`solve`](Self::solve) for `n = N` known at compile time (iLQR's reduced models have
    /// `m = 2` or 3 controls), or any `n` when `N` is 0: the same operations in the same order.
    #[inline(always)]
    fn solve_sized<const N: usize>(
        &mut self,
        h: &[f64],
        g: &[f64],
        lower: &[f64],
        upper: &[f64],
        x: &mut [f64],
        settings: &BoxQpSettings,
    ) -> Result<BoxQpReport, OptimalError> {
        let n = if N == 0 { self.n } else { N };
        for (name, got, expected) in [
            ("H", h.len(), n * n),
            ("g", g.len(), n),
            ("lower", lower.len(), n),
            ("upper", upper.len(), n),
            ("x", x.len(), n),
        ] {
            if got != expected {
                return Err(OptimalError::Dimension {
                    name,
                    expected,
                    found: got,
                });
            }
        }
        settings.validate()?;
        let (h, g, lower, upper, x) = (&h[..n * n], &g[..n], &lower[..n], &upper[..n], &mut x[..n]);
        // A NaN or infinite `H` fails its factorisation; a NaN `g` would pass as a value.
        if let Some(&value) = g.iter().find(|v| !v.is_finite()) {
            return Err(OptimalError::InvalidSetting {
                name: "box QP gradient g",
                requirement: "finite",
                value,
            });
        }
        for i in 0..n {
            if lower[i].is_nan() || upper[i].is_nan() || lower[i] > upper[i] {
                return Err(OptimalError::InvalidSetting {
                    name: "box QP bounds",
                    requirement: "ordered (lower <= upper) and not NaN",
                    value: lower[i] - upper[i],
                });
            }
            x[i] = if x[i].is_finite() { x[i] } else { 0.0 }.clamp(lower[i], upper[i]);
        }
        let mut value = objective(h, g, x, n);
        let mut old_value = f64::INFINITY;
        let mut converged = false;
        let mut iterations = 0;
        let mut factored = false;
        while iterations < settings.max_iterations {
            if iterations > 0
                && old_value - value <= settings.relative_improvement * value.abs().max(1e-300)
            {
                converged = true;
                break;
            }
            iterations += 1;
            old_value = value;
            self.clamp_set(n, h, g, (lower, upper), x);
            let changed = self.update_free_set();
            if self.n_free == 0 {
                converged = true;
                break;
            }
            if changed || !factored {
                self.factor_free(h)?;
                factored = true;
            }
            let free_norm = (0..self.n_free)
                .map(|f| self.gradient[self.free_index[f]].powi(2))
                .sum::<f64>()
                .sqrt();
            if free_norm <= settings.gradient_tolerance {
                converged = true;
                break;
            }
            // Newton step on the free set with the clamped coordinates held:
            // x_f <- -H_ff^-1 (g_f + H_fc x_c).
            for f in 0..self.n_free {
                let i = self.free_index[f];
                let mut s = g[i];
                for j in 0..n {
                    if !self.free[j] {
                        s += h[i * n + j] * x[j];
                    }
                }
                self.rhs[f] = -s;
            }
            cholesky_solve(&self.factor, self.n_free, &mut self.rhs[..self.n_free], 1);
            let direction = &mut self.direction[..n];
            direction.fill(0.0);
            for f in 0..self.n_free {
                let i = self.free_index[f];
                direction[i] = self.rhs[f] - x[i];
            }
            let slope: f64 = direction
                .iter()
                .zip(&self.gradient[..n])
                .map(|(d, g)| d * g)
                .sum();
            if slope >= 0.0 {
                // No descent left (rounding): the free-set Newton point is the minimiser.
                converged = true;
                break;
            }
            // Projected Armijo backtracking.
            let mut step = 1.0;
            let (candidate, direction) = (&mut self.candidate[..n], &self.direction[..n]);
            loop {
                for i in 0..n {
                    candidate[i] = (x[i] + step * direction[i]).clamp(lower[i], upper[i]);
                }
                let candidate_value = objective(h, g, candidate, n);
                if (candidate_value - value) / (step * slope) >= ARMIJO {
                    x.copy_from_slice(candidate);
                    value = candidate_value;
                    break;
                }
                step *= STEP_FACTOR;
                if step < MIN_STEP {
                    break;
                }
            }
            if step < MIN_STEP {
                converged = true;
                break;
            }
        }
        // The factor must match the free set of the returned point.
        self.clamp_set(n, h, g, (lower, upper), x);
        if self.update_free_set() || !factored {
            self.factor_free(h)?;
        }
        Ok(BoxQpReport {
            iterations,
            converged,
            value,
        })
    }

    /// The gradient `g + H x` and the free set at `x` (`n` unknowns), into `gradient` and
    /// `next_free`.
    #[inline(always)]
    fn clamp_set(
        &mut self,
        n: usize,
        h: &[f64],
        g: &[f64],
        (lower, upper): (&[f64], &[f64]),
        x: &[f64],
    ) {
        let (h, g, lower, upper, x) = (&h[..n * n], &g[..n], &lower[..n], &upper[..n], &x[..n]);
        for i in 0..n {
            let mut s = g[i];
            for j in 0..n {
                s += h[i * n + j] * x[j];
            }
            self.gradient[i] = s;
            let clamped = (x[i] <= lower[i] && s > 0.0) || (x[i] >= upper[i] && s < 0.0);
            self.next_free[i] = !clamped;
        }
    }

    /// Moves the set computed by [`clamp_set`](Self::clamp_set) into `free`/`free_index`;
    /// whether it changed.
    fn update_free_set(&mut self) -> bool {
        let mut changed = false;
        self.n_free = 0;
        for i in 0..self.n {
            let free = self.next_free[i];
            changed |= free != self.free[i];
            self.free[i] = free;
            if free {
                self.free_index[self.n_free] = i;
                self.n_free += 1;
            }
        }
        changed
    }

    /// Cholesky factor of `H` on the free set.
    fn factor_free(&mut self, h: &[f64]) -> Result<(), OptimalError> {
        let (n, k) = (self.n, self.n_free);
        for a in 0..k {
            for b in 0..k {
                self.factor[a * k + b] = h[self.free_index[a] * n + self.free_index[b]];
            }
        }
        if cholesky(&mut self.factor[..k * k], k) {
            Ok(())
        } else {
            Err(OptimalError::NotPositiveDefinite("the box QP's Hessian"))
        }
    }

    /// Which coordinates are free (not clamped at a bound) at the last solution.
    pub fn free(&self) -> &[bool] {
        &self.free
    }

    /// Overwrites the `n x c` row-major right-hand sides `rhs` with `H_ff^-1 rhs_f` on the free
    /// rows of the last solution and zero on the clamped rows: the feedback gain of
    /// control-limited DDP, `K_f = -Q_uu,ff^-1 Q_ux,f`, `K_c = 0` (Tassa et al. 2014, eq 7),
    /// is `-` this applied to `Q_ux`.
    ///
    /// # Panics
    /// If `rhs` has fewer than `n x c` entries, like slice indexing.
    pub fn solve_free(&mut self, rhs: &mut [f64], c: usize) {
        let k = self.n_free;
        for col in 0..c {
            for f in 0..k {
                self.rhs[f] = rhs[self.free_index[f] * c + col];
            }
            cholesky_solve(&self.factor[..k * k], k, &mut self.rhs[..k], 1);
            for i in 0..self.n {
                rhs[i * c + col] = 0.0;
            }
            for f in 0..k {
                rhs[self.free_index[f] * c + col] = self.rhs[f];
            }
        }
    }
}

/// `1/2 x^T H x + g^T x`.
#[inline(always)]
fn objective(h: &[f64], g: &[f64], x: &[f64], n: usize) -> f64 {
    let mut value = 0.0;
    for i in 0..n {
        let mut hx = 0.0;
        for j in 0..n {
            hx += h[i * n + j] * x[j];
        }
        value += x[i] * (0.5 * hx + g[i]);
    }
    value
}
