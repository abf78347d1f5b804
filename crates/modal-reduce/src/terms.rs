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
//! *Prefix and suffix sums.* With `P_l = sum_{j<l} L_j w_j Phi_j` (`2 x m`),
//! `q_l = -sum_{j<l} L_j phi_dot_j^2 u_j` (the acceleration of joint `l` when `a_ddot = 0`) and
//! `R_l = sum_{j>l} S_j phi_dot_j^2 u_j`:
//!
//! ```text
//! v_l = P_l^T w_l = sum_{j<l} L_j cos(phi_j - phi_l) Phi_j^T
//! w_l . q_l       = sum_{j<l} L_j phi_dot_j^2 sin(phi_l - phi_j)
//! w_l . R_l       = sum_{j>l} S_j phi_dot_j^2 sin(phi_j - phi_l)
//! ```
//!
//! and splitting each double sum into `j < l`, `j = l` and `j > l`:
//!
//! ```text
//! M* = K + sum_l S_l (Phi_l^T v_l^T + v_l Phi_l),   K = sum_l h_ll Phi_l^T Phi_l  (constant),
//! c_l = S_l (w_l . q_l) - L_l (w_l . R_l),          C* = sum_l c_l Phi_l^T,
//! G* = g sum_l S_l cos(phi_l) Phi_l^T,
//! P_{l+1} = P_l + L_l w_l Phi_l,   q_{l+1} = q_l - L_l phi_dot_l^2 u_l,   R_{l-1} = R_l + S_l phi_dot_l^2 u_l.
//! ```
//!
//! So a pass from the base builds `P_l`, `M*` and the first part of `c_l`, and a pass from the
//! tip finishes `c_l` and projects `C*` and `G*`. Per link this is one sine-cosine pair (computed
//! for all links at once, see `trig`), `O(1)` work for `c_l`, `O(m)` for `v_l`, `P_l` and the
//! projections, and `O(m^2)` for the symmetric update of `M*` (its upper triangle; mirrored at
//! the end).

use crate::data::{LinkBuffers, ReducedData};
use crate::error::{ReduceError, check_finite_result, check_input};
use crate::model::ReducedModel;
use crate::trig::sin_cos;

/// Computes `M*(a)`, `C*(a, a_dot)` and `G*(a)` (eq 14) into `data` in `O(n m^2)`, by prefix and
/// suffix sums along the chain (the default path; see the [module documentation](self) for the
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
    // The paper's sizes run on stack arrays that the optimiser keeps in registers.
    match m {
        2 => accumulate_on_stack::<2>(model, data, a, a_dot),
        3 => accumulate_on_stack::<3>(model, data, a, a_dot),
        _ => {
            let data = &mut *data;
            let scratch = &mut data.scratch;
            accumulate(
                model,
                a,
                a_dot,
                m,
                Workspace {
                    links: &mut data.links,
                    mass: &mut data.mass,
                    coriolis: &mut data.coriolis,
                    gravity: &mut data.gravity,
                    joint: &mut scratch.joint,
                    cos_moment: &mut scratch.cos_moment,
                },
            );
        }
    }
    finish(model, m, data);
    check_finite_result("reduced mass matrix M*", &data.mass)?;
    check_finite_result("reduced Coriolis vector C*", &data.coriolis)?;
    check_finite_result("reduced gravity vector G*", &data.gravity)
}

/// An `(x, y)` pair: a column of the `2 x m` prefix sum `P_l`.
pub(crate) type Pair = [f64; 2];

/// The accumulators and scratch of the sums.
struct Workspace<'a> {
    /// Per link (`n` each): absolute angle, its sine and cosine, squared angular rate, force.
    links: &'a mut LinkBuffers,
    /// `sum_l S_l (Phi_l^T v_l^T + v_l Phi_l)`, row-major `m x m`, upper triangle.
    mass: &'a mut [f64],
    /// `C*`, length `m`.
    coriolis: &'a mut [f64],
    /// `G* / g`, length `m`.
    gravity: &'a mut [f64],
    /// Columns of `P_l`, length `m`.
    joint: &'a mut [Pair],
    /// `S_l v_l`, length `m`.
    cos_moment: &'a mut [f64],
}

