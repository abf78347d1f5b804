//! The eigen-decomposition of a symmetric 3 x 3 matrix by cyclic Jacobi rotations: the principal
//! moments and principal axes of a rotational inertia.
//!
//! Each Jacobi rotation zeroes one off-diagonal entry; sweeping the three in turn converges
//! quadratically (Golub and Van Loan, "Matrix Computations", section 8.5), and the eigenvalues
//! come out accurate to a few units in the last place of the largest magnitude whether or not
//! two of them are equal, where the trigonometric closed form of the characteristic cubic loses
//! half the digits (a slender rod's `(0, I, I)`).

use super::algebra::{IDENTITY, Mat3, Vec3};

/// A symmetric matrix as `vectors diag(values) vectors^T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymmetricEigen {
    /// The eigenvalues, ascending.
    pub values: Vec3,
    /// A rotation (orthonormal, determinant `+1`) whose column `k` is a unit eigenvector of
    /// `values[k]`: for an inertia, the principal axes in the frame the tensor is written in.
    pub vectors: Mat3,
}

/// Sweeps of the three rotations at most. Convergence to negligible entries takes at most six
/// (measured over random rotations of rods, spheres, plates and clusters at zero); the bound
/// only ends the loop on non-finite input.
const MAX_SWEEPS: usize = 32;

/// An off-diagonal entry at most this fraction of both its diagonal entries is set to zero: the
/// eigenvalues move by less than the rounding of those entries themselves. Without it, rotations
/// of a cluster of equal eigenvalues (a sphere) stir rounding noise sweep after sweep, and the
/// eigenvectors lose their orthogonality.
const NEGLIGIBLE_TO_DIAGONAL: f64 = f64::EPSILON / 16.0;

/// An off-diagonal entry at most this fraction of the matrix's largest entry is set to zero
/// (where the diagonal entries are themselves near zero).
const NEGLIGIBLE_TO_LARGEST: f64 = f64::EPSILON * f64::EPSILON;

/// The eigenvalues (ascending) and eigenvectors of the symmetric matrix `m` (its upper triangle
/// and diagonal are read), by cyclic Jacobi rotations of the matrix scaled by a power of two to
/// its largest entry (exact, so that neither huge nor tiny entries overflow or underflow). A
/// diagonal matrix gives its diagonal exactly. Finite input is assumed: non-finite entries give
/// non-finite values, never a panic.
///
/// ```
/// use manip_dyn::spatial::symmetric_eigen;
/// // A slender rod along (1, 1, 0) / sqrt 2: moments (0, 1, 1).
/// let rod = [[0.5, -0.5, 0.0], [-0.5, 0.5, 0.0], [0.0, 0.0, 1.0]];
/// let eigen = symmetric_eigen(&rod);
/// assert!(eigen.values[0].abs() < 1e-16);
/// assert!((eigen.values[1] - 1.0).abs() < 1e-15 && (eigen.values[2] - 1.0).abs() < 1e-15);
/// let axis = [eigen.vectors[0][0], eigen.vectors[1][0], eigen.vectors[2][0]];
/// assert!((axis[0] * axis[1] - 0.5).abs() < 1e-15);
/// ```
pub fn symmetric_eigen(m: &Mat3) -> SymmetricEigen {
    let upper = |r: usize, c: usize| if r <= c { m[r][c] } else { m[c][r] };
    let largest = (0..3)
        .flat_map(|r| (r..3).map(move |c| (r, c)))
        .fold(0.0f64, |x, (r, c)| x.max(upper(r, c).abs()));
    if largest == 0.0 {
        return SymmetricEigen {
            values: [0.0; 3],
            vectors: IDENTITY,
        };
    }
    // 2^-e with 2^e <= largest < 2^(e+1), both powers normal numbers.
    let exponent = (largest.log2().floor() as i32).clamp(-1022, 1022);
    let down = power_of_two(-exponent);
    let mut a = [0, 1, 2].map(|r| [0, 1, 2].map(|c| upper(r, c) * down));
    let negligible = NEGLIGIBLE_TO_LARGEST * largest * down;
    let mut v = IDENTITY;
    for _ in 0..MAX_SWEEPS {
        if a[0][1] == 0.0 && a[0][2] == 0.0 && a[1][2] == 0.0 {
            break;
        }
        for (p, q, r) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
            rotate(&mut a, &mut v, p, q, r, negligible);
        }
    }
    let up = power_of_two(exponent);
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let mut vectors = [0, 1, 2].map(|row| order.map(|k| v[row][k]));
    // An odd permutation of the columns reverses the orientation: turn one axis round.
    let inversions = usize::from(order[0] > order[1])
        + usize::from(order[0] > order[2])
        + usize::from(order[1] > order[2]);
    if inversions % 2 == 1 {
        for row in &mut vectors {
            row[0] = -row[0];
        }
    }
    SymmetricEigen {
        values: order.map(|k| a[k][k] * up),
        vectors,
    }
}

/// The Jacobi rotation in the `(p, q)` plane (`r` the third index) that zeroes `a[p][q]`
/// (Numerical Recipes' form: `t = tan` of the angle, the smaller root, so `|angle| <= pi/4`),
/// applied to `a` and accumulated into the eigenvectors `v`. An entry already negligible (at
/// most `negligible`, or [`NEGLIGIBLE_TO_DIAGONAL`] of both diagonal entries) is set to zero
/// instead.
fn rotate(a: &mut Mat3, v: &mut Mat3, p: usize, q: usize, r: usize, negligible: f64) {
    let apq = a[p][q];
    let below = |diagonal: f64| apq.abs() <= NEGLIGIBLE_TO_DIAGONAL * diagonal.abs();
    if apq.abs() <= negligible || (below(a[p][p]) && below(a[q][q])) {
        a[p][q] = 0.0;
        a[q][p] = 0.0;
        return;
    }
    let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    // hypot does not overflow for a huge theta; t is then about 1 / (2 theta).
    let t = theta.signum() / (theta.abs() + theta.hypot(1.0));
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    a[p][p] -= t * apq;
    a[q][q] += t * apq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    let (arp, arq) = (a[r][p], a[r][q]);
    a[r][p] = c * arp - s * arq;
    a[r][q] = s * arp + c * arq;
    a[p][r] = a[r][p];
    a[q][r] = a[r][q];
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - s * vq;
        row[q] = s * vp + c * vq;
    }
}

/// `2^k` for `-1022 <= k <= 1023` (a normal number), exactly.
fn power_of_two(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powers_of_two_are_exact() {
        assert_eq!(power_of_two(0), 1.0);
        assert_eq!(power_of_two(-3), 0.125);
        assert_eq!(power_of_two(1022), 2f64.powi(1022));
        assert_eq!(power_of_two(-1022), f64::MIN_POSITIVE);
    }

    #[test]
    fn zero_and_non_finite_matrices_end() {
        let zero = symmetric_eigen(&[[0.0; 3]; 3]);
        assert_eq!(zero.values, [0.0; 3]);
        assert_eq!(zero.vectors, IDENTITY);
        let nan = symmetric_eigen(&[[1.0, f64::NAN, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(nan.values.iter().any(|x| x.is_nan()));
        let inf = symmetric_eigen(&[[f64::INFINITY, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0; 3]]);
        assert!(inf.values.iter().any(|x| !x.is_finite()));
    }
}
