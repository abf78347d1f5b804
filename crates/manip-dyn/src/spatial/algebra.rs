//! The spatial algebra the spatial algorithms are written on (Featherstone's, in Pinocchio's
//! layout): 3-vectors and 3 x 3 matrices, rigid transforms, motion and force vectors, rigid-body
//! inertias and the symmetric 6 x 6 articulated inertias. Every vector is expressed in the axes of
//! a frame and referred to its origin; a spatial vector stores its linear part first.
//!
//! The types are generic over the number type `T` ([`Lane`]): `f64` for one state, a SIMD
//! register of several states for the batch articulated-body algorithm, with the same operations
//! in the same order (so the same bits). The lane-generic code is written without closures
//! (no array `map`): a closure is compiled on its own, outside the instruction set that
//! [`pulp::Arch::dispatch`] enables for a batch, so every register operation inside it would be
//! a function call instead of one instruction.

use lane_math::Lane;

/// A 3-vector.
pub type Vec3<T = f64> = [T; 3];

/// A 3 x 3 matrix, row-major: `m[row][column]`.
pub type Mat3<T = f64> = [[T; 3]; 3];

/// The 3 x 3 identity.
pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `a + b`.
#[inline(always)]
pub(crate) fn add<T: Lane>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline(always)]
pub(crate) fn sub<T: Lane>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
#[inline(always)]
pub(crate) fn scale<T: Lane>(a: Vec3<T>, s: T) -> Vec3<T> {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a . b`.
#[inline(always)]
pub(crate) fn dot<T: Lane>(a: Vec3<T>, b: Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
#[inline(always)]
pub(crate) fn cross<T: Lane>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `m v`.
#[inline(always)]
pub(crate) fn mat_vec<T: Lane>(m: &Mat3<T>, v: Vec3<T>) -> Vec3<T> {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `m^T v`.
#[inline(always)]
pub(crate) fn mat_t_vec<T: Lane>(m: &Mat3<T>, v: Vec3<T>) -> Vec3<T> {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// `m^T`.
#[inline(always)]
pub(crate) fn transpose<T: Lane>(m: &Mat3<T>) -> Mat3<T> {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// `a b`.
#[inline(always)]
pub(crate) fn mat_mul<T: Lane>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    let bt = transpose(b);
    [mat_vec(&bt, a[0]), mat_vec(&bt, a[1]), mat_vec(&bt, a[2])]
}

/// `a + b`, entry by entry.
#[inline(always)]
pub(crate) fn mat_add<T: Lane>(a: &Mat3<T>, b: &Mat3<T>) -> Mat3<T> {
    [add(a[0], b[0]), add(a[1], b[1]), add(a[2], b[2])]
}

/// `m [p]x`: row `r` is `m_r x p` (`[p]x` the cross-product matrix of `p`).
#[inline(always)]
pub(crate) fn mat_cross<T: Lane>(m: &Mat3<T>, p: Vec3<T>) -> Mat3<T> {
    [cross(m[0], p), cross(m[1], p), cross(m[2], p)]
}

/// `R m R^T`.
#[inline(always)]
pub(crate) fn rotate_congruent<T: Lane>(r: &Mat3<T>, m: &Mat3<T>) -> Mat3<T> {
    mat_mul(&mat_mul(r, m), &transpose(r))
}

/// Every entry as the number type `T`.
#[inline(always)]
pub(crate) fn splat3<T: Lane>(context: T::Context, v: Vec3) -> Vec3<T> {
    [
        T::splat(context, v[0]),
        T::splat(context, v[1]),
        T::splat(context, v[2]),
    ]
}

/// Every entry as the number type `T`.
#[inline(always)]
pub(crate) fn splat33<T: Lane>(context: T::Context, m: &Mat3) -> Mat3<T> {
    [
        splat3(context, m[0]),
        splat3(context, m[1]),
        splat3(context, m[2]),
    ]
}

/// The rotation by `angle` about the unit `axis` given as `(sin angle, cos angle)` (Rodrigues:
/// `R = I + s [a]x + (1 - c) [a]x^2`).
#[inline(always)]
pub(crate) fn axis_rotation<T: Lane>(context: T::Context, axis: Vec3, sin: T, cos: T) -> Mat3<T> {
    let one = T::splat(context, 1.0);
    let versine = one - cos;
    let [x, y, z] = axis;
    let (xs, ys, zs) = (sin * x, sin * y, sin * z);
    let (xv, yv, zv) = (versine * x, versine * y, versine * z);
    [
        [one - versine * (1.0 - x * x), yv * x - zs, zv * x + ys],
        [xv * y + zs, one - versine * (1.0 - y * y), zv * y - xs],
        [xv * z - ys, yv * z + xs, one - versine * (1.0 - z * z)],
    ]
}

/// A rigid transform from a child frame to its parent: a point of child coordinates `x` has
/// parent coordinates `rotation x + translation` (Pinocchio's `SE3` `parentMchild`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform<T = f64> {
    /// The child's axes in parent coordinates (columns), a rotation matrix.
    pub rotation: Mat3<T>,
    /// The child's origin in parent coordinates.
    pub translation: Vec3<T>,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Transform = Transform {
        rotation: IDENTITY,
        translation: [0.0; 3],
    };

    /// A pure translation.
    pub fn translation(translation: Vec3) -> Transform {
        Transform {
            rotation: IDENTITY,
            translation,
        }
    }

    /// The rotation of roll, pitch and yaw angles (rad) about the fixed `x`, `y`, `z` axes in
    /// that order (URDF's `rpy`: `R = Rz(yaw) Ry(pitch) Rx(roll)`) then the translation.
    pub fn from_rpy(rpy: Vec3, translation: Vec3) -> Transform {
        let [x, y, z] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let rotation = |axis, angle: f64| {
            let (s, c) = angle.sin_cos();
            axis_rotation::<f64>((), axis, s, c)
        };
        let r = mat_mul(
            &rotation(z, rpy[2]),
            &mat_mul(&rotation(y, rpy[1]), &rotation(x, rpy[0])),
        );
        Transform {
            rotation: r,
            translation,
        }
    }

    /// The roll, pitch and yaw of [`from_rpy`](Self::from_rpy) that give this rotation, pitch in
    /// `[-pi/2, pi/2]` (at `|pitch| = pi/2` the roll is taken as zero).
    ///
    /// ```
    /// use manip_dyn::spatial::Transform;
    /// let rpy = [0.3, -1.1, 2.5];
    /// let back = Transform::from_rpy(rpy, [0.0; 3]).to_rpy();
    /// assert!(rpy.iter().zip(back).all(|(a, b)| (a - b).abs() < 1e-12));
    /// ```
    pub fn to_rpy(&self) -> Vec3 {
        let r = &self.rotation;
        let cos_pitch = r[2][1].hypot(r[2][2]);
        let pitch = (-r[2][0]).atan2(cos_pitch);
        if cos_pitch > 1e-12 {
            [r[2][1].atan2(r[2][2]), pitch, r[1][0].atan2(r[0][0])]
        } else {
            [0.0, pitch, (-r[0][1]).atan2(r[1][1])]
        }
    }
}

