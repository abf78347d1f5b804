//! The immutable description of a spatial serial chain (the "Model" of the Model/Data split).

use super::algebra::{IDENTITY, Mat3, Motion, RigidInertia, Symmetric6, Transform, Vec3, dot};
use super::eigen::symmetric_eigen;
use crate::error::DynError;
use crate::model::{ChainModel, MAX_LINKS};

/// How a joint moves its child link relative to its joint frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation by `q` (rad) about the axis.
    Revolute,
    /// Translation by `q` (m) along the axis.
    Prismatic,
}

/// The largest magnitude of a prismatic joint's position `q` (m) the algorithms take: the bound of
/// a URDF's numbers (`robot_desc::MAX_MAGNITUDE`), far beyond any robot, so that the products
/// of a few positions and inertias stay within double precision (at `1e160` the derivatives'
/// intermediate terms overflowed where `rnea` still answered).
pub const MAX_PRISMATIC_POSITION: f64 = 1e9;

/// One joint: link `i`'s frame is its parent's frame moved by `origin`, then by the joint's
/// motion `q` about or along `axis` (both in the joint frame). At `q = 0` link `i`'s frame is the
/// joint frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialJoint {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// The unit axis in the joint frame (normalised by [`SpatialModel::new`], which refuses a
    /// norm off 1 by more than 1e-6).
    pub axis: Vec3,
    /// The joint frame in the parent link's frame (for the first joint, in the base frame).
    pub origin: Transform,
}

impl SpatialJoint {
    /// A revolute joint about `axis` at `origin`.
    pub fn revolute(axis: Vec3, origin: Transform) -> SpatialJoint {
        SpatialJoint {
            kind: JointKind::Revolute,
            axis,
            origin,
        }
    }

    /// A prismatic joint along `axis` at `origin`.
    pub fn prismatic(axis: Vec3, origin: Transform) -> SpatialJoint {
        SpatialJoint {
            kind: JointKind::Prismatic,
            axis,
            origin,
        }
    }

    /// The joint's motion subspace `S` in its child link's frame: `(0, axis)` for a revolute
    /// joint, `(axis, 0)` for a prismatic one (constant, since the motion leaves the axis fixed).
    pub fn motion_axis(&self) -> Motion {
        match self.kind {
            JointKind::Revolute => Motion {
                linear: [0.0; 3],
                angular: self.axis,
            },
            JointKind::Prismatic => Motion {
                linear: self.axis,
                angular: [0.0; 3],
            },
        }
    }
}

/// One rigid link: its mass, centre of mass and rotational inertia about the centre of mass, in
/// the link's frame (the frame its joint moves).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialLink {
    /// Mass (kg), non-negative and finite. A massless link (the cross of a universal joint
    /// written as two revolute joints) is valid; the algorithms that solve for accelerations
    /// refuse, naming it, a joint whose articulated inertia vanishes
    /// ([`DynError::SingularJoint`]), such as one moving only a massless tip link.
    pub mass: f64,
    /// Centre of mass in the link frame (m), finite.
    pub com: Vec3,
    /// Rotational inertia about the centre of mass in the link frame's axes (kg m^2): finite,
    /// symmetric, its principal moments non-negative and each at most the sum of the other two
    /// (the triangle inequalities every physical body satisfies).
    pub inertia: Mat3,
}

impl SpatialLink {
    /// A solid cuboid of the given mass and edge lengths (m) along the link's `x`, `y`, `z`,
    /// centred at `com`.
    pub fn cuboid(mass: f64, size: Vec3, com: Vec3) -> SpatialLink {
        let [x, y, z] = size.map(|s| s * s * mass / 12.0);
        SpatialLink {
            mass,
            com,
            inertia: [[y + z, 0.0, 0.0], [0.0, x + z, 0.0], [0.0, 0.0, x + y]],
        }
    }

    /// The checks of [`SpatialModel::new`], naming link `index`.
    fn validate(&self, index: usize) -> Result<(), DynError> {
        let invalid = |quantity, requirement, value| {
            Err(DynError::InvalidLink {
                index,
                quantity,
                requirement,
                value,
            })
        };
        if !(self.mass.is_finite() && self.mass >= 0.0) {
            return invalid("mass", "non-negative and finite", self.mass);
        }
        if let Some(&x) = self.com.iter().find(|x| !x.is_finite()) {
            return invalid("centre of mass", "finite", x);
        }
        if let Some(&x) = self.inertia.iter().flatten().find(|x| !x.is_finite()) {
            return invalid("inertia", "finite", x);
        }
        let i = &self.inertia;
        let scale = i.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let tolerance = 1e-9 * scale;
        for (r, c) in [(0, 1), (0, 2), (1, 2)] {
            let asymmetry = i[r][c] - i[c][r];
            if asymmetry.abs() > tolerance {
                return invalid(
                    "inertia (entry minus its transpose)",
                    "zero (the inertia symmetric)",
                    asymmetry,
                );
            }
        }
        // Sorted principal moments `a <= b <= c` satisfy the triangle inequalities (and so are
        // non-negative: `c <= a + b` and `a < 0` would give `c < b`) iff `a + b - c >= 0`.
        let [a, b, c] = symmetric_eigen(&self.rigid().inertia).values;
        let excess = 0.5 * (a + b - c);
        // Written so that a NaN (an inertia overflowing near f64::MAX) is refused too.
        if excess.is_nan() || excess < -tolerance {
            return invalid(
                "inertia (half the excess of the smallest principal-moment sum I_j + I_k - I_i)",
                "non-negative (the triangle inequalities of the principal moments)",
                excess,
            );
        }
        Ok(())
    }

