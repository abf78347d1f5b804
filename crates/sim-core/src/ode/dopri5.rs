//! The adaptive Dormand-Prince 5(4) method (Dormand & Prince 1980; Hairer, Norsett & Wanner,
//! *Solving Ordinary Differential Equations I*, section II.5, the `DOPRI5` code).

use super::{OdeError, OdeSystem, Stats, check_call, combine, eval};
use lane_math::Compact;

/// Nodes `c_i` of the Butcher tableau.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// Rows 2..=7 of the Butcher matrix `a_ij`; row 7 is also the fifth-order weights `b_j`
/// (first same as last: stage 7 is `f(t + h, y_new)`, the next step's stage 1).
const A2: [f64; 1] = [1.0 / 5.0];
const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
const A5: [f64; 4] = [
    19372.0 / 6561.0,
    -25360.0 / 2187.0,
    64448.0 / 6561.0,
    -212.0 / 729.0,
];
const A6: [f64; 5] = [
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
];
const B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
/// `b_j - b*_j`: the fifth-order weights minus the embedded fourth-order ones.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Step-size controller: safety factor and bounds on the growth factor per step.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;

/// Error-control settings of [`DormandPrince`].
///
/// A step is accepted when the root-mean-square of `err_i / (atol + rtol * max(|y_i|, |y_new_i|))`
/// is at most 1, `err` being the difference of the fifth- and fourth-order solutions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Relative tolerance, positive.
    pub rtol: f64,
    /// Absolute tolerance, positive.
    pub atol: f64,
    /// First step size; `None` picks one from the problem (Hairer's starting-step heuristic).
    pub h_init: Option<f64>,
    /// Smallest step size allowed before the integration fails (the floating-point resolution of
    /// `t` is always enforced too).
    pub h_min: f64,
    /// Largest step size.
    pub h_max: f64,
    /// Most steps (accepted plus rejected) one [`DormandPrince::integrate`] call may take.
    pub max_steps: usize,
}

impl Default for Tolerances {
    /// `rtol = 1e-6`, `atol = 1e-9`, automatic first step, no step bounds, 1,000,000 steps.
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: 1e-9,
            h_init: None,
            h_min: 0.0,
            h_max: f64::INFINITY,
            max_steps: 1_000_000,
        }
    }
}

/// The smallest relative tolerance, 100 machine epsilons (SciPy's floor for `solve_ivp`): a
/// tighter one asks for digits the arithmetic does not carry, and the step size would fall to
/// its minimum instead.
pub const MIN_RTOL: f64 = 100.0 * f64::EPSILON;

impl Tolerances {
    /// The setting that fails and what it must be, with the value given, if any (checked by
    /// every [`DormandPrince::integrate`] call and when a simulation is built).
    pub(crate) fn check(&self) -> Result<(), (&'static str, String)> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let refuse = |name, requirement: &str, value: f64| {
            Err((name, format!("{requirement}, got {}", Compact(value))))
        };
        if !(positive(self.rtol) && self.rtol >= MIN_RTOL) {
            return refuse(
                "rtol",
                &format!(
                    "must be finite and at least {} (100 machine epsilons)",
                    Compact(MIN_RTOL)
                ),
                self.rtol,
            );
        }
        if !positive(self.atol) {
            return refuse("atol", "must be positive and finite", self.atol);
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite()) {
            return refuse("h_min", "must be non-negative and finite", self.h_min);
        }
        if !(self.h_max > 0.0 && self.h_max >= self.h_min) {
            return refuse("h_max", "must be positive and at least h_min", self.h_max);
        }
        if let Some(h) = self.h_init
            && !positive(h)
        {
            return refuse("h_init", "must be positive and finite", h);
        }
        if self.max_steps == 0 {
            return Err(("max_steps", "must be at least 1, got 0".into()));
        }
        Ok(())
    }
}

