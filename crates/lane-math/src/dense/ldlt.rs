//! `L D L^T` factorisation and solves of small symmetric positive-definite matrices, generic
//! over [`Lane`] so that one call factorises `L::WIDTH` independent matrices.

use crate::Lane;

/// Factorises the symmetric positive-definite `m x m` matrix `a` (row-major) in place as
/// `a = L D L^T`, `L` unit lower triangular and `D` diagonal: `L` below the diagonal, `1 / D` on
/// it, scratch (`L^T D`) above it; only the lower triangle of the input is read. Each entry holds
/// `L::WIDTH` independent matrices (see [`Lane`]).
///
/// Square-root free and with one division per column, which is most of the cost at this size;
/// the solve then only multiplies.
/// Returns `false` if a pivot `D_j` is not positive and finite (the matrix is not numerically
/// positive definite; in any lane); `a` then holds a partial factorisation.
#[inline(always)]
pub fn ldlt_in_place<L: Lane>(context: L::Context, a: &mut [L], m: usize) -> bool {
    let a = &mut a[..m * m];
    for j in 0..m {
        // a[k][j] (k < j) holds L_jk D_k.
        let mut pivot = a[j * m + j];
        for k in 0..j {
            pivot = pivot - a[j * m + k] * a[k * m + j];
        }
        // Positive and finite in every lane, in two vector compares (false on a NaN).
        let positive = pivot.all_greater(L::splat(context, 0.0));
        if !(positive & L::splat(context, f64::INFINITY).all_greater(pivot)) {
            return false;
        }
        let inverse = L::splat(context, 1.0) / pivot;
        a[j * m + j] = inverse;
        for i in j + 1..m {
            let mut value = a[i * m + j];
            for k in 0..j {
                value = value - a[i * m + k] * a[k * m + j];
            }
            // value = L_ij D_j.
            a[j * m + i] = value;
            a[i * m + j] = value * inverse;
        }
    }
    true
}

/// Solves `L D L^T x = b` in place (`x` holds `b` on entry), with the factors left by
/// [`ldlt_in_place`].
#[inline(always)]
pub fn ldlt_solve_in_place<L: Lane>(factor: &[L], m: usize, x: &mut [L]) {
    let (f, x) = (&factor[..m * m], &mut x[..m]);
    for i in 0..m {
        for k in 0..i {
            x[i] = x[i] - f[i * m + k] * x[k];
        }
    }
    for i in 0..m {
        x[i] = x[i] * f[i * m + i];
    }
    for i in (0..m).rev() {
        for k in i + 1..m {
            x[i] = x[i] - f[k * m + i] * x[k];
        }
    }
}

/// Solves `L D L^T X = B` in place for the row-major `m x columns` matrix `x` (holding `B` on
/// entry), with the factors left by [`ldlt_in_place`]: the substitutions of
/// [`ldlt_solve_in_place`] on whole rows, so each column gets the same operations in the same
/// order (the same bits) as solved alone, and the inner loops run along contiguous rows.
#[inline(always)]
pub fn ldlt_solve_rows_in_place<L: Lane>(factor: &[L], m: usize, x: &mut [L], columns: usize) {
    let (f, x) = (&factor[..m * m], &mut x[..m * columns]);
    for i in 0..m {
        let (solved, rest) = x.split_at_mut(i * columns);
        let row = &mut rest[..columns];
        for (k, other) in solved.chunks_exact(columns).enumerate() {
            let l = f[i * m + k];
            for (entry, &value) in row.iter_mut().zip(other) {
                *entry = *entry - l * value;
            }
        }
    }
    for (i, row) in x.chunks_exact_mut(columns).enumerate() {
        let inverse = f[i * m + i];
        for entry in row {
            *entry = *entry * inverse;
        }
    }
    for i in (0..m).rev() {
        let (row, solved) = x[i * columns..].split_at_mut(columns);
        for (k, other) in solved.chunks_exact(columns).enumerate() {
            let l = f[(i + 1 + k) * m + i];
            for (entry, &value) in row.iter_mut().zip(other) {
                *entry = *entry - l * value;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A random symmetric positive-definite matrix `B B^T + m I` and the matrix `B`.
    fn spd(entries: &[f64], m: usize) -> Vec<f64> {
        let mut a = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                a[i * m + j] = (0..m)
                    .map(|k| entries[i * m + k] * entries[j * m + k])
                    .sum::<f64>();
            }
            a[i * m + i] += 0.1;
        }
        a
    }

    proptest! {
        #[test]
        fn ldlt_solves_spd_systems(
            (m, entries, rhs) in (1usize..8).prop_flat_map(|m| (
                Just(m),
                prop::collection::vec(-2.0..2.0f64, m * m),
                prop::collection::vec(-5.0..5.0f64, m),
            ))
        ) {
            let a = spd(&entries, m);
            let mut factor = a.clone();
            prop_assert!(ldlt_in_place((), &mut factor, m));
            let mut x = rhs.clone();
            ldlt_solve_in_place(&factor, m, &mut x);
            for i in 0..m {
                let ax: f64 = (0..m).map(|j| a[i * m + j] * x[j]).sum();
                prop_assert!((ax - rhs[i]).abs() <= 1e-9 * (1.0 + rhs[i].abs()), "row {i}");
            }
        }

        #[test]
        fn row_solves_equal_column_solves_bit_for_bit(
            (m, columns, entries, rhs) in (1usize..8, 1usize..10).prop_flat_map(|(m, columns)| (
                Just(m),
                Just(columns),
                prop::collection::vec(-2.0..2.0f64, m * m),
                prop::collection::vec(-5.0..5.0f64, m * columns),
            ))
        ) {
            let mut factor = spd(&entries, m);
            prop_assert!(ldlt_in_place((), &mut factor, m));
            let mut rows = rhs.clone();
            ldlt_solve_rows_in_place(&factor, m, &mut rows, columns);
            for j in 0..columns {
                let mut column: Vec<f64> = (0..m).map(|i| rhs[i * columns + j]).collect();
                ldlt_solve_in_place(&factor, m, &mut column);
                for i in 0..m {
                    prop_assert_eq!(rows[i * columns + j].to_bits(), column[i].to_bits(), "[{}][{}]", i, j);
                }
            }
        }
    }

    #[test]
    fn ldlt_refuses_indefinite_and_nan() {
        let mut indefinite = [1.0, 2.0, 2.0, 1.0];
        assert!(!ldlt_in_place((), &mut indefinite, 2));
        let mut nan = [f64::NAN, 0.0, 0.0, 1.0];
        assert!(!ldlt_in_place((), &mut nan, 2));
    }
}