    /// The link's rigid-body inertia (symmetrised).
    fn rigid(&self) -> RigidInertia {
        let i = &self.inertia;
        RigidInertia {
            mass: self.mass,
            com: self.com,
            inertia: [0, 1, 2].map(|r| [0, 1, 2].map(|c| 0.5 * (i[r][c] + i[c][r]))),
        }
    }
}

/// A spatial serial chain with a fixed base: joint `i` joins link `i - 1` (the base for `i = 0`)
/// to link `i`, under a uniform gravity field.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialModel {
    joints: Vec<SpatialJoint>,
    links: Vec<SpatialLink>,
    gravity: Vec3,
    /// Each link's rigid-body inertia, its 6 x 6 matrix, and each joint's motion subspace.
    pub(crate) inertias: Vec<RigidInertia>,
    pub(crate) matrices: Vec<Symmetric6>,
    pub(crate) axes: Vec<Motion>,
    /// Per joint, an upper bound of the diagonal entry of `M` over the configurations with the
    /// prismatic joints at zero: the scale of the rounding of its articulated-inertia pivot.
    pub(crate) pivot_scales: Vec<f64>,
    /// Per link, whether its inertia is exactly zero (the cross of a universal joint): such a
    /// link adds nothing to a composite inertia, momentum or force.
    pub(crate) massless: Vec<bool>,
}

impl SpatialModel {
    /// A chain of `joints` and `links` (as many of each, at least one, at most [`MAX_LINKS`]),
    /// under the gravitational acceleration `gravity` (m/s^2, base frame; ROS's convention is
    /// `[0, 0, -9.81]`). Each joint axis is normalised.
    ///
    /// ```
    /// use manip_dyn::spatial::{SpatialJoint, SpatialLink, SpatialModel, Transform};
    /// let link = SpatialLink::cuboid(0.1, [0.1, 0.01, 0.01], [0.05, 0.0, 0.0]);
    /// let yaw = SpatialJoint::revolute([0.0, 0.0, 1.0], Transform::IDENTITY);
    /// let pitch = SpatialJoint::revolute([0.0, 1.0, 0.0], Transform::translation([0.1, 0.0, 0.0]));
    /// let arm = SpatialModel::new(vec![yaw, pitch], vec![link; 2], [0.0, 0.0, -9.81])?;
    /// assert_eq!(arm.n_links(), 2);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    ///
    /// # Errors
    /// [`DynError::NoLinks`], [`DynError::TooManyLinks`], [`DynError::Dimension`] if the counts
    /// differ, [`DynError::InvalidJoint`] for a non-finite or non-unit axis or an origin that is
    /// not a finite rigid transform, [`DynError::InvalidLink`] for a link breaking the rules of
    /// [`SpatialLink`], [`DynError::InvalidGravity`] for a non-finite gravity component.
    pub fn new(
        joints: Vec<SpatialJoint>,
        links: Vec<SpatialLink>,
        gravity: Vec3,
    ) -> Result<SpatialModel, DynError> {
        match joints.len() {
            0 => return Err(DynError::NoLinks),
            n if n > MAX_LINKS => {
                return Err(DynError::TooManyLinks {
                    what: "a chain",
                    got: n,
                    max: MAX_LINKS,
                });
            }
            _ => {}
        }
        if links.len() != joints.len() {
            return Err(DynError::Dimension {
                name: "links (one per joint)",
                expected: joints.len(),
                found: links.len(),
            });
        }
        let mut joints = joints;
        for (index, joint) in joints.iter_mut().enumerate() {
            joint.axis = validate_joint(joint, index)?;
        }
        for (index, link) in links.iter().enumerate() {
            link.validate(index)?;
        }
        if let Some(&g) = gravity.iter().find(|g| !g.is_finite()) {
            return Err(DynError::InvalidGravity(g));
        }
        Ok(Self::assemble(joints, links, gravity))
    }

