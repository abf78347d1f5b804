//! Linear least squares `min |A x - b|^2 + lambda |x|^2` by Householder QR, with a workspace
//! sized once so that every solve is allocation-free (the consequent step of ANFIS's hybrid rule,
//! Jang 1993, eq 15, solved in batch rather than recursively).
//!
//! The ridge term is appended as `n` extra rows `sqrt(lambda) I` below `A`, so the same QR solves
//! both problems. Without a ridge, a rank-deficient `A` is an error naming the first column it
//! cannot determine; with one, the system is always full rank and no solve gives NaN.

/// Why a solve failed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum LeastSquaresError {
    /// Column `column` (0-based) is, to working precision, a combination of the ones before it.
    RankDeficient {
        /// The first undetermined column.
        column: usize,
    },
    /// `A` or `b` holds a non-finite value.
    NonFinite,
}

impl std::fmt::Display for LeastSquaresError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::RankDeficient { column } => write!(
                f,
                "column {column} of the least-squares problem is a combination of the ones \
                 before it"
            ),
            Self::NonFinite => write!(f, "the least-squares problem holds a non-finite value"),
        }
    }
}

impl std::error::Error for LeastSquaresError {}

impl crate::Classify for LeastSquaresError {
    /// [`Numerical`](crate::ErrorClass::Numerical): the data were valid numbers, the problem
    /// came out singular or overflowed in double precision.
    fn class(&self) -> crate::ErrorClass {
        crate::ErrorClass::Numerical
    }
}

/// A least-squares problem with `rows` equations in `cols` unknowns and its workspace.
#[derive(Debug, Clone)]
pub struct LeastSquares {
    rows: usize,
    cols: usize,
    /// `(rows + cols) x cols`, column-major; the last `cols` rows hold the ridge.
    a: Vec<f64>,
    /// `rows + cols`.
    b: Vec<f64>,
    /// The diagonal of `R`.
    diagonal: Vec<f64>,
    /// The solution.
    x: Vec<f64>,
}

impl LeastSquares {
    /// A zero problem of the given size (the caller bounds `rows * cols`).
    pub fn new(rows: usize, cols: usize) -> Self {
        let m = rows + cols;
        Self {
            rows,
            cols,
            a: vec![0.0; m * cols],
            b: vec![0.0; m],
            diagonal: vec![0.0; cols],
            x: vec![0.0; cols],
        }
    }

    /// Sets row `row` of `A` to zero and `b[row]` to `rhs`.
    #[inline]
    pub fn clear_row(&mut self, row: usize, rhs: f64) {
        let m = self.rows + self.cols;
        for c in 0..self.cols {
            self.a[c * m + row] = 0.0;
        }
        self.b[row] = rhs;
    }

    /// Adds `value` to `A[row, col]`.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, value: f64) {
        self.a[col * (self.rows + self.cols) + row] += value;
    }

    /// Solves with the ridge `lambda = ridge * |A|_F^2 / cols` (`ridge = 0`: plain least
    /// squares), overwriting `A` and `b`; returns the solution.
    pub fn solve(&mut self, ridge: f64) -> Result<&[f64], LeastSquaresError> {
        let (n, m) = (self.cols, self.rows + self.cols);
        let frobenius_sq: f64 = (0..n)
            .map(|c| {
                self.a[c * m..c * m + self.rows]
                    .iter()
                    .map(|v| v * v)
                    .sum::<f64>()
            })
            .sum();
        if !frobenius_sq.is_finite() || self.b[..self.rows].iter().any(|v| !v.is_finite()) {
            return Err(LeastSquaresError::NonFinite);
        }
        let root_lambda = (ridge * frobenius_sq / n as f64).sqrt();
        for c in 0..n {
            let column = &mut self.a[c * m + self.rows..(c + 1) * m];
            column.fill(0.0);
            column[c] = root_lambda;
        }
        self.b[self.rows..].fill(0.0);
        // Householder QR: column k becomes v_k below the diagonal, R above it.
        for k in 0..n {
            let (head, tail) = self.a.split_at_mut((k + 1) * m);
            let v = &mut head[k * m + k..];
            let norm = v.iter().map(|t| t * t).sum::<f64>().sqrt();
            if norm == 0.0 {
                self.diagonal[k] = 0.0;
                continue;
            }
            let alpha = if v[0] > 0.0 { -norm } else { norm };
            v[0] -= alpha;
            // H = I - beta v v^T with beta = 2 / |v|^2 = 1 / (norm (norm + |x_0|)) = -1 / (alpha v0).
            let beta = -1.0 / (alpha * v[0]);
            self.diagonal[k] = alpha;
            for j in 0..n - k - 1 {
                let column = &mut tail[j * m + k..(j + 1) * m];
                let s = beta * dot(v, column);
                axpy(-s, v, column);
            }
            let s = beta * dot(v, &self.b[k..]);
            axpy(-s, v, &mut self.b[k..]);
        }
        let largest = self.diagonal.iter().fold(0.0f64, |acc, d| acc.max(d.abs()));
        let tolerance = largest * f64::EPSILON * m as f64;
        if let Some(column) = self.diagonal.iter().position(|d| d.abs() <= tolerance) {
            return Err(LeastSquaresError::RankDeficient { column });
        }
        // Back substitution R x = Q^T b.
        for k in (0..n).rev() {
            let mut sum = self.b[k];
            for j in k + 1..n {
                sum -= self.a[j * m + k] * self.x[j];
            }
            self.x[k] = sum / self.diagonal[k];
        }
        if self.x.iter().any(|v| !v.is_finite()) {
            return Err(LeastSquaresError::NonFinite);
        }
        Ok(&self.x)
    }
}

