//! Reference motions for the `m` modal coordinates: steps, sinusoids, and Cartesian tip paths
//! followed through the inverse kinematics of the modal family (the closed form of eqs 5-6 for
//! the paper's `K = 1` with `alpha0` fixed, a numerical continuation otherwise), in the plane or,
//! for a spatial arm, in space ([`SpatialPath`]).
//!
//! A reference supplies the desired `a`, `a_dot` and `a_ddot` at any time; the controllers that
//! need rates or accelerations (computed torque) get them from the reference, not by
//! differencing the samples. A [`ReferencePreview`] samples a reference ahead over a horizon,
//! for the controllers that plan (model-predictive control).

pub(crate) mod continuation;
mod path;
mod preview;
mod spatial_path;
mod spline;
mod waypoints;

pub use path::{CartesianPath, FREE_BASE_START, MAX_SINE_PHASE, PathShape};
pub use preview::{MAX_PREVIEW_SAMPLES, ReferencePreview};
pub use spatial_path::{Helix, MAX_HELIX_EXTENT_M, MAX_SPATIAL_PATH_WORK, SpatialPath};
pub use spline::{MAX_SPLINE_SAMPLES, SplineMotion};
pub use waypoints::{MAX_WAYPOINTS, Waypoints};

use crate::error::{SimError, check_non_negative};
use lane_math::{Compact, check_all_finite};

/// The shortest travel time of a moving reference (s): its rates scale with its inverse and its
/// accelerations with its inverse square (`5e-324` s gave NaN rates).
pub const MIN_TRAVEL_TIME_S: f64 = 1e-6;

/// The highest frequency of a [`Sinusoid`] (Hz): its accelerations scale with the square
/// (`1e300` Hz gave a NaN acceleration at `t = 0`).
pub const MAX_REFERENCE_FREQUENCY_HZ: f64 = 1e6;

/// Checks that the travel time `name` is finite and at least [`MIN_TRAVEL_TIME_S`].
pub(crate) fn check_travel_time(name: &str, value: f64) -> Result<(), SimError> {
    if value.is_finite() && value >= MIN_TRAVEL_TIME_S {
        Ok(())
    } else {
        Err(SimError::setting(
            name,
            format!(
                "must be finite and at least {} s, got {}",
                Compact(MIN_TRAVEL_TIME_S),
                Compact(value)
            ),
        ))
    }
}

/// The desired modal motion at one instant, `m` entries per field.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReferenceSample {
    /// Desired coordinates (rad).
    pub a: Vec<f64>,
    /// Desired rates (rad/s).
    pub a_dot: Vec<f64>,
    /// Desired accelerations (rad/s^2).
    pub a_ddot: Vec<f64>,
}

impl ReferenceSample {
    /// A sample of `m` coordinates at rest at zero (also the buffer a reference fills).
    pub fn zeros(m: usize) -> Self {
        Self {
            a: vec![0.0; m],
            a_dot: vec![0.0; m],
            a_ddot: vec![0.0; m],
        }
    }

    /// The number of coordinates.
    pub fn n_coords(&self) -> usize {
        self.a.len()
    }

    /// Copies `other` (of the same size) into this sample without allocating.
    pub fn copy_from(&mut self, other: &Self) {
        self.a.copy_from_slice(&other.a);
        self.a_dot.copy_from_slice(&other.a_dot);
        self.a_ddot.copy_from_slice(&other.a_ddot);
    }
}

/// A desired motion of the `m` modal coordinates over time.
pub trait Reference: Send {
    /// The number of coordinates `m` it sets.
    fn n_coords(&self) -> usize;

    /// Writes the desired motion at time `t` (s) into `out` (`m` entries per field). `&mut self`
    /// only for workspaces: the sample is a function of `t` alone.
    ///
    /// # Panics
    /// Implementations may panic, like slice copying, when `out` was not made for
    /// [`n_coords`](Self::n_coords) coordinates (`ReferenceSample::zeros(reference.n_coords())`).
    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError>;
}

/// The minimum-jerk profile `s(u) = 10 u^3 - 15 u^4 + 6 u^5` at the elapsed fraction `u`
/// (clamped to `[0, 1]`) of a motion of `duration` s, with its first and second time
/// derivatives: `(s, ds/dt, d2s/dt2)`, rates and accelerations zero at both ends.
pub(crate) fn minimum_jerk(u: f64, duration: f64) -> (f64, f64, f64) {
    let u = u.clamp(0.0, 1.0);
    let (u2, u3) = (u * u, u * u * u);
    (
        u3 * (10.0 - 15.0 * u + 6.0 * u2),
        30.0 * u2 * (1.0 - u) * (1.0 - u) / duration,
        60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (duration * duration),
    )
}

/// Checks that the per-coordinate arrays `arrays` (named as in a scenario file) are non-empty and
/// of one length; returns it.
fn check_lengths(arrays: &[(&str, &[f64])]) -> Result<usize, SimError> {
    let (first, values) = arrays[0];
    let m = values.len();
    if m == 0 || m > crate::MAX_COORDINATES {
        return Err(SimError::setting(
            first,
            format!(
                "must have between 1 and {} entries, got {m}",
                crate::MAX_COORDINATES
            ),
        ));
    }
    for (name, values) in &arrays[1..] {
        if values.len() != m {
            return Err(SimError::setting(
                *name,
                format!("has {} entries, {first} has {m}", values.len()),
            ));
        }
        check_all_finite(name, values)?;
    }
    check_all_finite(first, values)?;
    Ok(m)
}

