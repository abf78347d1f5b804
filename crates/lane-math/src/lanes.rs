//! The number type the kernels are written in: one state (`f64`) or several states side by side
//! in a SIMD register ([`Pack`]), so that one kernel serves a single state and a batch (in
//! `modal-reduce`, `forward_dynamics` and `forward_dynamics_batch`).
//!
//! Both implementations do exactly the same operations in the same order, so a state gives the
//! same bits whether it is computed alone or in a batch. That includes the fused multiply-adds
//! ([`Lane::mul_add`]): one instruction with AVX2 and AVX-512, the correctly rounded software
//! `fma` without them, rounded once either way.

use std::ops::{Add, Div, Mul, Sub};

use pulp::Simd;

/// A real number of `WIDTH` independent states: the arithmetic of the kernels, plus loads and
/// stores from `[f64]` slices holding the `WIDTH` values side by side.
pub trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Mul<f64, Output = Self>
{
    /// How many states one value holds.
    const WIDTH: usize;
    /// What building a value needs (the SIMD token for [`Pack`], nothing for `f64`).
    type Context: Copy;
    /// `x` in every lane.
    fn splat(context: Self::Context, x: f64) -> Self;
    /// The value whose lanes are `slice[..WIDTH]`.
    fn load(context: Self::Context, slice: &[f64]) -> Self;
    /// Writes the lanes into `slice[..WIDTH]`.
    fn store(self, slice: &mut [f64]);
    /// Whether every lane is positive and finite (a usable pivot).
    fn all_positive_finite(self) -> bool;
    /// Lane by lane, the bitwise exclusive or of the two values' representations: with `-0.0`
    /// in a lane of `other`, flips the sign of that lane of `self`.
    fn xor_bits(self, other: Self) -> Self;
    /// Lane by lane, `if_set` where the representation of `self` has any of the bits of `mask`
    /// set, `if_clear` where it has none.
    fn select_by_bits(self, mask: u64, if_set: Self, if_clear: Self) -> Self;
    /// Whether every lane is greater than the same lane of `other` (false where either is NaN):
    /// one vector compare, for tests inside a kernel's loop.
    fn all_greater(self, other: Self) -> bool;
    /// `self * factor + addend` in every lane, rounded once (a fused multiply-add: one
    /// instruction with AVX2 and AVX-512, the correctly rounded software `fma` without them), so
    /// every instruction set gives the same bits.
    fn mul_add(self, factor: Self, addend: Self) -> Self;
    /// `addend - self * factor` in every lane, rounded once (as [`mul_add`](Self::mul_add)).
    fn neg_mul_add(self, factor: Self, addend: Self) -> Self;
    /// `|x|` in every lane.
    fn abs(self) -> Self;
    /// The smaller of the two values in every lane: `self` where `self < other`, else `other`
    /// (the x86 `minpd` rule, so both implementations agree; it equals `f64::min` unless a lane
    /// holds a NaN or both are zeros).
    fn min(self, other: Self) -> Self;
    /// The larger of the two values in every lane: `self` where `self > other`, else `other`
    /// (the x86 `maxpd` rule; it equals `f64::max` unless a lane holds a NaN or both are zeros).
    fn max(self, other: Self) -> Self;
    /// `f` applied to every lane, one lane at a time: the scalar fallback for what has no SIMD
    /// form (`exp`, `powf`, branchy formulas). Each lane gets exactly `f` of its value.
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
    /// Lane by lane, the bitwise and of the two values' representations: with all bits set in a
    /// lane of `other`, that lane of `self`; with none, `+0.0` (masks lanes out).
    fn and_bits(self, other: Self) -> Self;
    /// The value of lane `index` (`index < WIDTH`), for reading one state's result, or one
    /// coordinate of a register of coordinates.
    fn lane(self, index: usize) -> f64;
}

impl Lane for f64 {
    const WIDTH: usize = 1;
    type Context = ();

