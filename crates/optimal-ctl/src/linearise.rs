//! The reduced model linearised about a state: continuous and zero-order-hold discrete `(A, B)`.

use faer::MatRef;
use modal_reduce::{Plant, PlantData, PlantDerivatives};

use super::OptimalError;
use lane_math::dense::exponential;

/// The linearisation of the reduced dynamics `x_dot = f(x, u)`, `x = (a, a_dot)`, `u = tau*`
/// (eq 15 as a first-order system), about a state and control:
///
/// ```text
/// A = [[0, I], [d a_ddot / d a, d a_ddot / d a_dot]],   B = [[0], [M*^-1]]   (continuous)
/// A_d = exp(A h),   B_d = int_0^h exp(A s) ds B                            (zero-order hold)
/// ```
///
/// with the analytic derivatives of the planar or spatial plant
/// (`modal_reduce::Plant::derivatives`); the discrete pair is the exact transition of the linear
/// system over a period `h` with `u` held, computed as one matrix exponential, `exp([[A, B], [0, 0]] h) = [[A_d, B_d], [0, I]]`. Build it once per model;
/// [`linearise`](Self::linearise) allocates nothing.
#[derive(Debug, Clone)]
pub struct Linearisation {
    m: usize,
    data: PlantData,
    derivatives: PlantDerivatives,
    /// `(3m) x (3m)` row-major: the augmented `[[A, B], [0, 0]] h`, then its exponential.
    augmented: Vec<f64>,
    exponential: Vec<f64>,
    work: Vec<f64>,
    /// Row-major: `A` (`2m x 2m`), `B` (`2m x m`), `A_d`, `B_d` (`a` is kept for modal coordinates).
    state_matrix: Vec<f64>,
    input_matrix: Vec<f64>,
    a_d: Vec<f64>,
    b_d: Vec<f64>,
    /// `f(x, u)`: `(a_dot, a_ddot)` at the linearisation point.
    drift: Vec<f64>,
}

impl Linearisation {
    /// The workspace for `model` (a planar or spatial arm).
    pub fn new<'p>(model: impl Into<Plant<'p>>) -> Self {
        let model = model.into();
        let m = model.n_coords();
        let s = 3 * m;
        Self {
            m,
            data: PlantData::new(model),
            derivatives: PlantDerivatives::new(model),
            augmented: vec![0.0; s * s],
            exponential: vec![0.0; s * s],
            work: vec![0.0; 2 * s * s],
            state_matrix: vec![0.0; 4 * m * m],
            input_matrix: vec![0.0; 2 * m * m],
            a_d: vec![0.0; 4 * m * m],
            b_d: vec![0.0; 2 * m * m],
            drift: vec![0.0; 2 * m],
        }
    }

    /// Linearises about `(a, a_dot)` and `tau_star`, with the zero-order hold over `period`
    /// seconds.
    ///
    /// # Errors
    /// [`OptimalError::InvalidSetting`] unless `period` is positive and finite (at most 1e3 s);
    /// [`OptimalError::Dynamics`] if the reduced dynamics refuses the state.
    pub fn linearise<'p>(
        &mut self,
        model: impl Into<Plant<'p>>,
        a: &[f64],
        a_dot: &[f64],
        tau_star: &[f64],
        period: f64,
    ) -> Result<(), OptimalError> {
        if !(period.is_finite() && period > 0.0 && period <= 1e3) {
            return Err(OptimalError::InvalidSetting {
                name: "period",
                requirement: "positive and at most 1e3 s",
                value: period,
            });
        }
        model
            .into()
            .derivatives(&mut self.data, &mut self.derivatives, a, a_dot, tau_star)?;
        let m = self.m;
        let n = 2 * m;
        let d = &self.derivatives;
        self.state_matrix.fill(0.0);
        self.input_matrix.fill(0.0);
        for i in 0..m {
            self.state_matrix[i * n + m + i] = 1.0;
            for j in 0..m {
                self.state_matrix[(m + i) * n + j] = d.d_a()[(i, j)];
                self.state_matrix[(m + i) * n + m + j] = d.d_a_dot()[(i, j)];
                self.input_matrix[(m + i) * m + j] = d.d_tau_star()[(i, j)];
            }
        }
        self.drift[..m].copy_from_slice(a_dot);
        self.drift[m..].copy_from_slice(d.a_ddot());
        // exp([[A, B], [0, 0]] h).
        let s = 3 * m;
        self.augmented.fill(0.0);
        for i in 0..n {
            for j in 0..n {
                self.augmented[i * s + j] = self.state_matrix[i * n + j] * period;
            }
            for j in 0..m {
                self.augmented[i * s + n + j] = self.input_matrix[i * m + j] * period;
            }
        }
        exponential(&self.augmented, &mut self.exponential, &mut self.work, s);
        for i in 0..n {
            self.a_d[i * n..(i + 1) * n].copy_from_slice(&self.exponential[i * s..i * s + n]);
            self.b_d[i * m..(i + 1) * m].copy_from_slice(&self.exponential[i * s + n..i * s + s]);
        }
        if self.a_d.iter().chain(&self.b_d).all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(OptimalError::InvalidSetting {
                name: "period",
                requirement: "short enough for exp(A h) to be finite",
                value: period,
            })
        }
    }

    /// Number of modal coordinates `m` (the state has `2m` entries, the control `m`).
    pub fn n_coords(&self) -> usize {
        self.m
    }

    /// Continuous `A` (`2m x 2m`).
    pub fn continuous_a(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.state_matrix, 2 * self.m, 2 * self.m)
    }

    /// Continuous `B` (`2m x m`).
    pub fn continuous_b(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.input_matrix, 2 * self.m, self.m)
    }

    /// Discrete `A_d = exp(A h)` (`2m x 2m`).
    pub fn discrete_a(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.a_d, 2 * self.m, 2 * self.m)
    }

    /// Discrete `B_d` (`2m x m`).
    pub fn discrete_b(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.b_d, 2 * self.m, self.m)
    }

    /// `f(x, u) = (a_dot, a_ddot)` at the linearisation point (zero at an equilibrium).
    pub fn drift(&self) -> &[f64] {
        &self.drift
    }

    /// The discrete matrices as row-major slices, for [`Lqr`](super::Lqr).
    pub(crate) fn discrete(&self) -> (&[f64], &[f64]) {
        (&self.a_d, &self.b_d)
    }
}
