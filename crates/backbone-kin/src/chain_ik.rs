//! Inverse kinematics of the discrete chain on the modal family, for any link lengths.
//!
//! The closed form of eqs 5-6 inverts the backbone curve's end point, and the chain's tip is only
//! a quadrature of that curve (eq 7 puts link `i` along `alpha(s_i)`, `s_i` its midpoint): the
//! chain tip is `sum_i L_i (cos alpha(s_i), sin alpha(s_i))`, the midpoint rule applied to
//! eqs 3-4. With equal links that rule is spectrally accurate (the difference is the aliasing sum
//! of `docs/theory.md`, at most `2 l sum_{m >= 1} |J_{mn}(A)|`, led by `2 l |J_n(A)|`), but with
//! unequal links it is a non-uniform midpoint rule whose error is only second order in the link
//! lengths: per link at most `L_i^3 / 24 max |f''|` with `f = exp(i alpha)`, so for `K = 1`
//!
//! `|tip_chain - tip_curve| <= (pi^2 / 6) A (1 + A) sum_i L_i^3 / l^2`
//!
//! (`|alpha'| <= 2 pi A / l`, `|alpha''| <= 4 pi^2 A / l^2`). Measured (test
//! `unequal_links_curve_versus_chain`): 20 links tapering linearly from 0.075 m to 0.025 m
//! (`l = 1 m`) put the chain tip 2.6 mm from a target that the curve reaches exactly at
//! `A = 1.9` (the bound: 2.9 cm); 10 equal links miss by the aliasing error, `3.0e-7 m`, at the
//! same pose. The property tests hold the bound on random arms of 3 to 40 unequal links.
//!
//! [`ChainIk`] removes that error: it solves `tip_chain(a) = target` with the damped least-squares
//! iteration of [`HarmonicIk`](crate::HarmonicIk) on the chain's tip and its analytic Jacobian
//! `d tip / d a_j = sum_i L_i (-sin phi_i, cos phi_i) b_j(s_i)` ([`harmonic_basis`]), started
//! from the closed form (eqs 5-6) or the caller's guess. For `K = 1` the problem is square and
//! the iteration is Newton's method, which from the closed-form start converges in a few steps
//! whenever the chain is close to its curve (at most 5 in the tests).

use crate::closed_form::{Branch, check_reach, inverse_kinematics};
use crate::error::KinError;
use crate::harmonic_ik::{IkOptions, IkReport, Workspace, least_squares};
use crate::modal_map::{check_harmonics, harmonic_basis};
use crate::validate::{check_count, check_link_lengths};
use lane_math::{check_finite, check_len, check_values};

/// Reusable inverse kinematics of a chain of given link lengths whose joint angles follow the
/// `K`-harmonic modal map with `alpha0` fixed (eqs 7-8). Created once;
/// [`solve`](Self::solve) and [`solve_from_closed_form`](Self::solve_from_closed_form) allocate
/// nothing.
///
/// The default tolerance is `max(1e-14, 8 n eps)` relative to the chain's length `l` (the tip is a
/// sum of `n` terms, so its rounding grows with `n`): `4e-14 l` for 20 links, `2e-9 l` at
/// [`MAX_LINKS`](crate::MAX_LINKS).
///
/// ```
/// use backbone_kin::{Branch, ChainIk, ModalMap, tip_position};
/// // 20 tapered links of total length 1 m.
/// let lengths: Vec<f64> = (0..20).map(|i| 0.075 - 0.05 * f64::from(i) / 19.0).collect();
/// let alpha0 = std::f64::consts::FRAC_PI_2;
/// let mut ik = ChainIk::new(&lengths, 1, alpha0)?;
/// let mut a = [0.0; 2];
/// ik.solve_from_closed_form([0.3, 0.5], Branch::Positive, &mut a)?;
/// // The chain itself, joint angles from the modal map of these links, ends on the target.
/// let map = ModalMap::new(&lengths, 1, backbone_kin::BaseAngle::Fixed(alpha0))?;
/// let mut theta = vec![0.0; 20];
/// map.joint_angles(&a, &mut theta)?;
/// let tip = tip_position(&lengths, &theta)?;
/// assert!((tip[0] - 0.3).abs() < 1e-13 && (tip[1] - 0.5).abs() < 1e-13);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ChainIk {
    link_lengths: Vec<f64>,
    length: f64,
    harmonics: usize,
    alpha0: f64,
    options: IkOptions,
    trial: Vec<f64>,
    jacobian: Vec<f64>,
    trial_jacobian: Vec<f64>,
}

