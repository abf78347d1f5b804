//! Inverse kinematics of the tip of the spatial modal family's universal-joint chain
//! ([`SpatialModalMap`], [`spatial_chain`](crate::spatial_chain)), for any `K`.
//!
//! [`SpatialIk`] solves `tip_chain(a) = target` (3 equations, `4K` unknowns) with the damped
//! least-squares iteration of [`HarmonicIk`](crate::HarmonicIk) in three dimensions:
//! `delta = -J^T (J J^T + mu I)^{-1} (tip(a) - target)` with the analytic Jacobian
//! `d tip / d a = (d tip / d theta) J_modal`, `d tip / d theta_j = u_j x (tip - o_j)`
//! ([`spatial_tip_jacobian`]), steps of at most 0.5 rad in modal space. The problem is
//! underdetermined, so near a solution each step is the minimum-norm Gauss-Newton step and the
//! solver returns a solution near the guess. The method is local: the straight arm (`a = 0`) is
//! a singular start for targets on its axis, so give a bent guess for those.

use crate::closed_form::check_reach;
use crate::error::KinError;
use crate::harmonic_ik::{IkOptions, IkReport, Workspace, least_squares};
use crate::spatial_chain::{BasePose, spatial_tip_jacobian};
use crate::spatial_map::SpatialModalMap;
use crate::vec3::distance;
use lane_math::{check_finite, check_len, check_values};

/// Largest magnitude of a guess entry (rad) [`SpatialIk::solve_evaluable`] starts from: the
/// iteration is local and takes steps of at most 0.5 rad, so this bounds the amplitudes it visits,
/// and with them the quadrature's cost of the answer's curve.
pub const MAX_IK_GUESS: f64 = 10.0;

/// Reusable inverse kinematics of a universal-joint chain on the spatial modal family. Created
/// once; [`solve`](Self::solve) allocates nothing.
///
/// The default tolerance is `max(1e-14, 8 (2n) eps)` relative to the chain's length, as for the
/// planar [`ChainIk`](crate::ChainIk).
///
/// ```
/// use backbone_kin::{BasePose, SpatialIk, SpatialModalMap, spatial_tip_position};
/// let map = SpatialModalMap::new(&[0.1; 10], 1)?; // 10 links of 0.1 m
/// let base = BasePose::default();
/// let tip_of = |a: &[f64]| {
///     let mut theta = [0.0; 20];
///     map.joint_angles(a, &mut theta)?;
///     spatial_tip_position(map.link_lengths(), &base, &theta)
/// };
/// let target = tip_of(&[0.8, -0.3, -0.5, 0.2])?; // a point the family reaches
/// let mut ik = SpatialIk::new(map.clone(), base)?;
/// let mut a = [0.5, 0.0, -0.3, 0.0]; // guess on entry, solution on return
/// ik.solve(target, &mut a)?;
/// let tip = tip_of(&a)?;
/// assert!((0..3).all(|d| (tip[d] - target[d]).abs() < 1e-13));
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
#[derive(Debug, Clone)]
pub struct SpatialIk {
    map: SpatialModalMap,
    base: BasePose,
    length: f64,
    options: IkOptions,
    theta: Vec<f64>,
    joint_jacobian: Vec<f64>,
    trial: Vec<f64>,
    jacobian: Vec<f64>,
    trial_jacobian: Vec<f64>,
}

impl SpatialIk {
    /// A solver for the chain of `map`'s links leaving the base pose `base`.
    pub fn new(map: SpatialModalMap, base: BasePose) -> Result<Self, KinError> {
        base.validate()?;
        let (n2, m) = (map.n_joints(), map.n_coords());
        let length = map.link_lengths().iter().sum();
        Ok(Self {
            map,
            base,
            length,
            options: IkOptions::for_chain(n2),
            theta: lane_math::try_filled(n2, 0.0, "the inverse kinematics' joint angles")?,
            joint_jacobian: lane_math::try_filled(
                3 * n2,
                0.0,
                "the inverse kinematics' joint Jacobian",
            )?,
            trial: vec![0.0; m],
            jacobian: vec![0.0; 3 * m],
            trial_jacobian: vec![0.0; 3 * m],
        })
    }

    /// Replaces the stopping rules; `tolerance` (relative to the chain's length) must be positive
    /// and finite.
    pub fn with_options(mut self, options: IkOptions) -> Result<Self, KinError> {
        options.validate()?;
        self.options = options;
        Ok(self)
    }

    /// The stopping rules in use.
    pub fn options(&self) -> IkOptions {
        self.options
    }

    /// The modal map the solver inverts.
    pub fn map(&self) -> &SpatialModalMap {
        &self.map
    }

