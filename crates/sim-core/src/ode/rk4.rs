//! The classical fourth-order Runge-Kutta method with a fixed step.

use super::{OdeError, OdeSystem, Stats, check_call, combine, eval};

/// The most fixed steps an RK4 run may take (`duration / integrator.dt`), and one
/// [`Rk4::integrate`] call: about half an hour of computing for a 10-link arm, so a step typed
/// `1e-12` for `1e-4` is refused up front rather than running for days. A Dormand-Prince run
/// whose `h_max` forces more steps (`duration / h_max`) is refused the same way.
pub const MAX_RK4_STEPS: f64 = 1e9;

/// The nodes `c_s` of the classical tableau: stage `s` is evaluated at `t + c_s h` and
/// `y + h c_s k_{s-1}` (the first at `(t, y)` itself).
const NODES: [f64; Rk4::STAGES] = [0.0, 0.5, 0.5, 1.0];

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
    /// The stages of one step (right-hand side evaluations).
    pub(crate) const STAGES: usize = 4;

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
    /// in place. Returns the work done; `t1 == t0` takes no step, and an interval that needs more
    /// than [`MAX_RK4_STEPS`] steps is refused before the first.
    pub fn integrate<S: OdeSystem>(
        &mut self,
        system: &mut S,
        t0: f64,
        t1: f64,
        y: &mut [f64],
        max_step: f64,
    ) -> Result<Stats, OdeError<S::Error>> {
        let mut stats = Stats::default();
        let Some((steps, h)) = self.begin(t0, t1, y, max_step)? else {
            return Ok(stats);
        };
        for i in 0..steps {
            let t = Self::step_time(t0, i, h);
            for s in 0..Self::STAGES {
                let (t_s, y_s, k_s) = self.stage(s, t, y, h);
                eval(system, t_s, y_s, k_s, &mut stats)?;
            }
            stats.accepted += 1;
            self.finish_step(i, t, y, h)?;
        }
        Ok(stats)
    }

    /// Checks an integration of `y` from `t0` to `t1` in steps no longer than `max_step`, and
    /// plans it: the number of equal steps and their size, `None` for an empty interval.
    ///
    /// [`integrate`](Self::integrate) is `begin`, then for each step `i` the [`STAGES`](Self::STAGES)
    /// [`stage`](Self::stage)s from [`step_time`](Self::step_time)`(t0, i, h)` with their
    /// derivatives evaluated, then [`finish_step`](Self::finish_step); a lock-step group of
    /// runs (`crate::Lockstep`) drives the same calls for each of its runs, evaluating a stage
    /// of all of them at once.
    pub(crate) fn begin<E>(
        &self,
        t0: f64,
        t1: f64,
        y: &[f64],
        max_step: f64,
    ) -> Result<Option<(usize, f64)>, OdeError<E>> {
        check_call(self.dim(), y, t0, t1)?;
        if !(max_step.is_finite() && max_step > 0.0) {
            return Err(OdeError::InvalidSetting(
                "the RK4 step must be positive and finite",
            ));
        }
        let span = t1 - t0;
        if span == 0.0 {
            return Ok(None);
        }
        // A relative slack keeps `span / max_step = 1 + 1e-12` (the rounding of `t1 - t0` far from
        // the origin) from costing a second step; a step that much longer is harmless.
        let steps = ((span / max_step) * (1.0 - 1e-9)).ceil().max(1.0);
        if steps > MAX_RK4_STEPS {
            return Err(OdeError::InvalidSetting(
                "the RK4 step is too small for the interval: more than 1e9 steps (MAX_RK4_STEPS)",
            ));
        }
        let steps = steps as usize;
        Ok(Some((steps, span / steps as f64)))
    }

    /// The start of step `i` of size `h` of an integration from `t0`.
    pub(crate) fn step_time(t0: f64, i: usize, h: f64) -> f64 {
        if i == 0 { t0 } else { t0 + i as f64 * h }
    }

    /// Stage `s` (`0..STAGES`) of the step of size `h` from `(t, y)`, the stages before it
    /// evaluated: its time `t + c_s h`, its state (`y` itself for the first stage, else
    /// `y + h c_s k_{s-1}`, in the stage buffer) and the buffer its derivative `k_s` goes into.
    pub(crate) fn stage<'a>(
        &'a mut self,
        s: usize,
        t: f64,
        y: &'a [f64],
        h: f64,
    ) -> (f64, &'a [f64], &'a mut [f64]) {
        let (done, next) = self.k.split_at_mut(s);
        match done.last() {
            None => (t, y, &mut next[0]),
            Some(previous) => {
                combine(&mut self.stage, y, h, &[NODES[s]], &[previous]);
                (t + NODES[s] * h, &self.stage, &mut next[0])
            }
        }
    }

    /// The derivative buffer `k_s` of stage `s`, for a caller that evaluates it after
    /// [`stage`](Self::stage) has returned.
    pub(crate) fn derivative_mut(&mut self, s: usize) -> &mut [f64] {
        &mut self.k[s]
    }

    /// Completes step `i` of size `h` from `(t, y)` once its [`STAGES`](Self::STAGES) derivatives are in:
    /// `y += h/6 (k1 + 2 (k2 + k3) + k4)`, and after the first step of an integration its first
    /// derivative becomes the [`start_derivative`](Self::start_derivative). Fails if the new
    /// state is not finite.
    pub(crate) fn finish_step<E>(
        &mut self,
        i: usize,
        t: f64,
        y: &mut [f64],
        h: f64,
    ) -> Result<(), OdeError<E>> {
        let [k1, k2, k3, k4] = &self.k;
        let sixth = h / 6.0;
        for (j, yj) in y.iter_mut().enumerate() {
            *yj += sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
        if y.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t });
        }
        if i == 0 {
            self.start.copy_from_slice(k1);
        }
        Ok(())
    }
}
