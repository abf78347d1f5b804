//! The spatial modal family: joint angles of a universal-joint chain from two planar harmonic
//! families, one per bending plane (`docs/theory.md`, "Spatial modal arms").
//!
//! The arm has `n` links along their frames' `x` axes, each joined to the previous one (the
//! first to the base) by a universal joint: a revolute joint about the parent frame's `z` axis
//! (in-plane bending, the planar joint) followed by one about the resulting `y` axis
//! (out-of-plane bending). Joint angles are interleaved per link,
//! `theta = [z_1, y_1, z_2, y_2, ...]` (`2n` entries).
//!
//! The modal coordinates are two `K`-harmonic families, `a = [a_z (2K), a_y (2K)]` (`m = 4K`),
//! `alpha_z(s) = sum_k a_z,2k-1 sin(2 pi k s / l) + a_z,2k (1 - cos(2 pi k s / l))` and `alpha_y`
//! alike, with no `alpha0` term (the base pose holds the base angles). Each plane's joint angles
//! follow eq 7: `z_1 = alpha_z(s_1)`, `z_i = alpha_z(s_i) - alpha_z(s_{i-1})`, `s_i` the link
//! midpoints, and the same for `y`. So `theta = J a` with a constant `2n x 4K` map whose rows are
//! those of the planar map ([`ModalMap`] with `alpha0` fixed at 0) placed on the `a_z` columns for
//! the `z` joints and on the `a_y` columns for the `y` joints.

use crate::error::KinError;
use crate::modal_map::{BaseAngle, MAX_MAP_ENTRIES, ModalMap};
use crate::spatial_chain::BasePose;
use crate::spatial_curve::{SPATIAL_CURVE_TOLERANCE, SpatialCurve};
use crate::validate::check_count;
use lane_math::{check_len, check_values};

/// The constant map `theta = J a` of a universal-joint chain (module docs): `2n` joint angles
/// from `4K` modal coordinates.
///
/// ```
/// use backbone_kin::SpatialModalMap;
/// let map = SpatialModalMap::uniform(10, 1)?;
/// assert_eq!((map.n_joints(), map.n_coords()), (20, 4));
/// // a_z = (0.3, 0), a_y = (0, 0): only the z joints bend, as the planar map says.
/// let mut theta = [0.0; 20];
/// map.joint_angles(&[0.3, 0.0, 0.0, 0.0], &mut theta)?;
/// assert!((theta[0] - 0.3 * (std::f64::consts::PI / 10.0).sin()).abs() < 1e-15 && theta[1] == 0.0);
/// # Ok::<(), backbone_kin::KinError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialModalMap {
    planar: ModalMap,
    jacobian: Vec<f64>,
}

impl SpatialModalMap {
    /// The map of `n_links` equal links with `harmonics` harmonics per plane.
    pub fn uniform(n_links: usize, harmonics: usize) -> Result<Self, KinError> {
        Self::from_planar(ModalMap::uniform(
            n_links,
            harmonics,
            BaseAngle::Fixed(0.0),
        )?)
    }

    /// The map of links of the given lengths (base first), each link's angles taken at its
    /// midpoint `s_i` as in [`ModalMap::new`].
    pub fn new(link_lengths: &[f64], harmonics: usize) -> Result<Self, KinError> {
        Self::from_planar(ModalMap::new(
            link_lengths,
            harmonics,
            BaseAngle::Fixed(0.0),
        )?)
    }

    fn from_planar(planar: ModalMap) -> Result<Self, KinError> {
        let (n, k2) = (planar.n_joints(), planar.n_coords());
        let (rows, cols) = (2 * n, 2 * k2);
        check_count(
            "modal Jacobian entries (links x coordinates)",
            rows.saturating_mul(cols),
            MAX_MAP_ENTRIES,
        )?;
        let mut jacobian = lane_math::try_filled(rows * cols, 0.0, "the spatial modal Jacobian")?;
        for (i, pair) in jacobian.chunks_exact_mut(2 * cols).enumerate() {
            let (z_row, y_row) = pair.split_at_mut(cols);
            z_row[..k2].copy_from_slice(planar.row(i));
            y_row[k2..].copy_from_slice(planar.row(i));
        }
        Ok(Self { planar, jacobian })
    }

