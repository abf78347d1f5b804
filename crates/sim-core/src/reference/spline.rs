//! A motion through samples of the coordinates taken at equal steps of a path parameter (a
//! follow-the-leader deployment, sampled by its tip's progress), interpolated smoothly and timed.

use super::{Reference, ReferenceSample, check_lengths, minimum_jerk};
use crate::error::SimError;

/// The most samples a [`SplineMotion`] accepts.
pub const MAX_SPLINE_SAMPLES: usize = 65_536;

/// The natural cubic spline `S(u)` through samples `y_0, ..., y_N` of the coordinates at
/// `u_k = k / N` (each coordinate its own spline, second derivatives zero at both ends), followed
/// in time by the minimum-jerk profile `u = s(t / travel_time)`: `a = S(u)`,
/// `a_dot = S'(u) u_dot`, `a_ddot = S''(u) u_dot^2 + S'(u) u_ddot`; rest at `y_0` before the
/// start and at `y_N` from `travel_time` on. The spline passes through every sample and is
/// twice continuously differentiable, so the accelerations it asks for are continuous.
///
/// ```
/// use sim_core::reference::{Reference, ReferenceSample, SplineMotion};
/// // Samples of a straight line: the spline is that line.
/// let mut motion = SplineMotion::new(&[vec![0.0], vec![0.5], vec![1.0]], 2.0)?;
/// let mut s = ReferenceSample::zeros(1);
/// motion.sample(1.0, &mut s)?; // halfway in time and, by symmetry, along the path
/// assert!((s.a[0] - 0.5).abs() < 1e-15);
/// motion.sample(3.0, &mut s)?;
/// assert_eq!((s.a[0], s.a_dot[0], s.a_ddot[0]), (1.0, 0.0, 0.0));
/// # Ok::<(), sim_core::SimError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SplineMotion {
    /// The samples, `m` values each, one after the other.
    values: Vec<f64>,
    /// The spline's second derivatives in `u` at the samples, laid out as `values`.
    curvatures: Vec<f64>,
    m: usize,
    travel_time: f64,
}

impl SplineMotion {
    /// The motion through `samples` (at least two, at most [`MAX_SPLINE_SAMPLES`], all of one
    /// length `m`, finite) in `travel_time` (s, positive).
    pub fn new(samples: &[Vec<f64>], travel_time: f64) -> Result<Self, SimError> {
        if samples.len() < 2 || samples.len() > MAX_SPLINE_SAMPLES {
            return Err(SimError::setting(
                "reference samples",
                format!(
                    "must be between 2 and {MAX_SPLINE_SAMPLES}, got {}",
                    samples.len()
                ),
            ));
        }
        super::check_travel_time("reference travel time", travel_time)?;
        let arrays: Vec<(&str, &[f64])> = samples
            .iter()
            .map(|s| ("reference sample", s.as_slice()))
            .collect();
        let m = check_lengths(&arrays)?;
        let last = samples.len() - 1;
        let values: Vec<f64> = samples.iter().flatten().copied().collect();
        // M_{k-1} + 4 M_k + M_{k+1} = 6 N^2 (y_{k+1} - 2 y_k + y_{k-1}), M_0 = M_N = 0: the
        // Thomas algorithm, the same (diagonally dominant) elimination for every coordinate.
        let mut curvatures = vec![0.0; values.len()];
        let scale = 6.0 * (last * last) as f64;
        let mut pivots = vec![4.0; last];
        for k in 1..last {
            if k > 1 {
                pivots[k] = 4.0 - 1.0 / pivots[k - 1];
            }
            for i in 0..m {
                let rhs = scale
                    * (values[(k + 1) * m + i] - 2.0 * values[k * m + i] + values[(k - 1) * m + i]);
                let previous = if k > 1 {
                    curvatures[(k - 1) * m + i] / pivots[k - 1]
                } else {
                    0.0
                };
                curvatures[k * m + i] = rhs - previous;
            }
        }
        for k in (1..last).rev() {
            for i in 0..m {
                let next = curvatures[(k + 1) * m + i];
                curvatures[k * m + i] = (curvatures[k * m + i] - next) / pivots[k];
            }
        }
        if curvatures.iter().any(|c| !c.is_finite()) {
            return Err(SimError::setting(
                "reference samples",
                "must be close enough together for a finite spline",
            ));
        }
        Ok(Self {
            values,
            curvatures,
            m,
            travel_time,
        })
    }
}

