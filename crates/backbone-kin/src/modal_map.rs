//! The constant modal Jacobian: joint angles from backbone-curve coordinates (eqs 7-11).
//!
//! Each link takes the inclination of the backbone curve at its midpoint,
//! `phi_i = alpha(s_i)` with `s_i` the arc length at the middle of link `i`, and the joint angles
//! are the differences `theta_1 = phi_1`, `theta_i = phi_i - phi_{i-1}` (eq 7). Since `alpha` is
//! linear in the modal coordinates, `theta = J a + theta_0` with a constant `J` (eqs 8-11).
//!
//! For `K` harmonics the inclination is
//! `alpha(s) = alpha0 + sum_k a_{2k-1} sin(2 pi k s / l) + a_{2k} (1 - cos(2 pi k s / l))`,
//! the integral of the curvature `sum_k (2 pi k / l) (a_{2k-1} cos(2 pi k s / l) + a_{2k} sin(2 pi k s / l))`;
//! `K = 1` is the paper's eq 2 (with its sign error corrected). Coordinates are ordered
//! `(a_1, ..., a_{2K}, alpha0)`, or `(a_1, ..., a_{2K})` when `alpha0` is held fixed, in which case
//! the map is affine with offset `theta_0 = alpha0 e_1`.

use crate::error::KinError;
use crate::validate::{check_count, check_link_lengths};
use lane_math::{check_finite, check_len, check_values};

/// The most links any crate of the workspace accepts: `manip_dyn::MAX_LINKS` is this constant,
/// re-exported. Everything a chain or a reduced model holds grows as `O(n)` (a [`ModalMap`]'s `J`
/// as `O(n m)`, bounded by [`MAX_MAP_ENTRIES`]), so this limit only keeps a request for
/// `usize::MAX` links from reaching an allocation. The full chain's `n x n` algorithms (the mass
/// matrix, Cholesky forward dynamics, the analytic derivatives) have their own, lower limit,
/// `manip_dyn::MAX_DENSE_LINKS`.
pub const MAX_LINKS: usize = 1_000_000;

/// The most harmonics a [`ModalMap`] or a [`HarmonicIk`](crate::HarmonicIk) may have. A map needs
/// at least `2K` links to resolve `K` harmonics; `2048` harmonics suit the 4096 links of the
/// dense algorithms' limit, and a map's size is bounded by [`MAX_MAP_ENTRIES`] as well.
pub const MAX_HARMONICS: usize = 2048;

/// The most entries (links times modal coordinates) of a [`ModalMap`]'s `J`: `2^25`, 256 MiB,
/// enough for 4096 links with every harmonic up to [`MAX_HARMONICS`], or 10^6 links with up to 16
/// harmonics.
pub const MAX_MAP_ENTRIES: usize = 1 << 25;

/// At least one harmonic and at most [`MAX_HARMONICS`].
pub(crate) fn check_harmonics(harmonics: usize) -> Result<(), KinError> {
    if harmonics == 0 {
        return Err(KinError::NoHarmonics);
    }
    check_count("harmonics", harmonics, MAX_HARMONICS)
}

/// Whether the base inclination `alpha0` is a modal coordinate or a fixed parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BaseAngle {
    /// `alpha0` is the last modal coordinate (the paper's three-coordinate form `(a1, a2, alpha0)`).
    Free,
    /// `alpha0` is held at this value (radians) and is not a coordinate (the paper's experiment).
    Fixed(f64),
}

/// `sin(2 pi k s / l)` and `1 - cos(2 pi k s / l)`: the contributions of the coordinates
/// `a_{2k-1}` and `a_{2k}` to the inclination `alpha(s)` (eq 2 generalised to harmonic `k`).
///
/// `length` must be positive and finite (a mathematical primitive: like `f64::sin` it returns NaN
/// outside its domain; [`ModalMap`] calls it only on validated lengths).
///
/// Both come from one `sin_cos` of the half angle: `sin(x) = 2 sin(x/2) cos(x/2)` and
/// `1 - cos(x) = 2 sin^2(x / 2)`, which keeps full relative accuracy near `s = 0`.
pub fn harmonic_basis(k: usize, s: f64, length: f64) -> (f64, f64) {
    let x = std::f64::consts::TAU * k as f64 * s / length;
    let (sin_half, cos_half) = (0.5 * x).sin_cos();
    (2.0 * sin_half * cos_half, 2.0 * sin_half * sin_half)
}

