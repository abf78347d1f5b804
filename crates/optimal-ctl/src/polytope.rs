//! The closest point of a polytope `{x : G x <= g}` of `R^m`: least-distance programming solved
//! by non-negative least squares (Lawson and Hanson, *Solving Least Squares Problems*, 1974,
//! chapters 23 and 24).
//!
//! With `y = x - x0` the problem is `min |y|` subject to `-G y >= G x0 - g`, an LDP of `m`
//! unknowns. Its dual is the NNLS problem `min |E u - f|`, `u >= 0`, with
//! `E = [-G^T; (G x0 - g)^T]` (`m + 1` rows, one column per constraint) and `f = e_{m+1}`: the
//! residual `r = E u - f` gives `y = -r_{1..m} / r_{m+1}`, and a zero residual proves the polytope
//! empty. NNLS is the finite active-set method: a constraint enters the passive set while its
//! dual gradient is positive, and a step that would make a passive variable negative stops at
//! zero and returns it.
//!
//! Each constraint's row is scaled by a power of two to a norm in `(1/2, 1]` (exact: the same
//! half-space), since rows of very different norms make the dual badly conditioned, and each
//! dual gradient and multiplier is compared with `1e-12` times its own column's largest entry.
//! The point from NNLS's residual is then polished: recomputed as the shortest solution of its
//! active constraints held as equalities (`polish`), the same point with the constraints'
//! digits, which the residual's formula loses when large multipliers of nearly opposite rows
//! cancel. It is checked against the constraints before it is returned, to the rounding of its
//! terms: a polytope empty by more than that is reported empty, never left with a point
//! outside.

/// Why no point was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProjectionFailure {
    /// The constraints admit no point.
    Empty,
    /// The active-set iterations did not settle within their bound (rounding near a degenerate
    /// vertex).
    NoConvergence,
    /// The sizes disagree: `G` is not `g.len() x m`, `x0` or `x` not `m` long, or more rows than
    /// the working memory was made for.
    Dimension,
    /// A number of `G`, `g` or `x0` is NaN, or one of `G` or `x0` is infinite (an infinite
    /// bound `g_i` is a row that never binds).
    NonFinite,
}

impl std::fmt::Display for ProjectionFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Empty => "the constraints admit no point",
            Self::NoConvergence => "the active-set iterations did not converge",
            Self::Dimension => "the constraint matrix, bounds and points disagree in size",
            Self::NonFinite => {
                "a constraint row or the point holds a number that is not finite, or a bound is NaN"
            }
        })
    }
}

impl std::error::Error for ProjectionFailure {}

/// Working memory of the projection for `m` unknowns and up to `rows` constraints.
/// [`project`](Self::project) allocates nothing.
#[derive(Debug, Clone)]
pub struct PolytopeProjection {
    m: usize,
    rows: usize,
    /// `E`, column-major, `(m + 1) x rows`.
    e: Vec<f64>,
    u: Vec<f64>,
    z: Vec<f64>,
    passive: Vec<bool>,
    /// The passive columns, in order: the first `n_passive` (room for every column, so that a
    /// clone too never grows it).
    order: Vec<usize>,
    n_passive: usize,
    /// The least-squares subproblem: matrix `(m + 1) x k`, right-hand side, solution.
    qr: Vec<f64>,
    rhs: Vec<f64>,
    residual: Vec<f64>,
    /// Each column's tolerance: `1e-12` times its largest entry (at least 1).
    tolerances: Vec<f64>,
}

impl PolytopeProjection {
    /// The number of unknowns `m`.
    pub fn n_unknowns(&self) -> usize {
        self.m
    }

    /// The most constraints [`project`](Self::project) accepts.
    pub fn max_rows(&self) -> usize {
        self.rows
    }

    /// Working memory for `m` unknowns and at most `rows` constraints.
    pub fn new(m: usize, rows: usize) -> Self {
        let height = m + 1;
        Self {
            m,
            rows,
            e: vec![0.0; height * rows],
            u: vec![0.0; rows],
            z: vec![0.0; rows],
            passive: vec![false; rows],
            order: vec![0; rows],
            n_passive: 0,
            qr: vec![0.0; height * height],
            rhs: vec![0.0; height],
            residual: vec![0.0; height],
            tolerances: vec![0.0; rows],
        }
    }