impl<T: Lane> Transform<T> {
    /// `self * other`: `other` maps a grandchild to the child, the product maps it to the parent.
    #[inline(always)]
    pub(crate) fn compose(&self, other: &Transform<T>) -> Transform<T> {
        Transform {
            rotation: mat_mul(&self.rotation, &other.rotation),
            translation: add(mat_vec(&self.rotation, other.translation), self.translation),
        }
    }

    /// A point of child coordinates in parent coordinates.
    #[inline(always)]
    pub(crate) fn apply(&self, x: Vec3<T>) -> Vec3<T> {
        add(mat_vec(&self.rotation, x), self.translation)
    }

    /// A child motion vector in the parent frame (`X m`).
    #[inline(always)]
    pub(crate) fn act_motion(&self, m: &Motion<T>) -> Motion<T> {
        let angular = mat_vec(&self.rotation, m.angular);
        let linear = add(
            mat_vec(&self.rotation, m.linear),
            cross(self.translation, angular),
        );
        Motion { linear, angular }
    }

    /// A parent motion vector in the child frame (`X^-1 m`).
    #[inline(always)]
    pub(crate) fn inv_act_motion(&self, m: &Motion<T>) -> Motion<T> {
        let linear = sub(m.linear, cross(self.translation, m.angular));
        Motion {
            linear: mat_t_vec(&self.rotation, linear),
            angular: mat_t_vec(&self.rotation, m.angular),
        }
    }

