//! One link's step of the forward recursion of a universal-joint chain, shared by the reduced
//! terms and the joint torques (`docs/theory.md`, section 8).
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
    let (x, y, z) = (
        column(&carried.rotation, 0),
        column(&carried.rotation, 1),
        column(&carried.rotation, 2),
    );
    let (sin_z, cos_z) = sin_cos_lanes(context, angles[0]);
    let (sin_y, cos_y) = sin_cos_lanes(context, angles[1]);
    // R Rz(z): x' = x cos + y sin, y' = y cos - x sin; then Ry(y): x'' = x' cos - z sin,
    // z'' = x' sin + z cos.
    let x_mid = add(scale(x, cos_z), scale(y, sin_z));
    let u_y = sub(scale(y, cos_z), scale(x, sin_z));
    let along = sub(scale(x_mid, cos_y), scale(z, sin_y));
    let normal = add(scale(x_mid, sin_y), scale(z, cos_y));
    let u_z = z;
    let rotation = [
        [along[0], u_y[0], normal[0]],
        [along[1], u_y[1], normal[1]],
        [along[2], u_y[2], normal[2]],
    ];
    let omega_mid = add(carried.omega, scale(u_z, rates[0]));
    let omega = add(omega_mid, scale(u_y, rates[1]));
    let mut omega_dot = carried.omega_dot;
    for (term, factor) in [
        (cross(carried.omega, u_z), rates[0]),
        (u_z, accels[0]),
        (cross(omega_mid, u_y), rates[1]),
        (u_y, accels[1]),
    ] {
        omega_dot = add(omega_dot, scale(term, factor));
    }
    let to_com = scale(along, L::splat(context, 0.5 * length));
    let to_next = scale(along, L::splat(context, length));
    // The acceleration is affine in the offset: the centre of mass gets half the change.
    let change = add(
        cross(omega_dot, to_next),
        cross(omega, cross(omega, to_next)),
    );
    let joint = carried.point;
    let motion = LinkMotion {
        u_z,
        u_y,
        joint,
        rotation,
        omega,
        omega_dot,
        com: add(joint, to_com),
        com_accel: add(carried.accel, scale(change, L::splat(context, 0.5))),
    };
    *carried = Carried {
        rotation,
        point: add(joint, to_next),
        omega,
        omega_dot,
        accel: add(carried.accel, change),
    };
    motion
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
