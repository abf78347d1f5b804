//! Numerical inverse kinematics of the `K`-harmonic backbone curve (beyond the paper).
//!
//! With `alpha0` and the length fixed, the end point `p(a)` of the curve is a smooth map from the
//! `2K` modal coordinates to the plane. [`HarmonicIk`] solves `p(a) = target` by
//! Levenberg-Marquardt (damped least squares) from a caller's initial guess:
//! `delta = -J^T (J J^T + mu I)^{-1} (p(a) - target)`, with the analytic end-point Jacobian
//! `J = d p / d a` of [`BackboneCurve::end_point_jacobian`] and steps no longer than 0.5 rad (a
//! trust region in modal space). The damping `mu` shrinks after every step that reduces the
//! end-point error and grows after every step that does not, so near a solution the step is the
//! minimum-norm Gauss-Newton step. For `K = 1` (`J` square) that is Newton's method on eqs 3-4:
//! from a nearby guess it converges to the closed-form solution of eqs 5-6. For `K > 1` the
//! problem is underdetermined and the solver returns a solution near the guess.
//!
//! The method is local. Measured on the end points of random curves (`alpha0` uniform in
//! `[-0.5, 0.5]`), from guesses uniform in `[-0.5, 0.5]^{2K}`, 400 targets for each `K = 1, 2, 3`:
//! with modal coordinates uniform in `[-0.5, 0.5]` it converges in 1199 of 1200 cases (6-7
//! iterations on average), in `[-1, 1]` in 98%, in `[-2, 2]` in 99% (8-10 iterations); the test
//! `numeric_ik_convergence_rates` keeps these rates. Failures are stationary points of the
//! end-point error (where the tip cannot move radially) and are reported as
//! [`KinError::NotConverged`]. Without a caller's guess, [`HarmonicIk::solve_unguided`] starts
//! from the closed form of eqs 5-6 and, where that has no answer or does not converge, from a
//! fixed list of other starts: it reaches every end point of 200 random `K = 2` and `K = 3`
//! curves with coordinates in `[-0.5, 0.5]` (test `unguided_ik_reaches_what_the_family_reaches`).

use crate::closed_form::{Branch, check_reach, inverse_kinematics};
use crate::curve::BackboneCurve;
use crate::error::KinError;
use crate::modal_map::check_harmonics;
use lane_math::Classify;
use lane_math::{check_finite, check_values};

/// Stopping rules of [`HarmonicIk::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// End-point error to reach, relative to the curve length: the solver stops once
    /// `|p(a) - target| <= tolerance * l`. Default `1e-14`.
    pub tolerance: f64,
    /// Most trial steps (accepted or rejected) before giving up with
    /// [`KinError::NotConverged`]; 0 only checks the guess. Default 100.
    pub max_iterations: usize,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-14,
            max_iterations: 100,
        }
    }
}

impl IkOptions {
    /// The default options for the tip of a chain of `n_links` links: the tolerance is raised to
    /// `8 n eps` where the rounding of summing the links' contributions would not reach it.
    pub(crate) fn for_chain(n_links: usize) -> Self {
        let rounding = 8.0 * n_links as f64 * f64::EPSILON;
        let default = Self::default();
        Self {
            tolerance: default.tolerance.max(rounding),
            ..default
        }
    }

    /// Checks that `tolerance` is positive and finite.
    pub(crate) fn validate(&self) -> Result<(), KinError> {
        check_finite("IK tolerance", self.tolerance)?;
        if self.tolerance <= 0.0 {
            return Err(KinError::NonPositiveLength {
                name: "IK tolerance",
                value: self.tolerance,
            });
        }
        Ok(())
    }
}

/// What a successful [`HarmonicIk::solve`] spent and reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkReport {
    /// Trial steps taken (0 if the initial guess already met the tolerance).
    pub iterations: usize,
    /// Final end-point error `|p(a) - target|`.
    pub residual: f64,
}

/// Relative damping `mu / trace(J J^T)` of the first step and the smallest one used.
const DAMPING_MIN: f64 = 1e-15;
/// Relative damping after the first rejected step.
const DAMPING_RESTART: f64 = 1e-6;
/// Relative damping beyond which the solver has stalled.
const DAMPING_MAX: f64 = 1e16;
/// Longest step in modal space (radians, Euclidean norm): a trust region. Without it the first
/// Gauss-Newton steps from a near-straight guess (where `J` is nearly rank one) jump to
/// amplitudes of several radians, where the end-point map is full of stationary points.
const MAX_STEP: f64 = 0.5;

