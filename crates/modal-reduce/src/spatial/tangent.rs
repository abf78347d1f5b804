//! The tangent of the Newton-Euler recursion of [`motion`](super::motion) and
//! [`torques`](super::torques) along one direction of the joint angles and rates: the
//! directional derivative `d tau = (d tau / d theta) d_theta + (d tau / d theta_dot) d_theta_dot`
//! in `O(n)`, at fixed joint accelerations (`docs/theory.md`, section 8).
//!
//! Rotations are perturbed on the left, `d R = [t]x R`, so a vector fixed in a frame turning by
//! `t` changes by `t x u`. Forward, from the base (`t = 0` there), with the previous link's
//! `t`, `d p`, `d w`, `d w_dot`, `d a_p`:
//!
//! - `d u_z = t x u_z`; `t' = t + u_z d z`; `d u_y = t' x u_y`; `t_i = t' + u_y d y`;
//! - `d w' = d w + d u_z z_dot + u_z d z_dot`, `d w_i = d w' + d u_y y_dot + u_y d y_dot`;
//! - `d w_dot_i = d w_dot + (d w x u_z + w x d u_z) z_dot + (w x u_z) d z_dot + d u_z z_ddot
//!   + (d w' x u_y + w' x d u_y) y_dot + (w' x u_y) d y_dot + d u_y y_ddot`;
//! - for `r = (L/2) R_i e_x` or `L R_i e_x`, `d r = t_i x r` and
//!   `d a = d a_p + d w_dot_i x r + w_dot_i x d r + d w_i x (w_i x r) + w_i x (d w_i x r + w_i x d r)`.
//!
//! Backward, the products of [`link_wrench`] differentiated term by term, with
//! `d (I v) = t x (I v) - I (t x v) + I d v` for the world inertia `I = R D R^T`; the torques'
//! tangents are `d u . N + u . d N`.

use super::motion::{LinkMotion, link_wrench};
use backbone_kin::vec3::{Rotation, add, column, cross, dot, mat_vec, scale, sub};

/// The tangent of the state carried from link to link.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CarriedTangent {
    /// The frame's rotation `t` (`d R = [t]x R`).
    pub turn: [f64; 3],
    /// `d p` of the joint point.
    pub point: [f64; 3],
    /// `d w`.
    pub omega: [f64; 3],
    /// `d w_dot`.
    pub omega_dot: [f64; 3],
    /// `d a_p`.
    pub accel: [f64; 3],
}

/// The tangent of one link's [`LinkMotion`] (the fields the backward pass needs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkTangent {
    /// `d u_z`.
    pub u_z: [f64; 3],
    /// `d u_y`.
    pub u_y: [f64; 3],
    /// `d p_{i-1}`.
    pub joint: [f64; 3],
    /// The link frame's rotation `t_i`.
    pub turn: [f64; 3],
    /// `d w_i`.
    pub omega: [f64; 3],
    /// `d w_dot_i`.
    pub omega_dot: [f64; 3],
    /// `d c_i`.
    pub com: [f64; 3],
    /// `d a_i` of the centre of mass.
    pub com_accel: [f64; 3],
}

/// The joint rates and accelerations of one link and the direction's angles and rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointPair {
    /// `[z_dot, y_dot]`.
    pub rates: [f64; 2],
    /// `[z_ddot, y_ddot]`.
    pub accels: [f64; 2],
    /// `[d z, d y]`.
    pub d_angles: [f64; 2],
    /// `[d z_dot, d y_dot]`.
    pub d_rates: [f64; 2],
}

