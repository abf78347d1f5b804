//! The Coriolis matrix of eq 12 from the Christoffel symbols of `M`, O(n^2).
//!
//! With `r_b` the centre of mass of link `b`, `p_i` the position of joint `i` and
//! `J_b = d r_b / d q` (column `i` is `e_z x (r_b - p_i)` for `i <= b`), the mass matrix is
//! `M = sum_b m_b J_b^T J_b` plus a constant rotational part (`omega_b` is linear in `v` with a
//! constant Jacobian). Differentiating analytically, and using that `d J_bj / d q_k` is symmetric
//! in `j, k` (both are the second derivative of `r_b`), the Christoffel symbols of the first kind
//!
//! `Gamma_ijk = 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i)`
//!
//! reduce to `Gamma_ijk = sum_b m_b J_bi . dJ_bj/dq_k`, hence
//!
//! `c_ij = sum_k Gamma_ijk v_k = sum_{b >= max(i, j)} m_b (r_b - p_i) . (r_b_dot - p_j_dot)`.
//!
//! Then `dM/dt = C + C^T`, so `dM/dt - 2C = C^T - C` is skew-symmetric, and `C v` is the
//! Coriolis/centrifugal vector of [`coriolis`](crate::coriolis()).

use faer::MatMut;

use crate::check;
use crate::crba::accumulate_subtrees;
use crate::data::{ChainData, LinkFrame, Subtree, SubtreeMotion};
use crate::error::DynError;
use crate::kinematics::{dot, update_frames};
use crate::model::ChainModel;

/// The Coriolis matrix `C(q, v)` built from the Christoffel symbols of `M` (see the module
/// documentation), written in full into `out`. `C(q, v) v` is the vector
/// [`coriolis`](crate::coriolis()), and `dM/dt - 2 C` is skew-symmetric.
///
/// ```
/// use manip_dyn::{ChainData, ChainModel, coriolis, coriolis_matrix};
/// let arm = ChainModel::uniform(2, 1.0, 1.0, 9.81)?;
/// let mut data = ChainData::new(&arm);
/// let (q, v) = ([0.3, 0.7], [1.0, -2.0]);
/// let mut c = manip_dyn::faer::Mat::<f64>::zeros(2, 2);
/// coriolis_matrix(&arm, &mut data, &q, &v, c.as_mut())?;
/// let mut cv = [0.0; 2];
/// coriolis(&arm, &mut data, &q, &v, &mut cv)?;
/// for i in 0..2 {
///     assert!((c[(i, 0)] * v[0] + c[(i, 1)] * v[1] - cv[i]).abs() < 1e-12);
/// }
/// # Ok::<(), manip_dyn::DynError>(())
/// ```
///
/// # Errors
/// [`DynError::TooManyLinks`] for a chain of more than [`MAX_DENSE_LINKS`](crate::MAX_DENSE_LINKS)
/// links;
/// [`DynError::Dimension`] if `q` or `v` does not have `n` entries, `out` is not `n x n`, or
/// `data` was built for another chain; [`DynError::NonFinite`] for a NaN or infinite input;
/// [`DynError::NonFiniteResult`] if an entry overflows.
pub fn coriolis_matrix(
    model: &ChainModel,
    data: &mut ChainData,
    q: &[f64],
    v: &[f64],
    mut out: MatMut<'_, f64>,
) -> Result<(), DynError> {
    check::dense("the Coriolis matrix", model)?;
    let n = check::inputs(model, data, &[("q", q), ("v", v)])?;
    check::square_output(&out, n)?;
    update_frames(&mut data.frames, q, Some(v));
    accumulate_subtrees(model, &data.frames, &mut data.subtrees);
    accumulate_motions(
        model,
        &data.frames,
        &data.subtrees,
        &mut data.subtree_motions,
    );
    let frames = &data.frames;
    let links = model.links();
    // Column by column, so that the writes are contiguous.
    for j in 0..n {
        let motion = &data.subtree_motions[j];
        out[(j, j)] = motion.diagonal;
        // Above the diagonal (i < j, so max = j): c_ij = c_jj + (p_j - p_i) . momentum_j, the
        // offset growing by L_i u_i at each step up.
        let mut entry = motion.diagonal;
        for i in (0..j).rev() {
            entry += links[i].length * dot(frames[i].axis, motion.momentum);
            out[(i, j)] = entry;
        }
        // Below it (i > j, so max = i): c_ij = c_ii + h_i . (p_i_dot - p_j_dot), the velocity
        // offset growing by L_l omega_l (e_z x u_l) at each step down.
        let mut offset = [0.0, 0.0];
        for i in j + 1..n {
            let (link, frame) = (&links[i - 1], &frames[i - 1]);
            let normal = frame.normal();
            offset[0] += link.length * frame.omega * normal[0];
            offset[1] += link.length * frame.omega * normal[1];
            out[(i, j)] =
                data.subtree_motions[i].diagonal + dot(data.subtrees[i].first_moment, offset);
        }
    }
    check::finite_matrix("coriolis matrix", &out)
}

/// The velocity moments of every composite body, from the tip back (O(n)).
fn accumulate_motions(
    model: &ChainModel,
    frames: &[LinkFrame],
    subtrees: &[Subtree],
    motions: &mut [SubtreeMotion],
) {
    let mut child = SubtreeMotion::default();
    let mut child_subtree = Subtree::default();
    for i in (0..model.n_links()).rev() {
        let link = &model.links()[i];
        let frame = &frames[i];
        let normal = frame.normal();
        // Joint i + 1 relative to joint i: position L u, velocity L omega (e_z x u).
        let reach = [link.length * frame.axis[0], link.length * frame.axis[1]];
        let reach_rate = [
            link.length * frame.omega * normal[0],
            link.length * frame.omega * normal[1],
        ];
        let own = link.mass * link.com * frame.omega;
        // The link's own centre of mass moves perpendicular to c u, so it adds nothing to the
        // diagonal term.
        let current = SubtreeMotion {
            momentum: [
                own * normal[0] + child.momentum[0] + child_subtree.mass * reach_rate[0],
                own * normal[1] + child.momentum[1] + child_subtree.mass * reach_rate[1],
            ],
            diagonal: child.diagonal
                + dot(child_subtree.first_moment, reach_rate)
                + dot(reach, child.momentum),
        };
        motions[i] = current;
        child = current;
        child_subtree = subtrees[i];
    }
}
