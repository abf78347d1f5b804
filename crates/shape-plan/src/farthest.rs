//! The farthest point of a segment (a link) from a channel's centreline and guide: the largest
//! of [`Channel::distance`] along the segment, which the wall clearance of a deployment needs
//! exactly (a link cutting a bend is farthest from the centreline between its ends).
//!
//! Along the segment `x(t) = p + t (q - p)`, `t` in `[0, 1]`, the distance is the least of the
//! distances to the guide and to each centreline segment (the features), each convex in `t`.
//! A branch and bound over `t` keeps intervals whose bound exceeds the largest distance found
//! by more than a tolerance, and halves them; on an interval the distance is at most
//!
//! - the largest of `min(d_i, d_j)` for the features `i`, `j` nearest at its ends, found exactly
//!   where the two cross (their squares are quadratics in `t` between the breakpoints where the
//!   nearest point of a feature passes one of its ends), so that a bend's corner, where the two
//!   legs are equally far, is one step, not a halving down to the tolerance;
//! - the mean of its end values plus half the interval's length (the distance is 1-Lipschitz).
//!
//! Only features near enough to be nearest somewhere on the segment enter: those within the
//! last bound of the whole segment, found by the centreline's chunk boxes.
//!
//! The work is bounded twice: by [`MAX_FARTHEST_INTERVALS`] a call, and by an allowance of
//! measurements (a point against a feature) that grows by [`FARTHEST_ALLOWANCE`] a call and
//! carries over between the calls of one [`FarthestScratch`], so that a costly link is paid for
//! by cheap ones and `k` calls measure at most `k` allowances whatever the centreline. A call
//! that runs out answers with a bound at or above the exact distance.

use crate::channel::Channel;
use crate::polyline::{point_segment, point_segment_squared};

/// Most intervals [`Channel::farthest`] halves on one segment before it answers with its bound.
pub const MAX_FARTHEST_INTERVALS: usize = 1_000;

/// Measurements of a point against a feature that each call of [`Channel::farthest`] adds to
/// its scratch's allowance (the module documentation): some 10 us, against a mean of about
/// 2,900 for links among centrelines of a point every 0.1 to 0.3 mm.
pub const FARTHEST_ALLOWANCE: usize = 4_096;

/// Most features near a segment (the guide among them) for the branch and bound (each interval
/// measures every one): past it (a centreline of thousands of points within a link's reach), the distance is
/// sampled at [`FALLBACK_SAMPLES`] + 1 points and the answer is their largest plus half their
/// spacing, at or above the exact one.
pub const MAX_NEAR_FEATURES: usize = 256;

/// Intervals of the sampled answer past [`MAX_NEAR_FEATURES`].
pub const FALLBACK_SAMPLES: usize = 64;

/// More halvings than a parameter in `[0, 1]` can take before its intervals are empty (a
/// double's 53 significant bits and its exponents down to `2^-1074`).
const MAX_HALVINGS: usize = 1100;

/// A feature of the channel: a centreline segment `a`-`b`, or the guide (the ray from the entry
/// `a` along `-d`, `b` unused).
#[derive(Debug, Clone, Copy)]
struct Feature {
    a: [f64; 2],
    b: [f64; 2],
    ray: bool,
}

/// An interval of the parameter left to examine: its ends, the distances there and the
/// features nearest there.
#[derive(Debug, Clone, Copy)]
struct Interval {
    t: [f64; 2],
    d: [f64; 2],
    nearest: [usize; 2],
}

/// The reusable work of [`Channel::farthest`]: the features near the segment measured, the
/// intervals left to examine, and the measurements the calls so far have left unspent (the
/// module documentation). [`Default`] grows it to what any call needs ([`MAX_NEAR_FEATURES`],
/// and the intervals of the deepest halving a double's parameter allows), so that the calls
/// allocate nothing, and starts with no allowance.
#[derive(Debug, Clone)]
pub struct FarthestScratch {
    near: Vec<Feature>,
    intervals: Vec<Interval>,
    allowance: usize,
}

impl Default for FarthestScratch {
    fn default() -> Self {
        Self {
            near: Vec::with_capacity(MAX_NEAR_FEATURES),
            intervals: Vec::with_capacity(MAX_HALVINGS + 2),
            allowance: 0,
        }
    }
}

impl FarthestScratch {
    /// The measurements of a point against a feature that later calls may spend beyond their
    /// own [`FARTHEST_ALLOWANCE`].
    pub fn allowance(&self) -> usize {
        self.allowance
    }
}

