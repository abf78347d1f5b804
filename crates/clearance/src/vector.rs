//! Vector arithmetic on `[f64; D]`: three dimensions for spatial chains, two for the planar
//! fast path (a planar arm lies in `z = 0`, where the third coordinate only adds zeros).

/// A vector of `D` coordinates.
pub(crate) type V<const D: usize> = [f64; D];

/// A vector of space.
pub(crate) type V3 = V<3>;

#[inline]
pub(crate) fn sub<const D: usize>(a: V<D>, b: V<D>) -> V<D> {
    std::array::from_fn(|k| a[k] - b[k])
}

#[inline]
pub(crate) fn add<const D: usize>(a: V<D>, b: V<D>) -> V<D> {
    std::array::from_fn(|k| a[k] + b[k])
}

#[inline]
pub(crate) fn scale<const D: usize>(a: V<D>, s: f64) -> V<D> {
    a.map(|x| x * s)
}

/// `a . b`, summed from the first coordinate.
#[inline]
pub(crate) fn dot<const D: usize>(a: V<D>, b: V<D>) -> f64 {
    let mut sum = a[0] * b[0];
    for k in 1..D {
        sum += a[k] * b[k];
    }
    sum
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
pub(crate) fn lerp<const D: usize>(a: V<D>, b: V<D>, t: f64) -> V<D> {
    add(a, scale(sub(b, a), t))
}

/// `R^T v` for a rotation whose columns are `r[0], ..., r[D - 1]`.
#[inline]
pub(crate) fn to_local<const D: usize>(r: &[V<D>; D], v: V<D>) -> V<D> {
    std::array::from_fn(|k| dot(r[k], v))
}

/// `R v` for a rotation whose columns are `r[0], ..., r[D - 1]`.
#[inline]
pub(crate) fn to_world<const D: usize>(r: &[V<D>; D], v: V<D>) -> V<D> {
    let mut sum = scale(r[0], v[0]);
    for k in 1..D {
        sum = add(sum, scale(r[k], v[k]));
    }
    sum
}

/// The first two coordinates of `v`.
#[inline]
pub(crate) fn planar(v: V3) -> V<2> {
    [v[0], v[1]]
}

/// `v` in space: its coordinates, then zeros (for `D = 2`, the plane `z = 0`).
#[inline]
pub(crate) fn widen<const D: usize>(v: V<D>) -> V3 {
    std::array::from_fn(|k| if k < D { v[k] } else { 0.0 })
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
