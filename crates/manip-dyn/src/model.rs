//! The immutable description of a planar serial chain (the "Model" of the Model/Data split).

use crate::error::DynError;

/// One rigid link of a planar chain: joint at its proximal end, revolute about `z`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// Length from this link's joint to the next joint (m), positive.
    pub length: f64,
    /// Mass (kg), at least [`MIN_LINK_SCALE`], as is `mass * length` (kg m).
    pub mass: f64,
    /// Distance of the centre of mass from the link's joint, along the link (m).
    pub com: f64,
    /// Moment of inertia about the centre of mass, about `z` (kg m^2), non-negative: zero is a
    /// point mass, allowed as long as the link's inertia about its own joint, `inertia + mass *
    /// com^2`, is positive (a point mass must sit off the joint axis, or the joint would drive
    /// nothing and the mass matrix would be singular).
    pub inertia: f64,
}

impl Link {
    /// A uniform beam: centre of mass at the midpoint, inertia `m L^2 / 12` (the paper's links).
    /// A length or mass whose inertia under- or overflows (`length = 1e-300`) is refused by
    /// that name, not as the inertia it derives.
    pub fn uniform_beam(length: f64, mass: f64) -> Result<Self, DynError> {
        let inertia = mass * length * length / 12.0;
        let squared = length * length;
        if length > 0.0 && mass > 0.0 && !(inertia.is_finite() && inertia > 0.0) {
            let (quantity, value) = if squared.is_finite() && squared > 0.0 {
                ("mass", mass)
            } else {
                ("length", length)
            };
            return Err(DynError::InvalidLinkParameter {
                quantity,
                requirement: "such that the beam's inertia mass * length^2 / 12 is positive and \
                              finite in double precision",
                value,
            });
        }
        Self::new(length, mass, 0.5 * length, inertia)
    }

    /// A link with explicit centre-of-mass offset and inertia; validated as in [`ChainModel::new`],
    /// but a lone link has no index, so a failure is [`DynError::InvalidLinkParameter`] (see
    /// [`DynError::at_link`]).
    pub fn new(length: f64, mass: f64, com: f64, inertia: f64) -> Result<Self, DynError> {
        let link = Self {
            length,
            mass,
            com,
            inertia,
        };
        link.validate()?;
        Ok(link)
    }

    /// Checks the parameters; a failure is [`DynError::InvalidLinkParameter`], without an index.
    fn validate(&self) -> Result<(), DynError> {
        let invalid = |quantity, requirement, value| {
            Err(DynError::InvalidLinkParameter {
                quantity,
                requirement,
                value,
            })
        };
        for (quantity, value) in [("length", self.length), ("mass", self.mass)] {
            if !(value.is_finite() && value > 0.0) {
                return invalid(quantity, "positive and finite", value);
            }
        }
        // The articulated-body algorithm forms products of two masses and of two first moments
        // (`mass * length` sets their scale): below this scale they fall out of the normal
        // numbers and its results lose every digit.
        if self.mass < MIN_LINK_SCALE {
            return invalid("mass", MIN_SCALE_REQUIREMENT, self.mass);
        }
        if self.mass * self.length < MIN_LINK_SCALE {
            return invalid(
                "mass * length",
                MIN_SCALE_REQUIREMENT,
                self.mass * self.length,
            );
        }
        if !(self.inertia.is_finite() && self.inertia >= 0.0) {
            return invalid("inertia", "non-negative and finite", self.inertia);
        }
        if !self.com.is_finite() {
            return invalid("centre of mass", "finite", self.com);
        }
        let about_joint = self.inertia + self.mass * self.com * self.com;
        if about_joint <= 0.0 {
            return invalid(
                "inertia about the joint (inertia + mass * com^2)",
                "positive (a point mass must sit off the joint)",
                about_joint,
            );
        }
        Ok(())
    }
}

/// The smallest mass (kg) and first moment `mass * length` (kg m) of a link: `1e-150`, whose
/// square is still a normal double. The dynamics' algorithms multiply two of either (the
/// articulated-body inertias' updates), which below this scale lose their digits to underflow.
pub const MIN_LINK_SCALE: f64 = 1e-150;

/// What a link's mass and first moment must be.
const MIN_SCALE_REQUIREMENT: &str = "at least 1e-150 (MIN_LINK_SCALE: the dynamics multiply \
                                     two of them, whose product must stay a normal number)";