    /// Writes into `x` the point of `{x : G x <= g}` closest to `x0`; `G` is row-major with `m`
    /// columns and `g.len()` rows (at most the `rows` of [`new`](Self::new)). Returns whether
    /// `x0` had to move. Allocation-free.
    ///
    /// # Errors
    /// [`ProjectionFailure::Empty`] when no point satisfies the constraints,
    /// [`ProjectionFailure::NoConvergence`] when the iterations do not settle,
    /// [`ProjectionFailure::Dimension`] when the sizes disagree, [`ProjectionFailure::NonFinite`]
    /// for a NaN anywhere or an infinite row entry or `x0` (no polytope to call empty).
    pub fn project(
        &mut self,
        constraints: &[f64],
        g: &[f64],
        x0: &[f64],
        x: &mut [f64],
    ) -> Result<bool, ProjectionFailure> {
        let (m, p) = (self.m, g.len());
        if p > self.rows || constraints.len() != p * m || x0.len() != m || x.len() != m {
            return Err(ProjectionFailure::Dimension);
        }
        let finite = constraints.iter().chain(x0).all(|v| v.is_finite());
        if !finite || g.iter().any(|v| v.is_nan()) {
            return Err(ProjectionFailure::NonFinite);
        }
        let height = m + 1;
        let mut violated = false;
        for (i, (column, &bound)) in self.e.chunks_exact_mut(height).zip(g).enumerate() {
            let row = &constraints[i * m..(i + 1) * m];
            let mut gx = 0.0;
            for ((e, &r), &x) in column.iter_mut().zip(row).zip(x0) {
                *e = -r;
                gx += r * x;
            }
            column[m] = gx - bound;
            violated |= gx > bound;
            // The row scaled to a norm in (1/2, 1] by a power of two (exact, the same
            // half-space): rows of very different norms make the dual badly conditioned.
            let norm2: f64 = column[..m].iter().map(|e| e * e).sum();
            if norm2 > 0.0 && norm2.is_finite() {
                let scale = power_of_two_at_most(norm2.sqrt().recip());
                for e in column.iter_mut() {
                    *e *= scale;
                }
            }
        }
        x.copy_from_slice(x0);
        if !violated {
            return Ok(false);
        }
        self.nnls(p)?;
        // r = E u - f.
        self.residual.fill(0.0);
        self.residual[m] = -1.0;
        for i in 0..p {
            if self.u[i] != 0.0 {
                let column = &self.e[i * height..(i + 1) * height];
                for (r, c) in self.residual.iter_mut().zip(column) {
                    *r += c * self.u[i];
                }
            }
        }
        let norm = self.residual.iter().map(|r| r * r).sum::<f64>().sqrt();
        if norm <= 1e-12 {
            return Err(ProjectionFailure::Empty);
        }
        let last = self.residual[m];
        for k in 0..m {
            x[k] = x0[k] - self.residual[k] / last;
        }
        self.polish(x0, x);
        // Constraints that (nearly) admit no point leave a residual above the test's rounding
        // and a point far outside them: refused as empty, never returned.
        if !satisfies(constraints, g, x) {
            return Err(ProjectionFailure::Empty);
        }
        Ok(true)
    }

