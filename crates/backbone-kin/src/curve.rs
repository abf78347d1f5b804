//! The backbone curve (eqs 1-4, corrected, generalised to `K` harmonics).
//!
//! A curve of length `l` leaves the base at the origin with inclination `alpha0`. Its curvature
//! is a sum of `K` harmonics (eq 1 for `K = 1`),
//! `kappa(s) = sum_k (2 pi k / l) (a_{2k-1} cos(2 pi k s / l) + a_{2k} sin(2 pi k s / l))`,
//! and its inclination is the integral (eq 2, with the sign of the last term corrected),
//! `alpha(s) = alpha0 + sum_k a_{2k-1} sin(2 pi k s / l) + a_{2k} (1 - cos(2 pi k s / l))`,
//! the same basis [`harmonic_basis`] that builds the modal Jacobian. A point of the curve is
//! `(x(s), y(s)) = int_0^s (cos alpha(u), sin alpha(u)) du`; only the end point of the two-mode
//! curve has a closed form (eqs 3-4, [`crate::end_point`]), every other point comes from
//! quadrature with the accuracy stated on [`QUADRATURE_TOLERANCE`].

use crate::closed_form::bessel_end_point;
use crate::error::KinError;
use crate::modal_map::harmonic_basis;
use crate::quadrature::{self, Resolution};
use crate::validate::check_length;
use lane_math::{check_finite, check_len, check_values};
use std::f64::consts::TAU;

/// Bound on the quadrature (truncation) error of [`BackboneCurve::point`] and of the `K > 1`
/// [`BackboneCurve::end_point`], relative to the curve length: every coordinate is within
/// `QUADRATURE_TOLERANCE * l` of the exact integral, plus floating-point rounding (a few
/// `1e-16 l`).
///
/// The bound is a priori and rigorous: `cos alpha` and `sin alpha` are entire in the arc length,
/// bounded by `exp(sum_k A_k sinh(2 pi k sigma / l))` in the strip `|Im s| <= sigma`
/// (`A_k = sqrt(a_{2k-1}^2 + a_{2k}^2)`). Points use the composite 10-point Gauss-Legendre rule
/// with panels narrow enough for the analytic-function error bound of Gauss quadrature to fall
/// below the tolerance; the end point, an integral over a full period of every harmonic, uses
/// the trapezoid rule with enough nodes for its geometric error bound to fall below it (see the
/// crate's `quadrature` module). Cost for the whole two-mode curve at amplitudes 0.1 to
/// `j_{0,1}`: 30-80 evaluations of `alpha` for a point, 9-20 for the end point.
pub const QUADRATURE_TOLERANCE: f64 = 1e-15;

/// Most quadrature nodes (evaluations of `alpha`) one integral over the whole curve may need;
/// curves whose amplitudes need more (modal amplitudes in the thousands of radians) are refused
/// with [`KinError::TooOscillatory`].
pub const MAX_QUADRATURE_NODES: usize = 1 << 20;

/// A backbone curve with `K` harmonics: length `l`, base inclination `alpha0` and modal
/// coordinates `(a_1, ..., a_{2K})`.
///
/// ```
/// use backbone_kin::BackboneCurve;
/// let curve = BackboneCurve::paper(1.0, 0.9, 0.4, 0.2)?;
/// // The quadrature reproduces the closed-form end point (eqs 3-4).
/// let (tip, end) = (curve.point(1.0)?, curve.end_point());
/// assert!((tip[0] - end[0]).abs() < 1e-14 && (tip[1] - end[1]).abs() < 1e-14);
/// assert!((curve.inclination(0.0)? - 0.2).abs() < 1e-15);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BackboneCurve {
    length: f64,
    alpha0: f64,
    modes: Vec<f64>,
    /// Quadrature that meets [`QUADRATURE_TOLERANCE`] for these modes.
    resolution: Resolution,
}

