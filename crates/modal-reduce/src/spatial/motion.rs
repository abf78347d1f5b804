//! One link's step of the forward recursion of a universal-joint chain in the world frame, for
//! the joint torques and the derivatives (`docs/theory.md`, section 8).
//!
//! Entering link `i`: the frame `R` of link `i - 1` (the base's for the first link), the joint
//! point `p = p_{i-1}`, the angular velocity `w` and acceleration `w_dot` of link `i - 1`, and
//! the acceleration `a_p` of the point `p` (fixed on link `i - 1`). The joint about `z` turns by
//! `z_i` about `u_z = R e_z`, the joint about `y` by `y_i` about `u_y = R Rz(z_i) e_y`, both at
//! `p`:
//!
//! - `w' = w + u_z z_dot`, `w_i = w' + u_y y_dot`;
//! - `w_dot_i = w_dot + w x u_z z_dot + u_z z_ddot + w' x u_y y_dot + u_y y_ddot` (an axis fixed
//!   in a frame turning at `w` changes at `w x u`);
//! - the centre of mass `c = p + (L / 2) R_i e_x` and the next joint `p_i = p + L R_i e_x`, each
//!   at `a = a_p + w_dot_i x r + w_i x (w_i x r)` (affine in `r`: the centre of mass gets half
//!   the change of the next joint).
//!
//! With zero joint accelerations the accelerations are the bias terms of `C*` (velocity
//! products only).

use backbone_kin::vec3::{Rotation, add, column, cross, dot, mat_vec, scale, sub};
use lane_math::{Lane, sin_cos_lanes};

/// The state the recursion carries from link to link (of one state, `f64`, or of one state per
/// lane, [`Lane`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Carried<L = f64> {
    /// Frame of the previous link (or the base).
    pub rotation: Rotation<L>,
    /// The joint point `p_{i-1}` (world frame).
    pub point: [L; 3],
    /// Angular velocity of the previous link.
    pub omega: [L; 3],
    /// Angular acceleration of the previous link.
    pub omega_dot: [L; 3],
    /// Acceleration of the joint point.
    pub accel: [L; 3],
}

impl<L: Lane> Carried<L> {
    /// The base: at rest, in its pose (in every lane).
    #[inline(always)]
    pub fn base(context: L::Context, rotation: Rotation, point: [f64; 3]) -> Self {
        let zero = L::splat(context, 0.0);
        let mut carried = Self {
            rotation: [[zero; 3]; 3],
            point: [zero; 3],
            omega: [zero; 3],
            omega_dot: [zero; 3],
            accel: [zero; 3],
        };
        for ((row, given), (entry, &x)) in carried
            .rotation
            .iter_mut()
            .zip(rotation)
            .zip(carried.point.iter_mut().zip(&point))
        {
            for (value, r) in row.iter_mut().zip(given) {
                *value = L::splat(context, r);
            }
            *entry = L::splat(context, x);
        }
        carried
    }
}

/// What one link's step gives: its joints' axes, its frame, its angular velocity and
/// acceleration, its centre of mass and that point's acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkMotion<L = f64> {
    /// Axis of the joint about `z` (world frame).
    pub u_z: [L; 3],
    /// Axis of the joint about `y` (world frame).
    pub u_y: [L; 3],
    /// The joints' point `p_{i-1}`.
    pub joint: [L; 3],
    /// The link's frame `R_i`.
    pub rotation: Rotation<L>,
    /// Angular velocity `w_i`.
    pub omega: [L; 3],
    /// Angular acceleration `w_dot_i`.
    pub omega_dot: [L; 3],
    /// Centre of mass `c_i`.
    pub com: [L; 3],
    /// Acceleration of the centre of mass.
    pub com_accel: [L; 3],
}

/// Link `i`'s step: `angles = [z_i, y_i]`, `rates`, `accels` likewise, `length` its length.
/// Returns the link's motion and updates `carried` for the next link.
///
/// Generic over [`Lane`] (`context` its constructor's argument, `()` for `f64`): the same
/// operations in the same order for one state and for a register of states, so each lane gets
/// the bits of its state alone. The turns are applied column by column, `R Rz(z)` mixing the
/// first two columns of `R` and `Rz(z) Ry(y)` the first and last, with the sine and cosine of
/// [`sin_cos_lanes`]. (No closures here or below: a closure is compiled without the instruction
/// set of the SIMD dispatch that inlines this function, and would call its intrinsics.)
#[inline(always)]
pub fn link_step<L: Lane>(
    context: L::Context,
    carried: &mut Carried<L>,
    length: f64,
    angles: [L; 2],
    rates: [L; 2],
    accels: [L; 2],
) -> LinkMotion<L> {
    let (sin_z, cos_z) = sin_cos_lanes(context, angles[0]);
    let (sin_y, cos_y) = sin_cos_lanes(context, angles[1]);
    let turns = JointTurns {
        sin: [sin_z, sin_y],
        cos: [cos_z, cos_y],
        rates,
    };
    link_step_turned(context, carried, length, turns, Some(accels))
}

/// A link's two joint angles, by their sines and cosines (`[z_i, y_i]`), and their rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointTurns<L = f64> {
    /// `[sin z_i, sin y_i]`.
    pub sin: [L; 2],
    /// `[cos z_i, cos y_i]`.
    pub cos: [L; 2],
    /// `[z_dot_i, y_dot_i]`.
    pub rates: [L; 2],
}