    /// Lawson and Hanson's NNLS on the first `p` columns of `E`, `f = e_{m+1}`, into `u`.
    ///
    /// A column's dual gradient and its variable are compared with `1e-12` times the column's
    /// own scale (its largest entry, at least 1), the size of their rounding: a far-away
    /// constraint's huge bound (a distant obstacle's clearance, a joint left practically
    /// unlimited) then sets no tolerance but its own, where one scale over all columns would
    /// let the others' gradients pass as zero.
    fn nnls(&mut self, p: usize) -> Result<(), ProjectionFailure> {
        let height = self.m + 1;
        for (tolerance, column) in self.tolerances[..p]
            .iter_mut()
            .zip(self.e.chunks_exact(height))
        {
            *tolerance = 1e-12 * column.iter().fold(1.0, |s, e| f64::max(s, e.abs()));
        }
        self.u[..p].fill(0.0);
        self.passive[..p].fill(false);
        self.n_passive = 0;
        for _ in 0..3 * p + 10 {
            // w = E^T (f - E u).
            self.residual.fill(0.0);
            self.residual[height - 1] = 1.0;
            for &j in &self.order[..self.n_passive] {
                let column = &self.e[j * height..(j + 1) * height];
                for (r, c) in self.residual.iter_mut().zip(column) {
                    *r -= c * self.u[j];
                }
            }
            // The entering column: the largest dual gradient w_j = E_j . r above the tolerance.
            let mut best: Option<(usize, f64)> = None;
            if self.n_passive < height {
                for (((j, column), &passive), &tolerance) in self.e[..p * height]
                    .chunks_exact(height)
                    .enumerate()
                    .zip(&self.passive[..p])
                    .zip(&self.tolerances[..p])
                {
                    let w: f64 = column.iter().zip(&self.residual).map(|(c, r)| c * r).sum();
                    if !passive && w > tolerance && best.is_none_or(|(_, b)| w > b) {
                        best = Some((j, w));
                    }
                }
            }
            let Some((entering, _)) = best else {
                return Ok(());
            };
            self.passive[entering] = true;
            self.order[self.n_passive] = entering;
            self.n_passive += 1;
            loop {
                if !self.solve_passive() {
                    // Dependent columns: the entering one (the last) adds nothing.
                    self.passive[entering] = false;
                    self.n_passive -= 1;
                    return Ok(());
                }
                let order = &self.order[..self.n_passive];
                if order.iter().all(|&j| self.z[j] > 0.0) {
                    for &j in order {
                        self.u[j] = self.z[j];
                    }
                    break;
                }
                let mut alpha = f64::INFINITY;
                for &j in order {
                    if self.z[j] <= 0.0 {
                        alpha = alpha.min(self.u[j] / (self.u[j] - self.z[j]));
                    }
                }
                for &j in order {
                    self.u[j] += alpha * (self.z[j] - self.u[j]);
                }
                // The passive variables that reached zero leave, the others keep their order.
                let mut kept = 0;
                for i in 0..self.n_passive {
                    let j = self.order[i];
                    if self.u[j] > self.tolerances[j] {
                        self.order[kept] = j;
                        kept += 1;
                    } else {
                        self.u[j] = 0.0;
                        self.passive[j] = false;
                    }
                }
                self.n_passive = kept;
                if kept == 0 {
                    break;
                }
            }
        }
        Err(ProjectionFailure::NoConvergence)
    }

    /// Replaces `x` by `x0 + y`, `y` the shortest solution of the passive constraints held as
    /// equalities, `G_P y = g_P - G_P x0` (their rows as scaled in `E`), by Householder QR of
    /// `G_P^T`, where they are independent and fewer than `m + 1`. The closest point makes its
    /// constraints with positive multipliers active, so this is the same point; computed from
    /// the constraints directly, it keeps their digits where the residual's formula loses them
    /// (large multipliers of nearly opposite rows in a badly conditioned problem).
    fn polish(&mut self, x0: &[f64], x: &mut [f64]) {
        let (m, height, k) = (self.m, self.m + 1, self.n_passive);
        if k == 0 || k > m {
            return;
        }
        // Column c of `G_P^T` (length m) into `qr`, its right-hand side into `rhs`.
        for (c, &j) in self.order[..k].iter().enumerate() {
            let column = &self.e[j * height..(j + 1) * height];
            for (q, e) in self.qr[c * m..(c + 1) * m].iter_mut().zip(column) {
                *q = -e;
            }
            self.rhs[c] = -column[m];
        }
        // Householder: column c's entries c.. become its reflection's vector, R's diagonal goes
        // to `z` (indexed by position), R's entries above it stay in the later columns.
        for c in 0..k {
            let (done, later) = self.qr[..k * m].split_at_mut((c + 1) * m);
            let v = &mut done[c * m + c..];
            let Some((alpha, vv)) = reflector(v) else {
                return;
            };
            for other in later.chunks_exact_mut(m) {
                reflect(v, vv, &mut other[c..]);
            }
            self.z[c] = alpha;
        }
        // R^T w = b (w in `residual`), then y = Q [w; 0].
        for c in 0..k {
            let mut value = self.rhs[c];
            for i in 0..c {
                value -= self.qr[c * m + i] * self.residual[i];
            }
            self.residual[c] = value / self.z[c];
        }
        self.residual[k..m].fill(0.0);
        for c in (0..k).rev() {
            let v = &self.qr[c * m + c..(c + 1) * m];
            let vv: f64 = v.iter().map(|x| x * x).sum();
            reflect(v, vv, &mut self.residual[c..m]);
        }
        for ((x, x0), y) in x.iter_mut().zip(x0).zip(&self.residual[..m]) {
            *x = x0 + y;
        }
    }