/// The affine map `theta = J a + theta_0` from modal coordinates to joint angles (eqs 8-9).
///
/// `J` is stored row-major (`n` joints by `m` coordinates) and is constant, so joint rates and
/// accelerations are `J a_dot` and `J a_ddot` (eqs 10-11).
#[derive(Debug, Clone, PartialEq)]
pub struct ModalMap {
    n_joints: usize,
    n_coords: usize,
    harmonics: usize,
    base: BaseAngle,
    link_lengths: Vec<f64>,
    jacobian: Vec<f64>,
    offset: Vec<f64>,
}

impl ModalMap {
    /// The paper's map for `n_links` equal links and coordinates `(a1, a2, alpha0)`: eq 9, with
    /// the minus sign of the second column restored.
    ///
    /// ```
    /// use backbone_kin::ModalMap;
    /// let map = ModalMap::paper(10)?;
    /// assert_eq!((map.n_joints(), map.n_coords()), (10, 3));
    /// assert!((map.entry(0, 0) - (std::f64::consts::PI / 10.0).sin()).abs() < 1e-15);
    /// # Ok::<(), backbone_kin::KinError>(())
    /// ```
    pub fn paper(n_links: usize) -> Result<Self, KinError> {
        Self::uniform(n_links, 1, BaseAngle::Free)
    }

    /// The paper's map with `alpha0` held fixed: coordinates `(a1, a2)`, offset `alpha0 e_1`.
    pub fn paper_fixed_alpha0(n_links: usize, alpha0: f64) -> Result<Self, KinError> {
        Self::uniform(n_links, 1, BaseAngle::Fixed(alpha0))
    }

    /// A `harmonics`-mode map for `n_links` links of equal length.
    pub fn uniform(n_links: usize, harmonics: usize, base: BaseAngle) -> Result<Self, KinError> {
        if n_links == 0 {
            return Err(KinError::NoLinks);
        }
        check_count("links", n_links, MAX_LINKS)?;
        Self::new(&vec![1.0; n_links], harmonics, base)
    }

    /// A `harmonics`-mode map for links of the given lengths; link `i` takes the curve's
    /// inclination at the arc length of its midpoint, `s_i = L_1 + ... + L_{i-1} + L_i / 2`,
    /// on a curve of length `l = L_1 + ... + L_n`.
    pub fn new(link_lengths: &[f64], harmonics: usize, base: BaseAngle) -> Result<Self, KinError> {
        let length = check_link_lengths(link_lengths)?;
        check_count("links", link_lengths.len(), MAX_LINKS)?;
        check_harmonics(harmonics)?;
        if let BaseAngle::Fixed(alpha0) = base {
            check_finite("alpha0", alpha0)?;
        }
        let n = link_lengths.len();
        let n_modal = 2 * harmonics;
        let m = n_modal + usize::from(base == BaseAngle::Free);
        check_count(
            "modal Jacobian entries (links x coordinates)",
            n.saturating_mul(m),
            MAX_MAP_ENTRIES,
        )?;
        // Rows of the inclination map phi = Phi a (+ alpha0), then theta_i = phi_i - phi_{i-1}.
        let mut jacobian = lane_math::try_filled(n * m, 0.0, "the modal map's Jacobian")?;
        let mut previous = vec![0.0; m];
        let mut start = 0.0;
        for (i, &len) in link_lengths.iter().enumerate() {
            let s = start + 0.5 * len;
            start += len;
            let row = &mut jacobian[i * m..(i + 1) * m];
            for k in 1..=harmonics {
                let (sin_term, one_minus_cos) = harmonic_basis(k, s, length);
                row[2 * k - 2] = sin_term;
                row[2 * k - 1] = one_minus_cos;
            }
            if m > n_modal {
                row[n_modal] = 1.0;
            }
            for (entry, prev) in row.iter_mut().zip(previous.iter_mut()) {
                let phi = *entry;
                *entry = phi - *prev;
                *prev = phi;
            }
        }
        let mut offset = lane_math::try_filled(n, 0.0, "the modal map's joint offsets")?;
        if let BaseAngle::Fixed(alpha0) = base {
            offset[0] = alpha0;
        }
        Ok(Self {
            n_joints: n,
            n_coords: m,
            harmonics,
            base,
            link_lengths: lane_math::try_copied(link_lengths, "the modal map's link lengths")?,
            jacobian,
            offset,
        })
    }