impl Channel {
    /// The largest [`distance`](Self::distance) of a point of the segment `p`-`q` (the module's
    /// branch and bound): at most `1e-14` of the segment's length or its largest coordinate
    /// below the exact one. Past [`MAX_FARTHEST_INTERVALS`] intervals or the scratch's
    /// allowance of measurements (never met by the tests' channels and links but one built to
    /// exhaust it), the smaller of the largest bound left and the sampled bound, and past
    /// [`MAX_NEAR_FEATURES`] features near the segment, the sampled bound (the largest of
    /// [`FALLBACK_SAMPLES`] + 1 samples plus half their spacing): at or above the exact one.
    /// `scratch` holds the work ([`FarthestScratch::default`]), so that calls allocate nothing.
    pub fn farthest(&self, p: [f64; 2], q: [f64; 2], scratch: &mut FarthestScratch) -> f64 {
        let v = [q[0] - p[0], q[1] - p[1]];
        let length = v[0].hypot(v[1]);
        let at = |t: f64| [p[0] + t * v[0], p[1] + t * v[1]];
        let (f0, f1) = (self.distance(p), self.distance(q));
        // Far above the distances' rounding, so that a flat stretch is not halved for ever.
        let scale = [p[0], p[1], q[0], q[1]]
            .iter()
            .fold(length, |m, x| m.max(x.abs()));
        let tolerance = 1e-14 * scale;
        // The Lipschitz bound of the whole segment: a feature farther than it from every point
        // of `p`-`q` is nearest nowhere on it.
        let reach = 0.5 * (f0 + f1 + length) * (1.0 + 1e-9);
        let bounds = [
            [p[0].min(q[0]), p[1].min(q[1])],
            [p[0].max(q[0]), p[1].max(q[1])],
        ];
        let FarthestScratch {
            near,
            intervals,
            allowance,
        } = scratch;
        *allowance = allowance.saturating_add(FARTHEST_ALLOWANCE);
        near.clear();
        near.push(Feature {
            a: self.entry(),
            b: self.entry(),
            ray: true,
        });
        let mut crowded = false;
        self.line().segments_near(bounds, reach, |a, b| {
            if near.len() < MAX_NEAR_FEATURES {
                near.push(Feature { a, b, ray: false });
            } else {
                crowded = true;
            }
        });
        // The largest of the samples plus half their spacing (the distance is 1-Lipschitz along
        // the segment): at or above the exact answer, for a bounded cost.
        let sampled = || {
            let largest = (0..=FALLBACK_SAMPLES)
                .map(|k| self.distance(at(k as f64 / FALLBACK_SAMPLES as f64)))
                .fold(0.0, f64::max);
            largest + 0.5 * length / FALLBACK_SAMPLES as f64
        };
        if crowded {
            return sampled();
        }
        let distance = |feature: &Feature, x: [f64; 2]| {
            if feature.ray {
                self.guide_distance(x)
            } else {
                point_segment(x, feature.a, feature.b)
            }
        };
        // The distance at `x` and the feature nearest there, as `Channel::distance` measures it
        // (the segments' squares, one square root), every feature that can be nearest on the
        // segment being in `near` (the guide first).
        let nearest = |x: [f64; 2]| {
            let (square, segment) = near
                .iter()
                .enumerate()
                .skip(1)
                .map(|(k, feature)| (point_segment_squared(x, feature.a, feature.b), k))
                .fold((f64::INFINITY, 0), |best, this| {
                    if this.0 < best.0 { this } else { best }
                });
            let guide = self.guide_distance(x);
            if guide <= square.sqrt() {
                (guide, 0)
            } else {
                (square.sqrt(), segment)
            }
        };
        // Within the allowance just added: two measurements of at most MAX_NEAR_FEATURES.
        *allowance -= 2 * near.len();
        let (_, n0) = nearest(p);
        let (_, n1) = nearest(q);
        let mut best = f0.max(f1);
        intervals.clear();
        intervals.push(Interval {
            t: [0.0, 1.0],
            d: [f0, f1],
            nearest: [n0, n1],
        });
        let mut examined = 0;
        while let Some(interval) = intervals.pop() {
            let ([t0, t1], [d0, d1]) = (interval.t, interval.d);
            let lipschitz = 0.5 * (d0 + d1 + (t1 - t0) * length);
            let [i, j] = interval.nearest.map(|k| near[k]);
            let pair = pair_bound(
                &i,
                &j,
                [t0, t1],
                |t| {
                    let x = at(t);
                    distance(&i, x).min(distance(&j, x))
                },
                self.axis(),
                p,
                v,
            );
            let bound = lipschitz.min(pair);
            if bound <= best + tolerance {
                continue;
            }
            examined += 1;
            if examined > MAX_FARTHEST_INTERVALS || *allowance < near.len() {
                let left = intervals
                    .iter()
                    .map(|i| 0.5 * (i.d[0] + i.d[1] + (i.t[1] - i.t[0]) * length))
                    .fold(bound, f64::max);
                return best.max(left).min(sampled());
            }
            let middle = 0.5 * (t0 + t1);
            *allowance -= near.len();
            let (dm, nm) = nearest(at(middle));
            best = best.max(dm);
            intervals.push(Interval {
                t: [t0, middle],
                d: [d0, dm],
                nearest: [interval.nearest[0], nm],
            });
            intervals.push(Interval {
                t: [middle, t1],
                d: [dm, d1],
                nearest: [nm, interval.nearest[1]],
            });
        }
        best
    }
}

