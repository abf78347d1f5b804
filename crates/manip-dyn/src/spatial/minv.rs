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
//! with `S_i`, `U_i` in the base frame (from the base-frame articulated-body algorithm of
//! [`aba_derivatives`](super::aba_derivatives())), `F_{i-1}[:, j] = F_i[:, j] + U_i m_ij` and `a_i[:, j] = a_{i-1}[:, j] +
//! S_i (M^-1)_ij`, so each entry costs two 6-vector dot products and two 6-vector updates,
//! computed along the row `j = i..n`, a SIMD register of entries at a time, with the columns of
//! `F` and `a` stored by component.

use pulp::{Arch, Simd, WithSimd};

use super::derivative_data::{BaseFrameJoint, Six, padded};
use lane_math::{Lane, Pack};

/// `M^-1` into `columns` (its `n` columns one after another, each zero-padded to
/// [`padded`]`(n)` entries, the layout of the product that follows it) from `joints`, the
/// base-frame articulated quantities `S_i`, `U_i` and `1 / D_i` of an articulated-body
/// algorithm at the same `q` (whose pivots it checked), with `sweep` (6 rows of
/// [`padded`]`(n)`) as scratch. The padding of `columns` must be zero, and stays zero.
/// Allocation-free.
pub(crate) fn inverse_mass_matrix(
    arch: Arch,
    joints: &[BaseFrameJoint],
    sweep: &mut [Vec<f64>; 6],
    columns: &mut [f64],
) {
    arch.dispatch(Sweeps {
        joints,
        sweep,
        columns,
    });
}

/// The two sweeps under [`Arch::dispatch`] (the loops along a row vectorise with this
/// processor's widest registers).
struct Sweeps<'a> {
    joints: &'a [BaseFrameJoint],
    sweep: &'a mut [Vec<f64>; 6],
    columns: &'a mut [f64],
}

/// Joint `i`'s axis `S_i` and `U_i` in the base frame, as plain components.
#[inline(always)]
fn world(joint: &BaseFrameJoint) -> [Six; 2] {
    let (s, u) = (&joint.axis, &joint.coupling);
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
    fn with_simd<S: Simd>(self, simd: S) {
        let Sweeps {
            joints,
            sweep,
            columns,
        } = self;
        let n = joints.len();
        let width = Pack::<S>::WIDTH;
        let stride = padded(n);
        // F (then a) by component. All start at zero and stay zero past `n`, as do the columns'
        // paddings, so whole registers can be read anywhere.
        for row in sweep.iter_mut() {
            row[..stride].fill(0.0);
        }
        let [r0, r1, r2, r3, r4, r5] = sweep;
        let mut f = [
            &mut r0[..stride],
            &mut r1[..stride],
            &mut r2[..stride],
            &mut r3[..stride],
            &mut r4[..stride],
            &mut r5[..stride],
        ];
        // Entry (i, j), j >= i, is computed at (j, i): column i of the lower triangle.
        // Tip to base (S1, S2): the m_ij.
        for i in (0..n).rev() {
            let [s, u] = registers(simd, world(&joints[i]));
            let inverse = Pack::splat(simd, -joints[i].inverse);
            let column = &mut columns[i * stride..(i + 1) * stride];
            let mut j = i;
            while j < n {
                let mut dot = Pack::load(simd, &f[0][j..]) * s[0];
                for c in 1..6 {
                    dot = Pack::load(simd, &f[c][j..]).mul_add(s[c], dot);
                }
                (inverse * dot).store(&mut column[j..]);
                j += width;
            }
            column[i] = joints[i].inverse;
            let mut j = i;
            while j < n {
                let m = Pack::load(simd, &column[j..]);
                for c in 0..6 {
                    let updated = m.mul_add(u[c], Pack::load(simd, &f[c][j..]));
                    updated.store(&mut f[c][j..]);
                }
                j += width;
            }
        }
        // Base to tip (S3), a by component in the same rows: the m_ij become (M^-1)_ij.
        for row in f.iter_mut() {
            row.fill(0.0);
        }
        for i in 0..n {
            let [s, u] = registers(simd, world(&joints[i]));
            let inverse = Pack::splat(simd, joints[i].inverse);
            let column = &mut columns[i * stride..(i + 1) * stride];
            let mut j = i;
            while j < n {
                let mut dot = Pack::load(simd, &f[0][j..]) * u[0];
                for c in 1..6 {
                    dot = Pack::load(simd, &f[c][j..]).mul_add(u[c], dot);
                }
                let entry = inverse.neg_mul_add(dot, Pack::load(simd, &column[j..]));
                entry.store(&mut column[j..]);
                for c in 0..6 {
                    let updated = entry.mul_add(s[c], Pack::load(simd, &f[c][j..]));
                    updated.store(&mut f[c][j..]);
                }
                j += width;
            }
        }
        // The upper triangle by symmetry.
        for i in 0..n {
            for j in i + 1..n {
                columns[j * stride + i] = columns[i * stride + j];
            }
        }
    }
}

/// `S_i` and `U_i` of [`world`] in every lane.
#[inline(always)]
fn registers<S: Simd>(simd: S, vectors: [Six; 2]) -> [[Pack<S>; 6]; 2] {
    let mut out = [[Pack::splat(simd, 0.0); 6]; 2];
    for (lanes, vector) in out.iter_mut().zip(vectors) {
        for (lane, value) in lanes.iter_mut().zip(vector) {
            *lane = Pack::splat(simd, value);
        }
    }
    out
}