/// Reusable solver for the end point of a `K`-harmonic curve of fixed length and `alpha0`.
/// Created once; [`solve`](Self::solve) allocates nothing.
///
/// ```
/// use backbone_kin::{BackboneCurve, HarmonicIk};
/// let mut ik = HarmonicIk::new(1.0, 2, 0.3)?;
/// let target = [0.4, 0.6];
/// let mut a = [0.5, 0.5, 0.1, -0.1]; // initial guess on entry, solution on return
/// let report = ik.solve(target, &mut a)?;
/// let tip = BackboneCurve::new(1.0, &a, 0.3)?.end_point();
/// assert!((tip[0] - 0.4).abs() < 1e-13 && (tip[1] - 0.6).abs() < 1e-13);
/// assert!(report.residual <= 1e-14);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
#[derive(Debug, Clone)]
pub struct HarmonicIk {
    curve: BackboneCurve,
    options: IkOptions,
    trial: Vec<f64>,
    jacobian: Vec<f64>,
    trial_jacobian: Vec<f64>,
}

impl HarmonicIk {
    /// A solver for curves of length `length` with `harmonics` harmonics (`2 * harmonics`
    /// unknowns) leaving the base at `alpha0`, with [`IkOptions::default`].
    pub fn new(length: f64, harmonics: usize, alpha0: f64) -> Result<Self, KinError> {
        check_harmonics(harmonics)?;
        let m = 2 * harmonics;
        Ok(Self {
            curve: BackboneCurve::new(length, &vec![0.0; m], alpha0)?,
            options: IkOptions::default(),
            trial: vec![0.0; m],
            jacobian: vec![0.0; 2 * m],
            trial_jacobian: vec![0.0; 2 * m],
        })
    }

    /// Replaces the stopping rules; `tolerance` must be positive and finite.
    pub fn with_options(mut self, options: IkOptions) -> Result<Self, KinError> {
        options.validate()?;
        self.options = options;
        Ok(self)
    }

    /// The number of harmonics `K` (the solver has `2K` unknowns).
    pub fn harmonics(&self) -> usize {
        self.curve.harmonics()
    }

    /// The stopping rules in use.
    pub fn options(&self) -> IkOptions {
        self.options
    }

    /// Solves `p(a) = target` for the modal coordinates `a` (`2K` entries), which hold the
    /// initial guess on entry and the solution on success; after [`KinError::NotConverged`] they
    /// hold the best iterate found.
    ///
    /// Errors: [`KinError::OutOfReach`] if `|target| > l` beyond rounding (no curve of length `l`
    /// reaches it); [`KinError::NotConverged`] if the tolerance is not met within the iteration
    /// budget or the iteration stalls (for a target the family cannot reach with this `alpha0`);
    /// [`KinError::Stationary`] where no step is defined (from the straight guess `a = 0`, where
    /// the end point does not move to first order); input errors for a non-finite target or
    /// guess, or a guess of the wrong size.
    pub fn solve(&mut self, target: [f64; 2], a: &mut [f64]) -> Result<IkReport, KinError> {
        check_finite("target x", target[0])?;
        check_finite("target y", target[1])?;
        check_values("initial guess", a, self.trial.len())?;
        let length = self.curve.length();
        let r = target[0].hypot(target[1]);
        check_reach(r, length)?;
        let tolerance = self.options.tolerance * length;
        let curve = &mut self.curve;
        least_squares(
            target,
            a,
            tolerance,
            self.options.max_iterations,
            Workspace {
                trial: &mut self.trial,
                jacobian: &mut self.jacobian,
                trial_jacobian: &mut self.trial_jacobian,
            },
            |modes, jacobian| {
                curve.set_modes(modes)?;
                curve.end_point_jacobian(jacobian)
            },
        )
    }
}

/// The first two modal coordinates of the starts [`HarmonicIk::solve_unguided`] tries after the
/// closed form (the higher harmonics start at zero), for `branch = Positive`; `Negative` flips
/// the sign of `a1`. Curves of moderate curvature on both sides of the base direction.
const FALLBACK_STARTS: [[f64; 2]; 12] = [
    [0.5, 0.5],
    [0.5, -0.5],
    [1.0, 1.0],
    [1.0, -1.0],
    [1.5, 0.0],
    [-0.5, 0.5],
    [-0.5, -0.5],
    [2.0, 1.0],
    [2.0, -1.0],
    [-1.0, 1.0],
    [-1.0, -1.0],
    [0.0, 1.5],
];

