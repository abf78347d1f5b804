//! Cholesky factorisation `a = L L^T` in place and the triangular solves with its factor.

/// Cholesky factorisation in place of the symmetric `m x m` matrix `a` (lower triangle);
/// `false` if it is not numerically positive definite.
#[inline]
pub fn cholesky(a: &mut [f64], m: usize) -> bool {
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
#[inline]
pub fn cholesky_solve(l: &[f64], m: usize, x: &mut [f64], c: usize) {
    forward_substitute(l, m, x, c);
    back_substitute(l, m, x, c);
}

/// Overwrites the `m x c` right-hand sides `x` with `L^-1 x`, `L` from [`cholesky`].
#[inline]
pub fn forward_substitute(l: &[f64], m: usize, x: &mut [f64], c: usize) {
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
#[inline]
pub fn back_substitute(l: &[f64], m: usize, x: &mut [f64], c: usize) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dense::{multiply, multiply_by_transposed, test_matrix};

    #[test]
    fn cholesky_solves_an_spd_system_and_refuses_an_indefinite_one() {
        let m = 6;
        // B B^T + I: symmetric positive definite.
        let b = test_matrix(m, m, 11);
        let mut a = vec![0.0; m * m];
        multiply_by_transposed(&b, &b, &mut a, m, m, m);
        for i in 0..m {
            a[i * m + i] += 1.0;
        }
        let rhs = test_matrix(m, 3, 13);
        let (mut l, mut x) = (a.clone(), rhs.clone());
        assert!(cholesky(&mut l, m));
        cholesky_solve(&l, m, &mut x, 3);
        let mut ax = vec![0.0; m * 3];
        multiply(&a, &x, &mut ax, m, m, 3);
        for (got, want) in ax.iter().zip(&rhs) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        let mut indefinite = [1.0, 2.0, 2.0, 1.0];
        assert!(!cholesky(&mut indefinite, 2));
        let mut nan = [f64::NAN, 0.0, 0.0, 1.0];
        assert!(!cholesky(&mut nan, 2));
    }
}
