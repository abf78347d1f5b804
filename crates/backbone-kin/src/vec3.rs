//! 3-vectors and 3 x 3 matrices as plain arrays: the arithmetic of the spatial modal family's
//! kinematics ([`spatial_chain`](crate::spatial_chain), [`spatial_curve`](crate::spatial_curve)),
//! shared with the spatial reduced dynamics of `modal-reduce`.
//!
//! The arithmetic is generic over [`Lane`]: an `f64` is one value, a
//! [`Pack`](lane_math::Pack) a SIMD register of independent values (the spatial reduced
//! dynamics' batches across states), with the same operations in the same order either way.

use lane_math::Lane;

/// A 3 x 3 matrix, `r[row][column]` (a rotation, or an inertia), of `f64` or of lanes.
pub type Rotation<L = f64> = [[L; 3]; 3];

/// `a + b`.
#[inline(always)]
pub fn add<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline(always)]
pub fn sub<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
#[inline(always)]
pub fn scale<L: Lane>(a: [L; 3], s: L) -> [L; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `a . b`.
#[inline(always)]
pub fn dot<L: Lane>(a: [L; 3], b: [L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
#[inline(always)]
pub fn cross<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a - b|`: the square root of the summed squares, or, where that sum underflows or overflows
/// (an arm of links of `1e-200` m, a target `1e308` m away), the scaled `hypot`, so that a
/// nonzero distance never reads as zero nor a finite one as infinite.
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    let squares = dot(d, d);
    if (f64::MIN_POSITIVE..f64::INFINITY).contains(&squares) {
        squares.sqrt()
    } else {
        d[0].hypot(d[1]).hypot(d[2])
    }
}

/// `A v`.
#[inline(always)]
pub fn mat_vec<L: Lane>(a: &Rotation<L>, v: [L; 3]) -> [L; 3] {
    [dot(a[0], v), dot(a[1], v), dot(a[2], v)]
}

/// The product `a b`.
#[inline(always)]
pub fn mat_mul<L: Lane>(a: Rotation<L>, b: Rotation<L>) -> Rotation<L> {
    // Loops, not closures: a closure is compiled without the instruction set of a SIMD
    // dispatch that inlines this function, and would call its intrinsics.
    let mut product = a;
    for (row, a_row) in product.iter_mut().zip(a) {
        for (j, entry) in row.iter_mut().enumerate() {
            *entry = a_row[0] * b[0][j] + a_row[1] * b[1][j] + a_row[2] * b[2][j];
        }
    }
    product
}

/// Column `j` of `r`.
#[inline(always)]
pub fn column<L: Lane>(r: &Rotation<L>, j: usize) -> [L; 3] {
    [r[0][j], r[1][j], r[2][j]]
}

/// The rotation by `angle` about `x`.
pub fn rot_x(angle: f64) -> Rotation {
    let (s, c) = angle.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

/// The rotation by `angle` about `y`.
pub fn rot_y(angle: f64) -> Rotation {
    let (s, c) = angle.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

/// The rotation by `angle` about `z`.
pub fn rot_z(angle: f64) -> Rotation {
    let (s, c) = angle.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}
