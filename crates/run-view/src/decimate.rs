//! Decimation: fewer samples and fewer digits, so that a page of many runs stays small.

use crate::view::RunView;

/// `max` or fewer evenly strided indices of `0..n`, the first and the last included.
///
/// ```
/// assert_eq!(run_view::strided(10, 4), [0, 3, 6, 9]);
/// assert_eq!(run_view::strided(11, 4), [0, 3, 6, 9, 10]);
/// assert_eq!(run_view::strided(3, 10), [0, 1, 2]);
/// ```
///
/// With the last index added, at most `max + 1` indices: the caller's bound is a size, not a
/// count to the sample.
pub fn strided(n: usize, max: usize) -> Vec<usize> {
    let stride = n.div_ceil(max.max(1)).max(1);
    let mut picked: Vec<usize> = (0..n).step_by(stride).collect();
    if n > 0 && !(n - 1).is_multiple_of(stride) {
        picked.push(n - 1);
    }
    picked
}

/// `v` rounded to a multiple of `10^exponent`, as the double nearest that decimal (so that it
/// prints as the short decimal, not `0.30000000000000004`).
pub fn round_decimal(v: f64, exponent: i32) -> f64 {
    if exponent < -300 {
        // `10^-exponent` overflows for a peak near the subnormals: scale in two steps.
        let (first, second) = (10f64.powi(300), 10f64.powi(-exponent - 300));
        (v * first * second).round() / second / first
    } else if exponent < 0 {
        let scale = 10f64.powi(-exponent);
        (v * scale).round() / scale
    } else {
        let scale = 10f64.powi(exponent);
        (v / scale).round() * scale
    }
}

/// The exponent that keeps `digits` significant digits of the largest magnitude in `values`.
fn exponent_for(values: impl Iterator<Item = f64>, digits: i32) -> i32 {
    let peak = values.fold(0.0f64, |m, v| m.max(v.abs()));
    if peak > 0.0 && peak.is_finite() {
        peak.log10().floor() as i32 + 1 - digits
    } else {
        0
    }
}

/// Decimal places of the arm's coordinates: 0.1 mm.
const POSITION_EXPONENT: i32 = -4;
/// Significant digits of a time series (relative to its curve's peak) and of a joint torque
/// (relative to the run's peak torque).
const SERIES_DIGITS: i32 = 4;

impl RunView {
    /// The run at no more than about `max_samples` evenly strided samples (the first and the
    /// last kept, [`strided`]), positions rounded to 0.01 mm and series and torques to four
    /// significant digits of their peak: what a page embeds.
    pub fn decimated(&self, max_samples: usize) -> RunView {
        let keep = strided(self.len(), max_samples);
        let rows = |rows: &[Vec<f64>], exponent: i32| -> Vec<Vec<f64>> {
            if rows.is_empty() {
                return Vec::new();
            }
            keep.iter()
                .map(|&k| {
                    rows[k]
                        .iter()
                        .map(|&v| round_decimal(v, exponent))
                        .collect()
                })
                .collect()
        };
        let torque_exponent =
            exponent_for(self.joint_torque.iter().flatten().copied(), SERIES_DIGITS);
        RunView {
            t: keep.iter().map(|&k| round_decimal(self.t[k], -6)).collect(),
            joints: rows(&self.joints, POSITION_EXPONENT),
            tip_ref: rows(&self.tip_ref, POSITION_EXPONENT),
            joint_torque: rows(&self.joint_torque, torque_exponent),
            series: self
                .series
                .iter()
                .map(|s| crate::Series {
                    values: s
                        .values
                        .iter()
                        .map(|curve| {
                            let e = exponent_for(curve.iter().copied(), SERIES_DIGITS);
                            keep.iter().map(|&k| round_decimal(curve[k], e)).collect()
                        })
                        .collect(),
                    ..s.clone()
                })
                .collect(),
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strided_indices_keep_both_ends_and_bound_the_count() {
        for n in [0usize, 1, 2, 7, 299, 300, 301, 5501] {
            for max in [1usize, 2, 3, 300] {
                let k = strided(n, max);
                assert!(k.len() <= max + 1, "{n} {max}: {}", k.len());
                if n > 0 {
                    assert_eq!((k[0], *k.last().unwrap()), (0, n - 1));
                }
                assert!(k.windows(2).all(|w| w[0] < w[1]));
                if n <= max {
                    assert_eq!(k.len(), n);
                }
            }
        }
    }

    #[test]
    fn rounding_prints_short_decimals() {
        assert_eq!(round_decimal(0.1 + 0.2, -3).to_string(), "0.3");
        assert_eq!(round_decimal(-0.123456, -5).to_string(), "-0.12346");
        assert_eq!(round_decimal(31_234.7, 2), 31_200.0);
        assert_eq!(exponent_for([0.5, -31.2].into_iter(), 4), -2);
        assert_eq!(exponent_for([0.0].into_iter(), 4), 0);
        // A peak near the subnormals: 10^327 overflows, the two-step scaling does not.
        let tiny = f64::from_bits(1);
        let exponent = exponent_for([tiny].into_iter(), 4);
        assert_eq!(exponent, -327);
        assert_eq!(round_decimal(tiny, exponent), tiny);
        assert_eq!(round_decimal(-1.2345678e-310, -313), -1.235e-310);
    }
}
