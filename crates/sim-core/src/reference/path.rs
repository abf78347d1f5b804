//! A Cartesian path for the tip, followed through the inverse kinematics of the modal family:
//! the closed form (eqs 5-6) with exact modal rates and accelerations for the paper's `K = 1`
//! with `alpha0` fixed, a numerical continuation with minimum-norm rates otherwise.

use super::continuation::{Family, TipMotion, resolve};
use super::{Reference, ReferenceSample};
use crate::error::{SimError, check_positive};
use backbone_kin::{BaseAngle, Branch, inverse_kinematics};
use lane_math::{Compact, check_all_finite};

/// How finely [`CartesianPath::new`] checks the path for reachability and singular points; also
/// the number of intervals of the continuation grid.
const CHECK_SAMPLES: usize = 2000;
/// Below this `|a1|` (rad) or `J1(A)` the inverse kinematics is treated as singular.
const SINGULAR_TOLERANCE: f64 = 1e-8;

/// The most phase a sine path may turn through between `x_start` and `x_end` (rad): some
/// 160,000 periods, where the paper's path turns through 1.6 rad; beyond it `sin` of the phase
/// has lost its digits and the path's derivatives (`k A`, `k^2 A`) their meaning.
pub const MAX_SINE_PHASE: f64 = 1e6;
/// The base angle a free `alpha0` starts the continuation from (rad): the paper's `pi/2`.
pub const FREE_BASE_START: f64 = std::f64::consts::FRAC_PI_2;

/// The geometric shape of a tip path.
#[derive(Debug, Clone, PartialEq)]
pub enum PathShape {
    /// `y = amplitude sin(wavenumber x + phase) + offset` from `x = x_start` to `x = x_end`,
    /// traversed at constant speed in `x` (the paper's eq 25 is amplitude 0.4, wavenumber 5,
    /// phase 0, offset 0.2, x from 0.08 to 0.4).
    Sine {
        /// Amplitude (m).
        amplitude: f64,
        /// Wavenumber (rad/m).
        wavenumber: f64,
        /// Phase (rad).
        phase: f64,
        /// Offset (m).
        offset: f64,
        /// First `x` (m).
        x_start: f64,
        /// Last `x` (m), different from `x_start`.
        x_end: f64,
    },
    /// The polyline through these points (m), linearly interpolated and traversed at constant
    /// speed along its length.
    Polyline(Vec<[f64; 2]>),
}

/// A tip path traversed in `travel_time` seconds, then held at its end point; before `t = 0` it
/// holds its first point. The modal reference is its inverse kinematics for a curve of length
/// `l` with `K` harmonics, leaving the base at a fixed angle `alpha0` or with `alpha0` free:
///
/// - `K = 1` with `alpha0` fixed (the paper's): the closed form of eqs 5-6 on the chosen sign
///   branch of `a1`, with exact rates and accelerations.
/// - Otherwise: numerical continuation. The path starts at the closed-form `K = 1` solution on
///   the chosen branch (higher harmonics zero; a free `alpha0` at [`FREE_BASE_START`]), and is
///   resolved at the minimum-norm modal rate `a_dot = J^+ p_dot` (see `docs/theory.md`): the
///   positions are solved on a grid of 2000 intervals (`CHECK_SAMPLES`), each node
///   warm-started from the previous one, and any time `t` is solved from its grid node, so a
///   sample depends on `t` alone.
#[derive(Debug, Clone)]
pub struct CartesianPath {
    shape: PathShape,
    /// Arc length at each vertex of a polyline (empty for a sine).
    arc: Vec<f64>,
    travel_time: f64,
    length: f64,
    solver: Solver,
}

/// How the path's modal reference is resolved.
#[derive(Debug, Clone)]
enum Solver {
    /// Eqs 5-6 with this `alpha0` and branch.
    ClosedForm { alpha0: f64, branch: Branch },
    /// Numerical continuation over a time grid.
    Continuation {
        family: Box<Family>,
        /// Node `k` at `t = k * step`: `a`, `a_dot`, `a_ddot`, `m` entries each.
        nodes: Vec<ReferenceSample>,
        step: f64,
    },
}

