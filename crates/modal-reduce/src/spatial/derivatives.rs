//! Analytic derivatives of the reduced forward dynamics of a spatial modal arm:
//! `d a_ddot / d a`, `d a_ddot / d a_dot` and `d a_ddot / d tau* = M*^-1`, in `O(n m^2)` without
//! any `2n x 2n` matrix (`docs/theory.md`, section 8).
//!
//! Differentiating `M*(a) a_ddot + C*(a, a_dot) + G*(a) = tau*` at fixed `tau*` gives
//! `d a_ddot / d a = -M*^-1 D_a` and `d a_ddot / d a_dot = -M*^-1 D_v`, with `D_a` and `D_v` the
//! partials of the reduced inverse dynamics `J^T tau(J a, J a_dot, J a_ddot)` at the solution
//! `a_ddot`. Since `J` is constant, column `k` of `D_a` is `J^T d tau` along the joint direction
//! `d theta = J e_k` (and of `D_v` along `d theta_dot = J e_k`): the tangent of the Newton-Euler
//! recursion ([`tangent`](super::tangent)), `O(n)` a direction, then `O(n m)` for `J^T`; `2m`
//! directions. The three Jacobians then come from one `L D L^T` solve of `M*` on the rows of the
//! `m x 3m` right-hand side `[-D_a | -D_v | 1]`.

use super::data::SpatialReducedData;
use super::forward::spatial_forward_dynamics;
use super::model::SpatialReducedModel;
use super::motion::world_inertia;
use super::tangent::{
    CarriedTangent, JointPair, LinkTangent, WrenchTangent, link_tangent, wrench_tangent,
};
use super::torques::spatial_joint_torques;
use crate::error::{ReduceError, check_finite_result};
use faer::MatRef;
use lane_math::check_len;
use lane_math::dense::ldlt_solve_rows_in_place;

/// Results and scratch of [`spatial_reduced_derivatives`] for one [`SpatialReducedModel`]:
/// `O(n + m^2)` memory, built once; every call then fills it without allocating.
///
/// After a call, [`a_ddot`](Self::a_ddot) holds the modal accelerations and
/// [`d_a`](Self::d_a), [`d_a_dot`](Self::d_a_dot) and [`d_tau_star`](Self::d_tau_star) their
/// `m x m` Jacobians, entry `(i, j) = d a_ddot_i / d in_j`.
#[derive(Debug, Clone)]
pub struct SpatialReducedDerivatives {
    n_links: usize,
    n_coords: usize,
    a_ddot: Vec<f64>,
    /// Row-major `m x 3m`: row `i` is `[d_a row i | d_a_dot row i | d_tau_star row i]`.
    jacobians: Vec<f64>,
    /// The joint torques of the nominal motion (`2n`) and the tangent of one direction (`2n`).
    tau: Vec<f64>,
    d_tau: Vec<f64>,
    /// Every link's tangent along the current direction.
    tangents: Vec<LinkTangent>,
}

impl SpatialReducedDerivatives {
    /// A workspace sized for `model`.
    ///
    /// # Panics
    /// When the system refuses the memory; [`SpatialReducedDerivatives::try_new`] returns the
    /// error.
    pub fn new(model: &SpatialReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`SpatialReducedDerivatives::new`], or [`ReduceError::OutOfMemory`] when the system
    /// refuses the memory.
    pub fn try_new(model: &SpatialReducedModel) -> Result<Self, ReduceError> {
        const WHAT: &str = "the workspace of the spatial reduced derivatives";
        let zeros = |len: usize| lane_math::try_filled(len, 0.0, WHAT);
        let (n, m) = (model.n_links(), model.n_coords());
        Ok(Self {
            n_links: n,
            n_coords: m,
            a_ddot: zeros(m)?,
            jacobians: zeros(3 * m * m)?,
            tau: zeros(2 * n)?,
            d_tau: zeros(2 * n)?,
            tangents: lane_math::try_filled(n, LinkTangent::default(), WHAT)?,
        })
    }

    /// The modal accelerations `a_ddot` (eq 15) of the last call.
    pub fn a_ddot(&self) -> &[f64] {
        &self.a_ddot
    }

    /// The three Jacobians side by side, row-major `m x 3m`: row `i` is
    /// `[d_a row i | d_a_dot row i | d_tau_star row i]`.
    #[inline]
    pub fn jacobians(&self) -> &[f64] {
        &self.jacobians
    }

