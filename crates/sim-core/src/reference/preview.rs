//! A reference sampled ahead on a uniform time grid, for controllers that plan over a horizon.

use super::{Reference, ReferenceSample};
use crate::error::{SimError, check_positive};
use lane_math::Compact;

/// The most samples a preview may hold.
pub const MAX_PREVIEW_SAMPLES: usize = 100_001;

/// A [`Reference`] previewed at `t, t + dt, ..., t + (count - 1) dt` from any time `t`: the
/// samples a model-predictive controller needs over its horizon. A preview that moves on by a
/// whole number of steps keeps the samples it already has and samples only the new ones (a
/// sample is a function of time alone); any other move samples them all. The buffers are sized
/// by [`new`](Self::new); [`advance`](Self::advance) allocates nothing.
///
/// ```
/// use sim_core::reference::{Reference, ReferencePreview, ReferenceSample, Sinusoid};
/// let sine = Sinusoid::new(&[0.0], &[0.2], &[1.0], &[0.0])?;
/// let mut preview = ReferencePreview::new(Box::new(sine.clone()), 51, 0.01)?;
/// let samples = preview.advance(0.3)?;
/// let mut direct = ReferenceSample::zeros(1);
/// let mut sine = sine;
/// sine.sample(0.3 + 50.0 * 0.01, &mut direct)?;
/// assert!((samples[50].a[0] - direct.a[0]).abs() < 1e-12);
/// # Ok::<(), sim_core::SimError>(())
/// ```
pub struct ReferencePreview {
    reference: Box<dyn Reference>,
    samples: Vec<ReferenceSample>,
    spacing: f64,
    /// The time of `samples[0]`, once sampled.
    start: Option<f64>,
}

impl std::fmt::Debug for ReferencePreview {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ReferencePreview")
            .field("count", &self.samples.len())
            .field("spacing", &self.spacing)
            .field("start", &self.start)
            .finish_non_exhaustive()
    }
}

impl ReferencePreview {
    /// A preview of `count` samples (1 to [`MAX_PREVIEW_SAMPLES`]) `spacing` seconds apart
    /// (positive).
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] for a count or spacing out of range.
    pub fn new(
        reference: Box<dyn Reference>,
        count: usize,
        spacing: f64,
    ) -> Result<Self, SimError> {
        if count == 0 || count > MAX_PREVIEW_SAMPLES {
            return Err(SimError::setting(
                "preview",
                format!("must have between 1 and {MAX_PREVIEW_SAMPLES} samples, got {count}"),
            ));
        }
        check_positive("preview spacing", spacing)?;
        if spacing > 1e3 {
            return Err(SimError::setting(
                "preview spacing",
                format!("must be at most 1000 s, got {} s", Compact(spacing)),
            ));
        }
        let m = reference.n_coords();
        Ok(Self {
            reference,
            samples: vec![ReferenceSample::zeros(m); count],
            spacing,
            start: None,
        })
    }

    /// The number of coordinates `m`.
    pub fn n_coords(&self) -> usize {
        self.reference.n_coords()
    }

    /// The samples at `t + k * spacing`, `k = 0..count`.
    ///
    /// # Errors
    /// [`SimError::InvalidSetting`] for a non-finite `t`; the reference's errors.
    pub fn advance(&mut self, t: f64) -> Result<&[ReferenceSample], SimError> {
        if !t.is_finite() {
            return Err(SimError::setting(
                "preview time",
                format!("must be finite, got {}", Compact(t)),
            ));
        }
        let count = self.samples.len();
        // Samples to keep: a move of a whole number of steps within the window.
        let kept = match self.start {
            Some(start) => {
                let steps = (t - start) / self.spacing;
                let whole = steps.round();
                if whole >= 0.0 && (steps - whole).abs() <= 1e-9 * whole.max(1.0) {
                    let whole = whole as usize;
                    if whole < count {
                        self.samples.rotate_left(whole);
                        count - whole
                    } else {
                        0
                    }
                } else {
                    0
                }
            }
            None => 0,
        };
        self.start = None;
        for k in kept..count {
            self.reference
                .sample(t + k as f64 * self.spacing, &mut self.samples[k])?;
        }
        self.start = Some(t);
        Ok(&self.samples)
    }
}
