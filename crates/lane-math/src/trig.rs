//! Sine and cosine of many angles at once, in a form the compiler vectorises.
//!
//! The default path needs `sin` and `cos` of every link's absolute angle, and a library call per
//! angle is half its cost. Here the whole batch goes through one branch-free loop:
//!
//! 1. Argument reduction (Cody-Waite): `x = k pi/2 + r` with `k` the integer nearest `x 2/pi`
//!    and `|r| <= pi/4`, subtracting `k pi/2` in two parts (`pi/2 = HI + LO`, `HI` with 33
//!    significant bits, so `k HI` and `x - k HI` are exact for `|k| < 2^20`, and `LO` the double
//!    nearest `pi/2 - HI`; `pi/2 - HI - LO` is below `4e-27`), each subtraction one fused
//!    multiply-add ([`Lane::mul_add`], rounded once), so `r` is within an ulp of `x - k pi/2`.
//! 2. Minimax polynomials on `|r| <= pi/4`: `sin r = r + r^3 P(r^2)` and
//!    `cos r = 1 + r^2 (-1/2 + r^2 Q(r^2))`, `P` and `Q` of degree 5, whose coefficients minimise the
//!    largest relative error of `sin` (`3.6e-18`) and the largest error of `cos` (`5.6e-20`);
//!    rounding (about one ulp) dominates. They take two and one fewer multiply-adds than the
//!    Taylor polynomials of the same accuracy (to `r^17` and `r^16`), and are evaluated by
//!    Estrin's scheme, whose chain of dependent operations is half Horner's, in fused
//!    multiply-adds (one operation, and one rounding, where a multiply and an add took two).
//! 3. The quadrant `k mod 4` swaps and negates the pair.
//!
//! Angles beyond `2^19 pi` (where the exact products run out of bits) go to `libm::sincos`.
//! Accuracy: within a few units in the last place of `libm` (tested).

use std::f64::consts::FRAC_2_PI;

use crate::lanes::Lane;

/// The two parts of `pi/2`: `HI` has 33 significant bits, `LO` is the double nearest
/// `pi/2 - HI`.
const PIO2_HI: f64 = 1.5707963267341256;
const PIO2_LO: f64 = 6.077100506506192e-11;

/// The largest `|x|` reduced here, `2^19 pi`: `|k| < 2^20` keeps `k HI` exact. Beyond it,
/// [`sin_cos`] and [`sin_cos_lanes`] call `libm`, and [`sin_cos_in_range`] is wrong.
pub const REDUCTION_LIMIT: f64 = 524288.0 * std::f64::consts::PI;

/// `1.5 2^52`: adding it rounds to an integer, which then sits in the low mantissa bits.
const ROUNDING_SHIFT: f64 = 6755399441055744.0;

/// The coefficients of `P`, `sin r = r + r^3 P(r^2)` on `|r| <= pi/4`, lowest degree first:
/// minimax for the relative error of `sin` (a Remez exchange in `r^2`, then rounded to the
/// nearest doubles). Compared with fdlibm's `__kernel_sin` (`S1` to `S6`, Sun Microsystems
/// 1993), derived the same way: the first agrees to `2e-16` relative, the last (which matters
/// least) to `5e-5`.
const SIN: [f64; 6] = [
    -0.1666666666666663,
    0.008333333333322118,
    -0.0001984126982958954,
    2.7557313621385676e-6,
    -2.5050747762850355e-8,
    1.5896230157221844e-10,
];

/// The coefficients of `Q`, `cos r = 1 - r^2/2 + r^4 Q(r^2)` on `|r| <= pi/4`, lowest degree
/// first: minimax for the error of `cos`, as [`SIN`]. Against fdlibm's `__kernel_cos` (`C1` to
/// `C6`): the first agrees to `2e-16` relative, the last to `1e-4`.
const COS: [f64; 6] = [
    0.041666666666666595,
    -0.0013888888888873056,
    2.48015872888517e-5,
    -2.755731417929574e-7,
    2.0875700841847973e-9,
    -1.1358536515252448e-11,
];

/// The most `f64` lanes of a SIMD register (AVX-512, the widest `pulp` dispatches to).
const MAX_LANES: usize = 8;

/// `sin[i] = sin(angles[i])` and `cos[i] = cos(angles[i])` (slices of equal length). Inlined,
/// so that inside a batch it vectorises with the batch's instruction set.
#[inline(always)]
pub fn sin_cos(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    let (sin, cos) = (&mut sin[..angles.len()], &mut cos[..angles.len()]);
    for ((&x, s), c) in angles.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
        (*s, *c) = sin_cos_in_range((), x);
    }
    redo_large(angles, sin, cos);
}