/// Adaptive Dormand-Prince 5(4) with preallocated stages.
///
/// The step size chosen at the end of one [`integrate`](Self::integrate) call is the first try of
/// the next, so integrating over many short intervals (a sampled controller) stays cheap.
///
/// ```
/// use sim_core::ode::{DormandPrince, OdeSystem, Tolerances};
/// // The harmonic oscillator x'' = -x, from x = 1 at rest.
/// struct Oscillator;
/// impl OdeSystem for Oscillator {
///     type Error = std::convert::Infallible;
///     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error> {
///         dy[0] = y[1];
///         dy[1] = -y[0];
///         Ok(())
///     }
/// }
/// let tol = Tolerances { rtol: 1e-10, atol: 1e-12, ..Tolerances::default() };
/// let mut solver = DormandPrince::new(2, tol);
/// let mut y = [1.0, 0.0];
/// solver.integrate(&mut Oscillator, 0.0, 3.0, &mut y).unwrap();
/// assert!((y[0] - 3.0f64.cos()).abs() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct DormandPrince {
    tolerances: Tolerances,
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    y_new: Vec<f64>,
    start: Vec<f64>,
    h_next: Option<f64>,
}

impl DormandPrince {
    /// An integrator for states of `dim` numbers; the tolerances are checked on each call.
    pub fn new(dim: usize, tolerances: Tolerances) -> Self {
        Self {
            tolerances,
            k: std::array::from_fn(|_| vec![0.0; dim]),
            stage: vec![0.0; dim],
            y_new: vec![0.0; dim],
            start: vec![0.0; dim],
            h_next: None,
        }
    }

    /// The state dimension this integrator was built for.
    pub fn dim(&self) -> usize {
        self.stage.len()
    }

    /// The error-control settings.
    pub fn tolerances(&self) -> &Tolerances {
        &self.tolerances
    }

    /// The derivative `f(t0, y0)` at the start of the last [`integrate`](Self::integrate) call
    /// (zeros before the first call).
    pub fn start_derivative(&self) -> &[f64] {
        &self.start
    }

    /// Forgets the step size carried over from the previous call.
    pub fn reset(&mut self) {
        self.h_next = None;
    }

