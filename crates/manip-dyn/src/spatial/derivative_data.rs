//! The workspace and results of the spatial analytic derivatives
//! ([`rnea_derivatives`](super::rnea_derivatives()) and
//! [`aba_derivatives`](super::aba_derivatives())).

use faer::{Mat, MatMut, MatRef};

use super::algebra::{Force, Mat3, Motion, RigidSum, Vec3};
use super::model::SpatialModel;
use crate::model::MAX_DENSE_LINKS;

/// A spatial 6-vector as plain numbers (linear part first), for the world-frame sums of the
/// derivatives.
pub(crate) type Six = [f64; 6];

/// The per-link component rows of [`SpatialDerivativeData`]: `J` (6), `P` (6), `Q`'s angular
/// part (3).
pub(crate) const ROWS: usize = 15;

/// `n` and room for one register of the widest SIMD instruction set (8 `f64` lanes): a whole
/// register can be read from any row index below `n`.
pub(crate) fn padded(n: usize) -> usize {
    n + MAX_LANES
}

/// The most `f64` lanes of a register (AVX-512).
pub(crate) const MAX_LANES: usize = 8;

/// `out[..rows]` from the first `rows` (at most [`MAX_LANES`]) of `lanes`, the last, partial
/// register of a SIMD loop, stored entry by entry (at these lengths a library copy call costs
/// more than the loop that fills the register).
#[inline(always)]
pub(crate) fn store_first(out: &mut [f64], lanes: &[f64; MAX_LANES], rows: usize) {
    for (r, &value) in lanes.iter().enumerate() {
        if r < rows {
            out[r] = value;
        }
    }
}

/// One joint's articulated-body quantities in the base frame, from the base-frame
/// articulated-body algorithm of [`aba_derivatives`](super::aba_derivatives()): what
/// [`inverse_mass_matrix`](super::minv::inverse_mass_matrix) reads (`S_i`, `U_i`, `1 / D_i`) and
/// what the algorithm's own sweeps pass on (`c_i`, `p_i`, `u_i`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BaseFrameJoint {
    /// The joint axis `S_i`.
    pub(crate) axis: Motion,
    /// The velocity-product acceleration `c_i = v_i x S_i qd_i`.
    pub(crate) bias: Motion,
    /// The link's bias force `p_i = v_i x* I_i v_i`.
    pub(crate) force: Force,
    /// `U_i = IA_i S_i`.
    pub(crate) coupling: Force,
    /// `1 / D_i`, `D_i = S_i . U_i`.
    pub(crate) inverse: f64,
    /// `u_i = tau_i - S_i . pA_i`.
    pub(crate) residual: f64,
}

/// Column `k` of `m` as a slice (a faer `Mat`'s blocks are column-major), for the SIMD loops
/// that fill the derivative matrices a column at a time.
#[inline(always)]
pub(crate) fn column_of<'m>(m: &'m mut MatMut<'_, f64>, k: usize) -> &'m mut [f64] {
    m.as_mut()
        .col_mut(k)
        .try_as_col_major_mut()
        .expect("the blocks of a faer Mat are column-major")
        .as_slice_mut()
}

/// Results and scratch of [`rnea_derivatives`](super::rnea_derivatives()) and
/// [`aba_derivatives`](super::aba_derivatives()) for one [`SpatialModel`]: build it once with
/// [`SpatialDerivativeData::new`] (about `48 n^2` bytes), then every call fills it without
/// allocating. For a chain of more than [`MAX_DENSE_LINKS`] links, which both refuse, it holds
/// nothing.
///
/// After a call it holds the differentiated function's value and its three Jacobians, entry
/// `(i, j) = d out_i / d in_j`:
///
/// | after | [`value`](Self::value) | [`d_q`](Self::d_q) | [`d_v`](Self::d_v) | [`d_input`](Self::d_input) |
/// |---|---|---|---|---|
/// | `rnea_derivatives` | `tau` | `d tau / d q` | `d tau / d v` | `d tau / d qdd = M` |
/// | `aba_derivatives` | `qdd` | `d qdd / d q` | `d qdd / d v` | `d qdd / d tau = M^-1` |
pub struct SpatialDerivativeData {
    pub(crate) n: usize,
    /// `tau` or `qdd`.
    pub(crate) value: Vec<f64>,
    /// The ABA's accelerations while the RNEA derivatives run (`aba_derivatives`).
    pub(crate) accelerations: Vec<f64>,
    /// `n x 3n`: `[d_q | d_v | d_input]`.
    pub(crate) blocks: Mat<f64>,
    /// Per link `i`, in the base frame, by components (`rows[c][i]`, for products down a
    /// column): the joint axis `J_i` (components 0-5), `P_i = Ic_i J_i` (6-11) and the angular
    /// part of `Q_i = Bc_i^T J_i` (12-14; its linear part vanishes) (theory.md, "Spatial
    /// derivatives"). Each row is zero-padded to [`padded`] entries.
    pub(crate) rows: [Vec<f64>; ROWS],
    /// Per link: `w_i`, `beta_i`, and the column constants `G_i`, `H_i`.
    pub(crate) w: Vec<Six>,
    pub(crate) beta: Vec<Six>,
    pub(crate) g: Vec<Six>,
    pub(crate) h: Vec<Six>,
    /// Of links `i..n`, in the base frame: the composite inertia `Ic_i`, and the two blocks of
    /// the composite Coriolis operator `Bc_i = [[0, -2 [Hc_i]x], [0, Dc_i]]`: the linear
    /// momentum `Hc_i` and the 3 x 3 `Dc_i`.
    pub(crate) composite: Vec<RigidSum>,
    pub(crate) momentum: Vec<Vec3>,
    pub(crate) coriolis: Vec<Mat3>,
    /// `[d tau / d q | d tau / d v]` while `aba_derivatives` multiplies it by `-M^-1`.
    pub(crate) rhs: Mat<f64>,
    /// The force, then motion, columns of the `O(n^2)` `M^-1` by component (`aba_derivatives`).
    pub(crate) sweep: [Vec<f64>; 6],
    /// The joints' articulated-body quantities in the base frame (`aba_derivatives`).
    pub(crate) joints: Vec<BaseFrameJoint>,
    /// `M^-1`'s columns, each zero-padded to [`padded`] entries, for its product with the
    /// RNEA derivatives (`aba_derivatives`).
    pub(crate) minv_columns: Vec<f64>,
}

