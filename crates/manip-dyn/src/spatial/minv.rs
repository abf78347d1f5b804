//! The inverse of the joint-space inertia matrix, `M^-1`, from the articulated-body
//! factorisation the ABA leaves behind, in `O(n^2)` without forming or factorising `M`
//! (Carpentier 2018, "Analytical inverse of the joint space inertia matrix"; Pinocchio's
//! `computeMinverse`).
//!
//! Column `j` of `M^-1` is the ABA's `qdd` for `tau = e_j` with no velocity and no gravity, so it
//! reuses the articulated quantities `X_i`, `U_i = IA_i S_i` and `1 / D_i`, which depend on `q`
//! only. With `F_i[:, j]`, the bias force link `i` receives from its subtree in column `j`, the
//! two sweeps are (theory.md, "Spatial chains: `M^-1` in `O(n^2)`", eqs. S1-S3):
//!
//! ```text
//! tip to base, j >= i:   m_ij = (delta_ij - S_i . F_i[:, j]) / D_i                      (S1)
//!                        F_{i-1}[:, j] = X_i^* (F_i[:, j] + U_i m_ij)                   (S2)
//! base to tip, j >= i:   a'_i[:, j] = X_i^-1 a_{i-1}[:, j],  a_{-1} = 0
//!                        (M^-1)_ij = m_ij - U_i . a'_i[:, j] / D_i,
//!                        a_i[:, j] = a'_i[:, j] + S_i (M^-1)_ij                         (S3)
//! ```
//!
//! Only the entries `j >= i` are computed (the rows of the subtree below each joint), about
//! `35 n^2` multiply-adds; the other half is the symmetric mirror.

use faer::MatMut;

use super::algebra::{Force, Motion, Transform};
use super::data::AbaLink;
use super::model::SpatialModel;

/// `M^-1` into `minv` (`n x n`) from `links`, the articulated quantities of an
/// [`aba`](super::aba()) at the same `q` (whose pivots it checked), with `forces` and `motions`
/// (`n` each) as scratch. Allocation-free.
pub(crate) fn inverse_mass_matrix(
    model: &SpatialModel,
    links: &[AbaLink<f64>],
    forces: &mut [Force],
    motions: &mut [Motion],
    mut minv: MatMut<'_, f64>,
) {
    let n = model.n_links();
    let placement = |link: &AbaLink<f64>| Transform {
        rotation: link.rotation,
        translation: link.translation,
    };
    let coupling = |link: &AbaLink<f64>| Force {
        linear: link.coupling[0],
        angular: link.coupling[1],
    };
    // Entry (i, j), j >= i, is kept at (j, i): column i of the lower triangle, contiguous.
    // Tip to base (S1, S2).
    for i in (0..n).rev() {
        let link = &links[i];
        let axis = &model.axes[i];
        forces[i] = Force::default();
        minv[(i, i)] = link.inverse;
        for j in i + 1..n {
            minv[(j, i)] = -link.inverse * axis.dot(&forces[j]);
        }
        if i > 0 {
            let (x, u) = (placement(link), coupling(link));
            for j in i..n {
                forces[j] = x.act_force(&forces[j].plus(&u.times(minv[(j, i)])));
            }
        }
    }
    // Base to tip (S3).
    motions.fill(Motion::default());
    for (i, link) in links.iter().enumerate().take(n) {
        let axis = &model.axes[i];
        let (x, u) = (placement(link), coupling(link));
        for j in i..n {
            let carried = x.inv_act_motion(&motions[j]);
            let entry = minv[(j, i)] - link.inverse * carried.dot(&u);
            minv[(j, i)] = entry;
            motions[j] = carried.plus(&axis.times(entry));
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            minv[(i, j)] = minv[(j, i)];
        }
    }
}