impl HarmonicIk {
    /// Solves `p(a) = target` without a caller's guess (the `2K` entries of `a` are
    /// overwritten): first from the closed form of eqs 5-6 on `branch` (higher harmonics zero),
    /// then, if the closed form has no answer (a target the `K = 1` family does not reach,
    /// `|a2| > A`) or the iteration does not converge from it, from the closed form on the
    /// other branch and from `FALLBACK_STARTS` in turn. A solution found from the closed form
    /// is the one [`solve`](Self::solve) finds from it; otherwise the first start that converges
    /// gives the answer, so the result is deterministic.
    ///
    /// Errors: those of [`solve`](Self::solve) for bad input or an out-of-reach target; if no
    /// start converges, the closed form's own error when it had none to offer (e.g.
    /// [`KinError::A2ExceedsAmplitude`]), else [`KinError::NotConverged`] from it.
    pub fn solve_unguided(
        &mut self,
        target: [f64; 2],
        branch: Branch,
        a: &mut [f64],
    ) -> Result<IkReport, KinError> {
        check_values("modal coordinates", a, self.trial.len())?;
        let (length, alpha0) = (self.curve.length(), self.curve.alpha0());
        let other = match branch {
            Branch::Positive => Branch::Negative,
            Branch::Negative => Branch::Positive,
        };
        let sign = match branch {
            Branch::Positive => 1.0,
            Branch::Negative => -1.0,
        };
        let mut first_error = None;
        for start in 0..2 + FALLBACK_STARTS.len() {
            a.fill(0.0);
            match start {
                0 | 1 => {
                    let side = if start == 0 { branch } else { other };
                    match inverse_kinematics(length, target, alpha0, side) {
                        Ok(closed) => a[..2].copy_from_slice(&closed),
                        Err(error) => {
                            if error.is_unreachable()
                                && !matches!(error, KinError::OutOfReach { .. })
                            {
                                first_error.get_or_insert(error);
                                continue;
                            }
                            return Err(error);
                        }
                    }
                }
                k => {
                    let [a1, a2] = FALLBACK_STARTS[k - 2];
                    a[0] = sign * a1;
                    a[1] = a2;
                }
            }
            match self.solve(target, a) {
                Ok(report) => return Ok(report),
                Err(error @ KinError::NotConverged { .. }) => {
                    first_error.get_or_insert(error);
                }
                Err(error) => return Err(error),
            }
        }
        Err(first_error.expect("at least one start was tried"))
    }
}

/// The buffers of [`least_squares`]: a trial point (`m` entries) and two `D x m` Jacobians.
pub(crate) struct Workspace<'w> {
    pub(crate) trial: &'w mut [f64],
    pub(crate) jacobian: &'w mut Vec<f64>,
    pub(crate) trial_jacobian: &'w mut Vec<f64>,
}

/// The damped least-squares iteration of the module docs on any end-point map into `D = 2` or
/// `3` dimensions: `point_and_jacobian(a, J)` returns `p(a)` and writes `J = d p / d a`
/// (`D x m`, row-major). `a` holds the guess on entry and the solution (or the best iterate) on
/// return.
pub(crate) fn least_squares<const D: usize>(
    target: [f64; D],
    a: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
    work: Workspace<'_>,
    mut point_and_jacobian: impl FnMut(&[f64], &mut [f64]) -> Result<[f64; D], KinError>,
) -> Result<IkReport, KinError> {
    let Workspace {
        trial,
        jacobian,
        trial_jacobian,
    } = work;
    let mut point = point_and_jacobian(a, jacobian)?;
    let mut residual = distance(point, target);
    let mut damping = DAMPING_MIN;
    let mut iterations = 0;
    while residual > tolerance {
        let error: [f64; D] = std::array::from_fn(|d| point[d] - target[d]);
        if iterations == max_iterations || damping > DAMPING_MAX {
            return Err(KinError::NotConverged {
                iterations,
                residual,
                tolerance,
            });
        }
        if !damped_step(jacobian, error, damping, a, trial) {
            return Err(KinError::Stationary {
                iterations,
                residual,
            });
        }
        iterations += 1;
        match point_and_jacobian(trial, trial_jacobian) {
            Ok(trial_point) if distance(trial_point, target) < residual => {
                point = trial_point;
                residual = distance(point, target);
                a.copy_from_slice(trial);
                std::mem::swap(jacobian, trial_jacobian);
                damping = (damping / 10.0).max(DAMPING_MIN);
            }
            _ => damping = (damping * 10.0).max(DAMPING_RESTART),
        }
    }
    Ok(IkReport {
        iterations,
        residual,
    })
}

