//! The extreme eigenvalues of a small symmetric matrix by cyclic Jacobi rotations.

/// The smallest and largest eigenvalues of the symmetric `m x m` matrix `a` (row-major), by
/// cyclic Jacobi rotations; `a` is overwritten (its diagonal ends up holding the eigenvalues).
///
/// Each rotation zeroes one off-diagonal pair; sweeps repeat until the off-diagonal part is
/// negligible against the diagonal (quadratic convergence: a handful of sweeps at this size).
#[inline]
pub fn symmetric_eigen_extremes(a: &mut [f64], m: usize) -> (f64, f64) {
    const MAX_SWEEPS: usize = 64;
    let a = &mut a[..m * m];
    for _ in 0..MAX_SWEEPS {
        let mut off = 0.0;
        let mut diag = 0.0;
        for i in 0..m {
            diag += a[i * m + i] * a[i * m + i];
            for j in i + 1..m {
                off += a[i * m + j] * a[i * m + j];
            }
        }
        if off <= (f64::EPSILON * f64::EPSILON) * diag || off == 0.0 {
            break;
        }
        for p in 0..m {
            for q in p + 1..m {
                rotate(a, m, p, q);
            }
        }
    }
    (0..m)
        .map(|i| a[i * m + i])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
}

/// Applies the Jacobi rotation in the `(p, q)` plane that zeroes `a[p][q]` (`a <- R^T a R`).
fn rotate(a: &mut [f64], m: usize, p: usize, q: usize) {
    let apq = a[p * m + q];
    if apq == 0.0 {
        return;
    }
    let theta = (a[q * m + q] - a[p * m + p]) / (2.0 * apq);
    let t = theta.signum() / (theta.abs() + theta.hypot(1.0));
    let c = 1.0 / t.hypot(1.0);
    let s = t * c;
    for k in 0..m {
        let (akp, akq) = (a[k * m + p], a[k * m + q]);
        a[k * m + p] = c * akp - s * akq;
        a[k * m + q] = s * akp + c * akq;
    }
    for k in 0..m {
        let (apk, aqk) = (a[p * m + k], a[q * m + k]);
        a[p * m + k] = c * apk - s * aqk;
        a[q * m + k] = s * apk + c * aqk;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn eigen_extremes_match_nalgebra(
            (m, entries) in (1usize..8).prop_flat_map(|m| (
                Just(m),
                prop::collection::vec(-3.0..3.0f64, m * m),
            ))
        ) {
            // A symmetric, indefinite in general.
            let mut a = vec![0.0; m * m];
            for i in 0..m {
                for j in 0..m {
                    a[i * m + j] = entries[i * m + j] + entries[j * m + i];
                }
            }
            let reference = nalgebra::DMatrix::from_row_slice(m, m, &a).symmetric_eigenvalues();
            let (lo, hi) = symmetric_eigen_extremes(&mut a, m);
            prop_assert!((lo - reference.min()).abs() <= 1e-12 * (1.0 + reference.amax()));
            prop_assert!((hi - reference.max()).abs() <= 1e-12 * (1.0 + reference.amax()));
        }
    }

    #[test]
    fn eigen_of_a_known_matrix() {
        // [[2, 1], [1, 2]] has eigenvalues 1 and 3.
        let mut a = [2.0, 1.0, 1.0, 2.0];
        let (lo, hi) = symmetric_eigen_extremes(&mut a, 2);
        assert!((lo - 1.0).abs() < 1e-15 && (hi - 3.0).abs() < 1e-15);
    }
}