    /// A copy of the map, or [`KinError::OutOfMemory`] when the system refuses the memory
    /// (`clone` aborts then).
    pub fn try_clone(&self) -> Result<Self, KinError> {
        const WHAT: &str = "a copy of the modal map";
        Ok(Self {
            link_lengths: lane_math::try_copied(&self.link_lengths, WHAT)?,
            jacobian: lane_math::try_copied(&self.jacobian, WHAT)?,
            offset: lane_math::try_copied(&self.offset, WHAT)?,
            ..*self
        })
    }

    /// Number of joints `n` (rows of `J`).
    pub fn n_joints(&self) -> usize {
        self.n_joints
    }

    /// Number of modal coordinates `m` (columns of `J`).
    pub fn n_coords(&self) -> usize {
        self.n_coords
    }

    /// Number of harmonics `K` of the modal family.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// Whether `alpha0` is a coordinate or held fixed.
    pub fn base_angle(&self) -> BaseAngle {
        self.base
    }

    /// The link lengths the map was built from, base first (all 1 for [`uniform`](Self::uniform)
    /// and [`paper`](Self::paper)). Only their ratios `L_i / l` enter `J`, so a chain matches the
    /// map when its links are proportional to these.
    pub fn link_lengths(&self) -> &[f64] {
        &self.link_lengths
    }

    /// `J`, row-major, `n_joints * n_coords` entries.
    pub fn jacobian(&self) -> &[f64] {
        &self.jacobian
    }

    /// Row `i` of `J` (joint `i`, 0-based).
    ///
    /// # Panics
    /// If `i >= n_joints()`, like slice indexing.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.jacobian[i * self.n_coords..(i + 1) * self.n_coords]
    }

    /// `J(i, j)`, 0-based.
    ///
    /// # Panics
    /// If `i >= n_joints()` or `j >= n_coords()`, like slice indexing.
    pub fn entry(&self, i: usize, j: usize) -> f64 {
        self.row(i)[j]
    }

    /// The constant offset `theta_0` (zero unless `alpha0` is fixed).
    pub fn offset(&self) -> &[f64] {
        &self.offset
    }

    /// Joint angles `theta = J a + theta_0` (eq 8). Allocation-free.
    pub fn joint_angles(&self, a: &[f64], theta: &mut [f64]) -> Result<(), KinError> {
        self.apply(a, theta, true)
    }

    /// Joint rates `theta_dot = J a_dot` (eq 10); the same map gives accelerations (eq 11).
    pub fn joint_rates(&self, a_dot: &[f64], theta_dot: &mut [f64]) -> Result<(), KinError> {
        self.apply(a_dot, theta_dot, false)
    }

    fn apply(&self, a: &[f64], out: &mut [f64], with_offset: bool) -> Result<(), KinError> {
        check_values("modal coordinates", a, self.n_coords)?;
        check_len("joint output", out.len(), self.n_joints)?;
        match self.n_coords {
            2 => self.apply_sized::<2>(a, out, with_offset),
            3 => self.apply_sized::<3>(a, out, with_offset),
            _ => self.apply_sized::<0>(a, out, with_offset),
        }
        Ok(())
    }

    /// [`apply`](Self::apply) after its checks, for `M` coordinates known at compile time (the
    /// shipped families' 2 and 3: each row's sum unrolled, the same operations in the same
    /// order), or any number when `M` is 0.
    #[inline(always)]
    fn apply_sized<const M: usize>(&self, a: &[f64], out: &mut [f64], with_offset: bool) {
        let m = if M == 0 { self.n_coords } else { M };
        let a = &a[..m];
        for (i, (o, &offset)) in out.iter_mut().zip(&self.offset).enumerate() {
            let row = &self.jacobian[i * m..(i + 1) * m];
            let dot: f64 = row.iter().zip(a).map(|(j, x)| j * x).sum();
            *o = if with_offset { dot + offset } else { dot };
        }
    }
}