    #[inline(always)]
    fn splat((): (), x: f64) -> Self {
        x
    }

    #[inline(always)]
    fn load((): (), slice: &[f64]) -> Self {
        slice[0]
    }

    #[inline(always)]
    fn store(self, slice: &mut [f64]) {
        slice[0] = self;
    }

    #[inline(always)]
    fn all_positive_finite(self) -> bool {
        self > 0.0 && self.is_finite()
    }

    #[inline(always)]
    fn xor_bits(self, other: Self) -> Self {
        f64::from_bits(self.to_bits() ^ other.to_bits())
    }

    #[inline(always)]
    fn select_by_bits(self, mask: u64, if_set: Self, if_clear: Self) -> Self {
        if self.to_bits() & mask != 0 {
            if_set
        } else {
            if_clear
        }
    }

    #[inline(always)]
    fn all_greater(self, other: Self) -> bool {
        self > other
    }

    #[inline(always)]
    fn mul_add(self, factor: Self, addend: Self) -> Self {
        f64::mul_add(self, factor, addend)
    }

    #[inline(always)]
    fn neg_mul_add(self, factor: Self, addend: Self) -> Self {
        f64::mul_add(-self, factor, addend)
    }

    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if self < other { self } else { other }
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        f(self)
    }

    #[inline(always)]
    fn and_bits(self, other: Self) -> Self {
        f64::from_bits(self.to_bits() & other.to_bits())
    }

    #[inline(always)]
    fn lane(self, index: usize) -> f64 {
        debug_assert_eq!(index, 0, "an f64 has one lane");
        self
    }
}

/// `S::F64_LANES` states in one SIMD register of the instruction set `S` (8 with AVX-512, 4 with
/// AVX2, 1 without either), chosen at run time by [`pulp::Arch`].
#[derive(Clone, Copy)]
pub struct Pack<S: Simd> {
    simd: S,
    value: S::f64s,
}

impl<S: Simd> Pack<S> {
    /// The first `m` lanes (`m` at most the register's width) turned by `by`: lane `i < m` of the
    /// result is lane `(i + by) % m` of `self`, the lanes from `m` on are zero. With `by` and `m`
    /// constants the compiler makes it one permutation.
    ///
    /// # Panics
    /// If `m` is more than the register's lanes (a caller's bug: `m` is a constant of the
    /// kernel, not an input).
    #[inline(always)]
    pub fn rotate_lanes(self, by: usize, m: usize) -> Self {
        let lanes: &[f64] = pulp::bytemuck::cast_slice(std::slice::from_ref(&self.value));
        let mut out = Self::splat(self.simd, 0.0);
        let turned: &mut [f64] =
            pulp::bytemuck::cast_slice_mut(std::slice::from_mut(&mut out.value));
        for (i, lane) in turned[..m].iter_mut().enumerate() {
            *lane = lanes[(i + by) % m];
        }
        out
    }

    /// `self` with lane `index` replaced by `value` (one blend or insertion with `index` a
    /// constant).
    ///
    /// # Panics
    /// If `index` is not a lane of the register (a caller's bug: the index is a constant of the
    /// kernel, not an input).
    #[inline(always)]
    pub fn with_lane(mut self, index: usize, value: f64) -> Self {
        let lanes: &mut [f64] =
            pulp::bytemuck::cast_slice_mut(std::slice::from_mut(&mut self.value));
        lanes[index] = value;
        self
    }
}

impl<S: Simd> Add for Pack<S> {
    type Output = Self;

    #[inline(always)]
    fn add(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.add_f64s(self.value, other.value),
        }
    }
}

impl<S: Simd> Sub for Pack<S> {
    type Output = Self;

    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.sub_f64s(self.value, other.value),
        }
    }
}

impl<S: Simd> Mul for Pack<S> {
    type Output = Self;

    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.mul_f64s(self.value, other.value),
        }
    }
}

impl<S: Simd> Div for Pack<S> {
    type Output = Self;

