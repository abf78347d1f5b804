//! The spatial modal arm: its links, base pose, gravity and modal map (the "Model").

use backbone_kin::{BasePose, Rotation, SpatialModalMap};
use manip_dyn::DynError;

use crate::error::ReduceError;
use crate::model::{LINK_PADDING, check_column_rank};

/// A link's mass and principal moments of inertia about its centre of mass, in the link frame
/// (`x` along the link), the centre of mass at the link's midpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialLinkInertia {
    /// Mass (kg), positive and finite.
    pub mass: f64,
    /// `[Ixx, Iyy, Izz]` (kg m^2): non-negative, finite, and each at most the sum of the other two
    /// (the triangle inequalities of a rigid body's principal moments).
    pub principal: [f64; 3],
}

impl SpatialLinkInertia {
    /// A slender uniform rod of length `length` along `x`: `Ixx = 0`, `Iyy = Izz = m L^2 / 12`
    /// (the paper's planar links seen in 3-D).
    pub fn rod(mass: f64, length: f64) -> Self {
        let bending = mass * length * length / 12.0;
        Self {
            mass,
            principal: [0.0, bending, bending],
        }
    }

    fn validate(&self, index: usize) -> Result<(), ReduceError> {
        let invalid = |quantity, requirement, value| {
            ReduceError::Dyn(DynError::InvalidLink {
                index,
                quantity,
                requirement,
                value,
            })
        };
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(invalid("mass", "positive and finite", self.mass));
        }
        let [a, b, c] = self.principal;
        for value in [a, b, c] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(invalid(
                    "principal inertia",
                    "non-negative and finite",
                    value,
                ));
            }
        }
        for (value, others) in [(a, b + c), (b, a + c), (c, a + b)] {
            if value > others * (1.0 + 4.0 * f64::EPSILON) {
                return Err(invalid(
                    "principal inertia",
                    "at most the sum of the other two (triangle inequality)",
                    value,
                ));
            }
        }
        Ok(())
    }
}

/// A spatial modal arm (module docs of [`spatial`](crate::spatial)): immutable once built.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialReducedModel {
    map: SpatialModalMap,
    base: BasePose,
    /// `base.rotation()`, formed once.
    base_rotation: Rotation,
    links: Vec<SpatialLinkInertia>,
    gravity: [f64; 3],
    /// The rows of the map `J`, two a link (`[P_i, 0]` for its joint about `z`, `[0, P_i]` for
    /// its joint about `y`, `P_i` row `i` of the planar map), `m` values each, followed by
    /// [`LINK_PADDING`] zeros so that a whole register loads from the start of any row.
    joint_rows: Vec<f64>,
    /// The planar map transposed, `2K` rows of [`padded_links`](Self::padded_links) values: column
    /// `k` of `P`, the weight of `a_k` in every link's angle, then zeros, so that the angles of all
    /// links are formed a whole register of links at a time.
    angle_columns: Vec<f64>,
    /// Each link's `[Izz - Iyy, Ixx - Izz, Iyy - Ixx]`, the factors of its gyroscopic torque
    /// `w x I_b w` ([`spin_moments`](Self::spin_moments)).
    spin_moments: Vec<[f64; 3]>,
}

