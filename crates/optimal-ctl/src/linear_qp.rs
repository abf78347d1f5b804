//! Strictly convex quadratic programs with linear inequality constraints,
//! `min 1/2 x^T H x + q^T x` subject to `G x <= g`, by reduction to the closest point of a
//! polytope (least-distance programming, [`PolytopeProjection`]).
//!
//! With `H = L L^T` (Cholesky) and `w = L^-1 q`, the change of variables `y = L^T x + w` turns
//! the objective into `1/2 |y|^2` less a constant and the constraints into
//! `(G L^-T) y <= g + (G L^-T) w` (Lawson and Hanson 1974, chapter 23, the reduction of LSI to
//! LDP): the solution is the point of that polytope closest to the origin, and
//! `x = L^-T (y - w)`. `|w|^2 = q^T H^-1 q` grows with the inverse square root of `H`'s smallest
//! eigenvalue, the unconstrained minimiser `x_u = -H^-1 q` (`y = 0`) with its inverse: with a
//! nearly singular `H` (a tip Jacobian of lower rank than the coordinates, regularised by
//! `1e-9`) `x_u` reaches `1e7`, and the bounds `g - G x_u` of the form around it would lose the
//! constraints' digits.
//!
//! This is the general form of the box QP of control-limited DDP
//! ([`BoxQp`](crate::BoxQp)) that the joint-torque polytope and linearised clearances need.

use crate::polytope::{PolytopeProjection, ProjectionFailure};
use lane_math::dense::{back_substitute, cholesky, forward_substitute};

/// Why a [`LinearQp`] has no solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearQpFailure {
    /// `H` is not numerically positive definite.
    NotPositiveDefinite,
    /// The projection failed: the constraints admit no point, the iterations did not settle,
    /// or the sizes disagree.
    Projection(ProjectionFailure),
}

impl std::fmt::Display for LinearQpFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotPositiveDefinite => f.write_str("H is not numerically positive definite"),
            Self::Projection(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for LinearQpFailure {}

/// Working memory of [`solve`](Self::solve) for `m` unknowns and at most `rows` constraints.
#[derive(Debug, Clone)]
pub struct LinearQp {
    projection: PolytopeProjection,
    /// The Cholesky factor of `H` (`m x m`, lower triangle).
    factor: Vec<f64>,
    /// `w = L^-1 q`.
    scaled_q: Vec<f64>,
    /// `G L^-T`, row-major (`rows x m`), built column by column through `scratch`.
    reduced: Vec<f64>,
    /// `g + (G L^-T) w`.
    bounds: Vec<f64>,
    origin: Vec<f64>,
    y: Vec<f64>,
    scratch: Vec<f64>,
}

impl LinearQp {
    /// Working memory for `m` unknowns and at most `rows` constraints.
    pub fn new(m: usize, rows: usize) -> Self {
        Self {
            projection: PolytopeProjection::new(m, rows),
            factor: vec![0.0; m * m],
            scaled_q: vec![0.0; m],
            reduced: vec![0.0; rows * m],
            bounds: vec![0.0; rows],
            origin: vec![0.0; m],
            y: vec![0.0; m],
            scratch: vec![0.0; m],
        }
    }

    /// Writes into `x` the minimiser of `1/2 x^T H x + q^T x` subject to `G x <= g`: `H`
    /// symmetric positive definite (`m x m`, row-major; its lower triangle is read), `G`
    /// row-major with `m` columns and `g.len()` rows. Returns whether a constraint is active
    /// (the unconstrained minimiser is infeasible). Allocation-free.
    ///
    /// # Errors
    /// [`LinearQpFailure::NotPositiveDefinite`] for an `H` without a Cholesky factor, and the
    /// projection's failures (an empty polytope, sizes that disagree, a NaN in `q`, `G` or `g`:
    /// [`ProjectionFailure::NonFinite`]).
    pub fn solve(
        &mut self,
        h: &[f64],
        q: &[f64],
        constraints: &[f64],
        g: &[f64],
        x: &mut [f64],
    ) -> Result<bool, LinearQpFailure> {
        let m = self.scaled_q.len();
        let p = g.len();
        if h.len() != m * m
            || q.len() != m
            || x.len() != m
            || p > self.bounds.len()
            || constraints.len() != p * m
        {
            return Err(LinearQpFailure::Projection(ProjectionFailure::Dimension));
        }
        self.factor.copy_from_slice(h);
        if !cholesky(&mut self.factor, m) {
            return Err(LinearQpFailure::NotPositiveDefinite);
        }
        // w = L^-1 q.
        self.scaled_q.copy_from_slice(q);
        forward_substitute(&self.factor, m, &mut self.scaled_q, 1);
        // Row r of G L^-T is (L^-1 G_r^T)^T; its bound g_r + (G L^-T)_r w.
        for r in 0..p {
            let row = &constraints[r * m..(r + 1) * m];
            self.scratch.copy_from_slice(row);
            forward_substitute(&self.factor, m, &mut self.scratch, 1);
            self.reduced[r * m..(r + 1) * m].copy_from_slice(&self.scratch);
            let rw: f64 = self
                .scratch
                .iter()
                .zip(&self.scaled_q)
                .map(|(a, b)| a * b)
                .sum();
            self.bounds[r] = g[r] + rw;
        }
        let active = self
            .projection
            .project(
                &self.reduced[..p * m],
                &self.bounds[..p],
                &self.origin,
                &mut self.y,
            )
            .map_err(LinearQpFailure::Projection)?;
        // x = L^-T (v - w).
        for (y, w) in self.y.iter_mut().zip(&self.scaled_q) {
            *y -= w;
        }
        back_substitute(&self.factor, m, &mut self.y, 1);
        x.copy_from_slice(&self.y);
        Ok(active)
    }
}
