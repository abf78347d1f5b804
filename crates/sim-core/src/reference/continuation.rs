//! The inverse kinematics of any modal family along a path, by numerical continuation: the
//! redundancy resolution of the Cartesian path reference beyond the paper's closed form
//! (`docs/theory.md`, "Tip paths for any modal family").
//!
//! The end point `p(a)` of a family with `m` coordinates (`2K` modes, plus `alpha0` when it is
//! free) is a map from `m` coordinates to the plane, redundant for `m > 2`. Along a tip path
//! `p(t)` the reference is resolved at the minimum-norm rate
//! `a_dot = J^+ p_dot = J^T (J J^T)^{-1} p_dot` (`J = d p / d a`, `2 x m`), the rate of
//! smallest Euclidean norm that moves the tip along the path; its acceleration is the time
//! derivative of that field, `a_ddot = d(J^+)/da[a_dot] p_dot + J^+ p_ddot`. Positions come from
//! Levenberg-Marquardt ([`backbone_kin::HarmonicIk`], minimum-norm Gauss-Newton steps near a
//! solution) warm-started from a second-order prediction off the previous node of a fixed time
//! grid; a free `alpha0` is held at its predicted value while the modes are corrected (the end
//! point of a curve with base angle `alpha0` is that of `alpha0 = 0` rotated by `alpha0`).

use super::ReferenceSample;
use crate::error::SimError;
use backbone_kin::{BackboneCurve, HarmonicIk, KinError};

/// `J J^T` counts as singular below this ratio of its eigenvalues: the tip cannot move in some
/// direction (e.g. radially, for a straight curve).
const SINGULAR_RATIO: f64 = 1e-10;
/// Largest correction (rad, Euclidean) the inverse kinematics may make to the predicted
/// configuration between two grid nodes; a larger one means the continuation left its branch.
const MAX_CORRECTION: f64 = 0.05;
/// Length of the modal step `delta` (rad) of the central difference of the rate field.
const RATE_FIELD_STEP: f64 = 1e-5;

/// Why the continuation could not resolve a point.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum ResolveError {
    /// The end-point Jacobian is (nearly) rank deficient.
    Singular,
    /// The kinematics refused (out of reach, not converged).
    Kinematics(KinError),
}

impl From<KinError> for ResolveError {
    fn from(e: KinError) -> Self {
        ResolveError::Kinematics(e)
    }
}

/// The scratch of the rate field's central difference (`m` entries each).
#[derive(Debug, Clone, Default)]
pub(super) struct RateScratch {
    shifted: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
}

impl RateScratch {
    pub(crate) fn new(m: usize) -> Self {
        Self {
            shifted: vec![0.0; m],
            plus: vec![0.0; m],
            minus: vec![0.0; m],
        }
    }
}

/// A modal family whose tip moves in `D` dimensions (the planar curve's end point, `D = 2`; the
/// spatial chain's tip, `D = 3`): what the continuation asks of it.
pub(super) trait TipFamily<const D: usize> {
    /// The rate field's scratch.
    fn scratch(&mut self) -> &mut RateScratch;

    /// The error of a point the family cannot reach.
    fn unreachable(t: f64, p: [f64; D], source: KinError) -> SimError;