/// [`link_step`] from the sines and cosines of the angles (`turns`), with the joint
/// accelerations `accels`, or none (`None`: zero, the terms they weigh skipped).
#[inline(always)]
pub fn link_step_turned<L: Lane>(
    context: L::Context,
    carried: &mut Carried<L>,
    length: f64,
    turns: JointTurns<L>,
    accels: Option<[L; 2]>,
) -> LinkMotion<L> {
    let (x, y, z) = (
        column(&carried.rotation, 0),
        column(&carried.rotation, 1),
        column(&carried.rotation, 2),
    );
    let JointTurns { sin, cos, rates } = turns;
    let [sin_z, sin_y] = sin;
    let [cos_z, cos_y] = cos;
    // R Rz(z): x' = x cos + y sin, y' = y cos - x sin; then Ry(y): x'' = x' cos - z sin,
    // z'' = x' sin + z cos.
    let (mut x_mid, mut u_y, mut along, mut normal) = (x, y, x, z);
    for d in 0..3 {
        x_mid[d] = x[d].mul_add(cos_z, y[d] * sin_z);
        u_y[d] = x[d].neg_mul_add(sin_z, y[d] * cos_z);
        along[d] = z[d].neg_mul_add(sin_y, x_mid[d] * cos_y);
        normal[d] = z[d].mul_add(cos_y, x_mid[d] * sin_y);
    }
    let u_z = z;
    let rotation = [
        [along[0], u_y[0], normal[0]],
        [along[1], u_y[1], normal[1]],
        [along[2], u_y[2], normal[2]],
    ];
    let omega_mid = mul_add3(u_z, rates[0], carried.omega);
    let omega = mul_add3(u_y, rates[1], omega_mid);
    let mut omega_dot = mul_add3(cross_fused(carried.omega, u_z), rates[0], carried.omega_dot);
    if let Some(accels) = accels {
        omega_dot = mul_add3(u_z, accels[0], omega_dot);
    }
    omega_dot = mul_add3(cross_fused(omega_mid, u_y), rates[1], omega_dot);
    if let Some(accels) = accels {
        omega_dot = mul_add3(u_y, accels[1], omega_dot);
    }
    // The acceleration is affine in the offset `r L` along the link (`r = 1` at the next joint,
    // `1/2` at the centre of mass): `a_p + L (w_dot x e + w x (w x e))` (`e` the unit `along`).
    let change = add(
        cross_fused(omega_dot, along),
        cross_fused(omega, cross_fused(omega, along)),
    );
    let (full, half) = (L::splat(context, length), L::splat(context, 0.5 * length));
    let joint = carried.point;
    let motion = LinkMotion {
        u_z,
        u_y,
        joint,
        rotation,
        omega,
        omega_dot,
        com: mul_add3(along, half, joint),
        com_accel: mul_add3(change, half, carried.accel),
    };
    *carried = Carried {
        rotation,
        point: mul_add3(along, full, joint),
        omega,
        omega_dot,
        accel: mul_add3(change, full, carried.accel),
    };
    motion
}

/// `a s + b`, each component one fused multiply-add.
#[inline(always)]
pub fn mul_add3<L: Lane>(a: [L; 3], s: L, b: [L; 3]) -> [L; 3] {
    [
        a[0].mul_add(s, b[0]),
        a[1].mul_add(s, b[1]),
        a[2].mul_add(s, b[2]),
    ]
}

/// `a x b`, each component a product and a fused multiply-add.
#[inline(always)]
pub fn cross_fused<L: Lane>(a: [L; 3], b: [L; 3]) -> [L; 3] {
    [
        a[2].neg_mul_add(b[1], a[1] * b[2]),
        a[0].neg_mul_add(b[2], a[2] * b[0]),
        a[1].neg_mul_add(b[0], a[0] * b[1]),
    ]
}

/// `R diag(principal) R^T`, a link's inertia about its centre of mass in the world frame
/// (generic over [`Lane`] as [`link_step`]; the six entries of one triangle, mirrored).
#[inline(always)]
pub fn world_inertia<L: Lane>(rotation: &Rotation<L>, principal: [f64; 3]) -> Rotation<L> {
    let r = rotation;
    let mut scaled = *r;
    for row in &mut scaled {
        for (entry, &moment) in row.iter_mut().zip(&principal) {
            *entry = *entry * moment;
        }
    }
    let (xx, yy, zz) = (
        dot(scaled[0], r[0]),
        dot(scaled[1], r[1]),
        dot(scaled[2], r[2]),
    );
    let (xy, xz, yz) = (
        dot(scaled[1], r[0]),
        dot(scaled[2], r[0]),
        dot(scaled[2], r[1]),
    );
    [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
}

/// Link `i`'s step of the backward pass: from the force `F_{i+1}` and the moment `N_{i+1}` about
/// `next_joint = p_i` that the links beyond it need, the force `F_i = m_i (a_i - g) + F_{i+1}` and
/// the moment about `p_{i-1}`, `N_i = I_i w_dot_i + w_i x I_i w_i + (c_i - p_{i-1}) x m_i (a_i - g)
/// + (p_i - p_{i-1}) x F_{i+1} + N_{i+1}` (`world` the link's inertia `I_i`, `mass` `m_i`).
pub fn link_wrench(
    motion: &LinkMotion,
    world: &Rotation,
    mass: f64,
    gravity: [f64; 3],
    force: [f64; 3],
    moment: [f64; 3],
    next_joint: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let own = scale(sub(motion.com_accel, gravity), mass);
    let spin = cross(motion.omega, mat_vec(world, motion.omega));
    let own_moment = add(
        add(mat_vec(world, motion.omega_dot), spin),
        cross(sub(motion.com, motion.joint), own),
    );
    let moment = add(
        add(moment, cross(sub(next_joint, motion.joint), force)),
        own_moment,
    );
    (add(force, own), moment)
}
