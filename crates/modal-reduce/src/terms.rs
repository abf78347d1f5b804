//! The default path: `M*`, `C*` and `G*` (eq 14) in `O(n m^2)` without forming the `n x n` mass
//! matrix, from prefix sums along the chain in absolute link angles.
//!
//! # Derivation
//!
//! Number links from 0 at the base. Link `l` has absolute angle `phi_l = theta_0 + ... + theta_l`;
//! with `theta = J a + theta_0` (eq 8) this is `phi_l = Phi_l . a + phi0_l`, where the row
//! `Phi_l = J_0 + ... + J_l` (running sum of the rows of `J`) and `phi0_l` are constants, so
//! `phi_dot_l = Phi_l . a_dot` and `phi_ddot_l = Phi_l . a_ddot`. Write
//! `u_l = (cos phi_l, sin phi_l)`, `w_l = (-sin phi_l, cos phi_l)`, and let `L_l`, `m_l`, `r_l`,
//! `I_l` be the link's length, mass, centre-of-mass offset and inertia.
//!
//! *The chain in absolute angles.* Joint `l` sits at `p_l = sum_{j<l} L_j u_j` and the centre of
//! mass of link `l` at `c_l = p_l + r_l u_l`, so `c_dot_l = sum_{j<l} L_j phi_dot_j w_j +
//! r_l phi_dot_l w_l`. Expanding `T = 1/2 sum_l (m_l |c_dot_l|^2 + I_l phi_dot_l^2)` gives
//! `T = 1/2 phi_dot^T H phi_dot` with
//!
//! ```text
//! H_jl = h_jl cos(phi_j - phi_l),   h_ll = I_l + m_l r_l^2 + L_l^2 mu_l,   h_jl = L_j S_l  (j < l),
//! mu_l = sum_{i>l} m_i  (mass beyond link l),   S_l = m_l r_l + L_l mu_l.
//! ```
//!
//! The potential is `V = g sum_l m_l (c_l)_y = g sum_l S_l sin phi_l`. Lagrange's equations
//! for this `H` give the Coriolis/centrifugal forces `c_j = sum_l h_jl sin(phi_j - phi_l)
//! phi_dot_l^2` and the gravity forces `dV/dphi_l = g S_l cos phi_l`.
//!
//! *Reduction.* `phi = Phi a + phi0` with constant `Phi` (rows `Phi_l`) is an exact holonomic
//! constraint, so the reduced system is Lagrangian with `M* = Phi^T H Phi`,
//! `C* = Phi^T c(phi, Phi a_dot)` and `G* = Phi^T dV/dphi`; these are the projections
//! `J^T M J`, `J^T C`, `J^T G` of eq 14, written in absolute rather than relative angles.
//!
//! *Prefix sums.* With `P_l = sum_{j<l} L_j w_j Phi_j` (`2 x m`) and
//! `q_l = -sum_{j<l} L_j phi_dot_j^2 u_j` (the acceleration of joint `l` when `a_ddot = 0`):
//!
//! ```text
//! v_l = P_l^T w_l = sum_{j<l} L_j cos(phi_j - phi_l) Phi_j^T
//! w_l . q_l       = sum_{j<l} L_j phi_dot_j^2 sin(phi_l - phi_j)
//! ```
//!
//! and splitting each double sum into `j < l`, `j = l` and `j > l`:
//!
//! ```text
//! M* = K + sum_l S_l (Phi_l^T v_l^T + v_l Phi_l),   K = sum_l h_ll Phi_l^T Phi_l  (constant),
//! c_l = S_l (w_l . q_l) - L_l sum_{j>l} S_j phi_dot_j^2 sin(phi_j - phi_l).
//! ```
//!
//! The second part of `c_l` is a suffix sum, but its projection is a prefix sum again: exchanging
//! the order of summation, `sum_l L_l sum_{j>l} S_j phi_dot_j^2 sin(phi_j - phi_l) Phi_l^T =
//! sum_j S_j phi_dot_j^2 P_j^T u_j`, so
//!
//! ```text
//! C* = sum_l (S_l (w_l . q_l) Phi_l^T - S_l phi_dot_l^2 P_l^T u_l),
//! G* = g sum_l S_l cos(phi_l) Phi_l^T,
//! P_{l+1} = P_l + L_l w_l Phi_l,   q_{l+1} = q_l - L_l phi_dot_l^2 u_l.
//! ```
//!
//! So one pass from the base builds `P_l` and `q_l` and accumulates `M*`, `C*` and `G*`. Per link
//! this is one sine-cosine pair (computed for all links at once, see `trig`), `O(m)` work for
//! `v_l`, `P_l^T u_l`, `P_l` and the projections, and `O(m^2)` for the symmetric update of `M*`
//! (its upper triangle; mirrored at the end).
//!
//! The kernel is written once, generic over its number type: `f64` for one state, and a SIMD
//! register of several states side by side for [`forward_dynamics_batch`].
//!
//! [`forward_dynamics_batch`]: crate::forward_dynamics_batch

