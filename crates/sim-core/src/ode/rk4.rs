//! The classical fourth-order Runge-Kutta method with a fixed step.

use super::{OdeError, OdeSystem, Stats, check_call, combine, eval};

/// Classical RK4 with preallocated stages: four right-hand side evaluations per step, global
/// error `O(h^4)`.
///
/// ```
/// use sim_core::ode::{OdeSystem, Rk4};
/// // y' = -y, y(0) = 1.
/// struct Decay;
/// impl OdeSystem for Decay {
///     type Error = std::convert::Infallible;
///     fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Self::Error> {
///         dy[0] = -y[0];
///         Ok(())
///     }
/// }
/// let mut y = [1.0];
/// Rk4::new(1).integrate(&mut Decay, 0.0, 1.0, &mut y, 1e-2).unwrap();
/// assert!((y[0] - (-1.0f64).exp()).abs() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct Rk4 {
    k: [Vec<f64>; 4],
    stage: Vec<f64>,
    start: Vec<f64>,
}

impl Rk4 {
    /// An integrator for states of `dim` numbers.
    pub fn new(dim: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            stage: vec![0.0; dim],
            start: vec![0.0; dim],
        }
    }

    /// The state dimension this integrator was built for.
    pub fn dim(&self) -> usize {
        self.stage.len()
    }

    /// The derivative `f(t0, y0)` at the start of the last [`integrate`](Self::integrate) call
    /// (zeros before the first call).
    pub fn start_derivative(&self) -> &[f64] {
        &self.start
    }

    /// Integrates from `t0` to exactly `t1` in equal steps no longer than `max_step`, updating `y`
    /// in place. Returns the work done; `t1 == t0` takes no step.
    pub fn integrate<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t0: f64,
        t1: f64,
        y: &mut [f64],
        max_step: f64,
    ) -> Result<Stats, OdeError<S::Error>> {
        check_call(self.dim(), y, t0, t1)?;
        if !(max_step.is_finite() && max_step > 0.0) {
            return Err(OdeError::InvalidSetting(
                "the RK4 step must be positive and finite",
            ));
        }
        let mut stats = Stats::default();
        let span = t1 - t0;
        if span == 0.0 {
            return Ok(stats);
        }
        // A relative slack keeps `span / max_step = 1 + 1e-12` (the rounding of `t1 - t0` far from
        // the origin) from costing a second step; a step that much longer is harmless.
        let steps = ((span / max_step) * (1.0 - 1e-9)).ceil().max(1.0);
        if steps > usize::MAX as f64 / 2.0 {
            return Err(OdeError::InvalidSetting(
                "the RK4 step is too small for the interval",
            ));
        }
        let steps = steps as usize;
        let h = span / steps as f64;
        for i in 0..steps {
            let t = if i == 0 { t0 } else { t0 + i as f64 * h };
            self.step(system, t, y, h, &mut stats)?;
            if i == 0 {
                self.start.copy_from_slice(&self.k[0]);
            }
        }
        Ok(stats)
    }

    /// One RK4 step of size `h` from `(t, y)`.
    fn step<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t: f64,
        y: &mut [f64],
        h: f64,
        stats: &mut Stats,
    ) -> Result<(), OdeError<S::Error>> {
        let [k1, k2, k3, k4] = &mut self.k;
        let stage = &mut self.stage;
        eval(system, t, y, k1, stats)?;
        combine(stage, y, h, &[0.5], &[k1]);
        eval(system, t + 0.5 * h, stage, k2, stats)?;
        combine(stage, y, h, &[0.5], &[k2]);
        eval(system, t + 0.5 * h, stage, k3, stats)?;
        combine(stage, y, h, &[1.0], &[k3]);
        eval(system, t + h, stage, k4, stats)?;
        let sixth = h / 6.0;
        for (j, yj) in y.iter_mut().enumerate() {
            *yj += sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
        stats.accepted += 1;
        if y.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t });
        }
        Ok(())
    }
}