/// A step from `initial` to `target` at time `time` (a constant reference when `time = 0`);
/// rates and accelerations are zero (the step's impulse is not part of the reference).
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    initial: Vec<f64>,
    target: Vec<f64>,
    time: f64,
}

impl Step {
    /// A step from `initial` to `target` (one entry per coordinate, equal lengths) at `time`
    /// (s, non-negative); `a = target` from `time` on.
    ///
    /// ```
    /// use sim_core::reference::{Reference, ReferenceSample, Step};
    /// let mut step = Step::new(&[0.0, 0.0, 0.0], &[0.2, -0.1, 0.05], 0.5)?;
    /// let mut sample = ReferenceSample::zeros(3);
    /// step.sample(0.4, &mut sample)?;
    /// assert_eq!(sample.a, [0.0, 0.0, 0.0]);
    /// step.sample(0.5, &mut sample)?;
    /// assert_eq!(sample.a, [0.2, -0.1, 0.05]);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(initial: &[f64], target: &[f64], time: f64) -> Result<Self, SimError> {
        check_lengths(&[("reference.target", target), ("reference.initial", initial)])?;
        check_non_negative("reference.time", time)?;
        Ok(Self {
            initial: initial.to_vec(),
            target: target.to_vec(),
            time,
        })
    }

    /// A constant reference.
    pub fn constant(a: &[f64]) -> Result<Self, SimError> {
        check_lengths(&[("reference.a", a)])?;
        Self::new(a, a, 0.0)
    }
}

impl Reference for Step {
    fn n_coords(&self) -> usize {
        self.target.len()
    }

    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError> {
        let a = if t < self.time {
            &self.initial
        } else {
            &self.target
        };
        out.a.copy_from_slice(a);
        out.a_dot.fill(0.0);
        out.a_ddot.fill(0.0);
        Ok(())
    }
}

/// `a_i(t) = offset_i + amplitude_i sin(2 pi frequency_i t + phase_i)` for each coordinate.
#[derive(Debug, Clone, PartialEq)]
pub struct Sinusoid {
    offset: Vec<f64>,
    amplitude: Vec<f64>,
    /// Angular frequencies `2 pi f_i` (rad/s).
    omega: Vec<f64>,
    phase: Vec<f64>,
}

impl Sinusoid {
    /// A sinusoid per coordinate (equal lengths); `frequency_hz` in Hz (non-negative, at most
    /// [`MAX_REFERENCE_FREQUENCY_HZ`]), `phase` in rad.
    ///
    /// ```
    /// use sim_core::reference::{Reference, ReferenceSample, Sinusoid};
    /// let mut sine = Sinusoid::new(&[0.1, 0.0], &[0.2, 0.1], &[0.5, 1.0], &[0.0, 0.0])?;
    /// let mut s = ReferenceSample::zeros(2);
    /// sine.sample(0.0, &mut s)?;
    /// assert_eq!(s.a, [0.1, 0.0]);
    /// assert!((s.a_dot[0] - 0.2 * std::f64::consts::PI).abs() < 1e-15);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(
        offset: &[f64],
        amplitude: &[f64],
        frequency_hz: &[f64],
        phase: &[f64],
    ) -> Result<Self, SimError> {
        check_lengths(&[
            ("reference.amplitude", amplitude),
            ("reference.offset", offset),
            ("reference.frequency_hz", frequency_hz),
            ("reference.phase", phase),
        ])?;
        for &f in frequency_hz {
            check_non_negative("reference.frequency_hz", f)?;
            if f > MAX_REFERENCE_FREQUENCY_HZ {
                return Err(SimError::setting(
                    "reference.frequency_hz",
                    format!(
                        "must be at most {} Hz, got {}",
                        Compact(MAX_REFERENCE_FREQUENCY_HZ),
                        Compact(f)
                    ),
                ));
            }
        }
        Ok(Self {
            offset: offset.to_vec(),
            amplitude: amplitude.to_vec(),
            omega: frequency_hz
                .iter()
                .map(|f| std::f64::consts::TAU * f)
                .collect(),
            phase: phase.to_vec(),
        })
    }
}

impl Reference for Sinusoid {
    fn n_coords(&self) -> usize {
        self.amplitude.len()
    }

    fn sample(&mut self, t: f64, s: &mut ReferenceSample) -> Result<(), SimError> {
        for i in 0..self.amplitude.len() {
            let (sin, cos) = (self.omega[i] * t + self.phase[i]).sin_cos();
            let w = self.omega[i];
            s.a[i] = self.offset[i] + self.amplitude[i] * sin;
            s.a_dot[i] = self.amplitude[i] * w * cos;
            s.a_ddot[i] = -self.amplitude[i] * w * w * sin;
        }
        Ok(())
    }
}