impl BackboneCurve {
    /// A curve of length `length` with modal coordinates `modes = (a_1, ..., a_{2K})`,
    /// `K = modes.len() / 2 >= 1`, leaving the base at inclination `alpha0`.
    pub fn new(length: f64, modes: &[f64], alpha0: f64) -> Result<Self, KinError> {
        check_length("curve length", length)?;
        if modes.is_empty() {
            return Err(KinError::NoHarmonics);
        }
        if modes.len() % 2 == 1 {
            return Err(KinError::UnpairedModes { got: modes.len() });
        }
        check_values("modal coordinates", modes, modes.len())?;
        check_finite("alpha0", alpha0)?;
        Ok(Self {
            length,
            alpha0,
            modes: modes.to_vec(),
            resolution: resolution(length, modes, QUADRATURE_TOLERANCE)?,
        })
    }

    /// The paper's two-mode curve (`K = 1`, eqs 1-2) with coordinates `(a1, a2)`.
    pub fn paper(length: f64, a1: f64, a2: f64, alpha0: f64) -> Result<Self, KinError> {
        Self::new(length, &[a1, a2], alpha0)
    }

    /// Replaces the modal coordinates, keeping `K`, the length and `alpha0`. Allocation-free;
    /// on error the curve is unchanged.
    pub fn set_modes(&mut self, modes: &[f64]) -> Result<(), KinError> {
        check_values("modal coordinates", modes, self.modes.len())?;
        self.resolution = resolution(self.length, modes, QUADRATURE_TOLERANCE)?;
        self.modes.copy_from_slice(modes);
        Ok(())
    }

    /// The curve length `l`.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The base inclination `alpha0` (radians).
    pub fn alpha0(&self) -> f64 {
        self.alpha0
    }

    /// The modal coordinates `(a_1, ..., a_{2K})`.
    pub fn modes(&self) -> &[f64] {
        &self.modes
    }

    /// The number of harmonics `K`.
    pub fn harmonics(&self) -> usize {
        self.modes.len() / 2
    }

    /// The curvature `kappa(s)` (eq 1, generalised to `K` harmonics), for `0 <= s <= l`.
    pub fn curvature(&self, s: f64) -> Result<f64, KinError> {
        self.check_arc(s)?;
        Ok(self
            .modes
            .chunks_exact(2)
            .enumerate()
            .map(|(i, pair)| {
                let k = i + 1;
                let (sin, one_minus_cos) = harmonic_basis(k, s, self.length);
                TAU * k as f64 / self.length * (pair[0] * (1.0 - one_minus_cos) + pair[1] * sin)
            })
            .sum())
    }

    /// The inclination `alpha(s)` (eq 2, corrected), for `0 <= s <= l`.
    pub fn inclination(&self, s: f64) -> Result<f64, KinError> {
        self.check_arc(s)?;
        Ok(self.alpha(s))
    }

    /// The point `(x(s), y(s))` at arc length `0 <= s <= l`, by composite Gauss-Legendre
    /// quadrature of `(cos alpha, sin alpha)` over `[0, s]`, within
    /// [`QUADRATURE_TOLERANCE`]` * l` per coordinate.
    pub fn point(&self, s: f64) -> Result<[f64; 2], KinError> {
        self.check_arc(s)?;
        let mut point = [0.0; 2];
        quadrature::for_each_node(0.0, s, self.resolution.panel_width, |u, w| {
            let (sin, cos) = self.alpha(u).sin_cos();
            point[0] += w * cos;
            point[1] += w * sin;
        });
        Ok(point)
    }

    /// The end point `(x(l), y(l))`: the closed form `l J0(A) (cos(alpha0 + a2), sin(alpha0 + a2))`
    /// for `K = 1` (eqs 3-4, corrected), the trapezoid rule over the whole curve otherwise
    /// (within [`QUADRATURE_TOLERANCE`]` * l`, like [`point`](Self::point)`(l)`).
    pub fn end_point(&self) -> [f64; 2] {
        match self.modes[..] {
            [a1, a2] => bessel_end_point(self.length, [a1, a2], self.alpha0),
            _ => {
                let mut point = [0.0; 2];
                self.integrate_end(|_, w, sin, cos| {
                    point[0] += w * cos;
                    point[1] += w * sin;
                });
                point
            }
        }
    }

