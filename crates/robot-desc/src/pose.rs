//! Rigid transforms as URDF writes them (`<origin xyz rpy>`) and the little rotation algebra
//! that merging fixed links and writing MJCF need.

/// A 3x3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The identity rotation.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A frame relative to its parent, as URDF's `<origin xyz="x y z" rpy="roll pitch yaw"/>`:
/// the rotation is `R = Rz(yaw) Ry(pitch) Rx(roll)` (fixed axes x, then y, then z), and a point
/// `p` of the frame is `R p + xyz` in the parent. The numbers are kept as read, so that a model
/// written back gives the same bits.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Translation (m).
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw (rad).
    pub rpy: [f64; 3],
}

impl Pose {
    /// The identity transform.
    pub const IDENTITY: Pose = Pose {
        xyz: [0.0; 3],
        rpy: [0.0; 3],
    };

    /// True for the identity (all six numbers zero).
    pub fn is_identity(&self) -> bool {
        self.xyz.iter().chain(&self.rpy).all(|&v| v == 0.0)
    }

    /// The rotation matrix `Rz(yaw) Ry(pitch) Rx(roll)`.
    pub fn rotation(&self) -> Mat3 {
        rpy_matrix(self.rpy)
    }

    /// `self * other`: the pose of a frame given relative to `self`'s frame, in `self`'s parent.
    /// Exact when `self` is the identity.
    pub fn compose(&self, other: &Pose) -> Pose {
        if self.is_identity() {
            return *other;
        }
        let r = self.rotation();
        let t = mat_vec(&r, other.xyz);
        Pose {
            xyz: [self.xyz[0] + t[0], self.xyz[1] + t[1], self.xyz[2] + t[2]],
            rpy: matrix_rpy(&mat_mul(&r, &other.rotation())),
        }
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose {
        let rt = transpose(&self.rotation());
        let t = mat_vec(&rt, self.xyz);
        Pose {
            xyz: [-t[0], -t[1], -t[2]],
            rpy: matrix_rpy(&rt),
        }
    }
}

/// `Rz(y) Ry(p) Rx(r)` of `[r, p, y]`.
pub fn rpy_matrix([roll, pitch, yaw]: [f64; 3]) -> Mat3 {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Roll, pitch, yaw of a rotation matrix (the inverse of [`rpy_matrix`], pitch in
/// `[-pi/2, pi/2]`; at pitch `+-pi/2` the roll is taken as zero).
pub fn matrix_rpy(r: &Mat3) -> [f64; 3] {
    let cos_pitch = r[0][0].hypot(r[1][0]);
    let pitch = (-r[2][0]).atan2(cos_pitch);
    if cos_pitch > 1e-12 {
        [r[2][1].atan2(r[2][2]), pitch, r[1][0].atan2(r[0][0])]
    } else {
        [0.0, pitch, (-r[0][1]).atan2(r[1][1])]
    }
}

/// The unit quaternion `[w, x, y, z]` of a rotation matrix (Shepperd's method, `w >= 0`).
pub fn matrix_quaternion(r: &Mat3) -> [f64; 4] {
    let trace = r[0][0] + r[1][1] + r[2][2];
    let q = if trace > 0.0 {
        let s = 2.0 * (1.0 + trace).sqrt();
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = 2.0 * (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt();
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = 2.0 * (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt();
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    if q[0] < 0.0 { q.map(|v| -v) } else { q }
}

/// `a b`.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            *entry = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    c
}

/// `a v`.
pub fn mat_vec(a: &Mat3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// `a^T`.
pub fn transpose(a: &Mat3) -> Mat3 {
    [0, 1, 2].map(|i| [a[0][i], a[1][i], a[2][i]])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() <= tol))
    }

    #[test]
    fn rpy_is_fixed_axes_x_then_y_then_z() {
        // A quarter turn of roll maps y to z; a quarter turn of yaw then maps x to y.
        let r = rpy_matrix([std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        let y = mat_vec(&r, [0.0, 1.0, 0.0]);
        assert!((y[2] - 1.0).abs() < 1e-15 && y[1].abs() < 1e-15);
        let r = rpy_matrix([
            std::f64::consts::FRAC_PI_2,
            0.0,
            std::f64::consts::FRAC_PI_2,
        ]);
        // x -> (roll) x -> (yaw) y.
        let x = mat_vec(&r, [1.0, 0.0, 0.0]);
        assert!((x[1] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn rpy_round_trips_through_the_matrix() {
        for rpy in [
            [0.3, -1.2, 2.9],
            [-3.0, 1.5, 0.1],
            [1.0, std::f64::consts::FRAC_PI_2, 0.5],
        ] {
            let r = rpy_matrix(rpy);
            assert!(close(&rpy_matrix(matrix_rpy(&r)), &r, 1e-14), "{rpy:?}");
        }
    }

    #[test]
    fn quaternion_rotates_as_the_matrix() {
        for rpy in [
            [0.3, -1.2, 2.9],
            [-3.0, 1.5, 0.1],
            [3.1, 0.0, 0.0],
            [0.0, 3.1, 0.0],
        ] {
            let r = rpy_matrix(rpy);
            let q = test_support::numeric::quaternion_matrix(matrix_quaternion(&r));
            assert!(close(&q, &r, 1e-14), "{rpy:?}");
        }
    }

    #[test]
    fn compose_and_inverse_give_the_identity() {
        let a = Pose {
            xyz: [0.1, -0.4, 2.0],
            rpy: [0.3, -1.2, 2.9],
        };
        let i = a.compose(&a.inverse());
        assert!(i.xyz.iter().chain(&i.rpy).all(|v| v.abs() < 1e-14), "{i:?}");
    }
}
