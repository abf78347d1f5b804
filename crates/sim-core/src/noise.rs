//! Seeded Gaussian noise, reproducible bit for bit from the seed.
//!
//! ChaCha8 is a portable, version-stable generator, and `rand_distr`'s `StandardNormal` is
//! deterministic, so a seed gives the same run on every machine. Each noise source draws from
//! its own ChaCha stream of the run's seed, and always draws the same number of values per
//! sample whatever its standard deviations: runs that differ only in noise level see the same
//! underlying normal variates (common random numbers, which sharpens noise-level comparisons).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Zero-mean Gaussian noise with per-component standard deviations.
#[derive(Debug, Clone)]
pub(crate) struct GaussianNoise {
    rng: ChaCha8Rng,
    std: Vec<f64>,
}

impl GaussianNoise {
    /// Noise on stream `stream` of `seed`; `None` when every deviation is zero (no draws at all).
    pub(crate) fn new(seed: u64, stream: u64, std: &[f64]) -> Option<Self> {
        if std.iter().all(|&s| s == 0.0) {
            return None;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        Some(Self {
            rng,
            std: std.to_vec(),
        })
    }

    /// Adds one draw of the noise to `values` (as many entries as deviations).
    pub(crate) fn perturb(&mut self, values: &mut [f64]) {
        for (v, &s) in values.iter_mut().zip(&self.std) {
            let z: f64 = StandardNormal.sample(&mut self.rng);
            *v += s * z;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_deviation_is_no_noise() {
        assert!(GaussianNoise::new(7, 1, &[0.0, 0.0]).is_none());
    }

    #[test]
    fn same_seed_same_noise_and_streams_are_independent() {
        let draw = |seed, stream| {
            let mut noise = GaussianNoise::new(seed, stream, &[1.0, 2.0]).unwrap();
            let mut values = [0.0; 2];
            noise.perturb(&mut values);
            values
        };
        assert_eq!(draw(3, 1), draw(3, 1));
        assert_ne!(draw(3, 1), draw(3, 2));
        assert_ne!(draw(3, 1), draw(4, 1));
    }

    #[test]
    fn noise_has_the_requested_moments() {
        let mut noise = GaussianNoise::new(11, 1, &[0.5, 2.0]).unwrap();
        let n = 200_000;
        let (mut sum, mut sum_sq) = ([0.0; 2], [0.0; 2]);
        for _ in 0..n {
            let mut v = [0.0; 2];
            noise.perturb(&mut v);
            for i in 0..2 {
                sum[i] += v[i];
                sum_sq[i] += v[i] * v[i];
            }
        }
        for (i, s) in [0.5, 2.0].into_iter().enumerate() {
            let mean = sum[i] / n as f64;
            let std = (sum_sq[i] / n as f64 - mean * mean).sqrt();
            // Standard errors: s / sqrt(n) ~ 0.0045 s for the mean, 0.0016 s for the deviation.
            assert!(mean.abs() < 0.02 * s, "mean {mean}");
            assert!((std / s - 1.0).abs() < 0.01, "std {std}");
        }
    }
}
