//! The discrete infinite-horizon linear-quadratic regulator, its Riccati equation solved by the
//! structure-preserving doubling algorithm.

use faer::MatRef;

use super::OptimalError;
use super::linearise::Linearisation;
use lane_math::dense::{
    cholesky, cholesky_solve, lu_solve, multiply, multiply_by_transposed, multiply_transposed,
    symmetrise,
};

/// Iteration limit and tolerance of [`Lqr::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LqrSettings {
    /// The most doubling steps (at most 1e6); step `k` reaches the Riccati recursion's value
    /// after `2^k` steps, so a few tens always suffice.
    pub max_iterations: usize,
    /// Stop when the largest change of `P` is below this fraction of its largest entry.
    pub tolerance: f64,
}

impl Default for LqrSettings {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            tolerance: 1e-12,
        }
    }
}

/// The discrete LQR: for `x_{k+1} = A_d x_k + B_d u_k` and the cost
/// `sum_k x_k^T Q x_k + u_k^T R u_k`, the stabilising solution `P` of the discrete algebraic
/// Riccati equation
///
/// ```text
/// P = Q + A^T P A - A^T P B (R + B^T P B)^-1 B^T P A
/// ```
///
/// and the gain `K = (R + B^T P B)^-1 B^T P A`, so that `u = -K x` minimises the cost. About a
/// reference `(x_ref, u_ref)` at which the linearisation was taken, `u = u_ref - K (x - x_ref)`.
///
/// `P` comes from the structure-preserving doubling algorithm (Chu, Fan, Lin and Wang,
/// "Structure-preserving algorithms for periodic discrete-time algebraic Riccati equations",
/// Int. J. Control 77, 2004): with `G = B R^-1 B^T`, from `A_0 = A`, `G_0 = G`, `H_0 = Q`,
///
/// ```text
/// W_k = I + G_k H_k,   A_{k+1} = A_k W_k^-1 A_k,
/// G_{k+1} = G_k + A_k W_k^-1 G_k A_k^T,   H_{k+1} = H_k + A_k^T H_k W_k^-1 A_k,
/// ```
///
/// `H_k` is the Riccati recursion's value after `2^k` steps from `P = 0`, so it converges to the
/// stabilising `P` quadratically (for a stabilisable, detectable pair and `R` positive definite)
/// where the recursion itself converges only linearly, at the rate of the closed loop's
/// spectral radius squared: for a lightly damped arm, thousands of recursion steps against
/// about a dozen doublings. Build it once per model; [`solve`](Self::solve) allocates nothing.
#[derive(Debug, Clone)]
pub struct Lqr {
    m: usize,
    /// `2m x 2m`: `Q`, `P`, and scratch.
    q: Vec<f64>,
    p: Vec<f64>,
    next: Vec<f64>,
    /// `m x m`: `R`, then `R + B^T P B` and its Cholesky factor.
    r: Vec<f64>,
    s: Vec<f64>,
    /// `2m x m`: `P B`; `m x 2m`: `B^T P A` and `K`; `2m x 2m`: `P A`.
    pb: Vec<f64>,
    bpa: Vec<f64>,
    gain: Vec<f64>,
    pa: Vec<f64>,
    /// The Cholesky factor of `R`.
    r_factor: Vec<f64>,
    /// The doubling's `2m x 2m` matrices: `A_k`, `G_k`, `W_k`, `W_k^-1 A_k`, `W_k^-1 G_k`; and
    /// `[A_k | G_k]` solved in place (`2m x 4m`).
    a_k: Vec<f64>,
    g_k: Vec<f64>,
    w: Vec<f64>,
    wa: Vec<f64>,
    wg: Vec<f64>,
    stacked: Vec<f64>,
}

