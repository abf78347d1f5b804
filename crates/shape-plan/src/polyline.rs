//! A planar polyline that answers "how far is this point" quickly: its segments in chunks of
//! [`CHUNK`] with each chunk's bounding box, so that a query measures every segment only of the
//! chunks whose box is nearer than the nearest segment found; and the distances of points from
//! points and segments it is made of.

/// Segments a chunk holds.
const CHUNK: usize = 32;

/// A polyline, its points in order, and the bounding box of each chunk of [`CHUNK`] segments
/// (the points `CHUNK c` to `CHUNK (c + 1)`).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Polyline {
    points: Vec<[f64; 2]>,
    /// Per chunk, the lower and upper corners of its box.
    boxes: Vec<[[f64; 2]; 2]>,
}

impl Polyline {
    /// The polyline through `points`.
    pub(crate) fn new(points: &[[f64; 2]]) -> Self {
        let mut line = Self::default();
        for &p in points {
            line.push(p);
        }
        line
    }

    /// Reserves room for `more` points (allocates at most once).
    pub(crate) fn try_reserve(
        &mut self,
        more: usize,
    ) -> Result<(), std::collections::TryReserveError> {
        self.points.try_reserve_exact(more)?;
        self.boxes.try_reserve_exact(more.div_ceil(CHUNK) + 1)
    }

    /// Appends the point `p`, the end of a new segment when there was a point before.
    pub(crate) fn push(&mut self, p: [f64; 2]) {
        self.points.push(p);
        let segments = self.points.len() - 1;
        if segments == 0 {
            return;
        }
        let chunk = (segments - 1) / CHUNK;
        let previous = self.points[segments - 1];
        if chunk == self.boxes.len() {
            self.boxes.push([
                [previous[0].min(p[0]), previous[1].min(p[1])],
                [previous[0].max(p[0]), previous[1].max(p[1])],
            ]);
        } else {
            let [low, high] = &mut self.boxes[chunk];
            for k in 0..2 {
                low[k] = low[k].min(p[k]);
                high[k] = high[k].max(p[k]);
            }
        }
    }

    /// The first point, if any.
    pub(crate) fn first(&self) -> Option<[f64; 2]> {
        self.points.first().copied()
    }

    /// Calls `visit` with every segment of the chunks whose box lies within `reach` of the box
    /// `low`-`high` (a superset of the segments within `reach` of any point of that box).
    pub(crate) fn segments_near(
        &self,
        [low, high]: [[f64; 2]; 2],
        reach: f64,
        mut visit: impl FnMut([f64; 2], [f64; 2]),
    ) {
        for (c, [box_low, box_high]) in self.boxes.iter().enumerate() {
            let dx = (box_low[0] - high[0]).max(low[0] - box_high[0]).max(0.0);
            let dy = (box_low[1] - high[1]).max(low[1] - box_high[1]).max(0.0);
            if dx.hypot(dy) > reach {
                continue;
            }
            let end = ((c + 1) * CHUNK + 1).min(self.points.len());
            for pair in self.points[c * CHUNK..end].windows(2) {
                visit(pair[0], pair[1]);
            }
        }
    }

    /// The distance of `x` from the polyline (`+inf` without a segment): the least
    /// [`point_segment`] over its segments, the same number as
    /// measuring every one. The chunk whose box is nearest is measured first; then every chunk
    /// whose box is not farther than the nearest segment found (with a relative `1e-9` for the
    /// boxes' rounding). Squared distances throughout, one square root at the end.
    pub(crate) fn distance(&self, x: [f64; 2]) -> f64 {
        let box_distance2 = |[low, high]: &[[f64; 2]; 2]| {
            let dx = (low[0] - x[0]).max(x[0] - high[0]).max(0.0);
            let dy = (low[1] - x[1]).max(x[1] - high[1]).max(0.0);
            dx * dx + dy * dy
        };
        let chunk = |c: usize| {
            let end = ((c + 1) * CHUNK + 1).min(self.points.len());
            self.points[c * CHUNK..end]
                .windows(2)
                .fold(f64::INFINITY, |best, pair| {
                    best.min(point_segment_squared(x, pair[0], pair[1]))
                })
        };
        let Some(nearest) = (0..self.boxes.len()).min_by(|&a, &b| {
            box_distance2(&self.boxes[a]).total_cmp(&box_distance2(&self.boxes[b]))
        }) else {
            return f64::INFINITY;
        };
        let mut best = chunk(nearest);
        for (c, bounds) in self.boxes.iter().enumerate() {
            if c != nearest && box_distance2(bounds) <= best * (1.0 + 1e-9) {
                best = best.min(chunk(c));
            }
        }
        best.sqrt()
    }
}

/// The distance between `a` and `b`.
pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The distance of `x` from the segment `a`-`b`.
pub(crate) fn point_segment(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    point_segment_squared(x, a, b).sqrt()
}

/// The squared distance of `x` from the segment `a`-`b` (coordinates within
/// [`MAX_CENTERLINE_EXTENT`](crate::MAX_CENTERLINE_EXTENT) and the arms' reach: the squares neither overflow nor, above
/// `1e-150` m, underflow).
pub(crate) fn point_segment_squared(x: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let length2 = d[0] * d[0] + d[1] * d[1];
    let t = if length2 > 0.0 {
        (((x[0] - a[0]) * d[0] + (x[1] - a[1]) * d[1]) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [x[0] - (a[0] + t * d[0]), x[1] - (a[1] + t * d[1])];
    e[0] * e[0] + e[1] * e[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_distance_is_that_of_every_segment_measured() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for points in [0, 1, 2, 33, 64, 65, 500] {
            let mut path = vec![[0.0, 0.0]];
            for _ in 1..points {
                let last = path[path.len() - 1];
                path.push([
                    last[0] + rng.random_range(-0.05..0.1),
                    last[1] + rng.random_range(-0.05..0.1),
                ]);
            }
            path.truncate(points);
            let line = Polyline::new(&path);
            for _ in 0..200 {
                let x = [rng.random_range(-1.0..4.0), rng.random_range(-1.0..4.0)];
                let every = path.windows(2).fold(f64::INFINITY, |best, pair| {
                    best.min(point_segment(x, pair[0], pair[1]))
                });
                assert_eq!(
                    line.distance(x).to_bits(),
                    every.to_bits(),
                    "{points} points"
                );
            }
        }
    }
}