    /// The error of a singular point of the path.
    fn singular(what: &'static str, t: f64, p: [f64; D]) -> SimError;

    /// The tip at `a`, its `D x m` Jacobian kept for [`pseudo_inverse`](Self::pseudo_inverse).
    fn jacobian_at(&mut self, a: &[f64]) -> Result<[f64; D], KinError>;

    /// `out = J^+ v = J^T (J J^T)^{-1} v` with the Jacobian of the last
    /// [`jacobian_at`](Self::jacobian_at).
    fn pseudo_inverse(&self, v: [f64; D], out: &mut [f64]) -> Result<(), ResolveError>;

    /// Solves `p(a) = target` from the guess in `a`.
    fn solve(&mut self, target: [f64; D], a: &mut [f64]) -> Result<(), KinError>;

    /// The minimum-norm rate `a_dot = J^+ p_dot` at `a` and its time derivative
    /// `a_ddot = d(J^+)/da[a_dot] p_dot + J^+ p_ddot`, the first term by a central difference
    /// along `a_dot`.
    fn rates(
        &mut self,
        a: &[f64],
        p_dot: [f64; D],
        p_ddot: [f64; D],
        a_dot: &mut [f64],
        a_ddot: &mut [f64],
    ) -> Result<(), ResolveError> {
        self.jacobian_at(a)?;
        self.pseudo_inverse(p_dot, a_dot)?;
        self.pseudo_inverse(p_ddot, a_ddot)?;
        let speed = a_dot.iter().map(|v| v * v).sum::<f64>().sqrt();
        if speed == 0.0 {
            return Ok(());
        }
        let delta = RATE_FIELD_STEP / speed;
        let RateScratch {
            mut shifted,
            mut plus,
            mut minus,
        } = std::mem::take(self.scratch());
        let result = (|| {
            for (sign, out) in [(1.0, &mut plus), (-1.0, &mut minus)] {
                for ((s, &x), &v) in shifted.iter_mut().zip(a).zip(a_dot.iter()) {
                    *s = x + sign * delta * v;
                }
                self.jacobian_at(&shifted)?;
                self.pseudo_inverse(p_dot, out)?;
            }
            Ok::<(), ResolveError>(())
        })();
        if result.is_ok() {
            for ((dd, p), q) in a_ddot.iter_mut().zip(&plus).zip(&minus) {
                *dd += (p - q) / (2.0 * delta);
            }
        }
        *self.scratch() = RateScratch {
            shifted,
            plus,
            minus,
        };
        result
    }
}

/// A tip position and its first two time derivatives.
#[derive(Debug, Clone, Copy)]
pub(super) struct TipMotion<const D: usize> {
    pub(super) p: [f64; D],
    pub(super) v: [f64; D],
    pub(super) acc: [f64; D],
}

/// End point, Jacobian and inverse kinematics of a family with `harmonics` harmonics and a fixed
/// (`Some(alpha0)`) or free (`None`) base angle; all buffers sized at construction.
#[derive(Debug, Clone)]
pub(crate) struct Family {
    /// `2K`.
    modes: usize,
    /// `m`: `2K`, or `2K + 1` with a free base angle.
    m: usize,
    free: bool,
    /// The curve with the fixed `alpha0`, or with `alpha0 = 0` when it is free.
    curve: BackboneCurve,
    ik: HarmonicIk,
    /// `2 x 2K` Jacobian of the curve's modes, row-major.
    mode_jacobian: Vec<f64>,
    /// `2 x m` Jacobian of the family, row-major.
    jacobian: Vec<f64>,
    scratch: RateScratch,
}

impl Family {
    pub(crate) fn new(
        length: f64,
        harmonics: usize,
        alpha0: Option<f64>,
    ) -> Result<Self, KinError> {
        let modes = 2 * harmonics;
        let m = modes + usize::from(alpha0.is_none());
        let base = alpha0.unwrap_or(0.0);
        Ok(Self {
            modes,
            m,
            free: alpha0.is_none(),
            curve: BackboneCurve::new(length, &vec![0.0; modes], base)?,
            ik: HarmonicIk::new(length, harmonics, base)?,
            mode_jacobian: vec![0.0; 2 * modes],
            jacobian: vec![0.0; 2 * m],
            scratch: RateScratch::new(m),
        })
    }

    /// The number of coordinates `m`.
    pub(crate) fn n_coords(&self) -> usize {
        self.m
    }

    /// The end point at `a` (by quadrature for `K > 1`, in closed form for `K = 1`).
    pub(crate) fn end_point(&mut self, a: &[f64]) -> Result<[f64; 2], KinError> {
        let p = match a[..self.modes] {
            // One harmonic: the closed form, with no quadrature to set up for the curve.
            [a1, a2] => {
                backbone_kin::end_point(self.curve.length(), [a1, a2], self.curve.alpha0())?
            }
            _ => {
                self.curve.set_modes(&a[..self.modes])?;
                self.curve.end_point()
            }
        };
        Ok(if self.free {
            rotate(p, a[self.modes])
        } else {
            p
        })
    }
}

impl TipFamily<2> for Family {
    fn scratch(&mut self) -> &mut RateScratch {
        &mut self.scratch
    }

    fn unreachable(t: f64, [x, y]: [f64; 2], source: KinError) -> SimError {
        SimError::Unreachable { t, x, y, source }
    }

    fn singular(what: &'static str, t: f64, [x, y]: [f64; 2]) -> SimError {
        SimError::SingularPoint { what, t, x, y }
    }