    /// A child force vector in the parent frame (`X^-T f`).
    #[inline(always)]
    pub(crate) fn act_force(&self, f: &Force<T>) -> Force<T> {
        let linear = mat_vec(&self.rotation, f.linear);
        let angular = add(
            mat_vec(&self.rotation, f.angular),
            cross(self.translation, linear),
        );
        Force { linear, angular }
    }

    /// An articulated (or rigid) inertia of the child frame in the parent frame,
    /// `X^-T Y X^-1`: rotated blockwise, `R Y_ab R^T`, then shifted by `P = [p]x`:
    /// `A' = A`, `B' = B - A P`, `C' = C + P B - B'^T P` (theory.md, "spatial algebra").
    #[inline(always)]
    pub(crate) fn act_inertia(&self, y: &Symmetric6<T>) -> Symmetric6<T> {
        let r = &self.rotation;
        let p = self.translation;
        let a = rotate_congruent(r, &y.a);
        let b = rotate_congruent(r, &y.b);
        let c = rotate_congruent(r, &y.c);
        // Row r of A P is a_r x p: a_r^T P x = a_r . (p x x) = x . (a_r x p).
        let ap = mat_cross(&a, p);
        let b_new = [sub(b[0], ap[0]), sub(b[1], ap[1]), sub(b[2], ap[2])];
        // P B: column j is p x b_j, so (P B)^T has rows p x (column j of B).
        let pb_t = mat_cross_t(p, &b);
        let pbn_t = mat_cross_t(p, &b_new);
        // C' = C + P B + (P B')^T.
        let c_new = [
            [
                c[0][0] + pb_t[0][0] + pbn_t[0][0],
                c[0][1] + pb_t[1][0] + pbn_t[0][1],
                c[0][2] + pb_t[2][0] + pbn_t[0][2],
            ],
            [
                c[1][0] + pb_t[0][1] + pbn_t[1][0],
                c[1][1] + pb_t[1][1] + pbn_t[1][1],
                c[1][2] + pb_t[2][1] + pbn_t[1][2],
            ],
            [
                c[2][0] + pb_t[0][2] + pbn_t[2][0],
                c[2][1] + pb_t[1][2] + pbn_t[2][1],
                c[2][2] + pb_t[2][2] + pbn_t[2][2],
            ],
        ];
        Symmetric6 {
            a,
            b: b_new,
            c: c_new,
        }
    }
}

impl Transform {
    /// A rigid body's inertia given in the child frame, in the parent frame by its ten
    /// parameters (what [`act_inertia`](Self::act_inertia) gives of [`RigidInertia::matrix`]):
    /// the centre of mass `c = R c_child + p`, first moment `m c`,
    /// `C = R I_c R^T + m (|c|^2 E - c c^T)`.
    pub(crate) fn act_rigid_inertia(&self, body: &RigidInertia) -> RigidSum {
        let m = body.mass;
        let c = self.apply(body.com);
        let mut rotational = rotate_congruent(&self.rotation, &body.inertia);
        let c2 = dot(c, c);
        for (r, row) in rotational.iter_mut().enumerate() {
            for (k, entry) in row.iter_mut().enumerate() {
                let delta = if r == k { c2 } else { 0.0 };
                *entry += m * (delta - c[r] * c[k]);
            }
        }
        RigidSum {
            mass: m,
            moment: scale(c, m),
            rotational,
        }
    }
}

/// `([p]x m)^T`: row `j` is `p x` (column `j` of `m`).
#[inline(always)]
fn mat_cross_t<T: Lane>(p: Vec3<T>, m: &Mat3<T>) -> Mat3<T> {
    let t = transpose(m);
    [cross(p, t[0]), cross(p, t[1]), cross(p, t[2])]
}

/// A motion vector (spatial velocity or acceleration, or a joint axis): the linear velocity of
/// the body's point at the frame's origin, and the angular velocity.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion<T = f64> {
    /// Linear part (m/s, or m/s^2, or per unit joint rate).
    pub linear: Vec3<T>,
    /// Angular part (rad/s, ...).
    pub angular: Vec3<T>,
}

/// A force vector: the force and the moment about the frame's origin.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Force<T = f64> {
    /// Force (N).
    pub linear: Vec3<T>,
    /// Moment about the frame's origin (N m).
    pub angular: Vec3<T>,
}