/// [`accumulate`] for a compile-time `M`, on local arrays, copied into `data`.
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
    accumulate(
        model,
        a,
        a_dot,
        M,
        Workspace {
            links: &mut data.links,
            mass: mass.as_flattened_mut(),
            coriolis: &mut coriolis,
            gravity: &mut gravity,
            joint: &mut joint,
            cos_moment: &mut cos_moment,
        },
    );
    data.mass.copy_from_slice(mass.as_flattened());
    data.coriolis.copy_from_slice(&coriolis);
    data.gravity.copy_from_slice(&gravity);
}

/// The sums of the module documentation, for `m` coordinates, into `work`.
#[inline(always)]
fn accumulate(model: &ReducedModel, a: &[f64], a_dot: &[f64], m: usize, work: Workspace<'_>) {
    let (a, a_dot) = (&a[..m], &a_dot[..m]);
    let mass = &mut work.mass[..m * m];
    let coriolis = &mut work.coriolis[..m];
    let gravity = &mut work.gravity[..m];
    let joint = &mut work.joint[..m];
    let cos_moment = &mut work.cos_moment[..m];
    mass.fill(0.0);
    coriolis.fill(0.0);
    gravity.fill(0.0);
    joint.fill([0.0; 2]);
    // First pass: absolute angles, their sines and cosines, squared rates.
    let LinkBuffers {
        angle,
        sin,
        cos,
        rate_squared,
        force,
    } = work.links;
    for (((angle, rate_squared), phi), link) in angle
        .iter_mut()
        .zip(rate_squared.iter_mut())
        .zip(model.angle_rows().chunks_exact(m))
        .zip(model.link_constants())
    {
        let phi = &phi[..m];
        let mut phi_l = link.angle_offset;
        let mut rate = 0.0;
        for k in 0..m {
            phi_l += phi[k] * a[k];
            rate += phi[k] * a_dot[k];
        }
        *angle = phi_l;
        *rate_squared = rate * rate;
    }
    sin_cos(angle, sin, cos);
    // Second pass, from the base: P_l and M*; q_l and the first part of c_l.
    let mut q = [0.0; 2];
    for (((((link, phi), &sin), &cos), &rate2), force) in model
        .link_constants()
        .iter()
        .zip(model.angle_rows().chunks_exact(m))
        .zip(sin.iter())
        .zip(cos.iter())
        .zip(rate_squared.iter())
        .zip(force.iter_mut())
    {
        let phi = &phi[..m];
        let moment = link.first_moment;
        for k in 0..m {
            let [px, py] = joint[k];
            cos_moment[k] = moment * (cos * py - sin * px);
        }
        for j in 0..m {
            for k in j..m {
                mass[j * m + k] += phi[j] * cos_moment[k] + cos_moment[j] * phi[k];
            }
        }
        *force = moment * (cos * q[1] - sin * q[0]);
        let (l_sin, l_cos) = (link.length * sin, link.length * cos);
        for k in 0..m {
            joint[k][0] -= l_sin * phi[k];
            joint[k][1] += l_cos * phi[k];
        }
        q[0] -= l_cos * rate2;
        q[1] -= l_sin * rate2;
    }
    // Third pass, from the tip: R_l, the rest of c_l, and C* = Phi^T c, G* / g = Phi^T (S cos).
    let mut r = [0.0; 2];
    for (((((link, phi), &sin), &cos), &rate2), &force) in model
        .link_constants()
        .iter()
        .zip(model.angle_rows().chunks_exact(m))
        .zip(sin.iter())
        .zip(cos.iter())
        .zip(rate_squared.iter())
        .zip(force.iter())
        .rev()
    {
        let phi = &phi[..m];
        let coriolis_force = force - link.length * (cos * r[1] - sin * r[0]);
        let gravity_force = link.first_moment * cos;
        for k in 0..m {
            coriolis[k] += coriolis_force * phi[k];
            gravity[k] += gravity_force * phi[k];
        }
        let moment_rate2 = link.first_moment * rate2;
        r[0] += moment_rate2 * cos;
        r[1] += moment_rate2 * sin;
    }
}

/// Adds the constant part `K` to `M*` and mirrors its upper triangle; scales `G*` by `g`.
#[inline(always)]
fn finish(model: &ReducedModel, m: usize, data: &mut ReducedData) {
    let constant = model.constant_mass();
    let g = model.chain().gravity();
    for j in 0..m {
        for k in j..m {
            let entry = data.mass[j * m + k] + constant[j * m + k];
            data.mass[j * m + k] = entry;
            data.mass[k * m + j] = entry;
        }
        data.gravity[j] *= g;
    }
}
