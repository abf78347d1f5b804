//! The description of a serial chain as read from URDF: bodies with inertia and geometry,
//! joints with origins, axes and limits, fixed links already merged.

use crate::error::DescError;
use crate::pose::{Mat3, Pose, mat_mul, mat_vec, transpose};
use manip_dyn::spatial::{SymmetricEigen, symmetric_eigen};

/// Relative tolerance of the inertia checks of [`read_urdf`](crate::read_urdf) and the MJCF
/// export, against the tensor's trace: rounding of the principal moments is about `1e-16` of
/// it, CAD exports printed to 9 digits about `1e-9`.
pub const INERTIA_TOLERANCE: f64 = 1e-9;

/// A link's mass properties, as URDF's `<inertial>`: mass, centre-of-mass frame and the inertia
/// tensor about the centre of mass in that frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inertial {
    /// The centre-of-mass frame in the link frame (`<origin>`).
    pub origin: Pose,
    /// Mass (kg), non-negative.
    pub mass: f64,
    /// `[ixx, ixy, ixz, iyy, iyz, izz]` (kg m^2) about the centre of mass, in the `origin` frame.
    pub inertia: [f64; 6],
}

impl Inertial {
    /// No mass, no inertia (a link without `<inertial>`).
    pub fn is_massless(&self) -> bool {
        self.mass == 0.0 && self.inertia.iter().all(|&v| v == 0.0)
    }

    /// The inertia tensor about the centre of mass as a matrix in the `origin` frame.
    pub fn tensor(&self) -> Mat3 {
        let [xx, xy, xz, yy, yz, zz] = self.inertia;
        [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    }

    /// The centre of mass in the link frame and the inertia about it rotated into the link
    /// frame: `R I R^T`.
    pub fn in_link_frame(&self) -> ([f64; 3], Mat3) {
        let r = self.origin.rotation();
        let rotated = mat_mul(&mat_mul(&r, &self.tensor()), &transpose(&r));
        (self.origin.xyz, rotated)
    }

    /// The principal moments of inertia (ascending) and the principal axes in the link frame:
    /// [`symmetric_eigen`] of the tensor in the `origin` frame (as written, so a diagonal tensor
    /// gives its diagonal exactly), its eigenvectors turned by the origin's rotation `R`, so that
    /// `R I R^T = axes diag(moments) axes^T`.
    pub fn principal(&self) -> SymmetricEigen {
        let eigen = symmetric_eigen(&self.tensor());
        SymmetricEigen {
            values: eigen.values,
            vectors: mat_mul(&self.origin.rotation(), &eigen.vectors),
        }
    }

    /// [`principal`](Self::principal) of a physical inertia, or the error `refuse` makes of
    /// the problem (one line): the principal moments non-negative and satisfying the triangle
    /// inequalities `I_a <= I_b + I_c` (each moment is an integral of squared distances from two
    /// of the axes, whose sum exceeds the squared distance from the third), each within
    /// [`INERTIA_TOLERANCE`] of the trace.
    pub(crate) fn physical(
        &self,
        refuse: impl FnOnce(String) -> DescError,
    ) -> Result<SymmetricEigen, DescError> {
        let principal = self.principal();
        let moments = principal.values;
        let trace: f64 = moments.iter().sum();
        let tolerance = INERTIA_TOLERANCE * trace.abs();
        if moments[0] < -tolerance {
            return Err(refuse(format!(
                "inertia must be positive semi-definite, its principal moments are {moments:?}"
            )));
        }
        if moments[2] > moments[0] + moments[1] + tolerance {
            return Err(refuse(format!(
                "inertia breaks the triangle inequality: principal moments {moments:?}, the \
                 largest exceeds the sum of the other two"
            )));
        }
        Ok(principal)
    }

    /// The mass properties of a rigid union of `self` and `other`, whose link frame sits at
    /// `placement` in `self`'s link frame: masses add, the centre of mass is their weighted mean,
    /// and each inertia moves to it by the parallel-axis theorem,
    /// `I = sum_k R_k I_k R_k^T + m_k (|d_k|^2 E - d_k d_k^T)`. The result is in the link frame
    /// (`rpy` zero).
    pub fn merged(&self, other: &Inertial, placement: &Pose) -> Inertial {
        let (c_a, i_a) = self.in_link_frame();
        let (c_b_local, i_b_local) = other.in_link_frame();
        let r = placement.rotation();
        let i_b = mat_mul(&mat_mul(&r, &i_b_local), &transpose(&r));
        let c_b = add(mat_vec(&r, c_b_local), placement.xyz);
        let mass = self.mass + other.mass;
        let com = if mass > 0.0 {
            [0, 1, 2].map(|k| (self.mass * c_a[k] + other.mass * c_b[k]) / mass)
        } else {
            [0.0; 3]
        };
        let mut total = [[0.0; 3]; 3];
        for (m, c, i) in [(self.mass, c_a, i_a), (other.mass, c_b, i_b)] {
            let d = [c[0] - com[0], c[1] - com[1], c[2] - com[2]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            for a in 0..3 {
                for b in 0..3 {
                    let delta = if a == b { d2 } else { 0.0 };
                    total[a][b] += i[a][b] + m * (delta - d[a] * d[b]);
                }
            }
        }
        Inertial {
            origin: Pose {
                xyz: com,
                rpy: [0.0; 3],
            },
            mass,
            inertia: [
                total[0][0],
                total[0][1],
                total[0][2],
                total[1][1],
                total[1][2],
                total[2][2],
            ],
        }
    }
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// A shape, as URDF's `<geometry>`.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// `<box size="x y z"/>`: side lengths (m).
    Box([f64; 3]),
    /// `<cylinder radius length/>` along the frame's `z`.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// `<sphere radius/>`.
    Sphere(f64),
    /// `<mesh filename scale/>`: kept by file name only (never opened).
    Mesh {
        /// The file name as written (`package://...` or a path).
        filename: String,
        /// Scale per axis, if given.
        scale: Option<[f64; 3]>,
    },
}

/// A visual or collision shape placed in its link frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Geometry {
    /// The element's `name`, if any.
    pub name: Option<String>,
    /// The shape's frame in the link frame.
    pub origin: Pose,
    /// The shape.
    pub shape: Shape,
}

/// A rigid body of the chain: a URDF link together with every link welded to it by fixed
/// joints (merged into it, geometry included).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Body {
    /// The link's name.
    pub name: String,
    /// Mass properties (zero for a link without `<inertial>`).
    pub inertial: Inertial,
    /// `<visual>` shapes.
    pub visuals: Vec<Geometry>,
    /// `<collision>` shapes.
    pub collisions: Vec<Geometry>,
}