impl Lqr {
    /// An LQR for `m` modal coordinates with state weight `q` (`2m x 2m`, row-major, symmetric
    /// positive semi-definite) and control weight `r` (`m x m`, symmetric positive definite).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong sizes, [`OptimalError::InvalidSetting`] for a
    /// non-finite or asymmetric weight, [`OptimalError::NotPositiveDefinite`] if `r` is not.
    pub fn new(m: usize, q: &[f64], r: &[f64]) -> Result<Self, OptimalError> {
        // `2m` and `(2m)^2` are counts of `Q`'s entries: a count that overflows is no size `q`
        // can have.
        let n = m.saturating_mul(2);
        for (name, values, size) in [("Q", q, n), ("R", r, m)] {
            let expected = size.saturating_mul(size);
            if values.len() != expected || expected == usize::MAX {
                return Err(OptimalError::Dimension {
                    name,
                    expected,
                    found: values.len(),
                });
            }
            for i in 0..size {
                for j in 0..size {
                    let (x, y) = (values[i * size + j], values[j * size + i]);
                    if !x.is_finite() || (x - y).abs() > 1e-12 * x.abs().max(y.abs()) {
                        return Err(OptimalError::InvalidSetting {
                            name,
                            requirement: "finite and symmetric",
                            value: x,
                        });
                    }
                }
            }
        }
        let mut factor = r.to_vec();
        if !cholesky(&mut factor, m) {
            return Err(OptimalError::NotPositiveDefinite("R"));
        }
        Ok(Self {
            m,
            q: q.to_vec(),
            p: vec![0.0; n * n],
            next: vec![0.0; n * n],
            r: r.to_vec(),
            s: vec![0.0; m * m],
            pb: vec![0.0; n * m],
            bpa: vec![0.0; m * n],
            gain: vec![0.0; m * n],
            pa: vec![0.0; n * n],
            r_factor: factor,
            a_k: vec![0.0; n * n],
            g_k: vec![0.0; n * n],
            w: vec![0.0; n * n],
            wa: vec![0.0; n * n],
            wg: vec![0.0; n * n],
            stacked: vec![0.0; 2 * n * n],
        })
    }

    /// Solves the Riccati equation for the discrete pair of `linearisation`; the gain is then
    /// [`gain`](Self::gain). Returns the number of doubling steps.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] if the linearisation has another `m`,
    /// [`OptimalError::InvalidSetting`] for bad settings, [`OptimalError::NoConvergence`] if `P`
    /// has not settled within the step limit (or grew without bound, or `W_k` was singular),
    /// [`OptimalError::NotPositiveDefinite`] if `R + B^T P B` is not.
    pub fn solve(
        &mut self,
        linearisation: &Linearisation,
        settings: &LqrSettings,
    ) -> Result<usize, OptimalError> {
        if linearisation.n_coords() != self.m {
            return Err(OptimalError::Dimension {
                name: "linearisation coordinates",
                expected: self.m,
                found: linearisation.n_coords(),
            });
        }
        if !(settings.tolerance.is_finite() && settings.tolerance > 0.0) {
            return Err(OptimalError::InvalidSetting {
                name: "tolerance",
                requirement: "positive and finite",
                value: settings.tolerance,
            });
        }
        if settings.max_iterations == 0 || settings.max_iterations > 1_000_000 {
            return Err(OptimalError::InvalidSetting {
                name: "max_iterations",
                requirement: "between 1 and 1e6",
                value: settings.max_iterations as f64,
            });
        }
        let (a_d, b_d) = linearisation.discrete();
        let (m, n) = (self.m, 2 * self.m);
        // G = B R^-1 B^T, through R^-1 B^T (m x 2m, in `bpa`).
        for i in 0..m {
            for j in 0..n {
                self.bpa[i * n + j] = b_d[j * m + i];
            }
        }
        cholesky_solve(&self.r_factor, m, &mut self.bpa, n);
        multiply(b_d, &self.bpa, &mut self.g_k, n, m, n);
        self.a_k.copy_from_slice(a_d);
        self.p.copy_from_slice(&self.q);
        let mut change = f64::INFINITY;
        for step in 1..=settings.max_iterations {
            if !self.double() {
                break;
            }
            let scale = self.next.iter().fold(0.0f64, |acc, x| acc.max(x.abs()));
            change = self
                .next
                .iter()
                .zip(&self.p)
                .fold(0.0f64, |acc, (x, y)| acc.max((x - y).abs()))
                / scale.max(f64::MIN_POSITIVE);
            std::mem::swap(&mut self.p, &mut self.next);
            if !change.is_finite() || !scale.is_finite() {
                break;
            }
            if change <= settings.tolerance {
                self.gain_at(a_d, b_d)?;
                return Ok(step);
            }
        }
        Err(OptimalError::NoConvergence {
            iterations: settings.max_iterations,
            change,
        })
    }

