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
//! Only the entries `j >= i` are computed (the rows of the subtree below each joint); the other
//! half is the symmetric mirror. The sweeps run in the base frame, where `X_i` is the identity:
//! with `S_i`, `U_i` carried there by link `i`'s pose (the pairings `S . F` and `U . a` are
//! frame-free), `F_{i-1}[:, j] = F_i[:, j] + U_i m_ij` and `a_i[:, j] = a_{i-1}[:, j] +
//! S_i (M^-1)_ij`, so each entry costs two 6-vector dot products and two 6-vector updates,
//! computed along the row `j = i..n` with the columns of `F` and `a` stored by component.

use faer::MatMut;
use pulp::{Arch, Simd, WithSimd};

use super::algebra::{Force, Transform};
use super::data::AbaLink;
use super::derivative_data::Six;
use super::model::SpatialModel;

/// `M^-1` into `minv` (`n x n`) from `links`, the articulated quantities of an
/// [`aba`](super::aba()) at the same `q` (whose pivots it checked), and `poses`, the links'
/// poses in the base frame at that `q`, with `sweep` (6 rows of at least `n`) as scratch.
/// Allocation-free.
pub(crate) fn inverse_mass_matrix(
    arch: Arch,
    model: &SpatialModel,
    links: &[AbaLink<f64>],
    poses: &[Transform],
    sweep: &mut [Vec<f64>; 6],
    minv: MatMut<'_, f64>,
) {
    arch.dispatch(Sweeps {
        model,
        links,
        poses,
        sweep,
        minv,
    });
}

/// The two sweeps under [`Arch::dispatch`] (the loops along a row vectorise with this
/// processor's widest registers).
struct Sweeps<'a> {
    model: &'a SpatialModel,
    links: &'a [AbaLink<f64>],
    poses: &'a [Transform],
    sweep: &'a mut [Vec<f64>; 6],
    minv: MatMut<'a, f64>,
}

/// Joint `i`'s axis `S_i` and `U_i` in the base frame, as plain components.
#[inline(always)]
fn world(model: &SpatialModel, links: &[AbaLink<f64>], poses: &[Transform], i: usize) -> [Six; 2] {
    let pose = &poses[i];
    let s = pose.act_motion(&model.axes[i]);
    let u = pose.act_force(&Force {
        linear: links[i].coupling[0],
        angular: links[i].coupling[1],
    });
    [
        [
            s.linear[0],
            s.linear[1],
            s.linear[2],
            s.angular[0],
            s.angular[1],
            s.angular[2],
        ],
        [
            u.linear[0],
            u.linear[1],
            u.linear[2],
            u.angular[0],
            u.angular[1],
            u.angular[2],
        ],
    ]
}

impl WithSimd for Sweeps<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let Sweeps {
            model,
            links,
            poses,
            sweep,
            mut minv,
        } = self;
        let n = model.n_links();
        let [r0, r1, r2, r3, r4, r5] = sweep;
        let rows = [
            &mut r0[..n],
            &mut r1[..n],
            &mut r2[..n],
            &mut r3[..n],
            &mut r4[..n],
            &mut r5[..n],
        ];
        let [f0, f1, f2, f3, f4, f5] = rows;
        // Entry (i, j), j >= i, is kept at (j, i): column i of the lower triangle, contiguous.
        // Tip to base (S1, S2), F by component in f0..f5.
        for i in (0..n).rev() {
            let [s, u] = world(model, links, poses, i);
            let inverse = links[i].inverse;
            let column = column_of(&mut minv, i);
            column[i] = inverse;
            for j in i + 1..n {
                let dot = s[0] * f0[j]
                    + s[1] * f1[j]
                    + s[2] * f2[j]
                    + s[3] * f3[j]
                    + s[4] * f4[j]
                    + s[5] * f5[j];
                column[j] = -inverse * dot;
            }
            f0[i] = 0.0;
            f1[i] = 0.0;
            f2[i] = 0.0;
            f3[i] = 0.0;
            f4[i] = 0.0;
            f5[i] = 0.0;
            for j in i..n {
                let m = column[j];
                f0[j] += u[0] * m;
                f1[j] += u[1] * m;
                f2[j] += u[2] * m;
                f3[j] += u[3] * m;
                f4[j] += u[4] * m;
                f5[j] += u[5] * m;
            }
        }
        // Base to tip (S3), a by component in the same rows.
        let [a0, a1, a2, a3, a4, a5] = [f0, f1, f2, f3, f4, f5];
        for row in [&mut *a0, &mut *a1, &mut *a2, &mut *a3, &mut *a4, &mut *a5] {
            row.fill(0.0);
        }
        for i in 0..n {
            let [s, u] = world(model, links, poses, i);
            let inverse = links[i].inverse;
            let column = column_of(&mut minv, i);
            for j in i..n {
                let dot = u[0] * a0[j]
                    + u[1] * a1[j]
                    + u[2] * a2[j]
                    + u[3] * a3[j]
                    + u[4] * a4[j]
                    + u[5] * a5[j];
                let entry = column[j] - inverse * dot;
                column[j] = entry;
                a0[j] += s[0] * entry;
                a1[j] += s[1] * entry;
                a2[j] += s[2] * entry;
                a3[j] += s[3] * entry;
                a4[j] += s[4] * entry;
                a5[j] += s[5] * entry;
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                minv[(i, j)] = minv[(j, i)];
            }
        }
    }
}

/// Column `k` of `m` as a slice (a faer `Mat`'s blocks are column-major).
#[inline(always)]
fn column_of<'m>(m: &'m mut MatMut<'_, f64>, k: usize) -> &'m mut [f64] {
    m.as_mut()
        .col_mut(k)
        .try_as_col_major_mut()
        .expect("the blocks of a faer Mat are column-major")
        .as_slice_mut()
}