impl Reference for SplineMotion {
    fn n_coords(&self) -> usize {
        self.m
    }

    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError> {
        let m = self.m;
        let last = self.values.len() / m - 1;
        let fraction = if t.is_nan() {
            0.0
        } else {
            t / self.travel_time
        };
        let (u, u_dot, u_ddot) = minimum_jerk(fraction, self.travel_time);
        // The segment `[u_k, u_{k+1}]` holding `u`, and the position `x` within it.
        let h = 1.0 / last as f64;
        let k = ((u * last as f64).floor() as usize).min(last - 1);
        let x = (u * last as f64 - k as f64).clamp(0.0, 1.0);
        let y = 1.0 - x;
        for i in 0..m {
            let (y0, y1) = (self.values[k * m + i], self.values[(k + 1) * m + i]);
            let (c0, c1) = (self.curvatures[k * m + i], self.curvatures[(k + 1) * m + i]);
            let value =
                y * y0 + x * y1 + h * h / 6.0 * ((y * y * y - y) * c0 + (x * x * x - x) * c1);
            let slope =
                (y1 - y0) / h + h / 6.0 * ((1.0 - 3.0 * y * y) * c0 + (3.0 * x * x - 1.0) * c1);
            let curvature = y * c0 + x * c1;
            out.a[i] = value;
            out.a_dot[i] = slope * u_dot;
            out.a_ddot[i] = curvature * u_dot * u_dot + slope * u_ddot;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The samples of `f` at `u_k = k / n`.
    fn sampled(f: impl Fn(f64) -> [f64; 2], n: usize) -> Vec<Vec<f64>> {
        (0..=n).map(|k| f(k as f64 / n as f64).to_vec()).collect()
    }

    #[test]
    fn the_spline_passes_through_its_samples_and_its_rates_are_its_derivatives() {
        let f = |u: f64| [(3.0 * u).sin(), u * u * (1.0 - u)];
        let (n, travel) = (40, 2.0);
        let mut motion = SplineMotion::new(&sampled(f, n), travel).unwrap();
        let mut s = ReferenceSample::zeros(2);
        // At the times the profile reaches each sample, the sample itself.
        for k in 0..=n {
            let target = k as f64 / n as f64;
            let (mut lo, mut hi) = (0.0, travel);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if minimum_jerk(mid / travel, travel).0 < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            motion.sample(0.5 * (lo + hi), &mut s).unwrap();
            let expected = f(target);
            assert!((s.a[0] - expected[0]).abs() < 1e-9, "{k}: {:?}", s.a);
            assert!((s.a[1] - expected[1]).abs() < 1e-9, "{k}: {:?}", s.a);
        }
        // Between them, close to f (O(h^4) inside, O(h^2) near the ends, where the natural
        // spline's zero curvature is not f's), and the rates and
        // accelerations are the central differences of the values.
        let mut plus = ReferenceSample::zeros(2);
        let mut minus = ReferenceSample::zeros(2);
        let step = 1e-5;
        for j in 1..50 {
            let t = travel * (j as f64 + 0.37) / 50.0;
            motion.sample(t, &mut s).unwrap();
            motion.sample(t + step, &mut plus).unwrap();
            motion.sample(t - step, &mut minus).unwrap();
            let u = minimum_jerk(t / travel, travel).0;
            let exact = f(u);
            for (i, exact) in exact.iter().enumerate() {
                assert!((s.a[i] - exact).abs() < 1e-3, "t {t}: {:?}", s.a);
                let rate = (plus.a[i] - minus.a[i]) / (2.0 * step);
                assert!((s.a_dot[i] - rate).abs() < 1e-6, "t {t} rate {i}");
                let acceleration = (plus.a_dot[i] - minus.a_dot[i]) / (2.0 * step);
                assert!((s.a_ddot[i] - acceleration).abs() < 1e-5, "t {t} accel {i}");
            }
        }
        // At rest at both ends.
        for t in [-1.0, 0.0, travel, 5.0] {
            motion.sample(t, &mut s).unwrap();
            assert!(s.a_dot.iter().chain(&s.a_ddot).all(|v| v.abs() < 1e-12));
        }
    }

    #[test]
    fn bad_samples_are_refused_by_name() {
        let text = |e: SimError| e.to_string();
        let one = SplineMotion::new(&[vec![0.0]], 1.0).unwrap_err();
        assert!(text(one).contains("reference samples must be between 2"));
        let uneven = SplineMotion::new(&[vec![0.0], vec![0.0, 1.0]], 1.0).unwrap_err();
        assert!(text(uneven).contains("reference sample"));
        let nan = SplineMotion::new(&[vec![0.0], vec![f64::NAN]], 1.0).unwrap_err();
        assert!(text(nan).contains("finite"));
        let time = SplineMotion::new(&[vec![0.0], vec![1.0]], 0.0).unwrap_err();
        assert!(text(time).contains("travel time"));
    }
}