/// The kind of a movable joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// `revolute`: rotation about the axis, with position limits.
    Revolute,
    /// `continuous`: rotation about the axis, unlimited.
    Continuous,
    /// `prismatic`: translation along the axis.
    Prismatic,
}

impl JointKind {
    /// The URDF `type` attribute.
    pub fn urdf_name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
        }
    }

    /// True for the rotations (revolute, continuous).
    pub fn is_rotation(self) -> bool {
        !matches!(self, JointKind::Prismatic)
    }
}

/// URDF's `<limit>`: each attribute kept only when written.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Limits {
    /// Lower position limit (rad or m).
    pub lower: Option<f64>,
    /// Upper position limit (rad or m).
    pub upper: Option<f64>,
    /// Largest effort (N m or N), non-negative.
    pub effort: Option<f64>,
    /// Largest speed (rad/s or m/s), non-negative.
    pub velocity: Option<f64>,
}

/// URDF's `<dynamics>`: joint damping and Coulomb friction, kept only when written.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointDynamics {
    /// Viscous damping (N m s/rad or N s/m), non-negative.
    pub damping: Option<f64>,
    /// Coulomb friction (N m or N), non-negative.
    pub friction: Option<f64>,
}

/// A movable joint and the body it moves.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The joint's name.
    pub name: String,
    /// Revolute, continuous or prismatic.
    pub kind: JointKind,
    /// The joint frame in the parent body's frame (fixed links before it folded in). The
    /// child body's frame is this frame moved by the joint: `origin * Rot(axis, q)` or
    /// `origin * Trans(axis q)`.
    pub origin: Pose,
    /// Unit axis in the joint frame.
    pub axis: [f64; 3],
    /// `<limit>`, if given.
    pub limits: Option<Limits>,
    /// `<dynamics>`, if given.
    pub dynamics: Option<JointDynamics>,
    /// The body the joint moves.
    pub child: Body,
}

impl Joint {
    /// The joint's position range `[lower, upper]` (rad or m) as URDF reads it: unbounded for a
    /// continuous joint, and for a revolute or prismatic one without `<limit>` (which urdfdom
    /// refuses; hrm reads it as unlimited); otherwise `<limit>`'s `lower` and `upper`, each 0
    /// when missing (the specification's default, urdfdom's and Pinocchio's reading: a
    /// `<limit>` with neither holds the joint at 0).
    pub fn position_range(&self) -> [f64; 2] {
        match (self.kind, self.limits) {
            (JointKind::Continuous, _) | (_, None) => [f64::NEG_INFINITY, f64::INFINITY],
            (_, Some(limits)) => [limits.lower.unwrap_or(0.0), limits.upper.unwrap_or(0.0)],
        }
    }
}

/// A serial chain with a fixed base: the base body and the movable joints in chain order, one
/// degree of freedom each.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// `<robot name>`.
    pub name: String,
    /// The root link (fixed to the world) with the links welded to it.
    pub base: Body,
    /// The movable joints, base to tip.
    pub joints: Vec<Joint>,
}

impl Robot {
    /// Number of degrees of freedom (movable joints).
    pub fn n_joints(&self) -> usize {
        self.joints.len()
    }
}