impl<T: Lane> Motion<T> {
    /// `self + other`.
    #[inline(always)]
    pub(crate) fn plus(&self, other: &Motion<T>) -> Motion<T> {
        Motion {
            linear: add(self.linear, other.linear),
            angular: add(self.angular, other.angular),
        }
    }

    /// `s self`.
    #[inline(always)]
    pub(crate) fn times(&self, s: T) -> Motion<T> {
        Motion {
            linear: scale(self.linear, s),
            angular: scale(self.angular, s),
        }
    }

    /// The motion cross product `self x m = (w x v_m + v x w_m, w x w_m)`.
    #[inline(always)]
    pub(crate) fn cross_motion(&self, m: &Motion<T>) -> Motion<T> {
        Motion {
            linear: add(cross(self.angular, m.linear), cross(self.linear, m.angular)),
            angular: cross(self.angular, m.angular),
        }
    }

    /// The force cross product `self x* f = (w x f, w x n + v x f)`.
    #[inline(always)]
    pub(crate) fn cross_force(&self, f: &Force<T>) -> Force<T> {
        Force {
            linear: cross(self.angular, f.linear),
            angular: add(cross(self.angular, f.angular), cross(self.linear, f.linear)),
        }
    }

    /// The power `self . f = v . f + w . n`.
    #[inline(always)]
    pub(crate) fn dot(&self, f: &Force<T>) -> T {
        dot(self.linear, f.linear) + dot(self.angular, f.angular)
    }
}

impl<T: Lane> Force<T> {
    /// `self + other`.
    #[inline(always)]
    pub(crate) fn plus(&self, other: &Force<T>) -> Force<T> {
        Force {
            linear: add(self.linear, other.linear),
            angular: add(self.angular, other.angular),
        }
    }

    /// `s self`.
    #[inline(always)]
    pub(crate) fn times(&self, s: T) -> Force<T> {
        Force {
            linear: scale(self.linear, s),
            angular: scale(self.angular, s),
        }
    }
}

/// A symmetric 6 x 6 inertia `[[A, B], [B^T, C]]` mapping a motion `(v, w)` to the force
/// `(A v + B w, B^T v + C w)`: a rigid body's spatial inertia, or an articulated inertia.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Symmetric6<T = f64> {
    /// Force per linear velocity (symmetric).
    pub(crate) a: Mat3<T>,
    /// Force per angular velocity.
    pub(crate) b: Mat3<T>,
    /// Moment per angular velocity (symmetric).
    pub(crate) c: Mat3<T>,
}

impl<T: Lane> Symmetric6<T> {
    /// `Y m`.
    #[inline(always)]
    pub(crate) fn apply(&self, m: &Motion<T>) -> Force<T> {
        Force {
            linear: add(mat_vec(&self.a, m.linear), mat_vec(&self.b, m.angular)),
            angular: add(mat_t_vec(&self.b, m.linear), mat_vec(&self.c, m.angular)),
        }
    }

    /// Every entry as the number type `T`.
    #[inline(always)]
    pub(crate) fn splat(context: T::Context, y: &Symmetric6) -> Symmetric6<T> {
        Symmetric6 {
            a: splat33(context, &y.a),
            b: splat33(context, &y.b),
            c: splat33(context, &y.c),
        }
    }

    /// `self + other`.
    #[inline(always)]
    pub(crate) fn plus(&self, other: &Symmetric6<T>) -> Symmetric6<T> {
        Symmetric6 {
            a: mat_add(&self.a, &other.a),
            b: mat_add(&self.b, &other.b),
            c: mat_add(&self.c, &other.c),
        }
    }

    /// `self - u u^T s` for the force `u` (the articulated inertia with a joint's acceleration
    /// solved out, `s = 1 / D`).
    #[inline(always)]
    pub(crate) fn minus_outer(&self, u: &Force<T>, s: T) -> Symmetric6<T> {
        Symmetric6 {
            a: minus_scaled_outer(&self.a, u.linear, u.linear, s),
            b: minus_scaled_outer(&self.b, u.linear, u.angular, s),
            c: minus_scaled_outer(&self.c, u.angular, u.angular, s),
        }
    }
}

