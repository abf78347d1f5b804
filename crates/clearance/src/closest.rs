//! Closest points between a segment (a link's axis) and a point, a segment or a box.
//!
//! Each returns the parameter `t` of the closest point `c = a + t (b - a)` on the link's axis, the
//! distance between the cores (signed for a box: negative when `c` is inside) and the unit normal
//! `n`, the gradient of that distance with respect to `c`. By the envelope theorem the distance's
//! gradient with respect to the segment's ends is `(1 - t) n` and `t n`. Where two cores meet
//! (a link's axis through a sphere's centre, two crossing axes) the distance of the cores is
//! zero and stays zero under small motions of crossing axes: the normal is then zero, a
//! subgradient, and the clearance saturates at minus the radii.
//!
//! Each is written for `D`-vectors: a chain turning about `z` among obstacles of the plane
//! runs them in two dimensions (the third coordinate only adds zeros), others in three.

use crate::obstacle::{box_signed_distance, unit_or};
use crate::vector::{V, V3, add, clamp_symmetric, dot, scale, sub, to_local, to_world, widen};

/// The closest point of the link's axis `a`-`b` to a core and the signed distance between them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The parameter of the closest point on the link's axis, in `[0, 1]`.
    pub t: f64,
    /// The closest point on the link's axis.
    pub point: V3,
    /// The closest point on the other core (a point of the box's surface for a box).
    pub other: V3,
    /// The distance between the cores, negative when the link's axis enters a box.
    pub distance: f64,
    /// The unit gradient of `distance` with respect to `point`.
    pub normal: V3,
}

/// The unit vector along `v` and its length; below the rounding of coordinates of size `scale`
/// the cores meet, the direction is noise, and the normal is zero.
#[inline]
fn direction<const D: usize>(v: V<D>, scale: f64) -> (V<D>, f64) {
    let (normal, length) = unit_or(v, [0.0; D]);
    if length <= 1e-12 * scale {
        ([0.0; D], length)
    } else {
        (normal, length)
    }
}

/// A segment `a`-`b` with what every pair of it needs: its start `a`, its axis `b - a`, and the
/// axis' squared length, its inverse (zero for a point) and its length, computed once per link
/// rather than once per pair (a division or a square root costs several multiplications).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Segment<const D: usize> {
    /// The first end.
    pub(crate) start: V<D>,
    /// From the first end to the second.
    pub(crate) axis: V<D>,
    /// `|axis|^2`.
    pub(crate) length2: f64,
    /// `1 / |axis|^2`, or 0 for a point.
    pub(crate) inverse_length2: f64,
    /// `|axis|`.
    pub(crate) length: f64,
}

impl<const D: usize> Segment<D> {
    /// The segment from `a` to `b`.
    #[inline]
    pub(crate) fn new(a: V<D>, b: V<D>) -> Self {
        let axis = sub(b, a);
        let length2 = dot(axis, axis);
        Self {
            start: a,
            axis,
            length2,
            inverse_length2: if length2 > 0.0 { 1.0 / length2 } else { 0.0 },
            length: length2.sqrt(),
        }
    }

    /// The point `a + t (b - a)`.
    #[inline]
    fn at(&self, t: f64) -> V<D> {
        add(self.start, scale(self.axis, t))
    }
}

/// The closest point of the segment `a`-`b` to the point `o`.
///
/// For coordinates up to [`MAX_OBSTACLE_EXTENT`](crate::MAX_OBSTACLE_EXTENT) in magnitude, which
/// [`place`](crate::place) and the obstacles keep; beyond, the squared lengths can overflow to a
/// NaN result.
#[inline]
pub fn segment_point(a: V3, b: V3, o: V3) -> Closest {
    closest_to_point(&Segment::new(a, b), o)
}

