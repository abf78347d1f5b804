//! The reusable workspace of the reduced dynamics (the "Data" of the Model/Data split), and the
//! reduced terms it holds after a computation.

use faer::{Mat, MatRef};
use lane_math::try_filled;
use manip_dyn::ChainData;
use pulp::Arch;

use crate::cache_aligned::CacheAligned;
use crate::error::ReduceError;
use crate::model::{LINK_PADDING, ReducedModel};
use lane_math::check_len;

/// Per-link products the pre-pass leaves for the pass besides the sine and cosine, in this order
/// in the buffer: `S_l phi_dot_l^2`, `L_l sin phi_l`, `L_l cos phi_l`,
/// `L_l cos(phi_l) phi_dot_l^2`, `L_l sin(phi_l) phi_dot_l^2`.
pub(crate) const PRODUCTS: usize = 5;

/// An `(x, y)` pair: a column of the `2 x m` prefix sum `P_l`.
pub(crate) type Pair<L> = [L; 2];

/// Workspace for one [`ReducedModel`]: create it once, reuse it for every call.
///
/// After [`reduced_terms`](crate::reduced_terms), [`reduced_terms_by_projection`](crate::reduced_terms_by_projection)
/// or a forward-dynamics call it holds `M*`, `C*` and `G*` at the state passed in, readable with
/// [`mass_matrix`](Self::mass_matrix), [`coriolis`](Self::coriolis) and
/// [`gravity`](Self::gravity). Its memory is `O(n + m^2)`: per-link buffers of the default path
/// and the full chain's recursive workspace
/// ([`ChainData::recursive`](manip_dyn::ChainData::recursive)), a few hundred bytes a link. The
/// projection path ([`reduced_terms_by_projection`](crate::reduced_terms_by_projection)) needs an `n x n` mass matrix and
/// `M J` (`n x m`) besides: its first call allocates them, and it refuses chains of more than
/// [`manip_dyn::MAX_DENSE_LINKS`] links.
#[derive(Debug, Clone)]
pub struct ReducedData {
    pub(crate) n_links: usize,
    pub(crate) n_coords: usize,
    /// `M*`, row-major `m x m`, symmetric.
    pub(crate) mass: Vec<f64>,
    /// `C*`, length `m`.
    pub(crate) coriolis: Vec<f64>,
    /// `G*`, length `m`.
    pub(crate) gravity: Vec<f64>,
    /// Scratch `m x m`: the Cholesky factor of `M*`, or the matrix whose eigenvalues are sought.
    pub(crate) factor: Vec<f64>,
    /// Scratch `m`: the right-hand side `tau* - C* - G*` and the previous iterate of the eq-18
    /// iteration.
    pub(crate) rhs: Vec<f64>,
    pub(crate) iterate: Vec<f64>,
    /// Per-link buffers of the default path.
    pub(crate) links: OneStateLinks,
    /// Scratch of the default path for sizes without a specialised version.
    pub(crate) scratch: TermScratch,
    /// Joint-space state and torque buffers, length `n`.
    pub(crate) theta: Vec<f64>,
    pub(crate) theta_dot: Vec<f64>,
    pub(crate) theta_ddot: Vec<f64>,
    pub(crate) joint_torque: Vec<f64>,
    /// The projection path's matrices, allocated by its first call.
    pub(crate) projection: Option<Projection>,
    /// The full chain's own workspace, recursive algorithms only.
    pub(crate) chain: ChainData,
    /// The processor's instruction set, found at construction: the default path runs with it
    /// (see [`crate::terms`]).
    pub(crate) arch: Arch,
}

/// The matrices of the projection path ([`reduced_terms_by_projection`](crate::reduced_terms_by_projection)).
#[derive(Debug, Clone)]
pub(crate) struct Projection {
    /// The full mass matrix `M` (`n x n`).
    pub(crate) joint_mass: Mat<f64>,
    /// `M J` (`n x m`).
    pub(crate) mass_times_jacobian: Mat<f64>,
}