    /// The least-squares solution `z` of `E_P z = f` over the passive columns by Householder QR;
    /// `false` when the columns are numerically dependent.
    fn solve_passive(&mut self) -> bool {
        let height = self.m + 1;
        let k = self.n_passive;
        for (c, &j) in self.order[..k].iter().enumerate() {
            self.qr[c * height..(c + 1) * height]
                .copy_from_slice(&self.e[j * height..(j + 1) * height]);
        }
        self.rhs.fill(0.0);
        self.rhs[height - 1] = 1.0;
        for c in 0..k {
            // v: column c's entries c.. (the Householder vector once its first entry is shifted).
            let (done, later) = self.qr[..k * height].split_at_mut((c + 1) * height);
            let v = &mut done[c * height + c..];
            let Some((alpha, vv)) = reflector(v) else {
                return false;
            };
            // Apply I - 2 v v^T / v^T v to the later columns and the right-hand side.
            for other in later.chunks_exact_mut(height) {
                reflect(v, vv, &mut other[c..]);
            }
            reflect(v, vv, &mut self.rhs[c..]);
            v[0] = alpha;
        }
        for c in (0..k).rev() {
            let mut value = self.rhs[c];
            for other in c + 1..k {
                value -= self.qr[other * height + c] * self.z[self.order[other]];
            }
            self.z[self.order[c]] = value / self.qr[c * height + c];
        }
        true
    }
}

/// Turns column `v` into the vector of the Householder reflection that maps it onto
/// `alpha e_1` (its first entry shifted by `-alpha`), and returns `alpha` and `v^T v`; `None`
/// when the column is numerically zero (dependent on the ones before it).
fn reflector(v: &mut [f64]) -> Option<(f64, f64)> {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm <= 1e-13 {
        return None;
    }
    let alpha = if v[0] > 0.0 { -norm } else { norm };
    v[0] -= alpha;
    let vv: f64 = v.iter().map(|x| x * x).sum();
    Some((alpha, vv))
}

/// Applies the Householder reflection `I - 2 v v^T / v^T v` (`vv = v^T v`) to `target`.
fn reflect(v: &[f64], vv: f64, target: &mut [f64]) {
    let dot: f64 = v.iter().zip(target.iter()).map(|(a, b)| a * b).sum();
    let factor = 2.0 * dot / vv;
    for (t, x) in target.iter_mut().zip(v) {
        *t -= factor * x;
    }
}

/// Whether `x` satisfies every row of `G x <= g` (row-major, `x.len()` columns) to within the
/// rounding of its terms (a relative `1e-9`).
fn satisfies(constraints: &[f64], g: &[f64], x: &[f64]) -> bool {
    constraints
        .chunks_exact(x.len().max(1))
        .zip(g)
        .all(|(row, &bound)| {
            let (mut gx, mut size) = (0.0, bound.abs());
            for (&r, &x) in row.iter().zip(x) {
                gx += r * x;
                size += (r * x).abs();
            }
            gx - bound <= 1e-9 * (1.0 + size)
        })
}

/// The largest power of two at most `x` (positive, finite and normal, as the inverse of a
/// finite positive norm is): `x` with its significand's bits cleared.
fn power_of_two_at_most(x: f64) -> f64 {
    const SIGN_AND_EXPONENT: u64 = 0xfff0_0000_0000_0000;
    f64::from_bits(x.to_bits() & SIGN_AND_EXPONENT)
}

#[cfg(test)]
mod tests {
    use super::power_of_two_at_most;

    #[test]
    fn powers_of_two_at_most_bracket_their_argument() {
        // Exact powers, their neighbours a rounding away, and inverses of norms from the
        // smallest positive to the largest finite square.
        let mut xs = vec![1.0, 2.0, 0.5, 1024.0, f64::MIN_POSITIVE];
        for k in -300..300 {
            let power = 2f64.powi(k);
            xs.extend([power, power.next_down(), power.next_up(), 3.0 * power]);
        }
        xs.extend([f64::from_bits(1).sqrt().recip(), f64::MAX.sqrt().recip()]);
        for x in xs {
            let p = power_of_two_at_most(x);
            assert!(p <= x && x < 2.0 * p, "{x}: {p}");
            assert_eq!(
                p.to_bits() & ((1 << 52) - 1),
                0,
                "{x}: {p} is not a power of two"
            );
        }
    }
}