    /// A copy of the map, or [`KinError::OutOfMemory`] when the system refuses the memory
    /// (`clone` aborts then).
    ///
    /// ```
    /// let map = backbone_kin::SpatialModalMap::uniform(12, 2)?;
    /// assert_eq!(map.try_clone()?, map);
    /// # Ok::<(), backbone_kin::KinError>(())
    /// ```
    pub fn try_clone(&self) -> Result<Self, KinError> {
        Ok(Self {
            planar: self.planar.try_clone()?,
            jacobian: lane_math::try_copied(&self.jacobian, "a copy of the spatial modal map")?,
        })
    }

    /// Number of links `n`.
    pub fn n_links(&self) -> usize {
        self.planar.n_joints()
    }

    /// Number of joints `2n` (rows of `J`).
    pub fn n_joints(&self) -> usize {
        2 * self.planar.n_joints()
    }

    /// Number of modal coordinates `m = 4K` (columns of `J`).
    pub fn n_coords(&self) -> usize {
        2 * self.planar.n_coords()
    }

    /// Number of harmonics `K` per plane.
    pub fn harmonics(&self) -> usize {
        self.planar.harmonics()
    }

    /// The link lengths the map was built from, base first.
    pub fn link_lengths(&self) -> &[f64] {
        self.planar.link_lengths()
    }

    /// The tip (m) of the backbone curve of `a` leaving `base`, as long as the links together,
    /// integrated to [`SPATIAL_CURVE_TOLERANCE`] of that length ([`SpatialCurve::tip`]).
    ///
    /// # Errors
    /// As [`SpatialCurve::new`] and [`SpatialCurve::tip`]: [`KinError::TooOscillatory`] for a
    /// curve that turns too fast for the quadrature.
    pub fn curve_tip(&self, a: &[f64], base: BasePose) -> Result<[f64; 3], KinError> {
        let length: f64 = self.link_lengths().iter().sum();
        let curve = SpatialCurve::new(length, self.harmonics(), a, base)?;
        Ok(curve.tip(SPATIAL_CURVE_TOLERANCE * length)?.position)
    }

    /// The planar map (`alpha0` fixed at 0) both planes share.
    pub fn planar(&self) -> &ModalMap {
        &self.planar
    }

    /// `J`, row-major, `n_joints * n_coords` entries.
    pub fn jacobian(&self) -> &[f64] {
        &self.jacobian
    }

    /// Row `i` of `J` (joint `i`, 0-based: `z_{i/2+1}` for even `i`, `y_{i/2+1}` for odd).
    ///
    /// # Panics
    /// If `i >= n_joints()`, like slice indexing.
    pub fn row(&self, i: usize) -> &[f64] {
        let m = self.n_coords();
        &self.jacobian[i * m..(i + 1) * m]
    }

    /// Joint angles `theta = J a` (`2n` entries from `4K`). Allocation-free.
    pub fn joint_angles(&self, a: &[f64], theta: &mut [f64]) -> Result<(), KinError> {
        check_values("modal coordinates", a, self.n_coords())?;
        check_len("joint output", theta.len(), self.n_joints())?;
        let k2 = self.planar.n_coords();
        let (a_z, a_y) = a.split_at(k2);
        let dot = |row: &[f64], x: &[f64]| row.iter().zip(x).map(|(j, v)| j * v).sum::<f64>();
        for (i, pair) in theta.chunks_exact_mut(2).enumerate() {
            let row = self.planar.row(i);
            pair[0] = dot(row, a_z);
            pair[1] = dot(row, a_y);
        }
        Ok(())
    }

    /// Joint rates `theta_dot = J a_dot`; the same map gives accelerations.
    pub fn joint_rates(&self, a_dot: &[f64], theta_dot: &mut [f64]) -> Result<(), KinError> {
        self.joint_angles(a_dot, theta_dot)
    }
}
