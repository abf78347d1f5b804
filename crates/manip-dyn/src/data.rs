//! The reusable workspace of every algorithm (the "Data" of Pinocchio's Model/Data split).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt;
use faer::reborrow::ReborrowMut;
use faer::{Mat, Par};
use lane_math::{OutOfMemory, try_filled};
use pulp::Arch;

use crate::error::DynError;
use crate::model::{ChainModel, MAX_DENSE_LINKS};

/// Scratch space for one [`ChainModel`]: build it once with [`ChainData::new`], then pass it to
/// every algorithm. After construction, no algorithm of this crate allocates (on another thread
/// than the one that built it, faer may allocate its matrix-multiply buffer once, in the first
/// [`forward_dynamics`](crate::forward_dynamics()) of a chain of 100 links or more).
///
/// Its memory is `O(n)` (a few hundred bytes a link) plus, for the Cholesky
/// [`forward_dynamics`](crate::forward_dynamics()), an `n x n` factor (`8 n^2` bytes): `new`
/// allocates the factor for chains of up to [`MAX_DENSE_LINKS`] links (beyond, that algorithm
/// refuses the chain), [`recursive`](Self::recursive) leaves it out until the first call that
/// needs it.
///
/// Its contents between calls are unspecified; it holds no state that outlives a call.
pub struct ChainData {
    /// Direction and angular velocity of each link.
    pub(crate) frames: Vec<LinkFrame>,
    /// Absolute angle of each link, then its sine and cosine (the ABA's vectorised trigonometry).
    pub(crate) angle: Vec<f64>,
    pub(crate) sin: Vec<f64>,
    pub(crate) cos: Vec<f64>,
    /// Link accelerations of the Newton-Euler recursion.
    pub(crate) accelerations: Vec<LinkAcceleration>,
    /// Composite bodies `i..n` of the composite-rigid-body algorithm.
    pub(crate) subtrees: Vec<Subtree>,
    /// Velocity moments of the composite bodies (Coriolis matrix).
    pub(crate) subtree_motions: Vec<SubtreeMotion>,
    /// Articulated-body quantities of each joint.
    pub(crate) articulated: Vec<ArticulatedLink>,
    /// One row of the mass matrix during its assembly.
    pub(crate) mass_row: Vec<f64>,
    /// The Cholesky forward dynamics' `n x n` matrix and scratch, once allocated.
    pub(crate) factorisation: Option<Factorisation>,
    /// The instruction set found at construction, for one state's sines and cosines in the ABA
    /// (compiled for it, see `aba.rs`).
    pub(crate) arch: Arch,
}

/// The `n x n` part of a [`ChainData`], used by the Cholesky forward dynamics only.
pub(crate) struct Factorisation {
    /// `n x n`: the mass matrix, then its Cholesky factor (lower triangle).
    pub(crate) mass_factor: Mat<f64>,
    /// Scratch memory of the in-place Cholesky factorisation and solve.
    pub(crate) stack: MemBuffer,
}

impl ChainData {
    /// Allocates the workspace for `model`, with the `n x n` factor of the Cholesky
    /// [`forward_dynamics`](crate::forward_dynamics()) if the chain has at most
    /// [`MAX_DENSE_LINKS`] links.
    ///
    /// ```
    /// use manip_dyn::{ChainData, ChainModel};
    /// let arm = ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
    /// let data = ChainData::new(&arm);
    /// assert_eq!(data.n_links(), 10);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    pub fn new(model: &ChainModel) -> ChainData {
        let mut data = Self::with_links(model.n_links()).unwrap_or_else(|e| panic!("{e}"));
        if data.n_links() <= MAX_DENSE_LINKS {
            data.allocate_factorisation();
        }
        data
    }

    /// Allocates the `O(n)` workspace of the recursive algorithms only (RNEA, ABA, the bias
    /// terms, the energies, and the mass and Coriolis matrices into the caller's matrix): the
    /// first call of the Cholesky [`forward_dynamics`](crate::forward_dynamics()) allocates its
    /// `n x n` factor. What a workspace that never needs that factor (such as a reduced model's)
    /// is built with.
    ///
    /// ```
    /// use manip_dyn::{ChainData, ChainModel, gravity};
    /// let arm = ChainModel::uniform(100_000, 1e-5, 1e-5, 9.81)?;
    /// let mut data = ChainData::recursive(&arm);
    /// let (q, mut g) = (vec![0.0; 100_000], vec![0.0; 100_000]);
    /// gravity(&arm, &mut data, &q, &mut g)?;
    /// // Held out straight, the base carries the whole arm's weight at half its length.
    /// assert!((g[0] - 9.81 * 1.0 * 0.5).abs() < 1e-9);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    ///
    /// # Panics
    /// When the system refuses the memory; [`ChainData::try_recursive`] returns the error.
    pub fn recursive(model: &ChainModel) -> ChainData {
        Self::try_recursive(model).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`ChainData::recursive`], or [`DynError::OutOfMemory`] when the system refuses the
    /// memory.
    pub fn try_recursive(model: &ChainModel) -> Result<ChainData, DynError> {
        Ok(Self::with_links(model.n_links())?)
    }

    /// Number of links of the chain this workspace was built for.
    pub fn n_links(&self) -> usize {
        self.frames.len()
    }

    fn with_links(n: usize) -> Result<ChainData, OutOfMemory> {
        const WHAT: &str = "the workspace of the recursive algorithms";
        Ok(ChainData {
            frames: try_filled(n, LinkFrame::default(), WHAT)?,
            angle: try_filled(n, 0.0, WHAT)?,
            sin: try_filled(n, 0.0, WHAT)?,
            cos: try_filled(n, 0.0, WHAT)?,
            accelerations: try_filled(n, LinkAcceleration::default(), WHAT)?,
            subtrees: try_filled(n, Subtree::default(), WHAT)?,
            subtree_motions: try_filled(n, SubtreeMotion::default(), WHAT)?,
            articulated: try_filled(n, ArticulatedLink::default(), WHAT)?,
            mass_row: try_filled(n, 0.0, WHAT)?,
            factorisation: None,
            arch: Arch::new(),
        })
    }

    /// Allocates (and warms up) the `n x n` part.
    fn allocate_factorisation(&mut self) {
        self.factorisation = Some(Factorisation::new(self.n_links()));
    }
}

