//! Small dense row-major matrices on slices owned by a workspace: products, in-place Cholesky
//! and LU solves and the matrix exponential, all allocation-free (`m` is a handful).

/// `out = a b` with `a` `r x k`, `b` `k x c` (row-major; `out` must not alias).
pub(crate) fn multiply(a: &[f64], b: &[f64], out: &mut [f64], r: usize, k: usize, c: usize) {
    for i in 0..r {
        let row = &mut out[i * c..(i + 1) * c];
        row.fill(0.0);
        for l in 0..k {
            let x = a[i * k + l];
            for (o, &y) in row.iter_mut().zip(&b[l * c..(l + 1) * c]) {
                *o += x * y;
            }
        }
    }
}

/// `out = a^T b` with `a` `k x r`, `b` `k x c`.
pub(crate) fn multiply_transposed(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
    r: usize,
    k: usize,
    c: usize,
) {
    out[..r * c].fill(0.0);
    for l in 0..k {
        for i in 0..r {
            let x = a[l * r + i];
            for (o, &y) in out[i * c..(i + 1) * c]
                .iter_mut()
                .zip(&b[l * c..(l + 1) * c])
            {
                *o += x * y;
            }
        }
    }
}

/// `out = a b^T` with `a` `r x k`, `b` `c x k`.
pub(crate) fn multiply_by_transposed(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
    r: usize,
    k: usize,
    c: usize,
) {
    for i in 0..r {
        let row = &a[i * k..(i + 1) * k];
        for j in 0..c {
            out[i * c + j] = row
                .iter()
                .zip(&b[j * k..(j + 1) * k])
                .map(|(x, y)| x * y)
                .sum();
        }
    }
}

/// Replaces the `n x n` matrix `a` with its symmetric part `(a + a^T) / 2` (against the rounding
/// drift of products that are symmetric in exact arithmetic).
pub fn symmetrise(a: &mut [f64], n: usize) {
    for i in 0..n {
        for j in i + 1..n {
            let mean = 0.5 * (a[i * n + j] + a[j * n + i]);
            a[i * n + j] = mean;
            a[j * n + i] = mean;
        }
    }
}

/// Cholesky factorisation in place of the symmetric `m x m` matrix `a` (lower triangle);
/// `false` if it is not numerically positive definite.
pub(crate) fn cholesky(a: &mut [f64], m: usize) -> bool {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    true
}

/// Overwrites the `m x c` right-hand sides `x` with `(L L^T)^-1 x`, `L` from [`cholesky`].
pub(crate) fn cholesky_solve(l: &[f64], m: usize, x: &mut [f64], c: usize) {
    forward_substitute(l, m, x, c);
    back_substitute(l, m, x, c);
}

/// Overwrites the `m x c` right-hand sides `x` with `L^-1 x`, `L` from [`cholesky`].
pub(crate) fn forward_substitute(l: &[f64], m: usize, x: &mut [f64], c: usize) {
    for col in 0..c {
        for i in 0..m {
            let mut s = x[i * c + col];
            for k in 0..i {
                s -= l[i * m + k] * x[k * c + col];
            }
            x[i * c + col] = s / l[i * m + i];
        }
    }
}

/// Overwrites the `m x c` right-hand sides `x` with `L^-T x`, `L` from [`cholesky`].
pub(crate) fn back_substitute(l: &[f64], m: usize, x: &mut [f64], c: usize) {
    for col in 0..c {
        for i in (0..m).rev() {
            let mut s = x[i * c + col];
            for k in i + 1..m {
                s -= l[k * m + i] * x[k * c + col];
            }
            x[i * c + col] = s / l[i * m + i];
        }
    }
}

