//! The workspace and results of the analytic derivatives ([`rnea_derivatives`] and
//! [`aba_derivatives`]).
//!
//! [`rnea_derivatives`]: crate::rnea_derivatives()
//! [`aba_derivatives`]: crate::aba_derivatives()

use faer::MatRef;
use pulp::Arch;

use crate::model::{ChainModel, MAX_DENSE_LINKS};

/// The row stride of the three Jacobians is a multiple of this many entries (the widest SIMD
/// register's `f64` lanes, AVX-512), so that the many-right-hand-side sweeps of
/// `aba_derivatives` run on whole registers; the padding columns stay zero.
pub(crate) const ROW_ALIGNMENT: usize = 8;

/// Results and scratch of [`rnea_derivatives`](crate::rnea_derivatives()) and
/// [`aba_derivatives`](crate::aba_derivatives()) for one [`ChainModel`]: build it once with
/// [`DerivativeData::new`] (three `n x n` matrices side by side, about `24 n^2` bytes), then every call fills it
/// without allocating. For a chain of more than [`MAX_DENSE_LINKS`] links, which both
/// derivative functions refuse, it holds nothing: its value is empty and its matrices `0 x 0`.
///
/// After a call it holds the value of the differentiated function ([`value`](Self::value)) and
/// its three Jacobians, entry `(i, j) = d out_i / d in_j`:
///
/// | after | [`value`](Self::value) | [`d_q`](Self::d_q) | [`d_v`](Self::d_v) | [`d_input`](Self::d_input) |
/// |---|---|---|---|---|
/// | `rnea_derivatives` | `tau` | `d tau / d q` | `d tau / d v` | `d tau / d qdd = M` |
/// | `aba_derivatives` | `qdd` | `d qdd / d q` | `d qdd / d v` | `d qdd / d tau = M^-1` |
#[derive(Debug, Clone)]
pub struct DerivativeData {
    pub(crate) n: usize,
    /// `tau` or `qdd`.
    pub(crate) value: Vec<f64>,
    /// Row-major `n x stride`: row `i` is `[d_q row i | d_v row i | d_input row i | padding]`,
    /// so that the many-right-hand-side solve of `aba_derivatives` runs along contiguous rows.
    pub(crate) blocks: Vec<f64>,
    /// The row stride of `blocks`: `3n` rounded up to a multiple of [`ROW_ALIGNMENT`].
    pub(crate) stride: usize,
    /// Per-link terms of the derivative formulas (see `rnea_derivatives`).
    pub(crate) links: LinkTerms,
    /// Per-link constants of the many-right-hand-side sweeps (see `aba_derivatives`).
    pub(crate) solve: Vec<SweepLink>,
    /// The instruction set found at construction, for the sweeps.
    pub(crate) arch: Arch,
}

/// What the sweeps of `aba_derivatives` that apply `M^-1` need of joint `i`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SweepLink {
    /// `L_i u_i`, joint `i + 1` relative to joint `i`.
    pub offset: [f64; 2],
    /// The translational part `U_i` of the articulated inertia times the joint axis.
    pub coupling: [f64; 2],
    /// `U_i / D_i`.
    pub gain: [f64; 2],
    /// `1 / D_i`.
    pub inverse: f64,
}

/// Per-link vectors (length `n + 1`, the last entry the empty sum) of the closed forms in
/// [`rnea_derivatives`](crate::rnea_derivatives()): one set for `d/dq` and one for `d/dv`.
#[derive(Debug, Clone)]
pub(crate) struct LinkTerms {
    /// `S_j` and absolute angular acceleration `alpha_j` of each link.
    pub moment: Vec<f64>,
    pub accel: Vec<f64>,
    /// Joint positions `lambda_k = sum_{j<k} L_j u_j` and subtree moments
    /// `sigma_i = sum_{j>=i} S_j u_j`, by component.
    pub lambda: [Vec<f64>; 2],
    pub sigma: [Vec<f64>; 2],
    /// For `d/dq` (index 0) and `d/dv` (index 1): the suffix sums `A`, the prefix sums `B`, the
    /// row constants `K` and the column constants `base`.
    pub suffix: [[Vec<f64>; 2]; 2],
    pub prefix: [[Vec<f64>; 2]; 2],
    pub row_sum: [Vec<f64>; 2],
    pub base: [Vec<f64>; 2],
}

impl DerivativeData {
    /// Allocates the results and scratch for `model`.
    ///
    /// ```
    /// use manip_dyn::{ChainModel, DerivativeData};
    /// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
    /// let derivatives = DerivativeData::new(&arm);
    /// assert_eq!(derivatives.d_q().nrows(), 10);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    pub fn new(model: &ChainModel) -> DerivativeData {
        let n = model.n_links();
        // Beyond the dense limit every derivative call refuses the chain: allocate nothing.
        let sized = if n <= MAX_DENSE_LINKS { n } else { 0 };
        let vector = || vec![0.0; sized + 1];
        let pair = || [vector(), vector()];
        let stride = (3 * sized).next_multiple_of(ROW_ALIGNMENT);
        DerivativeData {
            n,
            value: vec![0.0; sized],
            blocks: vec![0.0; stride * sized],
            stride,
            links: LinkTerms {
                moment: vector(),
                accel: vector(),
                lambda: pair(),
                sigma: pair(),
                suffix: [pair(), pair()],
                prefix: [pair(), pair()],
                row_sum: pair(),
                base: pair(),
            },
            solve: vec![SweepLink::default(); sized],
            arch: Arch::new(),
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

    /// The Jacobian with respect to the joint angles `q` (`n x n`).
    pub fn d_q(&self) -> MatRef<'_, f64> {
        self.block(0)
    }

    /// The Jacobian with respect to the joint rates `v` (`n x n`).
    pub fn d_v(&self) -> MatRef<'_, f64> {
        self.block(1)
    }

    /// The Jacobian with respect to the third input (`n x n`): `M` after `rnea_derivatives`
    /// (input `qdd`), `M^-1` after `aba_derivatives` (input `tau`).
    pub fn d_input(&self) -> MatRef<'_, f64> {
        self.block(2)
    }

    fn block(&self, index: usize) -> MatRef<'_, f64> {
        let n = self.value.len();
        MatRef::from_row_major_slice_with_stride(&self.blocks[index * n..], n, n, self.stride)
    }
}
