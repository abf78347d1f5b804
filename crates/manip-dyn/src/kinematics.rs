//! The forward pass every algorithm starts with: each link's direction and angular velocity.

use crate::data::LinkFrame;

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