    /// The end point by quadrature together with its derivatives along the modal coordinates,
    /// `d(x, y)(l) / d a_j = int_0^l (-sin alpha, cos alpha) b_j(s) ds` with `b_j` the basis of
    /// [`harmonic_basis`]. `jacobian` receives the `2 x 2K` matrix row-major (row 0: `x`,
    /// row 1: `y`). The derivative along `alpha0` is `(-y, x)` and is not included.
    ///
    /// The nodes are those of the end point, so the derivatives carry a quadrature error of
    /// the same order (their integrands grow at most by a factor `1 + cosh(2 pi K sigma / l)`
    /// more in the strip).
    pub fn end_point_jacobian(&self, jacobian: &mut [f64]) -> Result<[f64; 2], KinError> {
        let m = self.modes.len();
        check_len("end-point jacobian", jacobian.len(), 2 * m)?;
        jacobian.fill(0.0);
        let (dx, dy) = jacobian.split_at_mut(m);
        let mut point = [0.0; 2];
        self.integrate_end(|s, w, sin, cos| {
            point[0] += w * cos;
            point[1] += w * sin;
            for k in 1..=m / 2 {
                let (b_sin, b_one_minus_cos) = harmonic_basis(k, s, self.length);
                for (j, b) in [(2 * k - 2, b_sin), (2 * k - 1, b_one_minus_cos)] {
                    dx[j] -= w * sin * b;
                    dy[j] += w * cos * b;
                }
            }
        });
        Ok(point)
    }

    /// Quadrature over the whole curve by the periodic trapezoid rule:
    /// `visit(s, w, sin alpha(s), cos alpha(s))` at every node.
    fn integrate_end(&self, mut visit: impl FnMut(f64, f64, f64, f64)) {
        // `resolution` checked the node count against MAX_NODES.
        let nodes = self.resolution.periodic_nodes as usize;
        quadrature::for_each_periodic_node(self.length, nodes, |s, w| {
            let (sin, cos) = self.alpha(s).sin_cos();
            visit(s, w, sin, cos);
        });
    }

    /// `alpha(s)` without the range check.
    fn alpha(&self, s: f64) -> f64 {
        self.alpha0
            + self
                .modes
                .chunks_exact(2)
                .enumerate()
                .map(|(i, pair)| {
                    let (sin, one_minus_cos) = harmonic_basis(i + 1, s, self.length);
                    pair[0] * sin + pair[1] * one_minus_cos
                })
                .sum::<f64>()
    }

    fn check_arc(&self, s: f64) -> Result<(), KinError> {
        check_finite("arc length", s)?;
        if (0.0..=self.length).contains(&s) {
            Ok(())
        } else {
            Err(KinError::ArcLength {
                s,
                length: self.length,
            })
        }
    }
}