impl ChainIk {
    /// A solver for the chain with these link lengths (base first), `harmonics` harmonics
    /// (`2 * harmonics` unknowns) and base angle `alpha0`.
    pub fn new(link_lengths: &[f64], harmonics: usize, alpha0: f64) -> Result<Self, KinError> {
        let length = check_link_lengths(link_lengths)?;
        check_count("links", link_lengths.len(), crate::MAX_LINKS)?;
        check_harmonics(harmonics)?;
        check_finite("alpha0", alpha0)?;
        let m = 2 * harmonics;
        Ok(Self {
            link_lengths: link_lengths.to_vec(),
            length,
            harmonics,
            alpha0,
            options: IkOptions::for_chain(link_lengths.len()),
            trial: vec![0.0; m],
            jacobian: vec![0.0; 2 * m],
            trial_jacobian: vec![0.0; 2 * m],
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

    /// The number of harmonics `K` (the solver has `2K` unknowns).
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// Solves `tip_chain(a) = target` for the modal coordinates `a` (`2K` entries), which hold
    /// the initial guess on entry and the solution on success (the best iterate after
    /// [`KinError::NotConverged`]).
    ///
    /// Errors: [`KinError::OutOfReach`] if `|target| > l` beyond rounding;
    /// [`KinError::NotConverged`] if the iteration stalls or runs out of steps (a target the
    /// chain cannot reach on this family and `alpha0`, or a poor guess); [`KinError::Stationary`]
    /// where no step is defined (a zero Jacobian); input errors for a non-finite target or guess, or a guess
    /// of the wrong size.
    pub fn solve(&mut self, target: [f64; 2], a: &mut [f64]) -> Result<IkReport, KinError> {
        check_finite("target x", target[0])?;
        check_finite("target y", target[1])?;
        check_values("initial guess", a, self.trial.len())?;
        let r = target[0].hypot(target[1]);
        check_reach(r, self.length)?;
        let (lengths, length, alpha0) = (&self.link_lengths, self.length, self.alpha0);
        least_squares(
            target,
            a,
            self.options.tolerance * length,
            self.options.max_iterations,
            Workspace {
                trial: &mut self.trial,
                jacobian: &mut self.jacobian,
                trial_jacobian: &mut self.trial_jacobian,
            },
            |modes, jacobian| Ok(chain_tip_jacobian(lengths, length, alpha0, modes, jacobian)),
        )
    }

    /// [`solve`](Self::solve) started from the closed-form inverse of the backbone curve
    /// (eqs 5-6, [`inverse_kinematics`] on `branch`), higher harmonics starting at zero; `a`
    /// (`2K` entries) receives the solution.
    ///
    /// The closed form is restricted to the first branch of `J0`, so a target the curve does not
    /// reach there is refused with its error ([`KinError::A2ExceedsAmplitude`], ...) even if
    /// the chain could reach it; give such targets a guess and call [`solve`](Self::solve).
    pub fn solve_from_closed_form(
        &mut self,
        target: [f64; 2],
        branch: Branch,
        a: &mut [f64],
    ) -> Result<IkReport, KinError> {
        check_len("modal coordinates", a.len(), self.trial.len())?;
        let start = inverse_kinematics(self.length, target, self.alpha0, branch)?;
        a.fill(0.0);
        a[..2].copy_from_slice(&start);
        self.solve(target, a)
    }
}

/// The closed-form start polished on the chain: the two-mode coordinates `[a1, a2]` (on
/// `branch`) that put the tip of the chain with these link lengths on `target`, for the modal
/// map with `alpha0` fixed. See [`ChainIk`]; with equal links this agrees with
/// [`inverse_kinematics`] to within the aliasing error of the curve.
///
/// ```
/// use backbone_kin::{Branch, chain_inverse_kinematics};
/// let a = chain_inverse_kinematics(&[0.5, 0.3, 0.2], [0.4, 0.6], 0.2, Branch::Positive)?;
/// assert!(a[0] >= 0.0);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
pub fn chain_inverse_kinematics(
    link_lengths: &[f64],
    target: [f64; 2],
    alpha0: f64,
    branch: Branch,
) -> Result<[f64; 2], KinError> {
    let mut a = [0.0; 2];
    ChainIk::new(link_lengths, 1, alpha0)?.solve_from_closed_form(target, branch, &mut a)?;
    Ok(a)
}

/// The chain's tip `sum_i L_i (cos phi_i, sin phi_i)`, `phi_i = alpha(s_i)`, and its derivatives
/// along the modal coordinates, written row-major into `jacobian` (`2 x 2K`).
fn chain_tip_jacobian(
    lengths: &[f64],
    length: f64,
    alpha0: f64,
    modes: &[f64],
    jacobian: &mut [f64],
) -> [f64; 2] {
    let m = modes.len();
    jacobian.fill(0.0);
    let (dx, dy) = jacobian.split_at_mut(m);
    let (mut tip, mut start) = ([0.0; 2], 0.0);
    for &link in lengths {
        let s = start + 0.5 * link;
        start += link;
        let phi = alpha0
            + modes
                .chunks_exact(2)
                .enumerate()
                .map(|(i, pair)| {
                    let (sin, one_minus_cos) = harmonic_basis(i + 1, s, length);
                    pair[0] * sin + pair[1] * one_minus_cos
                })
                .sum::<f64>();
        let (sin, cos) = phi.sin_cos();
        tip[0] += link * cos;
        tip[1] += link * sin;
        for k in 1..=m / 2 {
            let (b_sin, b_one_minus_cos) = harmonic_basis(k, s, length);
            for (j, b) in [(2 * k - 2, b_sin), (2 * k - 1, b_one_minus_cos)] {
                dx[j] -= link * sin * b;
                dy[j] += link * cos * b;
            }
        }
    }
    tip
}