/// Link `i`'s tangent step: `motion` its nominal motion (from [`link_step`](super::motion::link_step)),
/// `previous_omega` the angular velocity of link `i - 1` (zero for the base), `carried` the
/// tangent entering the link, updated for the next link.
pub fn link_tangent(
    carried: &mut CarriedTangent,
    motion: &LinkMotion,
    previous_omega: [f64; 3],
    length: f64,
    joints: JointPair,
) -> LinkTangent {
    let JointPair {
        rates,
        accels,
        d_angles,
        d_rates,
    } = joints;
    let (u_z, u_y) = (motion.u_z, motion.u_y);
    let d_u_z = cross(carried.turn, u_z);
    let turn_mid = add(carried.turn, scale(u_z, d_angles[0]));
    let d_u_y = cross(turn_mid, u_y);
    let turn = add(turn_mid, scale(u_y, d_angles[1]));
    let omega_mid = add(previous_omega, scale(u_z, rates[0]));
    let d_omega_mid = add(
        carried.omega,
        add(scale(d_u_z, rates[0]), scale(u_z, d_rates[0])),
    );
    let d_omega = add(
        d_omega_mid,
        add(scale(d_u_y, rates[1]), scale(u_y, d_rates[1])),
    );
    let mut d_omega_dot = carried.omega_dot;
    for (term, factor) in [
        (
            add(cross(carried.omega, u_z), cross(previous_omega, d_u_z)),
            rates[0],
        ),
        (cross(previous_omega, u_z), d_rates[0]),
        (d_u_z, accels[0]),
        (
            add(cross(d_omega_mid, u_y), cross(omega_mid, d_u_y)),
            rates[1],
        ),
        (cross(omega_mid, u_y), d_rates[1]),
        (d_u_y, accels[1]),
    ] {
        d_omega_dot = add(d_omega_dot, scale(term, factor));
    }
    let along = column(&motion.rotation, 0);
    let (omega, omega_dot) = (motion.omega, motion.omega_dot);
    let d_accel_at = |r: [f64; 3]| {
        let d_r = cross(turn, r);
        let d_a = add(
            add(carried.accel, cross(d_omega_dot, r)),
            add(
                cross(omega_dot, d_r),
                add(
                    cross(d_omega, cross(omega, r)),
                    cross(omega, add(cross(d_omega, r), cross(omega, d_r))),
                ),
            ),
        );
        (d_r, d_a)
    };
    let (d_to_com, d_com_accel) = d_accel_at(scale(along, 0.5 * length));
    let (d_to_next, d_next_accel) = d_accel_at(scale(along, length));
    let joint = carried.point;
    let tangent = LinkTangent {
        u_z: d_u_z,
        u_y: d_u_y,
        joint,
        turn,
        omega: d_omega,
        omega_dot: d_omega_dot,
        com: add(joint, d_to_com),
        com_accel: d_com_accel,
    };
    *carried = CarriedTangent {
        turn,
        point: add(joint, d_to_next),
        omega: d_omega,
        omega_dot: d_omega_dot,
        accel: d_next_accel,
    };
    tangent
}

/// The wrench the links from `i` to the tip exert through the joint point `p_{i-1}` and its
/// tangent: `force` `F`, `moment` `N` about the joint point (what [`link_wrench`] carries).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WrenchTangent {
    /// `F`.
    pub force: [f64; 3],
    /// `N`.
    pub moment: [f64; 3],
    /// The point `N` is taken about (`p_i` entering link `i`, `p_{i-1}` leaving it).
    pub point: [f64; 3],
    /// `d F`.
    pub d_force: [f64; 3],
    /// `d N`.
    pub d_moment: [f64; 3],
    /// `d` of the point.
    pub d_point: [f64; 3],
}

/// `d (I v) = t x (I v) - I (t x v) + I d v` for `I = R D R^T` turned by `t`.
fn d_inertia_times(world: &Rotation, turn: [f64; 3], v: [f64; 3], d_v: [f64; 3]) -> [f64; 3] {
    add(
        sub(
            cross(turn, mat_vec(world, v)),
            mat_vec(world, cross(turn, v)),
        ),
        mat_vec(world, d_v),
    )
}

/// Link `i`'s backward tangent step: the nominal [`link_wrench`] of `motion` (inertia `world`
/// in the world frame, `mass`, under `gravity`) and its tangent, from the wrench of the links
/// beyond it; returns the tangents of the two joints' torques `[d tau_z, d tau_y]`.
pub fn wrench_tangent(
    wrench: &mut WrenchTangent,
    motion: &LinkMotion,
    tangent: &LinkTangent,
    world: &Rotation,
    mass: f64,
    gravity: [f64; 3],
) -> [f64; 2] {
    let t = tangent.turn;
    let own = scale(sub(motion.com_accel, gravity), mass);
    let d_own = scale(tangent.com_accel, mass);
    let iw = mat_vec(world, motion.omega);
    let d_iw = d_inertia_times(world, t, motion.omega, tangent.omega);
    let d_spin = add(cross(tangent.omega, iw), cross(motion.omega, d_iw));
    let d_angular = d_inertia_times(world, t, motion.omega_dot, tangent.omega_dot);
    let arm = sub(motion.com, motion.joint);
    let d_arm = sub(tangent.com, tangent.joint);
    let d_own_moment = add(
        add(d_angular, d_spin),
        add(cross(d_arm, own), cross(arm, d_own)),
    );
    let reach = sub(wrench.point, motion.joint);
    let d_reach = sub(wrench.d_point, tangent.joint);
    let d_moment = add(
        add(wrench.d_moment, d_own_moment),
        add(cross(d_reach, wrench.force), cross(reach, wrench.d_force)),
    );
    let (force, moment) = link_wrench(
        motion,
        world,
        mass,
        gravity,
        wrench.force,
        wrench.moment,
        wrench.point,
    );
    *wrench = WrenchTangent {
        force,
        moment,
        point: motion.joint,
        d_force: add(wrench.d_force, d_own),
        d_moment,
        d_point: tangent.joint,
    };
    [
        dot(tangent.u_z, moment) + dot(motion.u_z, d_moment),
        dot(tangent.u_y, moment) + dot(motion.u_y, d_moment),
    ]
}
