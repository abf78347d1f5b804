//! Small dense row-major matrices on slices owned by a workspace: products, an in-place
//! Cholesky solve and the matrix exponential, all allocation-free (`m` is a handful).

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
    for col in 0..c {
        for i in 0..m {
            let mut s = x[i * c + col];
            for k in 0..i {
                s -= l[i * m + k] * x[k * c + col];
            }
            x[i * c + col] = s / l[i * m + i];
        }
        for i in (0..m).rev() {
            let mut s = x[i * c + col];
            for k in i + 1..m {
                s -= l[k * m + i] * x[k * c + col];
            }
            x[i * c + col] = s / l[i * m + i];
        }
    }
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