    /// The end point at `a` and its Jacobian into `self.jacobian`.
    fn jacobian_at(&mut self, a: &[f64]) -> Result<[f64; 2], KinError> {
        self.curve.set_modes(&a[..self.modes])?;
        let p = self.curve.end_point_jacobian(&mut self.mode_jacobian)?;
        let (k, m) = (self.modes, self.m);
        if !self.free {
            self.jacobian.copy_from_slice(&self.mode_jacobian);
            return Ok(p);
        }
        let angle = a[k];
        for j in 0..k {
            let [x, y] = rotate([self.mode_jacobian[j], self.mode_jacobian[k + j]], angle);
            self.jacobian[j] = x;
            self.jacobian[m + j] = y;
        }
        let p = rotate(p, angle);
        // d p / d alpha0 = (-y, x).
        self.jacobian[k] = -p[1];
        self.jacobian[m + k] = p[0];
        Ok(p)
    }

    /// `out = J^+ v` with the Jacobian in `self.jacobian`.
    fn pseudo_inverse(&self, v: [f64; 2], out: &mut [f64]) -> Result<(), ResolveError> {
        let (jx, jy) = self.jacobian.split_at(self.m);
        let dot = |u: &[f64], w: &[f64]| u.iter().zip(w).map(|(p, q)| p * q).sum::<f64>();
        let (gxx, gxy, gyy) = (dot(jx, jx), dot(jx, jy), dot(jy, jy));
        let det = gxx * gyy - gxy * gxy;
        let trace = gxx + gyy;
        if !(det > SINGULAR_RATIO * trace * trace && det.is_finite()) {
            return Err(ResolveError::Singular);
        }
        let y = [
            (gyy * v[0] - gxy * v[1]) / det,
            (gxx * v[1] - gxy * v[0]) / det,
        ];
        for ((o, &dx), &dy) in out.iter_mut().zip(jx).zip(jy) {
            *o = dx * y[0] + dy * y[1];
        }
        Ok(())
    }

    /// Solves `p(a) = target` from the guess in `a` (a free `alpha0` held at its guess).
    fn solve(&mut self, target: [f64; 2], a: &mut [f64]) -> Result<(), KinError> {
        let target = if self.free {
            rotate(target, -a[self.modes])
        } else {
            target
        };
        self.ik.solve(target, &mut a[..self.modes]).map(|_| ())
    }
}

/// The reference at `t` (tip motion `motion`) by the continuation: from `previous` (a node and the time from it to
/// `t`) by a second-order prediction, or from `out.a` itself; then the inverse kinematics
/// and the minimum-norm rates.
pub(super) fn resolve<const D: usize, F: TipFamily<D>>(
    family: &mut F,
    t: f64,
    motion: TipMotion<D>,
    previous: Option<(&ReferenceSample, f64)>,
    out: &mut ReferenceSample,
) -> Result<(), SimError> {
    let TipMotion { p, v, acc } = motion;
    if let Some((node, dt)) = previous {
        for i in 0..out.a.len() {
            out.a[i] = node.a[i] + dt * node.a_dot[i] + 0.5 * dt * dt * node.a_ddot[i];
        }
    }
    let unreachable = |source| F::unreachable(t, p, source);
    // Keep the prediction to measure the correction, in the a_dot buffer (rewritten below).
    out.a_dot.copy_from_slice(&out.a);
    family.solve(p, &mut out.a).map_err(unreachable)?;
    let correction = out
        .a
        .iter()
        .zip(&out.a_dot)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    let singular = |what| F::singular(what, t, p);
    if previous.is_some() && correction > MAX_CORRECTION {
        return Err(singular(
            "the numerical inverse kinematics left its branch between two grid nodes",
        ));
    }
    family
        .rates(&out.a, v, acc, &mut out.a_dot, &mut out.a_ddot)
        .map_err(|e| match e {
            ResolveError::Singular => {
                singular("the end-point Jacobian is rank deficient (J J^T singular)")
            }
            ResolveError::Kinematics(source) => unreachable(source),
        })
}

/// `p` rotated by `angle`.
fn rotate(p: [f64; 2], angle: f64) -> [f64; 2] {
    let (sin, cos) = angle.sin_cos();
    [cos * p[0] - sin * p[1], sin * p[0] + cos * p[1]]
}