/// The largest of `min(d_i, d_j)` over `[t0, t1]` (`min_ij(t)` evaluates it): at the interval's
/// ends, at the breakpoints of either feature (where its nearest point passes one of its ends)
/// and where the two squared distances, quadratics in `t` between breakpoints, are equal.
/// `axis` is the guide's direction `d`, `p + t v` the segment.
fn pair_bound(
    i: &Feature,
    j: &Feature,
    [t0, t1]: [f64; 2],
    min_ij: impl Fn(f64) -> f64,
    axis: [f64; 2],
    p: [f64; 2],
    v: [f64; 2],
) -> f64 {
    let (i, j) = (Line::of(i, axis), Line::of(j, axis));
    let mut cuts = [0.0; 6];
    let mut n = 0;
    for t in i
        .breakpoints(p, v)
        .into_iter()
        .chain(j.breakpoints(p, v))
        .flatten()
    {
        if t > t0 && t < t1 {
            cuts[n] = t;
            n += 1;
        }
    }
    let cuts = &mut cuts[..n];
    cuts.sort_by(f64::total_cmp);
    let mut largest = min_ij(t0).max(min_ij(t1));
    let mut start = t0;
    for end in cuts.iter().copied().chain([t1]) {
        largest = largest.max(min_ij(end));
        let middle = 0.5 * (start + end);
        let [a, b, c] =
            std::array::from_fn(|k| i.square(p, v, middle)[k] - j.square(p, v, middle)[k]);
        for t in quadratic_roots(a, b, c).into_iter().flatten() {
            if t > start && t < end {
                largest = largest.max(min_ij(t));
            }
        }
        start = end;
    }
    largest
}

/// A feature as a line: its start `a`, unit direction `u` and length (`inf` for the guide).
struct Line {
    a: [f64; 2],
    u: [f64; 2],
    length: f64,
}

impl Line {
    fn of(feature: &Feature, axis: [f64; 2]) -> Self {
        if feature.ray {
            return Self {
                a: feature.a,
                u: [-axis[0], -axis[1]],
                length: f64::INFINITY,
            };
        }
        let d = [feature.b[0] - feature.a[0], feature.b[1] - feature.a[1]];
        let length = d[0].hypot(d[1]);
        Self {
            a: feature.a,
            u: [d[0] / length, d[1] / length],
            length,
        }
    }

    /// The parameters `t` of `p + t v` where the nearest point of the feature passes its ends
    /// (where `(x(t) - a) . u` is 0 or the length).
    fn breakpoints(&self, p: [f64; 2], v: [f64; 2]) -> [Option<f64>; 2] {
        let s0 = (p[0] - self.a[0]) * self.u[0] + (p[1] - self.a[1]) * self.u[1];
        let sv = v[0] * self.u[0] + v[1] * self.u[1];
        if sv == 0.0 {
            return [None, None];
        }
        let end = (self.length - s0) / sv;
        [Some(-s0 / sv), end.is_finite().then_some(end)]
    }

    /// The squared distance from `p + t v` as `[A, B, C]` of `A t^2 + B t + C`, the quadratic of
    /// the piece `at` lies in.
    fn square(&self, p: [f64; 2], v: [f64; 2], at: f64) -> [f64; 3] {
        let w = [p[0] - self.a[0], p[1] - self.a[1]];
        let s = (w[0] + at * v[0]) * self.u[0] + (w[1] + at * v[1]) * self.u[1];
        let to_point = |c: [f64; 2]| {
            let w = [p[0] - c[0], p[1] - c[1]];
            [
                v[0] * v[0] + v[1] * v[1],
                2.0 * (v[0] * w[0] + v[1] * w[1]),
                w[0] * w[0] + w[1] * w[1],
            ]
        };
        if s <= 0.0 {
            return to_point(self.a);
        }
        if s >= self.length {
            return to_point([
                self.a[0] + self.length * self.u[0],
                self.a[1] + self.length * self.u[1],
            ]);
        }
        // |w + t v|^2 - ((w + t v) . u)^2.
        let (wu, vu) = (
            w[0] * self.u[0] + w[1] * self.u[1],
            v[0] * self.u[0] + v[1] * self.u[1],
        );
        [
            v[0] * v[0] + v[1] * v[1] - vu * vu,
            2.0 * (v[0] * w[0] + v[1] * w[1] - vu * wu),
            w[0] * w[0] + w[1] * w[1] - wu * wu,
        ]
    }
}

/// The real roots of `a t^2 + b t + c` (a linear or constant one when `a` vanishes), by the
/// formula that cancels no digits.
fn quadratic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a == 0.0 {
        return [(b != 0.0).then(|| -c / b), None];
    }
    let discriminant = b * b - 4.0 * a * c;
    if discriminant < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (b + b.signum() * discriminant.sqrt());
    if q == 0.0 {
        return [Some(0.0), None];
    }
    [Some(q / a), Some(c / q)]
}