    #[inline(always)]
    fn div(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.div_f64s(self.value, other.value),
        }
    }
}

impl<S: Simd> Mul<f64> for Pack<S> {
    type Output = Self;

    #[inline(always)]
    fn mul(self, other: f64) -> Self {
        self * Self::splat(self.simd, other)
    }
}

impl<S: Simd> Lane for Pack<S> {
    const WIDTH: usize = S::F64_LANES;
    type Context = S;

    #[inline(always)]
    fn splat(simd: S, x: f64) -> Self {
        Self {
            simd,
            value: simd.splat_f64s(x),
        }
    }

    #[inline(always)]
    fn load(simd: S, slice: &[f64]) -> Self {
        Self {
            simd,
            value: S::as_simd_f64s(&slice[..Self::WIDTH]).0[0],
        }
    }

    #[inline(always)]
    fn store(self, slice: &mut [f64]) {
        S::as_mut_simd_f64s(&mut slice[..Self::WIDTH]).0[0] = self.value;
    }

    #[inline(always)]
    fn all_positive_finite(self) -> bool {
        let lanes: &[f64] = pulp::bytemuck::cast_slice(std::slice::from_ref(&self.value));
        lanes.iter().all(|&x| x > 0.0 && x.is_finite())
    }

    #[inline(always)]
    fn xor_bits(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.xor_f64s(self.value, other.value),
        }
    }

    #[inline(always)]
    fn select_by_bits(self, mask: u64, if_set: Self, if_clear: Self) -> Self {
        let simd = self.simd;
        let bits = simd.and_u64s(simd.transmute_u64s_f64s(self.value), simd.splat_u64s(mask));
        let clear = simd.equal_u64s(bits, simd.splat_u64s(0));
        Self {
            simd,
            value: simd.select_f64s(clear, if_clear.value, if_set.value),
        }
    }

    #[inline(always)]
    fn all_greater(self, other: Self) -> bool {
        let simd = self.simd;
        let greater = simd.greater_than_f64s(self.value, other.value);
        let zero = simd.splat_f64s(0.0);
        let every = simd.greater_than_or_equal_f64s(zero, zero);
        // The lanes where `self > other` fails; none when the first of them is past the end.
        simd.first_true_m64s(simd.xor_m64s(greater, every)) == Self::WIDTH
    }

    #[inline(always)]
    fn mul_add(self, factor: Self, addend: Self) -> Self {
        Self {
            simd: self.simd,
            value: self
                .simd
                .mul_add_f64s(self.value, factor.value, addend.value),
        }
    }

    #[inline(always)]
    fn neg_mul_add(self, factor: Self, addend: Self) -> Self {
        Self {
            simd: self.simd,
            value: self
                .simd
                .negate_mul_add_f64s(self.value, factor.value, addend.value),
        }
    }

    #[inline(always)]
    fn abs(self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.abs_f64s(self.value),
        }
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.min_f64s(self.value, other.value),
        }
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.max_f64s(self.value, other.value),
        }
    }

    #[inline(always)]
    fn map(mut self, f: impl Fn(f64) -> f64) -> Self {
        let lanes: &mut [f64] =
            pulp::bytemuck::cast_slice_mut(std::slice::from_mut(&mut self.value));
        for x in lanes {
            *x = f(*x);
        }
        self
    }

    #[inline(always)]
    fn and_bits(self, other: Self) -> Self {
        Self {
            simd: self.simd,
            value: self.simd.and_f64s(self.value, other.value),
        }
    }

    #[inline(always)]
    fn lane(self, index: usize) -> f64 {
        let lanes: &[f64] = pulp::bytemuck::cast_slice(std::slice::from_ref(&self.value));
        lanes[index]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pulp::{Arch, WithSimd};

    /// `all_greater` of every pair of lanes drawn from `values`, against `f64`'s `>` lane by lane,
    /// with the instruction set of this processor.
    struct AllGreater<'a>(&'a [f64]);

    impl WithSimd for AllGreater<'_> {
        type Output = ();

        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) {
            let width = Pack::<S>::WIDTH;
            let values = self.0;
            // Every lane but one holds a passing pair; the other lane holds each case in turn.
            for &a in values {
                for &b in values {
                    for lane in 0..width {
                        let mut left = vec![2.0; width];
                        let mut right = vec![1.0; width];
                        left[lane] = a;
                        right[lane] = b;
                        let got = Pack::load(simd, &left).all_greater(Pack::load(simd, &right));
                        assert_eq!(got, a.all_greater(b), "{a} > {b} in lane {lane} of {width}");
                        assert_eq!(got, a > b);
                    }
                }
            }
        }
    }

    #[test]
    fn all_greater_matches_f64_in_every_lane() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            5e-324,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        Arch::new().dispatch(AllGreater(&values));
        // And with the narrowest registers, whatever this processor has.
        AllGreater(&values).with_simd(pulp::Scalar::new());
    }

    /// Values with both signs, zeros, subnormals, infinities and ties.
    const VALUES: [f64; 12] = [
        -3.5,
        2.25,
        0.0,
        1e-310,
        -1e-310,
        f64::INFINITY,
        f64::NEG_INFINITY,
        7.0,
        7.0,
        -0.125,
        1e300,
        -2.0,
    ];

    /// Every new operation of a [`Pack`] of the processor's widest instruction set against the
    /// `f64` implementation, lane by lane, bit for bit, and the `f64` one against `f64`'s own.
    struct Check;

    impl WithSimd for Check {
        type Output = ();

        fn with_simd<S: Simd>(self, simd: S) {
            let width = Pack::<S>::WIDTH;
            for start in 0..VALUES.len() {
                let a: Vec<f64> = (0..width).map(|i| VALUES[(start + i) % 12]).collect();
                let b: Vec<f64> = (0..width)
                    .map(|i| VALUES[(start + 5 * i + 1) % 12])
                    .collect();
                let (pa, pb) = (Pack::load(simd, &a), Pack::load(simd, &b));
                let mut out = vec![0.0; width];
                let square = |x: f64| x * x - 1.0;
                for (op, expect) in [
                    (
                        pa.abs(),
                        &(|x: f64, _: f64| Lane::abs(x)) as &dyn Fn(f64, f64) -> f64,
                    ),
                    (pa.min(pb), &|x: f64, y: f64| Lane::min(x, y)),
                    (pa.max(pb), &|x: f64, y: f64| Lane::max(x, y)),
                    (pa.map(square), &|x: f64, _: f64| Lane::map(x, square)),
                ] {
                    op.store(&mut out);
                    for i in 0..width {
                        assert_eq!(out[i].to_bits(), expect(a[i], b[i]).to_bits());
                    }
                }
                let mask: Vec<f64> = (0..width)
                    .map(|i| f64::from_bits(if (start + i) % 3 == 0 { !0 } else { 0 }))
                    .collect();
                pa.and_bits(Pack::load(simd, &mask)).store(&mut out);
                for i in 0..width {
                    let expect = Lane::and_bits(a[i], mask[i]);
                    assert_eq!(out[i].to_bits(), expect.to_bits());
                    let kept = if (start + i) % 3 == 0 { a[i] } else { 0.0 };
                    assert_eq!(expect.to_bits(), kept.to_bits());
                    assert_eq!(pa.lane(i).to_bits(), a[i].to_bits());
                    assert_eq!(Lane::lane(a[i], 0).to_bits(), a[i].to_bits());
                }
                // A third operand for the fused multiply-adds.
                let c: Vec<f64> = (0..width)
                    .map(|i| VALUES[(start + 7 * i + 3) % 12])
                    .collect();
                let pc = Pack::load(simd, &c);
                for (op, expect) in [
                    (pa.mul_add(pb, pc), f64::mul_add as fn(f64, f64, f64) -> f64),
                    (pa.neg_mul_add(pb, pc), |x: f64, y: f64, z: f64| {
                        (-x).mul_add(y, z)
                    }),
                ] {
                    op.store(&mut out);
                    for i in 0..width {
                        assert_eq!(out[i].to_bits(), expect(a[i], b[i], c[i]).to_bits());
                    }
                }
                // Rounded once: (1 + 2^-30)(1 - 2^-30) - 1 is -2^-60 exactly, where a multiply
                // and an add would give 0.
                let (x, y) = (1.0 + 2f64.powi(-30), 1.0 - 2f64.powi(-30));
                let fused =
                    Pack::splat(simd, x).mul_add(Pack::splat(simd, y), Pack::splat(simd, -1.0));
                let negated = Pack::splat(simd, -x)
                    .neg_mul_add(Pack::splat(simd, y), Pack::splat(simd, -1.0));
                for i in 0..width {
                    assert_eq!(fused.lane(i), -(2f64.powi(-60)));
                    assert_eq!(negated.lane(i), -(2f64.powi(-60)));
                }
                for i in 0..width {
                    let (x, y, z) = (a[i], b[i], c[i]);
                    assert_eq!(Lane::mul_add(x, y, z).to_bits(), x.mul_add(y, z).to_bits());
                    assert_eq!(
                        Lane::neg_mul_add(x, y, z).to_bits(),
                        (-x).mul_add(y, z).to_bits()
                    );
                }
                for i in 0..width {
                    let (x, y) = (a[i], b[i]);
                    assert_eq!(Lane::abs(x).to_bits(), x.abs().to_bits());
                    assert_eq!(Lane::map(x, square).to_bits(), square(x).to_bits());
                    if !(x == 0.0 && y == 0.0) {
                        assert_eq!(Lane::min(x, y).to_bits(), x.min(y).to_bits());
                        assert_eq!(Lane::max(x, y).to_bits(), x.max(y).to_bits());
                    }
                }
            }
        }
    }

    #[test]
    fn pack_operations_agree_with_f64_in_every_lane() {
        Arch::new().dispatch(Check);
        // The instruction-set-free fallback too.
        Check.with_simd(pulp::Scalar::new());
    }

    /// [`Pack::rotate_lanes`] against the index rule, every width `m` and turn `by`, and
    /// [`Pack::with_lane`], which replaces its lane and keeps the others, on every lane.
    struct LaneMoves;

    impl WithSimd for LaneMoves {
        type Output = ();

        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) {
            let width = Pack::<S>::WIDTH;
            let lanes: Vec<f64> = (0..width).map(|i| 10.0 + i as f64).collect();
            let pack = Pack::load(simd, &lanes);
            let mut got = vec![f64::NAN; width];
            for m in 1..=width {
                for by in 0..=m {
                    pack.rotate_lanes(by, m).store(&mut got);
                    for (i, &x) in got.iter().enumerate() {
                        let want = if i < m { lanes[(i + by) % m] } else { 0.0 };
                        assert_eq!(x, want, "lane {i} of {width}, m = {m}, by = {by}");
                    }
                }
            }
            for index in 0..width {
                pack.with_lane(index, -0.0).store(&mut got);
                for (i, &x) in got.iter().enumerate() {
                    let want = if i == index { -0.0 } else { lanes[i] };
                    let (x, want) = (x.to_bits(), want.to_bits());
                    assert_eq!(x, want, "lane {i} of {width}, with lane {index} replaced");
                }
            }
        }
    }

    #[test]
    fn rotate_lanes_and_with_lane_follow_the_index_rules() {
        Arch::new().dispatch(LaneMoves);
        LaneMoves.with_simd(pulp::Scalar::new());
    }

    #[test]
    fn min_and_max_follow_the_x86_rule_on_zeros() {
        assert_eq!(Lane::min(0.0, -0.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(Lane::min(-0.0, 0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(Lane::max(0.0, -0.0).to_bits(), (-0.0f64).to_bits());
    }
}