    /// Solves `tip_chain(a) = target` for the modal coordinates `a` (`4K` entries), which hold
    /// the initial guess on entry and the solution on success (the best iterate after
    /// [`KinError::NotConverged`]).
    ///
    /// Errors: [`KinError::OutOfReach`] if the target is farther from the base than the chain is
    /// long (beyond rounding); [`KinError::NotConverged`] if the iteration stalls or runs out of
    /// steps; [`KinError::Stationary`] where no step is defined (a zero Jacobian); input errors
    /// for a non-finite target or guess, or a guess of the wrong size.
    pub fn solve(&mut self, target: [f64; 3], a: &mut [f64]) -> Result<IkReport, KinError> {
        for (name, value) in ["target x", "target y", "target z"].into_iter().zip(target) {
            check_finite(name, value)?;
        }
        check_values("initial guess", a, self.trial.len())?;
        let r = distance(target, self.base.xyz);
        check_reach(r, self.length)?;
        let Self {
            map,
            base,
            theta,
            joint_jacobian,
            ..
        } = self;
        least_squares(
            target,
            a,
            self.options.tolerance * self.length,
            self.options.max_iterations,
            Workspace {
                trial: &mut self.trial,
                jacobian: &mut self.jacobian,
                trial_jacobian: &mut self.trial_jacobian,
            },
            |modes, jacobian| modal_tip_jacobian(map, base, modes, theta, joint_jacobian, jacobian),
        )
    }

    /// As [`solve`](Self::solve) from `guess` (default [`default_guess`](Self::default_guess)),
    /// for an answer the backbone curve's forward kinematics evaluates
    /// ([`SpatialModalMap::curve_tip`]): a guess far out can converge to coordinates whose curve
    /// turns too fast for the quadrature. `a` receives the solution (`4K` entries).
    ///
    /// Errors: as [`solve`](Self::solve); [`KinError::GuessTooLarge`] for a guess entry beyond
    /// [`MAX_IK_GUESS`] (rad), before any iteration; [`KinError::AnswerTooOscillatory`] for an
    /// answer whose curve cannot be evaluated.
    pub fn solve_evaluable(
        &mut self,
        target: [f64; 3],
        guess: Option<&[f64]>,
        a: &mut [f64],
    ) -> Result<IkReport, KinError> {
        check_len("modal coordinates", a.len(), self.trial.len())?;
        match guess {
            Some(guess) => {
                check_len("guess", guess.len(), a.len())?;
                if let Some((index, &value)) = guess
                    .iter()
                    .enumerate()
                    .find(|(_, v)| v.abs() > MAX_IK_GUESS)
                {
                    return Err(KinError::GuessTooLarge {
                        index,
                        value,
                        max: MAX_IK_GUESS,
                    });
                }
                a.copy_from_slice(guess);
            }
            None => Self::default_guess(a),
        }
        let report = self.solve(target, a)?;
        match self.map.curve_tip(a, self.base) {
            Err(KinError::TooOscillatory { needed, max }) => Err(KinError::AnswerTooOscillatory {
                iterations: report.iterations,
                residual: report.residual,
                needed,
                max,
            }),
            _ => Ok(report),
        }
    }

    /// The guess [`solve_evaluable`](Self::solve_evaluable) starts from when given none: a
    /// quarter bend (0.25 rad) in each plane's first coordinate of every harmonic, away from the
    /// straight arm's singularity.
    pub fn default_guess(a: &mut [f64]) {
        for (j, value) in a.iter_mut().enumerate() {
            *value = if j % 2 == 0 { 0.25 } else { 0.0 };
        }
    }

    /// The chain's tip at the modal coordinates `a` (`4K`) and its Jacobian
    /// `d tip / d a = (d tip / d theta) J` into `jacobian` (`3 x 4K`, row-major), the one the
    /// iteration of [`solve`](Self::solve) uses. Allocation-free.
    ///
    /// Errors: `a` or `jacobian` of the wrong size, a non-finite `a`.
    pub fn tip_jacobian(&mut self, a: &[f64], jacobian: &mut [f64]) -> Result<[f64; 3], KinError> {
        check_values("modal coordinates", a, self.trial.len())?;
        check_len("tip Jacobian", jacobian.len(), self.jacobian.len())?;
        for &value in a {
            check_finite("modal coordinate", value)?;
        }
        modal_tip_jacobian(
            &self.map,
            &self.base,
            a,
            &mut self.theta,
            &mut self.joint_jacobian,
            jacobian,
        )
    }
}

/// The tip at `a` and `d tip / d a = (d tip / d theta) J` into `jacobian`, row by row, with the
/// joint angles and their tip Jacobian in the scratch `theta` and `joint_jacobian`.
fn modal_tip_jacobian(
    map: &SpatialModalMap,
    base: &BasePose,
    a: &[f64],
    theta: &mut [f64],
    joint_jacobian: &mut [f64],
    jacobian: &mut [f64],
) -> Result<[f64; 3], KinError> {
    let (n2, m) = (map.n_joints(), map.n_coords());
    map.joint_angles(a, theta)?;
    let tip = spatial_tip_jacobian(map.link_lengths(), base, theta, joint_jacobian)?;
    for (out, row) in jacobian
        .chunks_exact_mut(m)
        .zip(joint_jacobian.chunks_exact(n2))
    {
        out.fill(0.0);
        for (j, &d_theta) in row.iter().enumerate() {
            for (o, &entry) in out.iter_mut().zip(map.row(j)) {
                *o += d_theta * entry;
            }
        }
    }
    Ok(tip)
}
