//! Solving a general small system by Gaussian elimination with partial pivoting.

/// Overwrites the `n x c` right-hand sides `x` with `a^-1 x` by Gaussian elimination with
/// partial pivoting, destroying `a` (`n x n`); `false` if a pivot is zero or not finite.
#[inline]
pub fn lu_solve(a: &mut [f64], n: usize, x: &mut [f64], c: usize) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dense::multiply;
    use crate::dense::test_matrix as matrix;

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
}