#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[inline]
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn problem(a: &[&[f64]], b: &[f64]) -> LeastSquares {
        let mut ls = LeastSquares::new(a.len(), a[0].len());
        for (r, row) in a.iter().enumerate() {
            ls.clear_row(r, b[r]);
            for (c, v) in row.iter().enumerate() {
                ls.add(r, c, *v);
            }
        }
        ls
    }

    #[test]
    fn fits_a_line_exactly() {
        // y = 2 x + 1 through (0, 1), (1, 3), (2, 5): columns [x, 1].
        let mut ls = problem(&[&[0.0, 1.0], &[1.0, 1.0], &[2.0, 1.0]], &[1.0, 3.0, 5.0]);
        let x = ls.solve(0.0).unwrap();
        assert!((x[0] - 2.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14);
    }

    #[test]
    fn rank_deficiency_is_an_error_without_ridge_and_regularised_with_one() {
        let a: &[&[f64]] = &[&[1.0, 2.0], &[2.0, 4.0], &[3.0, 6.0]];
        let b = [1.0, 2.0, 3.0];
        assert_eq!(
            problem(a, &b).solve(0.0).unwrap_err(),
            LeastSquaresError::RankDeficient { column: 1 }
        );
        // The ridge solution of collinear columns splits the weight as the columns' norms: the
        // minimum-norm solution x = (1, 2) / 5 of x1 + 2 x2 = 1 in the limit lambda -> 0.
        let x = problem(a, &b).solve(1e-12).unwrap().to_vec();
        assert!(
            (x[0] - 0.2).abs() < 1e-6 && (x[1] - 0.4).abs() < 1e-6,
            "{x:?}"
        );
        let zero: &[&[f64]] = &[&[0.0], &[0.0]];
        assert_eq!(
            problem(zero, &[1.0, 2.0]).solve(0.0).unwrap_err(),
            LeastSquaresError::RankDeficient { column: 0 }
        );
    }

    proptest! {
        /// Against the normal equations of a random, well-conditioned 3-unknown problem, solved
        /// by Cramer's rule.
        #[test]
        fn matches_the_normal_equations(values in prop::collection::vec(-1.0f64..1.0, 40), ridge in 0.0f64..0.1) {
            let rows: Vec<[f64; 3]> = values.chunks(4).map(|c| [c[0] + 2.0, c[1], c[2] * c[0]]).collect();
            let b: Vec<f64> = values.chunks(4).map(|c| c[3]).collect();
            let slices: Vec<&[f64]> = rows.iter().map(|r| &r[..]).collect();
            let mut ls = problem(&slices, &b);
            let x = ls.solve(ridge).unwrap().to_vec();
            let mut ata = [[0.0; 3]; 3];
            let mut atb = [0.0; 3];
            for (row, y) in rows.iter().zip(&b) {
                for i in 0..3 {
                    atb[i] += row[i] * y;
                    for j in 0..3 {
                        ata[i][j] += row[i] * row[j];
                    }
                }
            }
            let lambda = ridge * (0..3).map(|i| ata[i][i]).sum::<f64>() / 3.0;
            for (i, row) in ata.iter_mut().enumerate() {
                row[i] += lambda;
            }
            let det = |m: [[f64; 3]; 3]| {
                m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
            };
            let d = det(ata);
            prop_assume!(d.abs() > 1e-3);
            for k in 0..3 {
                let mut mk = ata;
                for i in 0..3 {
                    mk[i][k] = atb[i];
                }
                prop_assert!((x[k] - det(mk) / d).abs() < 1e-8 * (1.0 + x[k].abs()));
            }
        }
    }
}