/// The most links a chain may have: the workspace's one limit, `backbone_kin::MAX_LINKS`
/// (10^6). A chain, a [`ChainData`](crate::ChainData) and the `O(n)` algorithms (RNEA, ABA, the
/// bias terms, the energies) need `O(n)` memory; a larger `n` is refused with
/// [`DynError::TooManyLinks`] rather than risk aborting the process on a failed allocation.
pub use backbone_kin::MAX_LINKS;

/// The most links of the `n x n` algorithms: [`mass_matrix`](crate::mass_matrix()),
/// [`coriolis_matrix`](crate::coriolis_matrix()), the Cholesky
/// [`forward_dynamics`](crate::forward_dynamics()), [`rnea_derivatives`](crate::rnea_derivatives())
/// and [`aba_derivatives`](crate::aba_derivatives()). Their matrices take `8 n^2` bytes each
/// (128 MiB at this limit, a [`DerivativeData`](crate::DerivativeData) three times that) and their
/// time grows as `n^2` or `n^3`; beyond it they refuse the chain with
/// [`DynError::TooManyLinks`], and [`ChainData::new`](crate::ChainData::new) and
/// [`DerivativeData::new`](crate::DerivativeData::new) allocate none of their `n x n` memory.
pub const MAX_DENSE_LINKS: usize = 4096;

/// A planar serial chain of revolute joints under gravity along `-y`.
///
/// Joint `i` sits at the proximal end of link `i`; `theta_i` is the angle of link `i` relative to
/// link `i - 1` (`theta_1` from the `x` axis), so link `i`'s absolute angle is
/// `phi_i = theta_1 + ... + theta_i`.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainModel {
    links: Vec<Link>,
    gravity: f64,
}

impl ChainModel {
    /// A chain of the given links, with gravitational acceleration `gravity` (m/s^2) along `-y`.
    pub fn new(links: Vec<Link>, gravity: f64) -> Result<Self, DynError> {
        check_link_count(links.len())?;
        for (index, link) in links.iter().enumerate() {
            link.validate().map_err(|e| e.at_link(index))?;
        }
        if !gravity.is_finite() {
            return Err(DynError::InvalidGravity(gravity));
        }
        // Every entry of M is at most the total mass times the total length squared (plus the
        // links' own inertias), every gravity torque the total mass times g times the length.
        let total_mass: f64 = links.iter().map(|l| l.mass).sum();
        let total_length: f64 = links.iter().map(|l| l.length).sum();
        let bounds = [
            total_mass,
            total_mass * total_length * total_length,
            total_mass * gravity.abs() * total_length,
        ];
        if !bounds.iter().all(|b| b.is_finite()) {
            return Err(DynError::ChainOverflows {
                total_mass,
                total_length,
                gravity: gravity.abs(),
            });
        }
        Ok(Self { links, gravity })
    }

    /// `n` identical uniform beams: the paper's arm is `uniform(10, 0.1, 0.1, 9.81)`.
    ///
    /// ```
    /// let arm = manip_dyn::ChainModel::uniform(10, 0.1, 0.1, 9.81)?;
    /// assert_eq!(arm.n_links(), 10);
    /// assert!((arm.total_length() - 1.0).abs() < 1e-15);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    pub fn uniform(n: usize, length: f64, mass: f64, gravity: f64) -> Result<Self, DynError> {
        check_link_count(n)?;
        let beam = Link::uniform_beam(length, mass)?;
        Self::new(
            lane_math::try_filled(n, beam, "the chain's links")?,
            gravity,
        )
    }

    /// Number of links (and joints) `n`.
    pub fn n_links(&self) -> usize {
        self.links.len()
    }

    /// The links, base first.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// Gravitational acceleration along `-y` (m/s^2).
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    /// Sum of the link lengths (m).
    pub fn total_length(&self) -> f64 {
        self.links.iter().map(|l| l.length).sum()
    }

    /// The link lengths, base first.
    pub fn link_lengths(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.links.iter().map(|l| l.length)
    }
}

/// At least one link and at most [`MAX_LINKS`].
fn check_link_count(n: usize) -> Result<(), DynError> {
    match n {
        0 => Err(DynError::NoLinks),
        n if n > MAX_LINKS => Err(DynError::TooManyLinks {
            what: "a chain",
            got: n,
            max: MAX_LINKS,
        }),
        _ => Ok(()),
    }
}