impl CartesianPath {
    /// The path `shape` traversed in `travel_time` s by the tip of a backbone curve of length
    /// `length` (m) with `harmonics` harmonics and base angle `base`; `branch` is the sign of
    /// `a1` of the closed form (where a numerical continuation starts for other families).
    ///
    /// Checks the shape's parameters, then samples the whole path densely: every point must be
    /// reachable ([`SimError::Unreachable`] names the first that is not) and away from the
    /// singular points of the inverse kinematics ([`SimError::SingularPoint`]).
    ///
    /// ```
    /// use backbone_kin::{BaseAngle, Branch};
    /// use sim_core::reference::{CartesianPath, PathShape, Reference, ReferenceSample};
    /// // The paper's eq 25 over 5 s, alpha0 = pi/2, on the 1 m arm.
    /// let shape = PathShape::Sine {
    ///     amplitude: 0.4, wavenumber: 5.0, phase: 0.0, offset: 0.2, x_start: 0.08, x_end: 0.4,
    /// };
    /// let alpha0 = std::f64::consts::FRAC_PI_2;
    /// let mut path = CartesianPath::new(shape, 5.0, 1.0, 1, BaseAngle::Fixed(alpha0), Branch::Positive)?;
    /// let mut start = ReferenceSample::zeros(2);
    /// path.sample(0.0, &mut start)?;
    /// let tip = backbone_kin::end_point(1.0, [start.a[0], start.a[1]], alpha0)?;
    /// assert!((tip[0] - 0.08).abs() < 1e-12);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn new(
        shape: PathShape,
        travel_time: f64,
        length: f64,
        harmonics: usize,
        base: BaseAngle,
        branch: Branch,
    ) -> Result<Self, SimError> {
        super::check_travel_time("reference.travel_time", travel_time)?;
        check_positive("arm length", length)?;
        if let BaseAngle::Fixed(alpha0) = base {
            check_all_finite("alpha0", &[alpha0])?;
        }
        let arc = validate_shape(&shape)?;
        let mut path = Self {
            shape,
            arc,
            travel_time,
            length,
            solver: Solver::ClosedForm {
                alpha0: match base {
                    BaseAngle::Fixed(alpha0) => alpha0,
                    BaseAngle::Free => FREE_BASE_START,
                },
                branch,
            },
        };
        let fixed = match base {
            BaseAngle::Fixed(alpha0) => Some(alpha0),
            BaseAngle::Free => None,
        };
        let mut sample = ReferenceSample::zeros(2);
        if harmonics == 1 && fixed.is_some() {
            for k in 0..=CHECK_SAMPLES {
                path.sample(travel_time * k as f64 / CHECK_SAMPLES as f64, &mut sample)?;
            }
        } else {
            // The start: the closed-form K = 1 solution, padded with zero harmonics.
            path.sample(0.0, &mut sample)?;
            let mut family = Family::new(length, harmonics, fixed)?;
            let m = family.n_coords();
            let mut start = ReferenceSample::zeros(m);
            start.a[..2].copy_from_slice(&sample.a);
            if fixed.is_none() {
                start.a[m - 1] = FREE_BASE_START;
            }
            let step = travel_time / CHECK_SAMPLES as f64;
            let mut nodes = Vec::with_capacity(CHECK_SAMPLES + 1);
            resolve(&mut family, 0.0, path.tip_motion(0.0), None, &mut start)?;
            nodes.push(start);
            for k in 1..=CHECK_SAMPLES {
                let t = k as f64 * step;
                let mut node = ReferenceSample::zeros(m);
                let previous = Some((&nodes[k - 1], step));
                resolve(&mut family, t, path.tip_motion(t), previous, &mut node)?;
                nodes.push(node);
            }
            path.solver = Solver::Continuation {
                family: Box::new(family),
                nodes,
                step,
            };
            sample = ReferenceSample::zeros(m);
        }
        if let PathShape::Polyline(_) = &path.shape {
            let speed = path.arc[path.arc.len() - 1] / travel_time;
            for s in path.arc.clone() {
                path.sample(s / speed, &mut sample)?;
            }
        }
        Ok(path)
    }

    /// The number of modal coordinates the path's reference sets.
    pub fn n_coords(&self) -> usize {
        match &self.solver {
            Solver::ClosedForm { .. } => 2,
            Solver::Continuation { family, .. } => family.n_coords(),
        }
    }

    /// The time the tip takes along the path (s); after it, the reference holds the end point.
    pub fn travel_time(&self) -> f64 {
        self.travel_time
    }

    /// The desired tip position at time `t` (m).
    pub fn point(&self, t: f64) -> [f64; 2] {
        self.tip_motion(t).p
    }

    /// The tip's position, velocity and acceleration at `t`.
    fn tip_motion(&self, t: f64) -> TipMotion<2> {
        let moving = (0.0..self.travel_time).contains(&t);
        let progress = (t / self.travel_time).clamp(0.0, 1.0);
        let rate = if moving { 1.0 / self.travel_time } else { 0.0 };
        match &self.shape {
            PathShape::Sine {
                amplitude,
                wavenumber,
                phase,
                offset,
                x_start,
                x_end,
            } => {
                let x = x_start + (x_end - x_start) * progress;
                let vx = (x_end - x_start) * rate;
                let (sin, cos) = (wavenumber * x + phase).sin_cos();
                TipMotion {
                    p: [x, amplitude * sin + offset],
                    v: [vx, amplitude * wavenumber * cos * vx],
                    acc: [0.0, -amplitude * wavenumber * wavenumber * sin * vx * vx],
                }
            }
            PathShape::Polyline(points) => {
                let total = self.arc[self.arc.len() - 1];
                let s = total * progress;
                let segment = self
                    .arc
                    .partition_point(|&a| a <= s)
                    .clamp(1, points.len() - 1)
                    - 1;
                let (p0, p1) = (points[segment], points[segment + 1]);
                let seg_len = self.arc[segment + 1] - self.arc[segment];
                let dir = [(p1[0] - p0[0]) / seg_len, (p1[1] - p0[1]) / seg_len];
                let along = s - self.arc[segment];
                let speed = total * rate;
                TipMotion {
                    p: [p0[0] + along * dir[0], p0[1] + along * dir[1]],
                    v: [dir[0] * speed, dir[1] * speed],
                    acc: [0.0, 0.0],
                }
            }
        }
    }
}