    /// The planar chain `chain` as a spatial chain: revolute joints about `z`, link `i`'s joint
    /// at `(L_{i-1}, 0, 0)` in link `i - 1`'s frame, its centre of mass at `(c_i, 0, 0)`, its
    /// inertia `diag(I_i, I_i, I_i)` (only `I_zz` acts in the plane), gravity along `-y`. Every
    /// algorithm gives what the planar one does.
    ///
    /// ```
    /// use manip_dyn::ChainModel;
    /// use manip_dyn::spatial::SpatialModel;
    /// let spatial = SpatialModel::from_planar(&ChainModel::uniform(10, 0.1, 0.1, 9.81)?);
    /// assert_eq!(spatial.gravity(), [0.0, -9.81, 0.0]);
    /// # Ok::<(), manip_dyn::DynError>(())
    /// ```
    pub fn from_planar(chain: &ChainModel) -> SpatialModel {
        let mut reach = 0.0;
        let mut joints = Vec::with_capacity(chain.n_links());
        let mut links = Vec::with_capacity(chain.n_links());
        for link in chain.links() {
            joints.push(SpatialJoint::revolute(
                [0.0, 0.0, 1.0],
                Transform::translation([reach, 0.0, 0.0]),
            ));
            reach = link.length;
            let i = link.inertia;
            links.push(SpatialLink {
                mass: link.mass,
                com: [link.com, 0.0, 0.0],
                inertia: [[i, 0.0, 0.0], [0.0, i, 0.0], [0.0, 0.0, i]],
            });
        }
        Self::assemble(joints, links, [0.0, -chain.gravity(), 0.0])
    }

    /// The model of validated joints and links, with its derived per-link constants.
    fn assemble(joints: Vec<SpatialJoint>, links: Vec<SpatialLink>, gravity: Vec3) -> Self {
        let inertias: Vec<RigidInertia> = links.iter().map(SpatialLink::rigid).collect();
        SpatialModel {
            matrices: inertias.iter().map(RigidInertia::matrix).collect(),
            axes: joints.iter().map(SpatialJoint::motion_axis).collect(),
            pivot_scales: pivot_scales(&joints, &inertias),
            massless: inertias
                .iter()
                .map(|body| body.matrix() == Symmetric6::default())
                .collect(),
            inertias,
            joints,
            links,
            gravity,
        }
    }

    /// Number of links (and joints) `n`.
    pub fn n_links(&self) -> usize {
        self.joints.len()
    }

    /// The joints, base first (axes normalised).
    pub fn joints(&self) -> &[SpatialJoint] {
        &self.joints
    }

    /// The links, base first.
    pub fn links(&self) -> &[SpatialLink] {
        &self.links
    }

    /// The gravitational acceleration in the base frame (m/s^2).
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }
}

/// Per joint `i`, the bound of `M_ii` of [`SpatialModel::pivot_scales`]: the subtree's mass
/// `mu_i` for a prismatic joint; for a revolute one `sum_{j >= i} tr(I_j) + mu_i rho_i^2`, with
/// `rho_i`, the sum of the joint offsets beyond `i` plus the largest centre-of-mass offset, bounding
/// every centre of mass's distance from the axis. `O(n)`, from the tip.
fn pivot_scales(joints: &[SpatialJoint], inertias: &[RigidInertia]) -> Vec<f64> {
    let mut scales = vec![0.0; joints.len()];
    let (mut mass, mut traces, mut offsets, mut com) = (0.0, 0.0, 0.0, 0.0f64);
    for i in (0..joints.len()).rev() {
        let inertia = &inertias[i];
        mass += inertia.mass;
        traces += inertia.inertia[0][0] + inertia.inertia[1][1] + inertia.inertia[2][2];
        com = com.max(dot(inertia.com, inertia.com).sqrt());
        let reach = offsets + com;
        scales[i] = match joints[i].kind {
            JointKind::Revolute => traces + mass * reach * reach,
            JointKind::Prismatic => mass,
        };
        let t = joints[i].origin.translation;
        offsets += dot(t, t).sqrt();
    }
    scales
}

/// The checks of a joint: a finite unit axis (returned normalised) and a finite rigid origin.
fn validate_joint(joint: &SpatialJoint, index: usize) -> Result<Vec3, DynError> {
    let invalid = |quantity, requirement, value| {
        Err(DynError::InvalidJoint {
            index,
            quantity,
            requirement,
            value,
        })
    };
    if let Some(&x) = joint.axis.iter().find(|x| !x.is_finite()) {
        return invalid("axis", "finite", x);
    }
    let norm = dot(joint.axis, joint.axis).sqrt();
    if (norm - 1.0).abs() > 1e-6 {
        return invalid("axis (its norm)", "1 (a unit vector)", norm);
    }
    let origin = &joint.origin;
    if let Some(&x) = origin
        .rotation
        .iter()
        .flatten()
        .chain(&origin.translation)
        .find(|x| !x.is_finite())
    {
        return invalid("origin", "finite", x);
    }
    // R^T R = E to 1e-9, and det R = +1 (not a reflection).
    let r = &origin.rotation;
    let mut error = 0.0f64;
    for a in 0..3 {
        for b in 0..3 {
            let column_dot = (0..3).map(|k| r[k][a] * r[k][b]).sum::<f64>();
            error = error.max((column_dot - IDENTITY[a][b]).abs());
        }
    }
    if error > 1e-9 {
        return invalid(
            "origin rotation (largest entry of R^T R - E)",
            "at most 1e-9 (a rotation matrix)",
            error,
        );
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if det < 0.0 {
        return invalid(
            "origin rotation (its determinant)",
            "+1 (a rotation, not a reflection)",
            det,
        );
    }
    Ok(joint.axis.map(|x| x / norm))
}