impl SpatialDerivativeData {
    /// Allocates the results and scratch for `model`.
    ///
    /// ```
    /// use manip_dyn::ChainModel;
    /// use manip_dyn::spatial::{SpatialDerivativeData, SpatialModel};
    /// let arm = SpatialModel::from_planar(&ChainModel::uniform(10, 0.1, 0.1, 9.81)?);
    /// assert_eq!(SpatialDerivativeData::new(&arm).d_q().nrows(), 10);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    pub fn new(model: &SpatialModel) -> SpatialDerivativeData {
        Self::sized(model.n_links())
    }

    /// The workspace of a chain of `n` links.
    fn sized(n: usize) -> SpatialDerivativeData {
        let sized = if n <= MAX_DENSE_LINKS { n } else { 0 };
        let six = || vec![[0.0; 6]; sized];
        SpatialDerivativeData {
            n,
            value: vec![0.0; sized],
            accelerations: vec![0.0; sized],
            blocks: Mat::zeros(sized, 3 * sized),
            rows: std::array::from_fn(|_| vec![0.0; padded(sized)]),
            w: six(),
            beta: six(),
            g: six(),
            h: six(),
            composite: vec![RigidSum::default(); sized],
            momentum: vec![[0.0; 3]; sized],
            coriolis: vec![[[0.0; 3]; 3]; sized],
            rhs: Mat::zeros(sized, 2 * sized),
            sweep: std::array::from_fn(|_| vec![0.0; padded(sized)]),
            joints: vec![BaseFrameJoint::default(); sized],
            minv_columns: vec![0.0; sized * padded(sized)],
        }
    }

    /// Number of links of the chain this workspace was built for.
    pub fn n_links(&self) -> usize {
        self.n
    }

    /// The differentiated function's value: `tau` after `rnea_derivatives`, `qdd` after
    /// `aba_derivatives`.
    pub fn value(&self) -> &[f64] {
        &self.value
    }

    /// The Jacobian with respect to the joint values `q` (`n x n`).
    pub fn d_q(&self) -> MatRef<'_, f64> {
        self.block(0)
    }

    /// The Jacobian with respect to the joint rates `v` (`n x n`).
    pub fn d_v(&self) -> MatRef<'_, f64> {
        self.block(1)
    }

    /// The Jacobian with respect to the third input: `M` after `rnea_derivatives`, `M^-1` after
    /// `aba_derivatives`.
    pub fn d_input(&self) -> MatRef<'_, f64> {
        self.block(2)
    }

    fn block(&self, index: usize) -> MatRef<'_, f64> {
        let n = self.value.len();
        self.blocks.as_ref().subcols(index * n, n)
    }
}

impl Clone for SpatialDerivativeData {
    /// A workspace of the same size, with the same results (the scratch is not copied).
    fn clone(&self) -> Self {
        let mut copy = Self::sized(self.n);
        copy.value.copy_from_slice(&self.value);
        copy.blocks.copy_from(&self.blocks);
        copy
    }
}

impl std::fmt::Debug for SpatialDerivativeData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpatialDerivativeData")
            .field("n_links", &self.n)
            .finish_non_exhaustive()
    }
}