use crate::data::{LinkBuffers, ReducedData};
use crate::error::{ReduceError, check_finite_result, check_input};
use crate::model::ReducedModel;
use lane_math::Lane;
use lane_math::sin_cos;

/// Computes `M*(a)`, `C*(a, a_dot)` and `G*(a)` (eq 14) into `data` in `O(n m^2)`, by prefix
/// sums along the chain (the default path; see the [module documentation](self) for the
/// derivation).
///
/// Read the results with [`ReducedData::mass_matrix`], [`ReducedData::coriolis`] and
/// [`ReducedData::gravity`]. Allocation-free.
///
/// ```
/// use backbone_kin::ModalMap;
/// use manip_dyn::ChainModel;
/// use modal_reduce::{ReducedData, ReducedModel, reduced_terms};
///
/// let model = ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81)?, ModalMap::paper(10)?)?;
/// let mut data = ReducedData::new(&model);
/// reduced_terms(&model, &mut data, &[0.3, -0.2, 0.5], &[1.0, 0.5, -0.4])?;
/// let m_star = data.mass_matrix();
/// assert!((m_star[(0, 1)] - m_star[(1, 0)]).abs() < 1e-15);
/// assert!(m_star[(2, 2)] > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn reduced_terms(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) -> Result<(), ReduceError> {
    data.check_model(model)?;
    let m = model.n_coords();
    check_input("a", a, m)?;
    check_input("a_dot", a_dot, m)?;
    // The paper's sizes and two harmonics (m = 2 to 5) run on stack arrays that the optimiser
    // keeps in registers.
    match m {
        2 => accumulate_on_stack::<2>(model, data, a, a_dot),
        3 => accumulate_on_stack::<3>(model, data, a, a_dot),
        4 => accumulate_on_stack::<4>(model, data, a, a_dot),
        5 => accumulate_on_stack::<5>(model, data, a, a_dot),
        _ => {
            let ReducedData {
                links,
                mass,
                coriolis,
                gravity,
                scratch,
                ..
            } = data;
            let terms = Terms {
                mass,
                coriolis,
                gravity,
                joint: &mut scratch.joint,
                cos_moment: &mut scratch.cos_moment,
            };
            accumulate((), model, a, a_dot, m, links.trig(), terms);
        }
    }
    check_finite_result("reduced mass matrix M*", &data.mass)?;
    check_finite_result("reduced Coriolis vector C*", &data.coriolis)?;
    check_finite_result("reduced gravity vector G*", &data.gravity)
}

/// An `(x, y)` pair: a column of the `2 x m` prefix sum `P_l`.
pub(crate) type Pair<L> = [L; 2];

/// The per-link buffers of the kernel, `n` values of `L::WIDTH` lanes each (`[link][lane]`).
pub(crate) struct LinkTrig<'a> {
    /// Absolute angle `phi_l`.
    pub(crate) angle: &'a mut [f64],
    /// Its sine and cosine.
    pub(crate) sin: &'a mut [f64],
    pub(crate) cos: &'a mut [f64],
}

impl LinkBuffers {
    /// The buffers as the kernel takes them.
    pub(crate) fn trig(&mut self) -> LinkTrig<'_> {
        LinkTrig {
            angle: &mut self.angle,
            sin: &mut self.sin,
            cos: &mut self.cos,
        }
    }
}

/// The results and scratch of the kernel, `m` or `m x m` values.
pub(crate) struct Terms<'a, L> {
    /// `M*`, row-major `m x m`.
    pub(crate) mass: &'a mut [L],
    /// `C*`, length `m`.
    pub(crate) coriolis: &'a mut [L],
    /// `G*`, length `m`.
    pub(crate) gravity: &'a mut [L],
    /// Columns of `P_l`, length `m`.
    pub(crate) joint: &'a mut [Pair<L>],
    /// `S_l v_l`, length `m`.
    pub(crate) cos_moment: &'a mut [L],
}

