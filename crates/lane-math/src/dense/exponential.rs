//! The exponential of a small square matrix by scaling and squaring.

use super::multiply;

/// `exp(a)` of the `s x s` matrix `a` into `out`, by scaling and squaring: `a / 2^j` with norm
/// below 1/2, its Taylor series to order 16 (truncation error below `2^-16 / 16!`, far under
/// rounding), then `j` squarings. `work` holds two `s x s` scratch matrices.
#[inline]
pub fn exponential(a: &[f64], out: &mut [f64], work: &mut [f64], s: usize) {
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