    /// `d a_ddot / d a` (`m x m`).
    pub fn d_a(&self) -> MatRef<'_, f64> {
        self.block(0)
    }

    /// `d a_ddot / d a_dot` (`m x m`).
    pub fn d_a_dot(&self) -> MatRef<'_, f64> {
        self.block(1)
    }

    /// `d a_ddot / d tau* = M*^-1` (`m x m`).
    pub fn d_tau_star(&self) -> MatRef<'_, f64> {
        self.block(2)
    }

    fn block(&self, index: usize) -> MatRef<'_, f64> {
        let m = self.n_coords;
        MatRef::from_row_major_slice_with_stride(&self.jacobians[index * m..], m, m, 3 * m)
    }
}

/// The reduced forward dynamics (as [`spatial_forward_dynamics`]) and its analytic derivatives
/// with respect to `a`, `a_dot` and `tau*` at one state, into `derivatives` (module
/// documentation). `O(n m^2)`, allocation-free; `data` holds `M*`, `C*` and `G*` afterwards.
///
/// Errors: as [`spatial_forward_dynamics`], and [`ReduceError::Dimension`] if `derivatives` was
/// built for another model.
pub fn spatial_reduced_derivatives(
    model: &SpatialReducedModel,
    data: &mut SpatialReducedData,
    derivatives: &mut SpatialReducedDerivatives,
    a: &[f64],
    a_dot: &[f64],
    tau_star: &[f64],
) -> Result<(), ReduceError> {
    check_len(
        "derivative workspace links",
        derivatives.n_links,
        model.n_links(),
    )?;
    check_len(
        "derivative workspace coordinates",
        derivatives.n_coords,
        model.n_coords(),
    )?;
    let SpatialReducedDerivatives {
        a_ddot,
        jacobians,
        tau,
        d_tau,
        tangents,
        ..
    } = derivatives;
    spatial_forward_dynamics(model, data, a, a_dot, tau_star, a_ddot)?;
    // The nominal motion at the solution: every link's motion into `data.links`, the joint
    // accelerations into `data.theta_ddot`.
    spatial_joint_torques(model, data, a, a_dot, a_ddot, tau)?;
    let m = model.n_coords();
    let width = 3 * m;
    let map = model.map();
    let gravity = model.gravity();
    jacobians.fill(0.0);
    for direction in 0..2 * m {
        let (k, on_rates) = (direction % m, direction >= m);
        let mut carried = CarriedTangent::default();
        let mut previous_omega = [0.0; 3];
        for (i, ((tangent, motion), &length)) in tangents
            .iter_mut()
            .zip(&data.links)
            .zip(map.link_lengths())
            .enumerate()
        {
            let along = [map.row(2 * i)[k], map.row(2 * i + 1)[k]];
            let joints = JointPair {
                rates: [data.theta_dot[2 * i], data.theta_dot[2 * i + 1]],
                accels: [data.theta_ddot[2 * i], data.theta_ddot[2 * i + 1]],
                d_angles: if on_rates { [0.0; 2] } else { along },
                d_rates: if on_rates { along } else { [0.0; 2] },
            };
            *tangent = link_tangent(&mut carried, motion, previous_omega, length, joints);
            previous_omega = motion.omega;
        }
        // Nothing acts beyond the tip: the point the moment is taken about enters only through
        // the force from beyond it, zero at the tip.
        let mut wrench = WrenchTangent::default();
        for (((motion, tangent), inertia), pair) in data
            .links
            .iter()
            .zip(tangents.iter())
            .zip(model.links())
            .zip(d_tau.chunks_exact_mut(2))
            .rev()
        {
            let world = world_inertia(&motion.rotation, inertia.principal);
            let torques =
                wrench_tangent(&mut wrench, motion, tangent, &world, inertia.mass, gravity);
            pair.copy_from_slice(&torques);
        }
        // Column `direction` of [-D_a | -D_v] = -J^T d tau.
        for (j, &d) in d_tau.iter().enumerate() {
            for (row, &r) in jacobians.chunks_exact_mut(width).zip(map.row(j)) {
                row[direction] -= r * d;
            }
        }
    }
    for (i, row) in jacobians.chunks_exact_mut(width).enumerate() {
        row[2 * m + i] = 1.0;
    }
    // `spatial_forward_dynamics` left the `L D L^T` factor of `M*` in the workspace.
    ldlt_solve_rows_in_place(&data.factor, m, jacobians, width);
    check_finite_result("reduced dynamics derivatives", jacobians)
}