impl Projection {
    /// Zero matrices for `n` links and `m` coordinates.
    pub(crate) fn new(n: usize, m: usize) -> Self {
        Self {
            joint_mass: Mat::zeros(n, n),
            mass_times_jacobian: Mat::zeros(n, m),
        }
    }
}

/// The per-link buffers of the default path (see [`crate::terms`]): every link's absolute angle,
/// its sine and cosine (read again by [`crate::derivatives`]) and the per-link products, `n`
/// rounded up to a whole number of the widest SIMD registers ([`LINK_PADDING`]) each, so that
/// they are computed in whole registers.
#[derive(Debug, Clone)]
pub(crate) struct OneStateLinks {
    pub(crate) angle: CacheAligned,
    pub(crate) sin: CacheAligned,
    pub(crate) cos: CacheAligned,
    /// `[product][link]`.
    pub(crate) products: CacheAligned,
}

/// Scratch of the default path for sizes without a specialised version (see [`crate::terms`]).
#[derive(Debug, Clone)]
pub(crate) struct TermScratch {
    /// `m x m`, `m`, `m`: `M*` (upper triangle), `C*` and `G*` as the kernel leaves them.
    pub(crate) mass: Vec<f64>,
    pub(crate) coriolis: Vec<f64>,
    pub(crate) gravity: Vec<f64>,
    /// `m`: the columns of the prefix sum `P_l`.
    pub(crate) joint: Vec<Pair<f64>>,
    /// `m`: `v_l`.
    pub(crate) v: Vec<f64>,
}

impl ReducedData {
    /// A workspace sized for `model`.
    ///
    /// # Panics
    /// When the system refuses the memory; [`ReducedData::try_new`] returns the error.
    pub fn new(model: &ReducedModel) -> Self {
        Self::try_new(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`ReducedData::new`], or [`ReduceError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_new(model: &ReducedModel) -> Result<Self, ReduceError> {
        const WHAT: &str = "the workspace of the reduced model";
        let (n, m) = (model.n_links(), model.n_coords());
        let zeros = |len: usize| try_filled(len, 0.0, WHAT);
        let padded = n.next_multiple_of(LINK_PADDING);
        let aligned = |len: usize| CacheAligned::try_zeros(len, WHAT);
        Ok(Self {
            n_links: n,
            n_coords: m,
            mass: zeros(m * m)?,
            coriolis: zeros(m)?,
            gravity: zeros(m)?,
            factor: zeros(m * m)?,
            rhs: zeros(m)?,
            iterate: zeros(m)?,
            links: OneStateLinks {
                angle: aligned(padded)?,
                sin: aligned(padded)?,
                cos: aligned(padded)?,
                products: aligned(PRODUCTS.saturating_mul(padded))?,
            },
            scratch: TermScratch {
                mass: zeros(m * m)?,
                coriolis: zeros(m)?,
                gravity: zeros(m)?,
                joint: try_filled(m, [0.0; 2], WHAT)?,
                v: zeros(m)?,
            },
            theta: zeros(n)?,
            theta_dot: zeros(n)?,
            theta_ddot: zeros(n)?,
            joint_torque: zeros(n)?,
            projection: None,
            chain: ChainData::try_recursive(model.chain())?,
            arch: Arch::new(),
        })
    }

    /// The reduced mass matrix `M* = J^T M J` (`m x m`, eq 14) of the last computation.
    pub fn mass_matrix(&self) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(&self.mass, self.n_coords, self.n_coords)
    }

    /// The reduced Coriolis/centrifugal vector `C* = J^T C` (length `m`, eq 14) of the last
    /// computation.
    pub fn coriolis(&self) -> &[f64] {
        &self.coriolis
    }

    /// The reduced gravity vector `G* = J^T G` (length `m`, eq 14) of the last computation.
    pub fn gravity(&self) -> &[f64] {
        &self.gravity
    }

    /// Checks that this workspace was made for `model`.
    pub(crate) fn check_model(&self, model: &ReducedModel) -> Result<(), ReduceError> {
        check_len("workspace links", self.n_links, model.n_links())?;
        check_len("workspace coordinates", self.n_coords, model.n_coords())?;
        Ok(())
    }
}
