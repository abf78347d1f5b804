//! Products of small row-major matrices and the symmetric part of a square one.

/// `out = a b` with `a` `r x k`, `b` `k x c` (row-major; `out` must not alias). Always
/// inlined, so that sizes known to the caller unroll its loops.
#[inline(always)]
pub fn multiply(a: &[f64], b: &[f64], out: &mut [f64], r: usize, k: usize, c: usize) {
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

/// `out = a^T b` with `a` `k x r`, `b` `k x c`. Always inlined, as [`multiply`].
#[inline(always)]
pub fn multiply_transposed(a: &[f64], b: &[f64], out: &mut [f64], r: usize, k: usize, c: usize) {
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

/// [`multiply`] for sizes known at compile time (`a` `R x K`, `b` `K x C`): the same operations
/// in the same order, accumulated in a local array that the compiler keeps in vector registers
/// (a row of `C` values at a time) instead of in `out`.
#[inline(always)]
pub fn multiply_sized<const R: usize, const K: usize, const C: usize>(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
) {
    let (a, b) = (&a[..R * K], &b[..K * C]);
    let mut product = [[0.0; C]; R];
    for (row, a_row) in product.iter_mut().zip(a.chunks_exact(K)) {
        for (&x, b_row) in a_row.iter().zip(b.chunks_exact(C)) {
            for (o, &y) in row.iter_mut().zip(b_row) {
                *o += x * y;
            }
        }
    }
    out[..R * C].copy_from_slice(product.as_flattened());
}

/// [`multiply_transposed`] for sizes known at compile time (`a` `K x R`, `b` `K x C`), as
/// [`multiply_sized`].
#[inline(always)]
pub fn multiply_transposed_sized<const R: usize, const K: usize, const C: usize>(
    a: &[f64],
    b: &[f64],
    out: &mut [f64],
) {
    let (a, b) = (&a[..K * R], &b[..K * C]);
    let mut product = [[0.0; C]; R];
    for (a_row, b_row) in a.chunks_exact(R).zip(b.chunks_exact(C)) {
        for (row, &x) in product.iter_mut().zip(a_row) {
            for (o, &y) in row.iter_mut().zip(b_row) {
                *o += x * y;
            }
        }
    }
    out[..R * C].copy_from_slice(product.as_flattened());
}

/// `out = a b^T` with `a` `r x k`, `b` `c x k`.
#[inline]
pub fn multiply_by_transposed(a: &[f64], b: &[f64], out: &mut [f64], r: usize, k: usize, c: usize) {
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
/// drift of products that are symmetric in exact arithmetic). Always inlined, as [`multiply`].
#[inline(always)]
pub fn symmetrise(a: &mut [f64], n: usize) {
    for i in 0..n {
        for j in i + 1..n {
            let mean = 0.5 * (a[i * n + j] + a[j * n + i]);
            a[i * n + j] = mean;
            a[j * n + i] = mean;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dense::test_matrix as matrix;

    #[test]
    fn sized_products_have_the_bits_of_the_general_ones() {
        let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let (a, b) = (matrix(3, 4, 3), matrix(4, 5, 5));
        let (mut sized, mut general) = (vec![0.0; 15], vec![0.0; 15]);
        multiply_sized::<3, 4, 5>(&a, &b, &mut sized);
        multiply(&a, &b, &mut general, 3, 4, 5);
        assert_eq!(bits(&sized), bits(&general));
        // `a` read as 4 x 3: `a^T b` is 3 x 5.
        multiply_transposed_sized::<3, 4, 5>(&a, &b, &mut sized);
        multiply_transposed(&a, &b, &mut general, 3, 4, 5);
        assert_eq!(bits(&sized), bits(&general));
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