impl Symmetric6 {
    /// `self + body`, with the body's matrix `[[m E, -[h]x], [[h]x, C]]` added entry by entry
    /// (its zeros skipped).
    #[inline(always)]
    pub(crate) fn plus_rigid(&self, body: &RigidSum) -> Symmetric6 {
        let (m, [hx, hy, hz]) = (body.mass, body.moment);
        let (a, b) = (&self.a, &self.b);
        Symmetric6 {
            a: [
                [a[0][0] + m, a[0][1], a[0][2]],
                [a[1][0], a[1][1] + m, a[1][2]],
                [a[2][0], a[2][1], a[2][2] + m],
            ],
            b: [
                [b[0][0], b[0][1] + hz, b[0][2] - hy],
                [b[1][0] - hz, b[1][1], b[1][2] + hx],
                [b[2][0] + hy, b[2][1] - hx, b[2][2]],
            ],
            c: mat_add(&self.c, &body.rotational),
        }
    }
}

/// `m - (s x) y^T`, row `r` being `m_r - y (s x_r)`.
#[inline(always)]
fn minus_scaled_outer<T: Lane>(m: &Mat3<T>, x: Vec3<T>, y: Vec3<T>, s: T) -> Mat3<T> {
    let xs = scale(x, s);
    [
        sub(m[0], scale(y, xs[0])),
        sub(m[1], scale(y, xs[1])),
        sub(m[2], scale(y, xs[2])),
    ]
}

/// A rigid body's inertia, or a sum of them (a subtree's composite inertia), in one frame by
/// its ten parameters: the total mass `m`, first moment `h = m c` and rotational inertia `C`
/// about the frame's origin; as a matrix `[[m E, -[h]x], [[h]x, C]]` (a [`Symmetric6`] with
/// `A = m E`, `B = -[h]x`), applied in about a third of the general product's operations.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct RigidSum {
    pub(crate) mass: f64,
    pub(crate) moment: Vec3,
    pub(crate) rotational: Mat3,
}

impl RigidSum {
    /// `Y m = (m v + w x h, h x v + C w)` for `m = (v, w)`.
    #[inline(always)]
    pub(crate) fn apply(&self, m: &Motion) -> Force {
        Force {
            linear: add(scale(m.linear, self.mass), cross(m.angular, self.moment)),
            angular: add(
                cross(self.moment, m.linear),
                mat_vec(&self.rotational, m.angular),
            ),
        }
    }

    /// `self + other`.
    #[inline(always)]
    pub(crate) fn plus(&self, other: &RigidSum) -> RigidSum {
        RigidSum {
            mass: self.mass + other.mass,
            moment: add(self.moment, other.moment),
            rotational: mat_add(&self.rotational, &other.rotational),
        }
    }
}

/// The rigid-body inertia of a link in its own frame: mass, centre of mass and rotational inertia
/// about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RigidInertia {
    pub(crate) mass: f64,
    pub(crate) com: Vec3,
    /// About the centre of mass.
    pub(crate) inertia: Mat3,
}

impl RigidInertia {
    /// `I m = (f, c x f + I_c w)` with `f = m (v - c x w)`.
    #[inline(always)]
    pub(crate) fn apply<T: Lane>(&self, context: T::Context, m: &Motion<T>) -> Force<T> {
        let com = splat3(context, self.com);
        let f = scale(
            sub(m.linear, cross(com, m.angular)),
            T::splat(context, self.mass),
        );
        Force {
            linear: f,
            angular: add(
                cross(com, f),
                mat_vec(&splat33(context, &self.inertia), m.angular),
            ),
        }
    }

    /// The 6 x 6 matrix: `A = m E`, `B = -m [c]x`, `C = I_c - m [c]x^2`.
    pub(crate) fn matrix(&self) -> Symmetric6 {
        let m = self.mass;
        let [x, y, z] = self.com;
        let mc = [x * m, y * m, z * m];
        let b = [
            [0.0, mc[2], -mc[1]],
            [-mc[2], 0.0, mc[0]],
            [mc[1], -mc[0], 0.0],
        ];
        // -m [c]x^2 = m (|c|^2 E - c c^T).
        let c2 = x * x + y * y + z * z;
        let mut c = self.inertia;
        for (r, row) in c.iter_mut().enumerate() {
            for (k, entry) in row.iter_mut().enumerate() {
                let delta = if r == k { c2 } else { 0.0 };
                *entry += m * (delta - self.com[r] * self.com[k]);
            }
        }
        Symmetric6 {
            a: [[m, 0.0, 0.0], [0.0, m, 0.0], [0.0, 0.0, m]],
            b,
            c,
        }
    }
}