/// Overwrites the `n x c` right-hand sides `x` with `a^-1 x` by Gaussian elimination with
/// partial pivoting, destroying `a` (`n x n`); `false` if a pivot is zero or not finite.
pub(crate) fn lu_solve(a: &mut [f64], n: usize, x: &mut [f64], c: usize) -> bool {
    for j in 0..n {
        let pivot = (j..n)
            .max_by(|&p, &q| a[p * n + j].abs().total_cmp(&a[q * n + j].abs()))
            .unwrap_or(j);
        let d = a[pivot * n + j];
        if !(d != 0.0 && d.is_finite()) {
            return false;
        }
        if pivot != j {
            for k in 0..n {
                a.swap(j * n + k, pivot * n + k);
            }
            for k in 0..c {
                x.swap(j * c + k, pivot * c + k);
            }
        }
        for i in j + 1..n {
            let factor = a[i * n + j] / d;
            for k in j + 1..n {
                a[i * n + k] -= factor * a[j * n + k];
            }
            for k in 0..c {
                x[i * c + k] -= factor * x[j * c + k];
            }
        }
    }
    for i in (0..n).rev() {
        let d = a[i * n + i];
        for k in 0..c {
            let mut s = x[i * c + k];
            for l in i + 1..n {
                s -= a[i * n + l] * x[l * c + k];
            }
            x[i * c + k] = s / d;
        }
    }
    true
}

/// `exp(a)` of the `s x s` matrix `a` into `out`, by scaling and squaring: `a / 2^j` with norm
/// below 1/2, its Taylor series to order 16 (truncation error below `2^-16 / 16!`, far under
/// rounding), then `j` squarings. `work` holds two `s x s` scratch matrices.
pub(crate) fn exponential(a: &[f64], out: &mut [f64], work: &mut [f64], s: usize) {
    let size = s * s;
    let norm = (0..s)
        .map(|i| a[i * s..(i + 1) * s].iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 && squarings < 1100 {
        scale *= 0.5;
        squarings += 1;
    }
    let (term, next) = work[..2 * size].split_at_mut(size);
    // out = I + sum_k (a scale)^k / k!, term = (a scale)^k / k!.
    out[..size].fill(0.0);
    term.fill(0.0);
    for i in 0..s {
        out[i * s + i] = 1.0;
        term[i * s + i] = 1.0;
    }
    for k in 1..=16 {
        multiply(term, a, next, s, s, s);
        let factor = scale / k as f64;
        for ((t, &n), o) in term.iter_mut().zip(next.iter()).zip(out.iter_mut()) {
            *t = n * factor;
            *o += *t;
        }
    }
    for _ in 0..squarings {
        multiply(out, out, next, s, s, s);
        out[..size].copy_from_slice(next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic `r x c` matrix with entries in [-1, 1].
    fn matrix(r: usize, c: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        (0..r * c)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    #[test]
    fn lu_solve_inverts_a_general_matrix_and_refuses_a_singular_one() {
        let n = 7;
        // Small diagonal: partial pivoting has to swap rows.
        let mut a = matrix(n, n, 3);
        for i in 0..n {
            a[i * n + i] *= 1e-3;
        }
        let b = matrix(n, 2, 5);
        let (mut lu, mut x) = (a.clone(), b.clone());
        assert!(lu_solve(&mut lu, n, &mut x, 2));
        let mut ax = vec![0.0; n * 2];
        multiply(&a, &x, &mut ax, n, n, 2);
        for (got, want) in ax.iter().zip(&b) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        let mut singular = a.clone();
        for k in 0..n {
            singular[n + k] = 2.0 * singular[k];
        }
        assert!(!lu_solve(&mut singular, n, &mut x, 2));
    }

    #[test]
    fn multiply_by_transposed_is_the_product_with_the_transpose() {
        let (r, k, c) = (3, 4, 5);
        let (a, b) = (matrix(r, k, 7), matrix(c, k, 9));
        let bt: Vec<f64> = (0..k * c).map(|x| b[(x % c) * k + x / c]).collect();
        let (mut got, mut want) = (vec![0.0; r * c], vec![0.0; r * c]);
        multiply_by_transposed(&a, &b, &mut got, r, k, c);
        multiply(&a, &bt, &mut want, r, k, c);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-15);
        }
    }
}