impl Factorisation {
    /// The factor and scratch for a chain of `n` links (at most [`MAX_DENSE_LINKS`], checked by
    /// the caller), warmed up.
    pub(crate) fn new(n: usize) -> Self {
        let stack = StackReq::or(
            llt::factor::cholesky_in_place_scratch::<f64>(n, Par::Seq, Default::default()),
            llt::solve::solve_in_place_scratch::<f64>(n, 1, Par::Seq),
        );
        let mut factorisation = Self {
            mass_factor: Mat::zeros(n, n),
            stack: MemBuffer::new(stack),
        };
        factorisation.warm_up(n);
        factorisation
    }

    /// faer's blocked Cholesky (from about 100 x 100) multiplies with a kernel that allocates a
    /// packing buffer per thread on first use. Factoring an identity of up to `WARM_UP` rows here
    /// takes that one-time allocation out of the first call of
    /// [`forward_dynamics`](crate::forward_dynamics()) on this thread, for about 0.5 ms.
    fn warm_up(&mut self, n: usize) {
        const WARM_UP: usize = 256;
        let size = n.min(WARM_UP);
        let mut block = self.mass_factor.as_mut().submatrix_mut(0, 0, size, size);
        block.rb_mut().fill(0.0);
        block.rb_mut().diagonal_mut().fill(1.0);
        let factored = llt::factor::cholesky_in_place(
            block,
            Default::default(),
            Par::Seq,
            MemStack::new(&mut self.stack),
            Default::default(),
        );
        debug_assert!(factored.is_ok(), "the identity is positive definite");
    }
}

impl Clone for ChainData {
    /// A fresh workspace of the same size, with the `n x n` factor if this one has it (the
    /// contents are scratch, so nothing else is copied).
    fn clone(&self) -> Self {
        let mut data = Self::with_links(self.n_links()).unwrap_or_else(|e| panic!("{e}"));
        if self.factorisation.is_some() {
            data.allocate_factorisation();
        }
        data
    }
}

impl std::fmt::Debug for ChainData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ChainData")
            .field("n_links", &self.n_links())
            .finish_non_exhaustive()
    }
}

/// What the forward sweep (and `aba_derivatives`) needs of joint `i`, for one state (`T = f64`)
/// or the lanes of a batch.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ArticulatedLink<T = f64> {
    /// The translational part of `U_i = IA_i S` (its rotational part is `D_i`).
    pub(crate) u_lin: [T; 2],
    /// `D_i = S^T IA_i S`: the articulated inertia about the joint axis.
    pub(crate) d: T,
    /// `tau_i - S^T pA_i`: the joint torque left after the articulated bias force.
    pub(crate) residual: T,
}

/// Links `i..n` welded into one rigid body, described about joint `i`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Subtree {
    /// Total mass.
    pub mass: f64,
    /// First moment of mass about joint `i`: `sum_b m_b (r_b - p_i)`.
    pub first_moment: [f64; 2],
    /// Polar moment of inertia about joint `i`: `sum_b I_b + m_b |r_b - p_i|^2`.
    pub second_moment: f64,
}

/// Velocity moments of the composite body of links `i..n`, about joint `i`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct SubtreeMotion {
    /// Momentum relative to joint `i`: `sum_b m_b (r_b_dot - p_i_dot)`.
    pub(crate) momentum: [f64; 2],
    /// `sum_b m_b (r_b - p_i) . (r_b_dot - p_i_dot)`: the diagonal entry `c_ii`.
    pub(crate) diagonal: f64,
}

/// Accelerations of one link, from the forward sweep of the recursion.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LinkAcceleration {
    /// Absolute angular acceleration `alpha_i = a_1 + ... + a_i`.
    pub(crate) alpha: f64,
    /// Acceleration of the centre of mass, plus `g` along `+y` (gravity enters as an upward
    /// acceleration of the base).
    pub(crate) com: [f64; 2],
}

/// Where link `i` points and how fast it turns, in the base frame: `T = f64` for one state, or
/// the lanes of several states side by side (the ABA batch, see `crate::aba::AbaLane`); filled by
/// `crate::kinematics::update_frames`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LinkFrame<T = f64> {
    /// Unit vector `u_i = (cos phi_i, sin phi_i)` from joint `i` to joint `i + 1`, where
    /// `phi_i = theta_1 + ... + theta_i` is the absolute angle.
    pub axis: [T; 2],
    /// Absolute angular velocity `omega_i = theta_dot_1 + ... + theta_dot_i` (0 without `v`).
    pub omega: T,
}

impl LinkFrame {
    /// `e_z x u_i = (-sin phi_i, cos phi_i)`: the direction a point of the link moves when the
    /// link turns about one of its points behind it.
    pub fn normal(&self) -> [f64; 2] {
        [-self.axis[1], self.axis[0]]
    }
}