/// [`accumulate`] for a compile-time `M` on one state, on local arrays, copied into `data`.
#[inline(always)]
fn accumulate_on_stack<const M: usize>(
    model: &ReducedModel,
    data: &mut ReducedData,
    a: &[f64],
    a_dot: &[f64],
) {
    let mut mass = [[0.0; M]; M];
    let (mut coriolis, mut gravity) = ([0.0; M], [0.0; M]);
    let mut joint = [[0.0; 2]; M];
    let mut cos_moment = [0.0; M];
    let terms = Terms {
        mass: mass.as_flattened_mut(),
        coriolis: &mut coriolis,
        gravity: &mut gravity,
        joint: &mut joint,
        cos_moment: &mut cos_moment,
    };
    accumulate((), model, a, a_dot, M, data.links.trig(), terms);
    data.mass.copy_from_slice(mass.as_flattened());
    data.coriolis.copy_from_slice(&coriolis);
    data.gravity.copy_from_slice(&gravity);
}

/// The sums of the module documentation, for `m` coordinates of `L::WIDTH` states each, into
/// `terms`: `M*` (both triangles), `C*` and `G*`.
#[inline(always)]
pub(crate) fn accumulate<L: Lane>(
    context: L::Context,
    model: &ReducedModel,
    a: &[L],
    a_dot: &[L],
    m: usize,
    links: LinkTrig<'_>,
    terms: Terms<'_, L>,
) {
    let width = L::WIDTH;
    let zero = L::splat(context, 0.0);
    let (a, a_dot) = (&a[..m], &a_dot[..m]);
    let mass = &mut terms.mass[..m * m];
    let coriolis = &mut terms.coriolis[..m];
    let gravity = &mut terms.gravity[..m];
    let joint = &mut terms.joint[..m];
    let cos_moment = &mut terms.cos_moment[..m];
    mass.fill(zero);
    coriolis.fill(zero);
    gravity.fill(zero);
    joint.fill([zero; 2]);
    let constants = model.link_constants();
    let rows = model.angle_rows();
    let size = constants.len() * width;
    let (angle, sin, cos) = (
        &mut links.angle[..size],
        &mut links.sin[..size],
        &mut links.cos[..size],
    );
    // Absolute angles, then their sines and cosines, all links at once.
    for ((angle, phi), link) in angle
        .chunks_exact_mut(width)
        .zip(rows.chunks_exact(m))
        .zip(constants)
    {
        let phi = &phi[..m];
        let mut phi_l = L::splat(context, link.angle_offset);
        for k in 0..m {
            phi_l = phi_l + a[k] * phi[k];
        }
        phi_l.store(angle);
    }
    sin_cos(angle, sin, cos);
    // One pass from the base: P_l, q_l, and the sums of M*, C* and G*.
    let mut q = [zero; 2];
    for (((link, phi), sin), cos) in constants
        .iter()
        .zip(rows.chunks_exact(m))
        .zip(sin.chunks_exact(width))
        .zip(cos.chunks_exact(width))
    {
        let phi = &phi[..m];
        let (sin, cos) = (L::load(context, sin), L::load(context, cos));
        let mut rate = zero;
        for k in 0..m {
            rate = rate + a_dot[k] * phi[k];
        }
        let rate2 = rate * rate;
        let moment = link.first_moment;
        // S_l (w_l . q_l), S_l phi_dot_l^2 and S_l cos(phi_l).
        let force = (cos * q[1] - sin * q[0]) * moment;
        let moment_rate2 = rate2 * moment;
        let gravity_force = cos * moment;
        for k in 0..m {
            let [px, py] = joint[k];
            cos_moment[k] = (cos * py - sin * px) * moment;
            let along = cos * px + sin * py;
            coriolis[k] = coriolis[k] + force * phi[k] - moment_rate2 * along;
            gravity[k] = gravity[k] + gravity_force * phi[k];
        }
        for j in 0..m {
            for k in j..m {
                mass[j * m + k] =
                    mass[j * m + k] + (cos_moment[k] * phi[j] + cos_moment[j] * phi[k]);
            }
        }
        let (l_sin, l_cos) = (sin * link.length, cos * link.length);
        for k in 0..m {
            joint[k][0] = joint[k][0] - l_sin * phi[k];
            joint[k][1] = joint[k][1] + l_cos * phi[k];
        }
        q[0] = q[0] - l_cos * rate2;
        q[1] = q[1] - l_sin * rate2;
    }
    // The constant part K of M*, the lower triangle, and G* = g (...).
    let constant = model.constant_mass();
    let g = model.chain().gravity();
    for j in 0..m {
        for k in j..m {
            let entry = mass[j * m + k] + L::splat(context, constant[j * m + k]);
            mass[j * m + k] = entry;
            mass[k * m + j] = entry;
        }
        gravity[j] = gravity[j] * g;
    }
}
