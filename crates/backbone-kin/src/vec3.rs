//! 3-vectors and 3 x 3 matrices as plain arrays: the arithmetic of the spatial modal family's
//! kinematics ([`spatial_chain`](crate::spatial_chain), [`spatial_curve`](crate::spatial_curve)),
//! shared with the spatial reduced dynamics of `modal-reduce`.

/// A 3 x 3 matrix, `r[row][column]` (a rotation, or an inertia).
pub type Rotation = [[f64; 3]; 3];

/// `a + b`.
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [s * a[0], s * a[1], s * a[2]]
}

/// `a . b`.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a - b|`.
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

/// `A v`.
pub fn mat_vec(a: &Rotation, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// The product `a b`.
pub fn mat_mul(a: Rotation, b: Rotation) -> Rotation {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Column `j` of `r`.
pub fn column(r: &Rotation, j: usize) -> [f64; 3] {
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