/// `(sin x, cos x)` in every lane of `x`, as [`sin_cos`] gives them (the same operations, so the
/// same bits): the form for a kernel that already holds its angles in registers (`Pack` inside
/// [`pulp::Arch::dispatch`], or `f64`), so they are not stored and read back. Branch-free but for
/// one test of the register: lanes beyond `2^19 pi` go to `libm`.
#[inline(always)]
pub fn sin_cos_lanes<L: Lane>(context: L::Context, x: L) -> (L, L) {
    let (sin, cos) = sin_cos_in_range(context, x);
    // Every lane within the limit (a NaN is not, and is left as it is below).
    if L::splat(context, REDUCTION_LIMIT.next_up()).all_greater(x.abs()) {
        return (sin, cos);
    }
    let [mut angles, mut sin_out, mut cos_out] = [[0.0; MAX_LANES]; 3];
    x.store(&mut angles);
    sin.store(&mut sin_out);
    cos.store(&mut cos_out);
    let lanes = ..L::WIDTH;
    sin_cos_large(&angles[lanes], &mut sin_out[lanes], &mut cos_out[lanes]);
    (L::load(context, &sin_out), L::load(context, &cos_out))
}

/// Redoes the angles beyond [`REDUCTION_LIMIT`], if any, with `libm`.
#[inline(always)]
fn redo_large(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    // One test of all the angles, without an early exit that would keep it from vectorising.
    if angles
        .iter()
        .fold(false, |large, x| large | (x.abs() > REDUCTION_LIMIT))
    {
        sin_cos_large(angles, sin, cos);
    }
}

/// Redoes the angles beyond [`REDUCTION_LIMIT`] with `libm`.
#[cold]
fn sin_cos_large(angles: &[f64], sin: &mut [f64], cos: &mut [f64]) {
    for ((&x, s), c) in angles.iter().zip(sin.iter_mut()).zip(cos.iter_mut()) {
        if x.abs() > REDUCTION_LIMIT {
            (*s, *c) = libm::sincos(x);
        }
    }
}

/// `(sin x, cos x)` in every lane, for lanes with `|x| <= REDUCTION_LIMIT` only (the caller's
/// guarantee: beyond it the result is wrong, though never unsafe), branch-free (steps 1-3 of the
/// module documentation): [`sin_cos_lanes`] without its test of the register, for a kernel
/// that bounds its angles beforehand. Within the limit, the same bits as the others.
#[inline(always)]
pub fn sin_cos_in_range<L: Lane>(context: L::Context, x: L) -> (L, L) {
    let splat = |c| L::splat(context, c);
    let shifted = x.mul_add(splat(FRAC_2_PI), splat(ROUNDING_SHIFT));
    let k = shifted - splat(ROUNDING_SHIFT);
    let r = k.neg_mul_add(splat(PIO2_LO), k.neg_mul_add(splat(PIO2_HI), x));
    let r2 = r * r;
    let r4 = r2 * r2;
    let sin_tail = estrin(splat, &SIN, r2, r4);
    let cos_tail = estrin(splat, &COS, r2, r4);
    // cos r = 1 + r^2 (-1/2 + r^2 Q(r^2)): one operation fewer than 1 - r^2/2 + r^4 Q(r^2), and
    // as accurate (one rounding of a value of at most 0.31 before the last addition).
    let cos_tail = cos_tail.mul_add(r2, splat(-0.5));
    let sin_r = (r * r2).mul_add(sin_tail, r);
    let cos_r = r2.mul_add(cos_tail, splat(1.0));
    // The low mantissa bits of `shifted` hold k in two's complement, so its bit 0 is k mod 2
    // and its bit 1 that of k div 2: k mod 4 = 0: (s, c); 1: (c, -s); 2: (-s, -c); 3: (-c, s).
    // Selections by bits rather than branches, so that the loops over angles vectorise.
    let (minus, plus) = (splat(-0.0), splat(0.0));
    let sin_sign = shifted.select_by_bits(2, minus, plus);
    let cos_sign = sin_sign.xor_bits(shifted.select_by_bits(1, minus, plus));
    let sin_x = shifted.select_by_bits(1, cos_r, sin_r);
    let cos_x = shifted.select_by_bits(1, sin_r, cos_r);
    (sin_x.xor_bits(sin_sign), cos_x.xor_bits(cos_sign))
}