/// `trial = a - J^T (J J^T + mu I)^{-1} error` with `mu = damping * trace(J J^T)`, `J` the
/// `D x m` row-major end-point Jacobian, the step shortened to at most [`MAX_STEP`]. Returns
/// false when the step is undefined (`J J^T + mu I` singular, e.g. `J = 0`).
///
/// The step is the same for `s J` and `s error`: `J` and `error` are scaled by the power of two
/// `s` that brings `J`'s largest entry near 1, so that the Gram matrix's determinant (the
/// fourth or sixth power of `J`'s scale) neither overflows for a chain of 1e80 m nor
/// underflows for one of 1e-90 m; a power of two scales every product exactly, so the step's
/// bits are those of the unscaled formula wherever that does not leave the normal numbers.
fn damped_step<const D: usize>(
    jacobian: &[f64],
    error: [f64; D],
    damping: f64,
    a: &[f64],
    trial: &mut [f64],
) -> bool {
    let m = a.len();
    let largest = jacobian.iter().fold(0.0f64, |big, x| big.max(x.abs()));
    if !(largest > 0.0 && largest.is_finite()) {
        return false;
    }
    let s = power_of_two_near_inverse(largest);
    let error = error.map(|e| e * s);
    let scaled: [&[f64]; D] = std::array::from_fn(|d| &jacobian[d * m..(d + 1) * m]);
    let row = |d: usize| scaled[d].iter().map(move |x| x * s);
    let mut gram: [[f64; D]; D] = std::array::from_fn(|i| {
        std::array::from_fn(|j| row(i).zip(row(j)).map(|(p, q)| p * q).sum::<f64>())
    });
    let mu = damping * (0..D).map(|d| gram[d][d]).sum::<f64>();
    for (d, g) in gram.iter_mut().enumerate() {
        g[d] += mu;
    }
    let Some(y) = solve_symmetric(&gram, error) else {
        return false;
    };
    let step = |j: usize| (0..D).map(|d| scaled[d][j] * s * y[d]).sum::<f64>();
    let norm = (0..m).map(|j| step(j).powi(2)).sum::<f64>().sqrt();
    let scale = (MAX_STEP / norm).min(1.0);
    for (j, (t, &aj)) in trial.iter_mut().zip(a).enumerate() {
        *t = aj - scale * step(j);
    }
    true
}

/// A power of two within a factor of two of `1 / x`, for a positive finite `x` (at most
/// `2^1022`, so never infinite; `2^-1022` at least, so never zero).
fn power_of_two_near_inverse(x: f64) -> f64 {
    let exponent = ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    2f64.powi((-exponent).clamp(-1022, 1022))
}

/// `G^{-1} e` for a symmetric `2 x 2` or `3 x 3` matrix `G` by its adjugate (Cramer's rule), or
/// `None` where the determinant is not positive and finite.
fn solve_symmetric<const D: usize>(g: &[[f64; D]; D], e: [f64; D]) -> Option<[f64; D]> {
    let mut y = [0.0; D];
    let det = match D {
        2 => {
            let det = g[0][0] * g[1][1] - g[0][1] * g[0][1];
            y[0] = g[1][1] * e[0] - g[0][1] * e[1];
            y[1] = g[0][0] * e[1] - g[0][1] * e[0];
            det
        }
        3 => {
            let c = |i: usize, j: usize, k: usize, l: usize| g[i][k] * g[j][l] - g[i][l] * g[j][k];
            let adj = [
                [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
                [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
                [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
            ];
            for (yi, a) in y.iter_mut().zip(adj) {
                *yi = a[0] * e[0] + a[1] * e[1] + a[2] * e[2];
            }
            g[0][0] * adj[0][0] + g[0][1] * adj[1][0] + g[0][2] * adj[2][0]
        }
        _ => return None,
    };
    if !(det > 0.0 && det.is_finite()) {
        return None;
    }
    for yi in &mut y {
        *yi /= det;
    }
    Some(y)
}

/// `|p - q|`: `hypot` in the plane, [`vec3::distance`](crate::vec3::distance) in space (safe
/// from underflow and overflow both).
fn distance<const D: usize>(p: [f64; D], q: [f64; D]) -> f64 {
    match D {
        2 => (p[0] - q[0]).hypot(p[1] - q[1]),
        _ => crate::vec3::distance(std::array::from_fn(|k| p[k]), std::array::from_fn(|k| q[k])),
    }
}
