//! The spatial backbone curve of the spatial modal family and its tip (`docs/theory.md`,
//! "Spatial modal arms").
//!
//! The curve's frame `R(s)` turns with the body-frame rate `w(s) = (0, alpha_y'(s),
//! alpha_z'(s))`: `R' = R [w]x`, `R(0)` the base rotation; its position follows the frame's `x`
//! axis, `p' = R e_x`, `p(0)` the base position. `alpha_z` and `alpha_y` are the two planar
//! `K`-harmonic inclinations of [`SpatialModalMap`](crate::SpatialModalMap), whose derivatives
//! are `alpha'(s) = sum_k (2 pi k / l) (a_{2k-1} cos(2 pi k s / l) + a_{2k} sin(2 pi k s / l))`.
//! A universal-joint chain whose joint angles follow the modal map is this curve discretised:
//! link `i`'s frame is the product of the turns `Rz(z_j) Ry(y_j)` up to it.
//!
//! Where the curve bends in one plane it has the planar closed forms (the end point through `J0`
//! for `K = 1`, quadrature otherwise: [`BackboneCurve`](crate::BackboneCurve)); in general the
//! frame equation has none, and [`SpatialCurve::tip`] integrates it with the classical fourth-order
//! Runge-Kutta method at `N` and `2N` equal steps, doubling `N` until Richardson's estimate of the
//! error of the finer result, `|p_2N - p_N| / 15`, meets the tolerance. The estimate is
//! asymptotically exact for a fourth-order method (its leading error term is `C h^4`); the tests
//! hold it against the planar closed forms and against a chain of many links.

use crate::error::KinError;
use crate::modal_map::check_harmonics;
use crate::spatial_chain::BasePose;
use crate::validate::check_length;
use crate::vec3::{Rotation, add, column, distance, mat_mul};
use lane_math::check_values;

/// The most Runge-Kutta steps [`SpatialCurve::tip`] takes over the curve with one harmonic per
/// plane (2^22); with `K` it takes at most `MAX_CURVE_STEPS / K`, since a step's work grows with
/// `K` (a refusal takes about as long for every `K`: about a second).
pub const MAX_CURVE_STEPS: usize = 1 << 22;

/// The most the frame may turn in one step (rad) of the first pair of integrations: below it
/// Richardson's estimate is in its asymptotic range, where the step-doubling cannot be fooled by
/// steps that sample the oscillation at the same phase (`a = 3000` was answered from two such
/// coarse grids, metres from the converged tip).
const MAX_STEP_TURN: f64 = 0.5;

/// The default tip tolerance of [`SpatialCurve::tip`], relative to the curve length.
pub const SPATIAL_CURVE_TOLERANCE: f64 = 1e-12;

/// The curve's tip as [`SpatialCurve::tip`] integrated it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveTip {
    /// The tip's position in the world frame (m).
    pub position: [f64; 3],
    /// The frame at the tip, `R(l)`.
    pub rotation: Rotation,
    /// Richardson's estimate of the position's error (m).
    pub error_estimate: f64,
    /// Runge-Kutta steps of the returned result.
    pub steps: usize,
}

/// A spatial backbone curve of length `l` with `K` harmonics per plane (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialCurve {
    length: f64,
    harmonics: usize,
    modes: Vec<f64>,
    base: BasePose,
}

impl SpatialCurve {
    /// The curve of length `length` with modal coordinates `a = [a_z (2K), a_y (2K)]`
    /// (`4 * harmonics` entries) leaving the base pose `base`.
    pub fn new(length: f64, harmonics: usize, a: &[f64], base: BasePose) -> Result<Self, KinError> {
        check_length("curve length", length)?;
        check_harmonics(harmonics)?;
        check_values("modal coordinates", a, 4 * harmonics)?;
        base.validate()?;
        Ok(Self {
            length,
            harmonics,
            modes: a.to_vec(),
            base,
        })
    }

    /// The curve length `l`.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// A bound on the turning rate `|w(s)|` over the curve (rad/m): each harmonic's
    /// `omega_k (|a_k| + |b_k|)`, summed over both planes.
    fn turning_bound(&self) -> f64 {
        self.modes
            .chunks_exact(2 * self.harmonics)
            .flat_map(|plane| plane.chunks_exact(2).enumerate())
            .map(|(k, pair)| {
                let omega = std::f64::consts::TAU * (k + 1) as f64 / self.length;
                omega * (pair[0].abs() + pair[1].abs())
            })
            .sum()
    }