impl Reference for CartesianPath {
    fn n_coords(&self) -> usize {
        CartesianPath::n_coords(self)
    }

    /// For the closed form, the inverse kinematics of the tip motion, differentiated exactly
    /// through the polar form of eqs 5-6: `a2 = atan2(y, x) - alpha0`, `J0(A) = r / l`,
    /// `a1^2 = A^2 - a2^2`. For the continuation, the solution from the grid node at or before
    /// `t` (see the type's docs).
    fn sample(&mut self, t: f64, out: &mut ReferenceSample) -> Result<(), SimError> {
        let motion = self.tip_motion(t);
        let (alpha0, branch) = match &mut self.solver {
            Solver::ClosedForm { alpha0, branch } => (*alpha0, *branch),
            Solver::Continuation {
                family,
                nodes,
                step,
            } => {
                let k = ((t / *step).floor().max(0.0) as usize).min(nodes.len() - 1);
                let node = &nodes[k];
                let dt = t.clamp(0.0, self.travel_time) - k as f64 * *step;
                out.a.copy_from_slice(&node.a);
                let previous = (dt > 0.0).then_some((node, dt));
                return resolve(&mut **family, t, motion, previous, out);
            }
        };
        let TipMotion { p, v, acc } = motion;
        let [x, y] = p;
        let [a1, a2] = inverse_kinematics(self.length, p, alpha0, branch)
            .map_err(|source| SimError::Unreachable { t, x, y, source })?;
        // Both at most J0's first zero (2.4): no overflow for `hypot` to guard against.
        let amplitude = (a1 * a1 + a2 * a2).sqrt();
        let j1 = libm::j1(amplitude);
        let singular = |what| SimError::SingularPoint { what, t, x, y };
        if j1 <= SINGULAR_TOLERANCE {
            return Err(singular("the curve is straight (A = 0, r = l)"));
        }
        if a1.abs() <= SINGULAR_TOLERANCE {
            return Err(singular("a1 = 0, the branch point of eq 6"));
        }
        // Polar coordinates of the tip and their rates.
        let r = x.hypot(y);
        let r_dot = (x * v[0] + y * v[1]) / r;
        let psi_dot = (x * v[1] - y * v[0]) / (r * r);
        let r_ddot = (v[0] * v[0] + v[1] * v[1] + x * acc[0] + y * acc[1] - r_dot * r_dot) / r;
        let psi_ddot = (x * acc[1] - y * acc[0]) / (r * r) - 2.0 * r_dot * psi_dot / r;
        // J0(A) = r / l (to the rounding of the inverse), with J0' = -J1 and J1' = J0 - J1 / A.
        let amp_dot = -r_dot / (self.length * j1);
        let j1_prime = (r / self.length).min(1.0) - j1 / amplitude;
        let amp_ddot = -(r_ddot / self.length + j1_prime * amp_dot * amp_dot) / j1;
        // a1 a1' = A A' - a2 a2', differentiated once more.
        let (a2_dot, a2_ddot) = (psi_dot, psi_ddot);
        let a1_dot = (amplitude * amp_dot - a2 * a2_dot) / a1;
        let a1_ddot = (amp_dot * amp_dot + amplitude * amp_ddot
            - a2_dot * a2_dot
            - a2 * a2_ddot
            - a1_dot * a1_dot)
            / a1;
        out.a.copy_from_slice(&[a1, a2]);
        out.a_dot.copy_from_slice(&[a1_dot, a2_dot]);
        out.a_ddot.copy_from_slice(&[a1_ddot, a2_ddot]);
        Ok(())
    }
}