/// `c[0] + c[1] t + ... + c[5] t^5` with `t2 = t^2`, by Estrin's scheme: three independent
/// pairs, then two steps in `t2`, so that its chain of dependent operations is half Horner's.
#[inline(always)]
fn estrin<L: Lane>(splat: impl Fn(f64) -> L, c: &[f64; 6], t: L, t2: L) -> L {
    let low = t.mul_add(splat(c[1]), splat(c[0]));
    let middle = t.mul_add(splat(c[3]), splat(c[2]));
    let high = t.mul_add(splat(c[5]), splat(c[4]));
    t2.mul_add(t2.mul_add(high, middle), low)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::Pack;
    use proptest::prelude::*;

    /// Both results of both routines (the same bits) against `libm` (within 1 ulp of the exact values) to 3e-16 absolute.
    fn check(angles: &[f64]) -> Result<(), TestCaseError> {
        let [sin, cos] =
            both(angles).map(|v| v.into_iter().map(f64::from_bits).collect::<Vec<_>>());
        for ((&x, s), c) in angles.iter().zip(&sin).zip(&cos) {
            let (s_ref, c_ref) = libm::sincos(x);
            prop_assert!((s - s_ref).abs() <= 3e-16, "sin({x}) = {s}, libm {s_ref}");
            prop_assert!((c - c_ref).abs() <= 3e-16, "cos({x}) = {c}, libm {c_ref}");
        }
        Ok(())
    }

    /// [`sin_cos_lanes`] of `angles`, a register of the processor's instruction set at a time
    /// (the last padded with zeros).
    struct Simd<'a> {
        angles: &'a [f64],
        sin: &'a mut [f64],
        cos: &'a mut [f64],
    }

    impl pulp::WithSimd for Simd<'_> {
        type Output = ();

        fn with_simd<S: pulp::Simd>(self, simd: S) {
            let width = Pack::<S>::WIDTH;
            for (first, angles) in self.angles.chunks(width).enumerate() {
                let mut padded = [0.0; MAX_LANES];
                padded[..angles.len()].copy_from_slice(angles);
                let (sin, cos) = sin_cos_lanes(simd, Pack::<S>::load(simd, &padded));
                let (mut sin_out, mut cos_out) = ([0.0; MAX_LANES], [0.0; MAX_LANES]);
                sin.store(&mut sin_out);
                cos.store(&mut cos_out);
                let range = first * width..first * width + angles.len();
                self.sin[range.clone()].copy_from_slice(&sin_out[..angles.len()]);
                self.cos[range].copy_from_slice(&cos_out[..angles.len()]);
            }
        }
    }

    /// The bits of `(sin, cos)` of `angles` by [`sin_cos`] and by [`sin_cos_lanes`] (which must
    /// agree).
    fn both(angles: &[f64]) -> [Vec<u64>; 2] {
        let n = angles.len();
        let (mut sin, mut cos) = (vec![0.0; n], vec![0.0; n]);
        sin_cos(angles, &mut sin, &mut cos);
        let (mut simd_sin, mut simd_cos) = (vec![0.0; n], vec![0.0; n]);
        pulp::Arch::new().dispatch(Simd {
            angles,
            sin: &mut simd_sin,
            cos: &mut simd_cos,
        });
        let bits = |v: Vec<f64>| v.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        assert_eq!(bits(simd_sin), bits(sin.clone()));
        assert_eq!(bits(simd_cos), bits(cos.clone()));
        [bits(sin), bits(cos)]
    }

    /// `xor_bits` and `select_by_bits` of [`Pack`] lane by lane against `f64`'s.
    struct BitOps<'a> {
        values: &'a [f64; 8],
        others: &'a [f64; 8],
        mask: u64,
    }

    impl pulp::WithSimd for BitOps<'_> {
        type Output = ();

        fn with_simd<S: pulp::Simd>(self, simd: S) {
            let width = Pack::<S>::WIDTH;
            if width > 8 {
                return;
            }
            for first in (0..8).step_by(width) {
                let lanes = first..first + width;
                let x = Pack::<S>::load(simd, &self.values[lanes.clone()]);
                let y = Pack::<S>::load(simd, &self.others[lanes.clone()]);
                let (mut xor, mut select) = ([0.0; 8], [0.0; 8]);
                x.xor_bits(y).store(&mut xor);
                x.select_by_bits(self.mask, x, y).store(&mut select);
                for (lane, i) in lanes.enumerate() {
                    let (x, y) = (self.values[i], self.others[i]);
                    assert_eq!(xor[lane].to_bits(), x.xor_bits(y).to_bits());
                    let expected = x.select_by_bits(self.mask, x, y);
                    assert_eq!(select[lane].to_bits(), expected.to_bits());
                    let set = x.to_bits() & self.mask != 0;
                    assert_eq!(expected.to_bits(), if set { x } else { y }.to_bits());
                }
            }
        }
    }

    proptest! {
        #[test]
        fn simd_matches_scalar_bit_for_bit(angles in prop::collection::vec(-2e6..2e6f64, 0..40)) {
            both(&angles);
        }

        #[test]
        fn pack_bit_operations_match_f64(
            values in prop::array::uniform8(any::<u64>()),
            others in prop::array::uniform8(any::<u64>()),
            mask in any::<u64>(),
        ) {
            let (values, others) = (values.map(f64::from_bits), others.map(f64::from_bits));
            pulp::Arch::new().dispatch(BitOps { values: &values, others: &others, mask });
        }

        #[test]
        fn matches_libm_on_ordinary_angles(angles in prop::collection::vec(-50.0..50.0f64, 1..40)) {
            check(&angles)?;
        }

        #[test]
        fn matches_libm_on_large_angles(angles in prop::collection::vec(-2e6..2e6f64, 1..40)) {
            check(&angles)?;
        }

        #[test]
        fn matches_libm_near_quadrant_boundaries(k in -100_000i64..100_000, offset in -1e-6..1e-6f64) {
            let x = k as f64 * std::f64::consts::FRAC_PI_2 + offset;
            check(&[x, x + std::f64::consts::FRAC_PI_4, x - std::f64::consts::FRAC_PI_4])?;
        }
    }

    /// The polynomials on their whole interval `|r| <= pi/4` (no reduction): a dense grid, and
    /// its ends, against `libm` to `1.2e-16` (about half an ulp of `libm`'s own error plus half an
    /// ulp of rounding near 1), tighter than [`check`]'s `3e-16`.
    #[test]
    fn the_polynomials_are_accurate_on_a_dense_grid() {
        let quarter = std::f64::consts::FRAC_PI_4;
        let points = 200_000;
        let grid: Vec<f64> = (0..=points)
            .map(|i| -quarter + 2.0 * quarter * i as f64 / points as f64)
            .chain([quarter, -quarter, quarter.next_up(), 1e-9, 1e-3])
            .collect();
        let [sin, cos] = both(&grid).map(|v| v.into_iter().map(f64::from_bits).collect::<Vec<_>>());
        let (mut worst_sin, mut worst_cos) = (0.0f64, 0.0f64);
        for ((&x, s), c) in grid.iter().zip(&sin).zip(&cos) {
            let (s_ref, c_ref) = libm::sincos(x);
            worst_sin = worst_sin.max((s - s_ref).abs());
            worst_cos = worst_cos.max((c - c_ref).abs());
            // Near zero, where sin r is r, relative to the value.
            if x.abs() <= 1e-3 {
                assert!(
                    (s - s_ref).abs() <= 2.3e-16 * s_ref.abs(),
                    "sin({x}) = {s}, libm {s_ref}"
                );
            }
        }
        assert!(worst_sin <= 1.2e-16, "sin: {worst_sin:e}");
        assert!(worst_cos <= 1.2e-16, "cos: {worst_cos:e}");
    }

    #[test]
    fn special_values() {
        check(&[
            0.0,
            -0.0,
            1e-300,
            5e-324,
            REDUCTION_LIMIT,
            -REDUCTION_LIMIT,
            1e300,
        ])
        .unwrap();
        let (mut s, mut c) = ([0.0; 2], [0.0; 2]);
        sin_cos(&[f64::NAN, f64::INFINITY], &mut s, &mut c);
        assert!(s.iter().chain(&c).all(|v| v.is_nan()));
        // A register with a NaN, infinities and an angle beyond the reduction among ordinary
        // ones: the same bits both ways (`both` asserts it), and NaN where there is no value.
        let mixed = [
            0.5,
            f64::NAN,
            f64::INFINITY,
            -3e6,
            -f64::INFINITY,
            1.0,
            2.0,
            3.0,
            4.0,
        ];
        let [sin, cos] = both(&mixed);
        for (i, &x) in mixed.iter().enumerate() {
            let (s, c) = (f64::from_bits(sin[i]), f64::from_bits(cos[i]));
            assert_eq!(s.is_nan() && c.is_nan(), !x.is_finite(), "{x}: {s}, {c}");
        }
    }
}