    /// One doubling step: `H_{k+1}` (from `H_k = P`) into `next`, `A_{k+1}` and `G_{k+1}` in
    /// place; `false` if `W_k` is singular.
    fn double(&mut self) -> bool {
        let n = 2 * self.m;
        // W = I + G H.
        multiply(&self.g_k, &self.p, &mut self.w, n, n, n);
        for i in 0..n {
            self.w[i * n + i] += 1.0;
        }
        // [W^-1 A | W^-1 G].
        for i in 0..n {
            let row = &mut self.stacked[2 * i * n..2 * (i + 1) * n];
            row[..n].copy_from_slice(&self.a_k[i * n..(i + 1) * n]);
            row[n..].copy_from_slice(&self.g_k[i * n..(i + 1) * n]);
        }
        if !lu_solve(&mut self.w, n, &mut self.stacked, 2 * n) {
            return false;
        }
        for i in 0..n {
            let row = &self.stacked[2 * i * n..2 * (i + 1) * n];
            self.wa[i * n..(i + 1) * n].copy_from_slice(&row[..n]);
            self.wg[i * n..(i + 1) * n].copy_from_slice(&row[n..]);
        }
        // H_{k+1} = H + A^T (H W^-1 A).
        multiply(&self.p, &self.wa, &mut self.pa, n, n, n);
        multiply_transposed(&self.a_k, &self.pa, &mut self.next, n, n, n);
        for (next, p) in self.next.iter_mut().zip(&self.p) {
            *next += p;
        }
        // G_{k+1} = G + (A W^-1 G) A^T.
        multiply(&self.a_k, &self.wg, &mut self.pa, n, n, n);
        multiply_by_transposed(&self.pa, &self.a_k, &mut self.w, n, n, n);
        for (g, w) in self.g_k.iter_mut().zip(&self.w) {
            *g += w;
        }
        // A_{k+1} = A W^-1 A.
        multiply(&self.a_k, &self.wa, &mut self.pa, n, n, n);
        self.a_k.copy_from_slice(&self.pa);
        // Symmetrise against rounding drift.
        symmetrise(&mut self.next, n);
        symmetrise(&mut self.g_k, n);
        true
    }

    /// `K = (R + B^T P B)^-1 B^T P A` at the current `P`; leaves `P A` and `B^T P A` in scratch.
    fn gain_at(&mut self, a_d: &[f64], b_d: &[f64]) -> Result<(), OptimalError> {
        let (m, n) = (self.m, 2 * self.m);
        multiply(&self.p, b_d, &mut self.pb, n, n, m);
        multiply(&self.p, a_d, &mut self.pa, n, n, n);
        multiply_transposed(b_d, &self.pb, &mut self.s, m, n, m);
        for (s, r) in self.s.iter_mut().zip(&self.r) {
            *s += r;
        }
        multiply_transposed(b_d, &self.pa, &mut self.bpa, m, n, n);
        self.gain.copy_from_slice(&self.bpa);
        if !cholesky(&mut self.s, m) {
            return Err(OptimalError::NotPositiveDefinite("R + B^T P B"));
        }
        cholesky_solve(&self.s, m, &mut self.gain, n);
        Ok(())
    }

    /// The gain `K` (`m x 2m`) of the last [`solve`](Self::solve): `u = u_ref - K (x - x_ref)`.
    pub fn gain(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.gain, self.m, 2 * self.m)
    }

    /// The Riccati solution `P` (`2m x 2m`) of the last [`solve`](Self::solve).
    pub fn cost_to_go(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.p, 2 * self.m, 2 * self.m)
    }

    /// `u = u_ref - K (x - x_ref)` into `u` (sizes `m`, `2m`, `2m`, `m`; checked by the caller's
    /// slices: a mismatch is a [`OptimalError::Dimension`]).
    pub fn control(
        &self,
        u_ref: &[f64],
        x: &[f64],
        x_ref: &[f64],
        u: &mut [f64],
    ) -> Result<(), OptimalError> {
        let (m, n) = (self.m, 2 * self.m);
        for (name, found, expected) in [
            ("u_ref", u_ref.len(), m),
            ("x", x.len(), n),
            ("x_ref", x_ref.len(), n),
            ("u", u.len(), m),
        ] {
            if found != expected {
                return Err(OptimalError::Dimension {
                    name,
                    expected,
                    found,
                });
            }
        }
        for (i, out) in u.iter_mut().enumerate() {
            let feedback: f64 = (0..n)
                .map(|j| self.gain[i * n + j] * (x[j] - x_ref[j]))
                .sum();
            *out = u_ref[i] - feedback;
        }
        Ok(())
    }
}