/// [`segment_point`] of a prepared segment.
#[inline(always)]
pub(crate) fn closest_to_point<const D: usize>(link: &Segment<D>, o: V<D>) -> Closest {
    let t = if link.length2 > 0.0 {
        (dot(sub(o, link.start), link.axis) * link.inverse_length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let point = link.at(t);
    let (normal, distance) = direction(sub(point, o), link.length);
    Closest {
        t,
        point: widen(point),
        other: widen(o),
        distance,
        normal: widen(normal),
    }
}

/// The closest points of the segments `a`-`b` and `c`-`d` (Ericson, *Real-Time Collision
/// Detection*, 5.1.9, with the degenerate and parallel cases resolved).
///
/// For coordinates up to [`MAX_OBSTACLE_EXTENT`](crate::MAX_OBSTACLE_EXTENT) in magnitude, which
/// [`place`](crate::place) and the obstacles keep; beyond, the squared lengths can overflow to a
/// NaN result.
#[inline]
pub fn segment_segment(a: V3, b: V3, c: V3, d: V3) -> Closest {
    closest_to_segment(&Segment::new(a, b), &Segment::new(c, d))
}

/// [`segment_segment`] of two prepared segments.
#[inline(always)]
pub(crate) fn closest_to_segment<const D: usize>(link: &Segment<D>, other: &Segment<D>) -> Closest {
    closest_at(link, other, segment_parameters(link, other))
}

/// The parameters `(t, s)` of the closest points of two prepared segments, on `link` and on
/// `other`.
#[inline(always)]
pub(crate) fn segment_parameters<const D: usize>(
    link: &Segment<D>,
    other: &Segment<D>,
) -> (f64, f64) {
    let (d1, d2) = (link.axis, other.axis);
    let r = sub(link.start, other.start);
    let (aa, ee, f) = (link.length2, other.length2, dot(d2, r));
    let (inverse_aa, inverse_ee) = (link.inverse_length2, other.inverse_length2);
    if aa <= 0.0 && ee <= 0.0 {
        (0.0, 0.0)
    } else if aa <= 0.0 {
        (0.0, (f * inverse_ee).clamp(0.0, 1.0))
    } else {
        let cc = dot(d1, r);
        if ee <= 0.0 {
            ((-cc * inverse_aa).clamp(0.0, 1.0), 0.0)
        } else {
            let bb = dot(d1, d2);
            let denom = aa * ee - bb * bb;
            let mut t = if denom > 0.0 {
                ((bb * f - cc * ee) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut s = (bb * t + f) * inverse_ee;
            if s < 0.0 {
                s = 0.0;
                t = (-cc * inverse_aa).clamp(0.0, 1.0);
            } else if s > 1.0 {
                s = 1.0;
                t = ((bb - cc) * inverse_aa).clamp(0.0, 1.0);
            }
            (t, s)
        }
    }
}

/// The closest points at the parameters `(t, s)` of [`segment_parameters`].
#[inline(always)]
pub(crate) fn closest_at<const D: usize>(
    link: &Segment<D>,
    other: &Segment<D>,
    (t, s): (f64, f64),
) -> Closest {
    let (point, closest_other) = (link.at(t), other.at(s));
    let (normal, distance) = direction(sub(point, closest_other), link.length + other.length);
    Closest {
        t,
        point: widen(point),
        other: widen(closest_other),
        distance,
        normal: widen(normal),
    }
}

/// The point of the segment `a`-`b` deepest in (or closest to) the box of `center`, `half`
/// and `axes` (the columns of its rotation), and its signed distance.
///
/// The box's signed distance along the segment, `f(t)`, is convex (the signed distance of a
/// convex set is convex). Where the segment meets the box (clipped to the slabs
/// `|q_k| <= h_k`, Liang and Barsky) `f` is the largest of the affine depths `+-q_k(t) - h_k`,
/// whose minimum on the clipped interval is at one of its ends or at a kink where two depths
/// tie (`deepest_inside`). Elsewhere `f = sqrt(D)` with `D` the squared distance, a sum of
/// convex, continuously differentiable per-axis pieces (`nearest_outside`).
///
/// For coordinates up to [`MAX_OBSTACLE_EXTENT`](crate::MAX_OBSTACLE_EXTENT) in magnitude, which
/// [`place`](crate::place) and the obstacles keep; beyond, the squared lengths can overflow to a
/// NaN result.
pub fn segment_box(a: V3, b: V3, center: V3, half: V3, axes: &[V3; 3]) -> Closest {
    closest_to_box(&Segment::new(a, b), center, half, axes)
}

/// [`segment_box`] of a prepared segment.
#[inline(always)]
pub(crate) fn closest_to_box<const D: usize>(
    link: &Segment<D>,
    center: V<D>,
    half: V<D>,
    axes: &[V<D>; D],
) -> Closest {
    let q0 = to_local(axes, sub(link.start, center));
    let dq = to_local(axes, link.axis);
    let at = |t: f64| along(q0, dq, t);
    let t = match clip(q0, dq, half) {
        Some((enter, exit)) => deepest_inside(q0, dq, half, enter, exit),
        None => nearest_outside(q0, dq, half),
    };
    let q = at(t);
    // The gradient of the box's signed distance at q: outward from the nearest surface point.
    let mut outside = [0.0; D];
    let (mut deepest, mut face) = (f64::NEG_INFINITY, 0);
    for k in 0..D {
        outside[k] = q[k] - clamp_symmetric(q[k], half[k]);
        let gap = q[k].abs() - half[k];
        if gap > deepest {
            (deepest, face) = (gap, k);
        }
    }
    let (mut local_normal, gap) = unit_or(outside, {
        let mut n = [0.0; D];
        n[face] = if q[face] < 0.0 { -1.0 } else { 1.0 };
        n
    });
    // Outside, the normal's length is the signed distance: the same squares summed in the
    // same order (a positive length has no axis where an infinite `q_k` meets its infinite
    // half-extent, which `box_signed_distance` leaves out).
    let distance = if gap > 0.0 {
        gap
    } else {
        box_signed_distance(q, half)
    };
    if gap == 0.0 && t > 0.0 && t < 1.0 {
        local_normal = inside_kink_normal(q, dq, half, deepest).unwrap_or(local_normal);
    }
    let mut surface = q;
    if gap > 0.0 {
        for k in 0..D {
            surface[k] = clamp_symmetric(q[k], half[k]);
        }
    } else {
        surface[face] = half[face].copysign(q[face]);
    }
    let normal = to_world(axes, local_normal);
    Closest {
        t,
        point: widen(link.at(t)),
        other: widen(add(center, to_world(axes, surface))),
        distance,
        normal: widen(normal),
    }
}

/// `q0 + t dq`.
#[inline]
fn along<const D: usize>(q0: V<D>, dq: V<D>, t: f64) -> V<D> {
    std::array::from_fn(|k| q0[k] + t * dq[k])
}

/// The parameters `[enter, exit]` of `[0, 1]` where `q0 + t dq` lies in the closed box
/// `|q_k| <= h_k` (Liang and Barsky's slab clipping); `None` when the segment misses it.
fn clip<const D: usize>(q0: V<D>, dq: V<D>, half: V<D>) -> Option<(f64, f64)> {
    // Both ends beyond the same face: no division needed.
    for k in 0..D {
        let (from, to) = (q0[k], q0[k] + dq[k]);
        if from.min(to) > half[k] || from.max(to) < -half[k] {
            return None;
        }
    }
    let (mut enter, mut exit) = (0.0_f64, 1.0_f64);
    for k in 0..D {
        if dq[k] == 0.0 {
            if q0[k].abs() > half[k] {
                return None;
            }
        } else {
            let low = (-half[k] - q0[k]) / dq[k];
            let high = (half[k] - q0[k]) / dq[k];
            enter = enter.max(low.min(high));
            exit = exit.min(low.max(high));
        }
    }
    (enter <= exit).then_some((enter, exit))
}

/// The deepest point of the clipped segment `[enter, exit]` inside the box: the depth
/// `g(t) = max_k (|q_k(t)| - h_k)` is the largest of six affine functions, so its minimum is at
/// an end of the interval or at a kink, where `q_k` crosses `0` or two faces' depths
/// `+-q_j - h_j`, `+-q_k - h_k` tie. Of equal depths the smallest `t` is kept.
fn deepest_inside<const D: usize>(q0: V<D>, dq: V<D>, half: V<D>, enter: f64, exit: f64) -> f64 {
    let depth = |t: f64| {
        let mut deepest = f64::NEG_INFINITY;
        for k in 0..D {
            deepest = deepest.max((q0[k] + t * dq[k]).abs() - half[k]);
        }
        deepest
    };
    let mut best = (enter, depth(enter));
    let mut consider = |t: f64| {
        if t > enter && t <= exit {
            let value = depth(t);
            if value < best.1 || (value == best.1 && t < best.0) {
                best = (t, value);
            }
        }
    };
    consider(exit);
    for k in 0..D {
        if dq[k] != 0.0 {
            consider(-q0[k] / dq[k]);
        }
    }
    for (j, k) in [(0, 1), (0, 2), (1, 2)] {
        if k >= D || !(half[j].is_finite() && half[k].is_finite()) {
            continue;
        }
        for (sj, sk) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let slope = sj * dq[j] - sk * dq[k];
            if slope != 0.0 {
                consider((half[j] - half[k] - sj * q0[j] + sk * q0[k]) / slope);
            }
        }
    }
    best.0
}

/// The point of a segment that misses the box nearest to it: the squared distance
/// `D(t) = sum_k e_k(t)^2`, `e_k = q_k - clamp(q_k, -h_k, h_k)`, is convex and continuously
/// differentiable with `D'(t) / 2 = sum_k e_k dq_k` piecewise affine between the parameters where
/// a `q_k` crosses `+-h_k`. Bisecting on the sign of `D'` at those parameters finds the piece
/// holding its zero, where `D' = 0` is solved in closed form.
fn nearest_outside<const D: usize>(q0: V<D>, dq: V<D>, half: V<D>) -> f64 {
    let at = |t: f64| along(q0, dq, t);
    let slope = |t: f64| {
        let q = at(t);
        let mut sum = 0.0;
        for k in 0..D {
            sum += (q[k] - clamp_symmetric(q[k], half[k])) * dq[k];
        }
        sum
    };
    if slope(0.0) >= 0.0 {
        return 0.0;
    }
    if slope(1.0) <= 0.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for k in 0..D {
        if dq[k] != 0.0 && half[k].is_finite() {
            for bound in [half[k], -half[k]] {
                // A bound behind the start (`t <= 0 <= lo`) needs no division.
                let ahead = bound - q0[k];
                if ahead != 0.0 && (ahead > 0.0) != (dq[k] > 0.0) {
                    continue;
                }
                let t = ahead / dq[k];
                if t > lo && t < hi {
                    if slope(t) < 0.0 {
                        lo = t;
                    } else {
                        hi = t;
                    }
                }
            }
        }
    }
    // On (lo, hi) each axis is below, within or above its slab throughout.
    let mid = at(0.5 * (lo + hi));
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..D {
        let bound = if mid[k] > half[k] {
            half[k]
        } else if mid[k] < -half[k] {
            -half[k]
        } else {
            continue;
        };
        num -= (q0[k] - bound) * dq[k];
        den += dq[k] * dq[k];
    }
    if den > 0.0 {
        (num / den).clamp(lo, hi)
    } else {
        hi
    }
}

/// Inside the box the depth along the segment is the largest of the affine pieces
/// `sigma q_k(t) - h_k`; at a minimum where two of them tie with slopes of opposite sign, the
/// minimum's gradient is their normals' combination `lambda n_- + (1 - lambda) n_+` that makes
/// the slope zero, `lambda s_- + (1 - lambda) s_+ = 0`. `None` when one piece is active.
fn inside_kink_normal<const D: usize>(q: V<D>, dq: V<D>, half: V<D>, deepest: f64) -> Option<V<D>> {
    let tolerance = 1e-9 * (1.0 + deepest.abs());
    // (slope, normal) of the active pieces with the smallest and the largest slope.
    let mut falling: Option<(f64, V<D>)> = None;
    let mut rising: Option<(f64, V<D>)> = None;
    for k in 0..D {
        for sign in [-1.0, 1.0] {
            if (sign * q[k] - half[k] - deepest).abs() > tolerance {
                continue;
            }
            let slope = sign * dq[k];
            let mut normal = [0.0; D];
            normal[k] = sign;
            if falling.is_none_or(|(s, _)| slope < s) {
                falling = Some((slope, normal));
            }
            if rising.is_none_or(|(s, _)| slope > s) {
                rising = Some((slope, normal));
            }
        }
    }
    let ((down, n_down), (up, n_up)) = (falling?, rising?);
    if !(down < 0.0 && up > 0.0) {
        return None;
    }
    let lambda = up / (up - down);
    Some(std::array::from_fn(|k| {
        lambda * n_down[k] + (1.0 - lambda) * n_up[k]
    }))
}
