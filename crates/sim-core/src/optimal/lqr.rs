//! The discrete infinite-horizon linear-quadratic regulator by the Riccati recursion.

use manip_dyn::faer::MatRef;

use super::OptimalError;
use super::dense::{cholesky, cholesky_solve, multiply, multiply_transposed};
use super::linearise::Linearisation;

/// Iteration limit and tolerance of [`Lqr::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LqrSettings {
    /// The most Riccati iterations (at most 1e6).
    pub max_iterations: usize,
    /// Stop when the largest change of `P` is below this fraction of its largest entry.
    pub tolerance: f64,
}

impl Default for LqrSettings {
    fn default() -> Self {
        Self {
            max_iterations: 100_000,
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
/// `P` comes from iterating the Riccati difference equation from `P = Q` to a fixed point (value
/// iteration; it converges for a stabilisable pair and `Q, R` positive definite). Build it once
/// per model; [`solve`](Self::solve) allocates nothing.
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
}

impl Lqr {
    /// An LQR for `m` modal coordinates with state weight `q` (`2m x 2m`, row-major, symmetric
    /// positive semi-definite) and control weight `r` (`m x m`, symmetric positive definite).
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] for wrong sizes, [`OptimalError::InvalidSetting`] for a
    /// non-finite or asymmetric weight, [`OptimalError::NotPositiveDefinite`] if `r` is not.
    pub fn new(m: usize, q: &[f64], r: &[f64]) -> Result<Self, OptimalError> {
        let n = 2 * m;
        for (name, values, size) in [("Q", q, n), ("R", r, m)] {
            if values.len() != size * size {
                return Err(OptimalError::Dimension {
                    name,
                    expected: size * size,
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
        })
    }

    /// Solves the Riccati equation for the discrete pair of `linearisation`; the gain is then
    /// [`gain`](Self::gain). Returns the number of iterations.
    ///
    /// # Errors
    /// [`OptimalError::Dimension`] if the linearisation has another `m`,
    /// [`OptimalError::InvalidSetting`] for bad settings, [`OptimalError::NoConvergence`] if `P`
    /// has not settled within the iteration limit (or grew without bound),
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
        self.p.copy_from_slice(&self.q);
        let mut change = f64::INFINITY;
        for iteration in 1..=settings.max_iterations {
            self.riccati_step(a_d, b_d)?;
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
                return Ok(iteration);
            }
        }
        Err(OptimalError::NoConvergence {
            iterations: settings.max_iterations,
            change,
        })
    }

    /// `next = Q + A^T P A - A^T P B (R + B^T P B)^-1 B^T P A`, leaving `K` in `gain`.
    fn riccati_step(&mut self, a_d: &[f64], b_d: &[f64]) -> Result<(), OptimalError> {
        self.gain_at(a_d, b_d)?;
        let (m, n) = (self.m, 2 * self.m);
        // next = Q + A^T (P A) - (B^T P A)^T K.
        multiply_transposed(a_d, &self.pa, &mut self.next, n, n, n);
        multiply_transposed(&self.bpa, &self.gain, &mut self.pa, n, m, n);
        for ((next, q), correction) in self.next.iter_mut().zip(&self.q).zip(&self.pa) {
            *next += q - correction;
        }
        // Symmetrise against rounding drift.
        for i in 0..n {
            for j in i + 1..n {
                let mean = 0.5 * (self.next[i * n + j] + self.next[j * n + i]);
                self.next[i * n + j] = mean;
                self.next[j * n + i] = mean;
            }
        }
        Ok(())
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