/// The quadrature that integrates `cos alpha` and `sin alpha` within `tolerance * length`: over
/// any part of the curve by Gauss-Legendre, over the whole curve by the trapezoid rule.
fn resolution(length: f64, modes: &[f64], tolerance: f64) -> Result<Resolution, KinError> {
    let harmonics = modes.len() / 2;
    // |Im alpha(t + i sigma)| <= sum_k A_k sinh(k x), x = 2 pi sigma / l, with sinh(k x) from
    // the recurrence sinh((k + 1) x) = 2 cosh(x) sinh(k x) - sinh((k - 1) x).
    let log_bound = |sigma: f64| -> f64 {
        let grow = (TAU * sigma / length).exp();
        let shrink = grow.recip();
        let (mut previous, mut current, twice_cosh) = (0.0, 0.5 * (grow - shrink), grow + shrink);
        let mut total = 0.0;
        for pair in modes.chunks_exact(2) {
            let square = pair[0] * pair[0] + pair[1] * pair[1];
            // `hypot` only where the square overflows (the same bits below).
            let amplitude = if square.is_finite() {
                square.sqrt()
            } else {
                pair[0].hypot(pair[1])
            };
            if amplitude > 0.0 {
                total += amplitude * current;
            }
            (previous, current) = (current, twice_cosh * current - previous);
        }
        total
    };
    let scale = length / (TAU * harmonics as f64);
    let resolution = quadrature::resolution(length, scale, tolerance * length, log_bound);
    let gauss_nodes = (length / resolution.panel_width).ceil() * quadrature::ORDER as f64;
    let needed = gauss_nodes.max(resolution.periodic_nodes);
    if needed <= MAX_QUADRATURE_NODES as f64 {
        Ok(resolution)
    } else {
        Err(KinError::TooOscillatory {
            needed,
            max: MAX_QUADRATURE_NODES,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panels(curve: &BackboneCurve) -> f64 {
        (curve.length / curve.resolution.panel_width).ceil()
    }

    #[test]
    fn panel_count_grows_with_amplitude_and_harmonics() {
        let straight = BackboneCurve::new(1.0, &[0.0, 0.0], 0.0).unwrap();
        assert_eq!(panels(&straight), 1.0);
        let paper = BackboneCurve::paper(1.0, 1.5, 1.5, 0.0).unwrap();
        let wild = BackboneCurve::paper(1.0, 15.0, 15.0, 0.0).unwrap();
        let high = BackboneCurve::new(1.0, &[0.0, 0.0, 0.0, 0.0, 1.5, 1.5], 0.0).unwrap();
        assert!(panels(&paper) <= 10.0, "{}", panels(&paper));
        assert!(
            panels(&wild) > panels(&paper),
            "{} {}",
            panels(&wild),
            panels(&paper)
        );
        assert!(
            panels(&high) > panels(&paper),
            "{} {}",
            panels(&high),
            panels(&paper)
        );
        // The panel count does not depend on the length scale.
        let long = BackboneCurve::paper(7.0, 1.5, 1.5, 0.0).unwrap();
        assert_eq!(panels(&long), panels(&paper));
    }

    #[test]
    fn error_bound_holds_at_measurable_tolerances() {
        // At loose tolerances the truncation error is far above rounding, so the a-priori bounds
        // are tested for real: the end point by both rules against eqs 3-4.
        for tolerance in [1e-4, 1e-7, 1e-10, 1e-13] {
            for (a1, a2) in [
                (0.3, 0.1),
                (1.0, -1.5),
                (-2.4, 0.2),
                (6.0, 5.0),
                (20.0, -3.0),
            ] {
                let length = 1.7;
                let mut curve = BackboneCurve::paper(length, a1, a2, 0.4).unwrap();
                curve.resolution = resolution(length, &[a1, a2], tolerance).unwrap();
                let exact = bessel_end_point(length, [a1, a2], 0.4);
                let error = |p: [f64; 2]| (p[0] - exact[0]).abs().max((p[1] - exact[1]).abs());
                let mut trapezoid = [0.0; 2];
                curve.integrate_end(|_, w, sin, cos| {
                    trapezoid[0] += w * cos;
                    trapezoid[1] += w * sin;
                });
                let gauss = curve.point(length).unwrap();
                for (rule, value) in [("trapezoid", trapezoid), ("Gauss", gauss)] {
                    assert!(
                        error(value) <= tolerance * length,
                        "{rule}, tol {tolerance}, a = ({a1}, {a2}): {}",
                        error(value)
                    );
                }
            }
        }
    }

    #[test]
    fn end_point_needs_few_trapezoid_nodes() {
        // The counts quoted on QUADRATURE_TOLERANCE: amplitudes up to j01, K = 1.
        for amplitude in [0.1, 1.0, 2.4] {
            let curve = BackboneCurve::paper(1.0, amplitude, 0.0, 0.0).unwrap();
            let nodes = curve.resolution.periodic_nodes;
            let gauss = panels(&curve) * quadrature::ORDER as f64;
            assert!(
                (8.0..=25.0).contains(&nodes),
                "A = {amplitude}: {nodes} trapezoid nodes"
            );
            assert!(
                (30.0..=80.0).contains(&gauss),
                "A = {amplitude}: {gauss} Gauss nodes"
            );
        }
    }

    #[test]
    fn set_modes_keeps_curve_on_error() {
        let mut curve = BackboneCurve::paper(1.0, 0.1, 0.2, 0.0).unwrap();
        let before = curve.clone();
        assert!(curve.set_modes(&[1e9, 0.0]).is_err());
        assert!(curve.set_modes(&[f64::NAN, 0.0]).is_err());
        assert!(curve.set_modes(&[0.0, 0.0, 0.0, 0.0]).is_err());
        assert_eq!(curve, before);
        curve.set_modes(&[0.3, -0.1]).unwrap();
        assert_eq!(curve.modes(), &[0.3, -0.1]);
    }
}
