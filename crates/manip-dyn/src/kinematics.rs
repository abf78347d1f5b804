//! The forward pass every algorithm starts with: each link's direction and angular velocity.

/// Where link `i` points and how fast it turns, in the base frame: `T = f64` for one state, or
/// the lanes of several states side by side (the ABA batch, see `crate::aba::AbaLane`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LinkFrame<T = f64> {
    /// Unit vector `u_i = (cos phi_i, sin phi_i)` from joint `i` to joint `i + 1`, where
    /// `phi_i = theta_1 + ... + theta_i` is the absolute angle.
    pub axis: [T; 2],
    /// Absolute angular velocity `omega_i = theta_dot_1 + ... + theta_dot_i` (0 without `v`).
    pub omega: T,
}

impl LinkFrame {
    /// `e_z x u_i = (-sin phi_i, cos phi_i)`: the direction a point of the link moves when the
    /// link turns about one of its points behind it.
    pub fn normal(&self) -> [f64; 2] {
        [-self.axis[1], self.axis[0]]
    }
}

/// Fills `frames` from the joint angles `q` and, if given, the joint rates `v` (inputs already
/// validated).
pub(crate) fn update_frames(frames: &mut [LinkFrame], q: &[f64], v: Option<&[f64]>) {
    let mut phi = 0.0;
    let mut omega = 0.0;
    for (i, frame) in frames.iter_mut().enumerate() {
        phi += q[i];
        omega += v.map_or(0.0, |v| v[i]);
        let (sin, cos) = phi.sin_cos();
        *frame = LinkFrame {
            axis: [cos, sin],
            omega,
        };
    }
}

/// Planar dot product.
pub(crate) fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Planar cross product (the `z` component of `a x b`).
pub(crate) fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