    /// The body-frame turning rate `w(s) = (0, alpha_y'(s), alpha_z'(s))` at arc length `s`.
    pub fn rate(&self, s: f64) -> [f64; 3] {
        let (a_z, a_y) = self.modes.split_at(2 * self.harmonics);
        [0.0, slope(a_y, s, self.length), slope(a_z, s, self.length)]
    }

    /// The tip, its displacement from the base integrated to `tolerance` (metres, absolute;
    /// positive and finite; the base position is added after, with its own rounding), e.g.
    /// `SPATIAL_CURVE_TOLERANCE * l`, starting from steps that turn the frame at most
    /// `MAX_STEP_TURN` each.
    ///
    /// Errors: [`KinError::TooOscillatory`] if resolving the turning or meeting the tolerance
    /// would take more than `MAX_CURVE_STEPS / K` steps; [`KinError::NonPositiveLength`] for a tolerance that is not
    /// positive and finite.
    pub fn tip(&self, tolerance: f64) -> Result<CurveTip, KinError> {
        check_length("curve tip tolerance", tolerance)?;
        let max_steps = MAX_CURVE_STEPS / self.harmonics;
        // Steps that resolve the fastest turning `|w| <= sum_k omega_k (|a_k| + |b_k|)` (both
        // planes), known before any integration: a curve that needs more is refused at once.
        let resolving = (self.turning_bound() * self.length / MAX_STEP_TURN).ceil();
        // A bound that overflows (amplitudes of 1e308) is refused too.
        let within_budget = 2.0 * resolving <= max_steps as f64;
        if !within_budget {
            return Err(KinError::TooOscillatory {
                needed: 2.0 * resolving,
                max: max_steps,
            });
        }
        let mut steps = (8 * self.harmonics).max(resolving as usize);
        let mut coarse = self.integrate(steps);
        loop {
            let fine = self.integrate(2 * steps);
            // Estimated on the curve's own displacement: the base's offset (a base at 1e9 m)
            // would add its rounding to both and never let the estimate fall.
            let error = distance(fine.0, coarse.0) / 15.0;
            if error <= tolerance {
                return Ok(CurveTip {
                    position: add(self.base.xyz, fine.0),
                    rotation: fine.1,
                    error_estimate: error,
                    steps: 2 * steps,
                });
            }
            steps *= 2;
            if 2 * steps > max_steps {
                return Err(KinError::TooOscillatory {
                    needed: (2 * steps) as f64,
                    max: max_steps,
                });
            }
            coarse = fine;
        }
    }

    /// The displacement from the base and the frame at `s = l` after `steps` classical
    /// Runge-Kutta steps of the frame equation.
    fn integrate(&self, steps: usize) -> ([f64; 3], Rotation) {
        let h = self.length / steps as f64;
        let (mut p, mut r) = ([0.0; 3], self.base.rotation());
        let derivative = |r: &Rotation, s: f64| (mat_mul(*r, skew(self.rate(s))), column(r, 0));
        for step in 0..steps {
            let s = step as f64 * h;
            let (k1r, k1p) = derivative(&r, s);
            let r2 = axpy(&r, 0.5 * h, &k1r);
            let (k2r, k2p) = derivative(&r2, s + 0.5 * h);
            let r3 = axpy(&r, 0.5 * h, &k2r);
            let (k3r, k3p) = derivative(&r3, s + 0.5 * h);
            let r4 = axpy(&r, h, &k3r);
            let (k4r, k4p) = derivative(&r4, s + h);
            r = std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    r[i][j] + h / 6.0 * (k1r[i][j] + 2.0 * (k2r[i][j] + k3r[i][j]) + k4r[i][j])
                })
            });
            p = std::array::from_fn(|d| {
                p[d] + h / 6.0 * (k1p[d] + 2.0 * (k2p[d] + k3p[d]) + k4p[d])
            });
        }
        (p, r)
    }
}

/// `alpha'(s)` of one plane's coefficients `(a_1, ..., a_2K)` on a curve of length `length`.
fn slope(coefficients: &[f64], s: f64, length: f64) -> f64 {
    coefficients
        .chunks_exact(2)
        .enumerate()
        .map(|(k, pair)| {
            let omega = std::f64::consts::TAU * (k + 1) as f64 / length;
            let (sin, cos) = (omega * s).sin_cos();
            omega * (pair[0] * cos + pair[1] * sin)
        })
        .sum()
}

/// `[w]x`, the matrix of the cross product `w x .`.
fn skew(w: [f64; 3]) -> Rotation {
    [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
}

fn axpy(r: &Rotation, h: f64, k: &Rotation) -> Rotation {
    std::array::from_fn(|i| std::array::from_fn(|j| r[i][j] + h * k[i][j]))
}