/// Checks a shape's numbers; returns the cumulative arc lengths of a polyline.
fn validate_shape(shape: &PathShape) -> Result<Vec<f64>, SimError> {
    match shape {
        PathShape::Sine {
            amplitude,
            wavenumber,
            phase,
            offset,
            x_start,
            x_end,
        } => {
            check_all_finite(
                "reference path",
                &[*amplitude, *wavenumber, *phase, *offset, *x_start, *x_end],
            )?;
            if x_start == x_end {
                return Err(SimError::setting(
                    "reference.sine.x_end",
                    format!("must differ from x_start, both are {}", Compact(*x_start)),
                ));
            }
            let turned = (wavenumber * (x_end - x_start)).abs();
            if turned > MAX_SINE_PHASE {
                return Err(SimError::setting(
                    "reference.sine.wavenumber",
                    format!(
                        "= {} turns the sine through {turned:.3e} rad from x_start to x_end, \
                         more than {MAX_SINE_PHASE:e}: its slope and curvature leave double \
                         precision",
                        Compact(*wavenumber),
                    ),
                ));
            }
            Ok(Vec::new())
        }
        PathShape::Polyline(points) => {
            if points.len() < 2 {
                return Err(SimError::setting(
                    "reference.points",
                    format!("needs at least 2 points, got {}", points.len()),
                ));
            }
            let mut arc = Vec::with_capacity(points.len());
            arc.push(0.0);
            for (k, pair) in points.windows(2).enumerate() {
                check_all_finite("reference.points", &pair[1])?;
                check_all_finite("reference.points", &pair[0])?;
                let seg = (pair[1][0] - pair[0][0]).hypot(pair[1][1] - pair[0][1]);
                if seg == 0.0 {
                    return Err(SimError::setting(
                        "reference.points",
                        format!("must not repeat a point, points {k} and {} coincide", k + 1),
                    ));
                }
                arc.push(arc[k] + seg);
            }
            Ok(arc)
        }
    }
}
