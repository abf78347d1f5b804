//! The motion the pass of [`terms`](super::terms) carries from link to link: the angular velocity
//! `w`, the angular acceleration `w_dot` and the joint point's acceleration `a` (all at zero
//! modal acceleration), and gravity `g`, each in the frame of the link the pass has reached.
//!
//! Entering a link, all four turn by the same two rotations ([`CarriedMotion::turn`]), which is
//! most of the pass's work on them. One state keeps `w`, `w_dot` and `g` side by side in the
//! lanes of one register per component ([`PackedMotion`]), so that their turn is four vector
//! operations rather than twelve; `a`, which every link then changes by its own length, stays in
//! numbers of its own, so that its update is not held up by moving lanes in and out of those
//! registers. A batch keeps one register of states a number ([`SeparateMotion`]). Every number
//! gets the same operations in the same order in both, so the bits agree.

use lane_math::{Lane, Pack};
use pulp::Simd;

/// The quantity `w` ([`CarriedMotion::get`]).
pub(crate) const OMEGA: usize = 0;
/// The quantity `w_dot`.
pub(crate) const OMEGA_DOT: usize = 1;
/// The quantity `g`, gravity.
pub(crate) const GRAVITY: usize = 2;
/// The quantity `a`, the acceleration of the joint point.
pub(crate) const ACCEL: usize = 3;

/// `w`, `w_dot`, `g` and `a` (the quantities [`OMEGA`], [`OMEGA_DOT`], [`GRAVITY`], [`ACCEL`]),
/// three components each, in one link's frame.
pub(crate) trait CarriedMotion: Copy {
    /// One number of each state.
    type Value: Lane;

    /// Turns all four from a parent frame into its child's, turned from it by `(sin, cos)` in
    /// the plane of axes `(a, b)` ([`to_child`]).
    fn turn(&mut self, plane: [usize; 2], sin: Self::Value, cos: Self::Value);

    /// Component `d` of quantity `q`.
    fn get(&self, q: usize, d: usize) -> Self::Value;

    /// Sets component `d` of quantity `q`.
    fn set(&mut self, q: usize, d: usize, value: Self::Value);

    /// The three components of quantity `q`.
    #[inline(always)]
    fn vector(&self, q: usize) -> [Self::Value; 3] {
        [self.get(q, 0), self.get(q, 1), self.get(q, 2)]
    }
}

/// Each number on its own: `[quantity][component]`.
#[derive(Clone, Copy)]
pub(crate) struct SeparateMotion<V>([[V; 3]; 4]);

impl<V: Lane> SeparateMotion<V> {
    /// At rest (`w`, `w_dot`, `a` zero) under `gravity`.
    #[inline(always)]
    pub(crate) fn at_rest(zero: V, gravity: [V; 3]) -> Self {
        let mut motion = Self([[zero; 3]; 4]);
        motion.0[GRAVITY] = gravity;
        motion
    }
}

impl<V: Lane> CarriedMotion for SeparateMotion<V> {
    type Value = V;

    #[inline(always)]
    fn turn(&mut self, plane: [usize; 2], sin: V, cos: V) {
        for v in &mut self.0 {
            to_child(v, plane, sin, cos);
        }
    }

    #[inline(always)]
    fn get(&self, q: usize, d: usize) -> V {
        self.0[q][d]
    }

    #[inline(always)]
    fn set(&mut self, q: usize, d: usize, value: V) {
        self.0[q][d] = value;
    }
}

/// One state in registers of `S` (at least three lanes): register `d` holds component `d` of
/// `w`, `w_dot` and `g`, quantity `q` in lane `q`; `a` in numbers of its own.
#[derive(Clone, Copy)]
pub(crate) struct PackedMotion<S: Simd> {
    simd: S,
    components: [Pack<S>; 3],
    accel: [f64; 3],
}

impl<S: Simd> PackedMotion<S> {
    /// At rest (`w`, `w_dot`, `a` zero) under `gravity`.
    #[inline(always)]
    pub(crate) fn at_rest(simd: S, gravity: [f64; 3]) -> Self {
        let zero = Pack::splat(simd, 0.0);
        Self {
            simd,
            components: gravity.map(|g| zero.with_lane(GRAVITY, g)),
            accel: [0.0; 3],
        }
    }
}

impl<S: Simd> CarriedMotion for PackedMotion<S> {
    type Value = f64;

    #[inline(always)]
    fn turn(&mut self, plane: [usize; 2], sin: f64, cos: f64) {
        let simd = self.simd;
        to_child(
            &mut self.components,
            plane,
            Pack::splat(simd, sin),
            Pack::splat(simd, cos),
        );
        to_child(&mut self.accel, plane, sin, cos);
    }

    #[inline(always)]
    fn get(&self, q: usize, d: usize) -> f64 {
        if q == ACCEL {
            return self.accel[d];
        }
        self.components[d].lane(q)
    }

    #[inline(always)]
    fn set(&mut self, q: usize, d: usize, value: f64) {
        if q == ACCEL {
            self.accel[d] = value;
            return;
        }
        self.components[d] = self.components[d].with_lane(q, value);
    }
}

/// Vector `v` (three numbers or three rows of registers) turned from a parent frame into its
/// child's, turned from it by `(sin, cos)` in the plane of axes `(a, b)`: `v_a' = c v_a + s v_b`,
/// `v_b' = c v_b - s v_a`.
#[inline(always)]
pub(crate) fn to_child<L: Lane>(v: &mut [L], [a, b]: [usize; 2], sin: L, cos: L) {
    let (va, vb) = (v[a], v[b]);
    v[a] = vb.mul_add(sin, va * cos);
    v[b] = va.neg_mul_add(sin, vb * cos);
}
