//! A motion through waypoints of the modal coordinates along straight segments: what a shape
//! plan (`shape-plan`) returns, followed in time.

use super::{Reference, ReferenceSample, check_lengths, minimum_jerk};
use crate::error::SimError;

/// The most waypoints a [`Waypoints`] reference accepts.
pub const MAX_WAYPOINTS: usize = 65_536;

/// The straight segments between waypoints `w_0, ..., w_N` of the modal coordinates, each
/// traversed with the minimum-jerk profile `s(u) = 10 u^3 - 15 u^4 + 6 u^5` (`u` the segment's
/// elapsed fraction, rates and accelerations zero at every waypoint), segment `k` taking the
/// share `|w_{k+1} - w_k| / sum |w_{j+1} - w_j|` of `travel_time`; then `w_N` held.
///
/// The shapes are exactly those of the segments (only the timing is shaped), so a plan's
/// clearance along its segments holds for the reference at every time.
///
/// ```
/// use sim_core::reference::{Reference, ReferenceSample, Waypoints};
/// let mut motion = Waypoints::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 2.0)?;
/// let mut s = ReferenceSample::zeros(2);
/// motion.sample(0.5, &mut s)?; // halfway along the first segment
/// assert!((s.a[0] - 0.5).abs() < 1e-15 && s.a[1] == 0.0);
/// motion.sample(3.0, &mut s)?; // held at the last waypoint
/// assert_eq!((s.a.as_slice(), s.a_dot.as_slice()), (&[1.0, 1.0][..], &[0.0, 0.0][..]));
/// # Ok::<(), sim_core::SimError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Waypoints {
    points: Vec<Vec<f64>>,
    /// The time each segment starts, and the end as the last entry.
    starts: Vec<f64>,
}

impl Waypoints {
    /// The motion through `points` (at least one, all of one length `m`) in `travel_time`
    /// (s, positive).
    pub fn new(points: &[Vec<f64>], travel_time: f64) -> Result<Self, SimError> {
        if points.is_empty() || points.len() > MAX_WAYPOINTS {
            return Err(SimError::setting(
                "reference waypoints",
                format!(
                    "must be between 1 and {MAX_WAYPOINTS}, got {}",
                    points.len()
                ),
            ));
        }
        super::check_travel_time("reference travel time", travel_time)?;
        let mut arrays = vec![("reference waypoint", points[0].as_slice())];
        arrays.extend(
            points[1..]
                .iter()
                .map(|p| ("reference waypoint", p.as_slice())),
        );
        check_lengths(&arrays)?;
        let lengths: Vec<f64> = points
            .windows(2)
            .map(|w| {
                w[0].iter()
                    .zip(&w[1])
                    .map(|(x, y)| (y - x) * (y - x))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let total: f64 = lengths.iter().sum();
        if !total.is_finite() {
            return Err(SimError::setting(
                "reference waypoints",
                "must be a finite distance apart",
            ));
        }
        let mut starts = vec![0.0];
        let mut elapsed = 0.0;
        for length in &lengths {
            elapsed += if total > 0.0 {
                travel_time * length / total
            } else {
                0.0
            };
            starts.push(elapsed);
        }
        Ok(Self {
            points: points.to_vec(),
            starts,
        })
    }
}

impl Reference for Waypoints {
    fn n_coords(&self) -> usize {
        self.points[0].len()
    }

    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError> {
        let last = self.points.len() - 1;
        // Before the start (or at a NaN time) the first waypoint, after the end the last.
        let held = if t.is_nan() || t <= 0.0 {
            Some(0)
        } else if last == 0 || t >= self.starts[last] {
            Some(last)
        } else {
            None
        };
        if let Some(held) = held {
            out.a.copy_from_slice(&self.points[held]);
            out.a_dot.fill(0.0);
            out.a_ddot.fill(0.0);
            return Ok(());
        }
        // The segment under way, `starts[k] <= t < starts[k + 1]` (never one of zero length).
        let k = self.starts.partition_point(|&s| s <= t) - 1;
        let (t0, t1) = (self.starts[k], self.starts[k + 1]);
        let duration = t1 - t0;
        let (s, s_dot, s_ddot) = minimum_jerk((t - t0) / duration, duration);
        let (from, to) = (&self.points[k], &self.points[k + 1]);
        for i in 0..from.len() {
            let delta = to[i] - from[i];
            out.a[i] = from[i] + s * delta;
            out.a_dot[i] = s_dot * delta;
            out.a_ddot[i] = s_ddot * delta;
        }
        Ok(())
    }
}