    /// Integrates from `t0` to exactly `t1` with error control, updating `y` in place.
    ///
    /// The first stage is always evaluated afresh at `(t0, y)`, so the right-hand side may change
    /// between calls (for instance a control input held over `[t0, t1]`).
    pub fn integrate<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t0: f64,
        t1: f64,
        y: &mut [f64],
    ) -> Result<Stats, OdeError<S::Error>> {
        check_call(self.dim(), y, t0, t1)?;
        self.tolerances
            .check()
            .map_err(|(name, requirement)| OdeError::InvalidTolerance { name, requirement })?;
        let tol = self.tolerances;
        let mut stats = Stats::default();
        if t1 == t0 {
            return Ok(stats);
        }
        eval(system, t0, y, &mut self.k[0], &mut stats)?;
        self.start.copy_from_slice(&self.k[0]);
        let mut h = match (self.h_next, tol.h_init) {
            (Some(h), _) | (None, Some(h)) => h,
            (None, None) => self.initial_step(system, t0, y, &mut stats)?,
        }
        .min(tol.h_max);
        let mut t = t0;
        let mut just_rejected = false;
        loop {
            if stats.accepted + stats.rejected >= tol.max_steps {
                return Err(OdeError::MaxSteps {
                    t,
                    max_steps: tol.max_steps,
                });
            }
            let remaining = t1 - t;
            // Land exactly on t1; a last step a hair longer than `h` beats a sliver of a step.
            let last = remaining <= h * (1.0 + 1e-10);
            let h_try = if last { remaining } else { h };
            let h_floor = tol.h_min.max(16.0 * f64::EPSILON * t.abs().max(t1.abs()));
            if h_try < h_floor && !last {
                return Err(OdeError::StepTooSmall {
                    t,
                    h: h_try,
                    h_min: h_floor,
                });
            }
            let err = self.try_step(system, t, y, h_try, &mut stats)?;
            if err <= 1.0 {
                stats.accepted += 1;
                y.copy_from_slice(&self.y_new);
                // First same as last: f(t + h, y_new) is the next step's first stage.
                self.k.swap(0, 6);
                let growth = if err == 0.0 {
                    FAC_MAX
                } else {
                    SAFETY * err.powf(-0.2)
                };
                let fac_max = if just_rejected { 1.0 } else { FAC_MAX };
                let h_proposed = (h_try * growth.clamp(FAC_MIN, fac_max)).min(tol.h_max);
                // A step cut short to land on t1 says nothing against the longer step.
                h = if last { h_proposed.max(h) } else { h_proposed };
                just_rejected = false;
                if last {
                    break;
                }
                t += h_try;
            } else {
                stats.rejected += 1;
                let shrink = if err.is_finite() {
                    (SAFETY * err.powf(-0.2)).clamp(FAC_MIN, 1.0)
                } else {
                    FAC_MIN
                };
                h = h_try * shrink;
                just_rejected = true;
                if h < h_floor {
                    return Err(OdeError::StepTooSmall {
                        t,
                        h,
                        h_min: h_floor,
                    });
                }
            }
        }
        self.h_next = Some(h);
        Ok(stats)
    }

    /// Computes stages 2-7 and `y_new` for a step of size `h` from `(t, y)` (stage 1 in `k[0]`),
    /// and returns the scaled RMS error estimate (`NaN` or infinite if the trial blew up).
    fn try_step<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Result<f64, OdeError<S::Error>> {
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let stage = &mut self.stage;
        combine(stage, y, h, &A2, &[k1]);
        eval(system, t + C[1] * h, stage, k2, stats)?;
        combine(stage, y, h, &A3, &[k1, k2]);
        eval(system, t + C[2] * h, stage, k3, stats)?;
        combine(stage, y, h, &A4, &[k1, k2, k3]);
        eval(system, t + C[3] * h, stage, k4, stats)?;
        combine(stage, y, h, &A5, &[k1, k2, k3, k4]);
        eval(system, t + C[4] * h, stage, k5, stats)?;
        combine(stage, y, h, &A6, &[k1, k2, k3, k4, k5]);
        eval(system, t + C[5] * h, stage, k6, stats)?;
        combine(&mut self.y_new, y, h, &B, &[k1, k2, k3, k4, k5, k6]);
        if self.y_new.iter().any(|v| !v.is_finite()) {
            return Ok(f64::INFINITY);
        }
        eval(system, t + h, &self.y_new, k7, stats)?;
        let tol = &self.tolerances;
        let mut sum = 0.0;
        for j in 0..y.len() {
            let e = h
                * (E[0] * k1[j]
                    + E[2] * k3[j]
                    + E[3] * k4[j]
                    + E[4] * k5[j]
                    + E[5] * k6[j]
                    + E[6] * k7[j]);
            let scale = tol.atol + tol.rtol * y[j].abs().max(self.y_new[j].abs());
            sum += (e / scale).powi(2);
        }
        Ok((sum / y.len().max(1) as f64).sqrt())
    }

    /// Hairer's starting step: `h0 = 0.01 |y0| / |f0|`, refined by a second-derivative estimate
    /// so that the local error of the first step is about the tolerance.
    fn initial_step<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t0: f64,
        y0: &[f64],
        stats: &mut Stats,
    ) -> Result<f64, OdeError<S::Error>> {
        let tol = self.tolerances;
        let n = y0.len().max(1) as f64;
        let scale = |j: usize| tol.atol + tol.rtol * y0[j].abs();
        let norm = |v: &[f64]| {
            (v.iter()
                .enumerate()
                .map(|(j, x)| (x / scale(j)).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        };
        let [f0, f1, ..] = &mut self.k;
        let d0 = norm(y0);
        let d1 = norm(f0);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        }
        .min(tol.h_max);
        combine(&mut self.stage, y0, h0, &[1.0], &[f0]);
        eval(system, t0 + h0, &self.stage, f1, stats)?;
        let d2 = (0..y0.len())
            .map(|j| ((f1[j] - f0[j]) / scale(j)).powi(2))
            .sum::<f64>()
            .sqrt()
            / n.sqrt()
            / h0;
        let d = d1.max(d2);
        let h1 = if !d.is_finite() {
            h0
        } else if d <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d).powf(0.2)
        };
        Ok((100.0 * h0).min(h1))
    }
}
