//! Reference motions for the two modal coordinates `(a1, a2)` (alpha0 held fixed, as in the
//! paper's experiment): steps, sinusoids, and Cartesian paths followed through the closed-form
//! inverse kinematics (eqs 5-6).
//!
//! A reference supplies the desired `a`, `a_dot` and `a_ddot` at any time; the controllers that
//! need rates or accelerations (computed torque) get them exactly, not by differencing.

mod path;

pub use path::{CartesianPath, PathShape};

use crate::error::{SimError, check_finite, check_non_negative};

/// The desired modal motion at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReferenceSample {
    /// Desired `(a1, a2)` (rad).
    pub a: [f64; 2],
    /// Desired `(a1_dot, a2_dot)` (rad/s).
    pub a_dot: [f64; 2],
    /// Desired `(a1_ddot, a2_ddot)` (rad/s^2).
    pub a_ddot: [f64; 2],
}

/// A desired motion of the modal coordinates `(a1, a2)` over time.
pub trait Reference: Send {
    /// The desired motion at time `t` (s).
    fn sample(&self, t: f64) -> Result<ReferenceSample, SimError>;
}

/// A step from `initial` to `target` at time `time` (a constant reference when `time = 0`);
/// rates and accelerations are zero (the step's impulse is not part of the reference).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    initial: [f64; 2],
    target: [f64; 2],
    time: f64,
}

impl Step {
    /// A step from `initial` to `target` at `time` (s, non-negative); `a = target` from `time` on.
    ///
    /// ```
    /// use sim_core::reference::{Reference, Step};
    /// let step = Step::new([0.0, 0.0], [0.2, -0.1], 0.5)?;
    /// assert_eq!(step.sample(0.4)?.a, [0.0, 0.0]);
    /// assert_eq!(step.sample(0.5)?.a, [0.2, -0.1]);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(initial: [f64; 2], target: [f64; 2], time: f64) -> Result<Self, SimError> {
        check_finite("reference.initial", &initial)?;
        check_finite("reference.target", &target)?;
        check_non_negative("reference.time", time)?;
        Ok(Self {
            initial,
            target,
            time,
        })
    }

    /// A constant reference.
    pub fn constant(a: [f64; 2]) -> Result<Self, SimError> {
        Self::new(a, a, 0.0)
    }
}

impl Reference for Step {
    fn sample(&self, t: f64) -> Result<ReferenceSample, SimError> {
        let a = if t < self.time {
            self.initial
        } else {
            self.target
        };
        Ok(ReferenceSample {
            a,
            ..ReferenceSample::default()
        })
    }
}

/// `a_i(t) = offset_i + amplitude_i sin(2 pi frequency_i t + phase_i)` for each coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sinusoid {
    offset: [f64; 2],
    amplitude: [f64; 2],
    /// Angular frequencies `2 pi f_i` (rad/s).
    omega: [f64; 2],
    phase: [f64; 2],
}

impl Sinusoid {
    /// A sinusoid per coordinate; `frequency_hz` in Hz (non-negative), `phase` in rad.
    ///
    /// ```
    /// use sim_core::reference::{Reference, Sinusoid};
    /// let sine = Sinusoid::new([0.1, 0.0], [0.2, 0.1], [0.5, 1.0], [0.0, 0.0])?;
    /// let s = sine.sample(0.0)?;
    /// assert_eq!(s.a, [0.1, 0.0]);
    /// assert!((s.a_dot[0] - 0.2 * std::f64::consts::PI).abs() < 1e-15);
    /// # Ok::<(), sim_core::SimError>(())
    /// ```
    pub fn new(
        offset: [f64; 2],
        amplitude: [f64; 2],
        frequency_hz: [f64; 2],
        phase: [f64; 2],
    ) -> Result<Self, SimError> {
        check_finite("reference.offset", &offset)?;
        check_finite("reference.amplitude", &amplitude)?;
        check_finite("reference.phase", &phase)?;
        for f in frequency_hz {
            check_non_negative("reference.frequency_hz", f)?;
        }
        Ok(Self {
            offset,
            amplitude,
            omega: frequency_hz.map(|f| std::f64::consts::TAU * f),
            phase,
        })
    }
}

impl Reference for Sinusoid {
    fn sample(&self, t: f64) -> Result<ReferenceSample, SimError> {
        let mut s = ReferenceSample::default();
        for i in 0..2 {
            let (sin, cos) = (self.omega[i] * t + self.phase[i]).sin_cos();
            let w = self.omega[i];
            s.a[i] = self.offset[i] + self.amplitude[i] * sin;
            s.a_dot[i] = self.amplitude[i] * w * cos;
            s.a_ddot[i] = -self.amplitude[i] * w * w * sin;
        }
        Ok(s)
    }
}
