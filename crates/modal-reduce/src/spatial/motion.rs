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
//!   at `a = a_p + w_dot_i x r + w_i x (w_i x r)`.
//!
//! With zero joint accelerations the accelerations are the bias terms of `C*` (velocity
//! products only).

use backbone_kin::vec3::{
    Rotation, add, column, cross, mat_mul, mat_vec, rot_y, rot_z, scale, sub,
};

/// The state the recursion carries from link to link.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Carried {
    /// Frame of the previous link (or the base).
    pub rotation: Rotation,
    /// The joint point `p_{i-1}` (world frame).
    pub point: [f64; 3],
    /// Angular velocity of the previous link.
    pub omega: [f64; 3],
    /// Angular acceleration of the previous link.
    pub omega_dot: [f64; 3],
    /// Acceleration of the joint point.
    pub accel: [f64; 3],
}

impl Carried {
    /// The base: at rest, in its pose.
    pub fn base(rotation: Rotation, point: [f64; 3]) -> Self {
        Self {
            rotation,
            point,
            omega: [0.0; 3],
            omega_dot: [0.0; 3],
            accel: [0.0; 3],
        }
    }
}

/// What one link's step gives: its joints' axes, its frame, its angular velocity and
/// acceleration, its centre of mass and that point's acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkMotion {
    /// Axis of the joint about `z` (world frame).
    pub u_z: [f64; 3],
    /// Axis of the joint about `y` (world frame).
    pub u_y: [f64; 3],
    /// The joints' point `p_{i-1}`.
    pub joint: [f64; 3],
    /// The link's frame `R_i`.
    pub rotation: Rotation,
    /// Angular velocity `w_i`.
    pub omega: [f64; 3],
    /// Angular acceleration `w_dot_i`.
    pub omega_dot: [f64; 3],
    /// Centre of mass `c_i`.
    pub com: [f64; 3],
    /// Acceleration of the centre of mass.
    pub com_accel: [f64; 3],
}

/// Link `i`'s step: `angles = [z_i, y_i]`, `rates`, `accels` likewise, `length` its length.
/// Returns the link's motion and updates `carried` for the next link.
pub fn link_step(
    carried: &mut Carried,
    length: f64,
    angles: [f64; 2],
    rates: [f64; 2],
    accels: [f64; 2],
) -> LinkMotion {
    let u_z = column(&carried.rotation, 2);
    let after_z = mat_mul(carried.rotation, rot_z(angles[0]));
    let u_y = column(&after_z, 1);
    let rotation = mat_mul(after_z, rot_y(angles[1]));
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
    let along = column(&rotation, 0);
    let accel_at = |r: [f64; 3]| {
        add(
            carried.accel,
            add(cross(omega_dot, r), cross(omega, cross(omega, r))),
        )
    };
    let to_com = scale(along, 0.5 * length);
    let to_next = scale(along, length);
    let joint = carried.point;
    let motion = LinkMotion {
        u_z,
        u_y,
        joint,
        rotation,
        omega,
        omega_dot,
        com: add(joint, to_com),
        com_accel: accel_at(to_com),
    };
    *carried = Carried {
        rotation,
        point: add(joint, to_next),
        omega,
        omega_dot,
        accel: accel_at(to_next),
    };
    motion
}

/// `R diag(principal) R^T`, a link's inertia about its centre of mass in the world frame.
pub fn world_inertia(rotation: &Rotation, principal: [f64; 3]) -> Rotation {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            (0..3)
                .map(|k| rotation[i][k] * principal[k] * rotation[j][k])
                .sum()
        })
    })
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