impl SpatialReducedModel {
    /// The arm of `map`'s links with these inertias (one per link), leaving `base`, under
    /// `gravity` (m/s^2, world frame).
    ///
    /// Errors: a number of inertias other than the map's links, a map of dependent columns
    /// ([`ReduceError::RankDeficient`]: fewer than `2K` links), an invalid inertia (naming the link),
    /// a non-finite base pose or gravity.
    pub fn new(
        map: SpatialModalMap,
        base: BasePose,
        links: Vec<SpatialLinkInertia>,
        gravity: [f64; 3],
    ) -> Result<Self, ReduceError> {
        if links.len() != map.n_links() {
            return Err(ReduceError::Dimension {
                name: "link inertias",
                expected: map.n_links(),
                found: links.len(),
            });
        }
        for (index, link) in links.iter().enumerate() {
            link.validate(index)?;
        }
        // J is two copies of the planar map, one per plane: full column rank with it.
        check_column_rank(map.planar())?;
        base.validate()?;
        lane_math::check_all_finite("gravity", &gravity)?;
        let (n, m) = (map.n_links(), map.n_coords());
        let half = m / 2;
        let zeros = |len: usize, what| lane_math::try_filled(len, 0.0, what);
        let mut joint_rows = zeros(2 * n * m + LINK_PADDING, "the reduced model's joint rows")?;
        let padded = n.next_multiple_of(LINK_PADDING);
        let mut angle_columns = zeros(half * padded, "the reduced model's angle columns")?;
        for (i, rows) in joint_rows.chunks_exact_mut(2 * m).take(n).enumerate() {
            let row = &map.planar().row(i)[..half];
            rows[..half].copy_from_slice(row);
            rows[m + half..].copy_from_slice(row);
            for (k, &value) in row.iter().enumerate() {
                angle_columns[k * padded + i] = value;
            }
        }
        let mut spin_moments = lane_math::try_with_capacity(n, "the reduced model's spin moments")?;
        spin_moments.extend(links.iter().map(|link| {
            let [xx, yy, zz] = link.principal;
            [zz - yy, xx - zz, yy - xx]
        }));
        Ok(Self {
            spin_moments,
            map,
            base_rotation: base.rotation(),
            base,
            links,
            gravity,
            joint_rows,
            angle_columns,
        })
    }

    /// `n` equal rods of `length` and `mass` ([`SpatialLinkInertia::rod`]) with `harmonics`
    /// harmonics per plane, from the identity base pose, under `gravity`.
    pub fn uniform_rods(
        n: usize,
        harmonics: usize,
        length: f64,
        mass: f64,
        gravity: [f64; 3],
    ) -> Result<Self, ReduceError> {
        if n > backbone_kin::MAX_LINKS {
            return Err(backbone_kin::KinError::TooMany {
                what: "links",
                got: n,
                max: backbone_kin::MAX_LINKS,
            }
            .into());
        }
        let map = SpatialModalMap::new(&vec![length; n], harmonics)?;
        let links = vec![SpatialLinkInertia::rod(mass, length); map.n_links()];
        Self::new(map, BasePose::default(), links, gravity)
    }

    /// The modal map `theta = J a`.
    pub fn map(&self) -> &SpatialModalMap {
        &self.map
    }

    /// The base pose.
    pub fn base(&self) -> &BasePose {
        &self.base
    }

    /// The base's rotation (of [`base`](Self::base)'s roll, pitch and yaw).
    pub fn base_rotation(&self) -> Rotation {
        self.base_rotation
    }

    /// The links' inertias, base first.
    pub fn links(&self) -> &[SpatialLinkInertia] {
        &self.links
    }

    /// Gravity in the world frame (m/s^2).
    pub fn gravity(&self) -> [f64; 3] {
        self.gravity
    }

    /// Number of links `n` (`2n` joints).
    pub fn n_links(&self) -> usize {
        self.links.len()
    }

    /// Number of modal coordinates `m = 4K`.
    pub fn n_coords(&self) -> usize {
        self.map.n_coords()
    }

    /// Link `i`'s two rows of `J` (`[P_i, 0]`, then `[0, P_i]`), continued by at least
    /// [`LINK_PADDING`] values.
    pub(crate) fn joint_rows(&self, i: usize) -> &[f64] {
        &self.joint_rows[2 * i * self.n_coords()..]
    }

    /// Each link's `[Izz - Iyy, Ixx - Izz, Iyy - Ixx]`: its gyroscopic torque in its own frame is
    /// `w x I_b w = [(Izz - Iyy) w_y w_z, (Ixx - Izz) w_z w_x, (Iyy - Ixx) w_x w_y]`.
    pub(crate) fn spin_moments(&self) -> &[[f64; 3]] {
        &self.spin_moments
    }

    /// The number of links rounded up to a multiple of [`LINK_PADDING`].
    pub(crate) fn padded_links(&self) -> usize {
        self.n_links().next_multiple_of(LINK_PADDING)
    }

    /// Column `k` of the planar map ([`padded_links`](Self::padded_links) values: `P_ik` for
    /// every link `i`, then zeros).
    pub(crate) fn angle_column(&self, k: usize) -> &[f64] {
        let padded = self.padded_links();
        &self.angle_columns[k * padded..(k + 1) * padded]
    }
}
