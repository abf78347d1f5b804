//! Three-vector arithmetic on `[f64; 3]` (the planar arm lies in `z = 0`).

pub(crate) type V3 = [f64; 3];

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a + t (b - a)`.
#[inline]
pub(crate) fn lerp(a: V3, b: V3, t: f64) -> V3 {
    add(a, scale(sub(b, a), t))
}

/// `R^T v` for a rotation whose columns are `r[0], r[1], r[2]`.
#[inline]
pub(crate) fn to_local(r: &[V3; 3], v: V3) -> V3 {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// `R v` for a rotation whose columns are `r[0], r[1], r[2]`.
#[inline]
pub(crate) fn to_world(r: &[V3; 3], v: V3) -> V3 {
    add(add(scale(r[0], v[0]), scale(r[1], v[1])), scale(r[2], v[2]))
}

/// `x` clamped to `[-h, h]` for `h >= 0`: `f64::clamp` without its run-time check of the bounds.
#[inline]
pub(crate) fn clamp_symmetric(x: f64, h: f64) -> f64 {
    if x < -h {
        -h
    } else if x > h {
        h
    } else {
        x
    }
}
