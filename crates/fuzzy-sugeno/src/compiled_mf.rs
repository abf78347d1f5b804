//! A validated membership function in the form the evaluation kernel reads
//! ([`CompiledMf`]), built by [`MembershipFn::compile`](crate::MembershipFn): the cheapest exact
//! formula of each shape (for example repeated squaring instead of `powf` for the paper's bell).

use lane_math::Lane;

/// The largest exponent `2 b` evaluated by repeated squaring; larger or non-integer ones use `powf`.
pub(crate) const MAX_INTEGER_BELL_EXPONENT: f64 = 64.0;

/// A validated membership function in evaluation form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CompiledMf {
    /// Bell with `b = 1`: `1 / (1 + u^2)`, `u = (x - c) / a`.
    BellSquare { center: f64, width: f64 },
    /// Bell with `b = 2` (the paper's): `1 / (1 + (u^2)^2)`.
    BellQuartic { center: f64, width: f64 },
    /// Bell with an integer exponent `2 b <= 64`: `|u|^(2b)` by repeated squaring.
    BellInteger {
        center: f64,
        width: f64,
        exponent: u32,
    },
    /// Any other bell: `|u|^(2b)` by `powf`.
    BellReal {
        center: f64,
        width: f64,
        exponent: f64,
    },
    /// `exp(-(x - c)^2 * k)` with `k = 1 / (2 sigma^2)`.
    Gaussian { center: f64, k: f64 },
    /// Two-sided Gaussian (MATLAB's `gauss2mf`).
    Gaussian2 {
        center1: f64,
        k1: f64,
        center2: f64,
        k2: f64,
    },
    /// `trimf`.
    Triangle { left: f64, peak: f64, right: f64 },
    /// `trapmf`.
    Trapezoid { a: f64, b: f64, c: f64, d: f64 },
    /// `sigmf`.
    Sigmoid { slope: f64, center: f64 },
    /// `dsigmf`.
    SigmoidDifference {
        slope1: f64,
        center1: f64,
        slope2: f64,
        center2: f64,
    },
    /// `psigmf`.
    SigmoidProduct {
        slope1: f64,
        center1: f64,
        slope2: f64,
        center2: f64,
    },
    /// `smf`, or its step when `a >= b`.
    SShape { start: f64, end: f64 },
    /// `zmf`, or its step when `a >= b`.
    ZShape { start: f64, end: f64 },
    /// `pimf`: `smf(x, [a b]) * zmf(x, [c d])`.
    PiShape { a: f64, b: f64, c: f64, d: f64 },
    /// `constant`.
    Constant(f64),
}

impl CompiledMf {
    /// The degrees of membership of the points of `x` (one or a SIMD register of them): the
    /// integer bells branch-free on all lanes at once, the other kinds by [`eval`](Self::eval)
    /// lane by lane. Either way each lane gets exactly what `eval` gives for it.
    #[inline(always)]
    pub(crate) fn eval_lane<L: Lane>(&self, cx: L::Context, x: L) -> L {
        match *self {
            Self::BellSquare { center, width } => bell(cx, x, center, width, |u| u * u),
            Self::BellQuartic { center, width } => bell(cx, x, center, width, |u| {
                let u2 = u * u;
                u2 * u2
            }),
            Self::BellInteger {
                center,
                width,
                exponent,
            } => bell(cx, x, center, width, |u| {
                integer_power(cx, u.abs(), exponent)
            }),
            _ => x.map(|x| self.eval(x)),
        }
    }

    /// The degree of membership of `x` (finite `x`; never NaN for finite `x`).
    #[inline]
    pub(crate) fn eval(&self, x: f64) -> f64 {
        match *self {
            Self::BellSquare { .. } | Self::BellQuartic { .. } | Self::BellInteger { .. } => {
                self.eval_lane((), x)
            }
            Self::BellReal {
                center,
                width,
                exponent,
            } => 1.0 / (1.0 + ((x - center) / width).abs().powf(exponent)),
            Self::Gaussian { center, k } => gaussian(x, center, k),
            Self::Gaussian2 {
                center1,
                k1,
                center2,
                k2,
            } => {
                let left = if x <= center1 {
                    gaussian(x, center1, k1)
                } else {
                    1.0
                };
                let right = if x >= center2 {
                    gaussian(x, center2, k2)
                } else {
                    1.0
                };
                left * right
            }
            Self::Triangle { left, peak, right } => {
                if x == peak {
                    1.0
                } else if x <= left || x >= right {
                    0.0
                } else if x < peak {
                    (x - left) / (peak - left)
                } else {
                    (right - x) / (right - peak)
                }
            }
            Self::Trapezoid { a, b, c, d } => {
                let (rising, falling) = trapezoid_sides(x, a, b, c, d);
                rising.min(falling)
            }
            Self::Sigmoid { slope, center } => sigmoid(x, slope, center),
            Self::SigmoidDifference {
                slope1,
                center1,
                slope2,
                center2,
            } => (sigmoid(x, slope1, center1) - sigmoid(x, slope2, center2)).abs(),
            Self::SigmoidProduct {
                slope1,
                center1,
                slope2,
                center2,
            } => sigmoid(x, slope1, center1) * sigmoid(x, slope2, center2),
            Self::SShape { start, end } => s_shape(x, start, end),
            Self::ZShape { start, end } => z_shape(x, start, end),
            Self::PiShape { a, b, c, d } => s_shape(x, a, b) * z_shape(x, c, d),
            Self::Constant(value) => value,
        }
    }
}

/// The rising and falling sides of `trapmf [a b c d]` at `x`: the degree is their minimum.
#[inline]
pub(crate) fn trapezoid_sides(x: f64, a: f64, b: f64, c: f64, d: f64) -> (f64, f64) {
    let rising = if x >= b {
        1.0
    } else if x < a {
        0.0
    } else {
        (x - a) / (b - a)
    };
    let falling = if x <= c {
        1.0
    } else if x > d {
        0.0
    } else {
        (d - x) / (d - c)
    };
    (rising, falling)
}

/// MATLAB's `smf(x, [a b])`: the quadratic spline from 0 at `a` to 1 at `b` (value 1/2 at the
/// midpoint), or the step `x >= (a + b) / 2` when `a >= b`.
#[inline]
pub(crate) fn s_shape(x: f64, a: f64, b: f64) -> f64 {
    let middle = 0.5 * (a + b);
    if a >= b {
        return if x >= middle { 1.0 } else { 0.0 };
    }
    if x <= a {
        0.0
    } else if x <= middle {
        let t = (x - a) / (b - a);
        2.0 * t * t
    } else if x <= b {
        let t = (b - x) / (b - a);
        1.0 - 2.0 * t * t
    } else {
        1.0
    }
}

/// MATLAB's `zmf(x, [a b])`: the quadratic spline from 1 at `a` to 0 at `b`, or the step
/// `x <= (a + b) / 2` when `a >= b`.
#[inline]
pub(crate) fn z_shape(x: f64, a: f64, b: f64) -> f64 {
    let middle = 0.5 * (a + b);
    if a >= b {
        return if x <= middle { 1.0 } else { 0.0 };
    }
    if x <= a {
        1.0
    } else if x <= middle {
        let t = (x - a) / (b - a);
        1.0 - 2.0 * t * t
    } else if x <= b {
        let t = (b - x) / (b - a);
        2.0 * t * t
    } else {
        0.0
    }
}

#[inline]
fn gaussian(x: f64, center: f64, k: f64) -> f64 {
    let d = x - center;
    (-(d * d) * k).exp()
}

/// MATLAB's `sigmf(x, [a c])`: `1 / (1 + exp(-a (x - c)))`.
#[inline]
pub(crate) fn sigmoid(x: f64, slope: f64, center: f64) -> f64 {
    1.0 / (1.0 + (-slope * (x - center)).exp())
}

/// The generalized bell `1 / (1 + power(u))`, `u = (x - center) / width`, `power(u)` standing
/// for `|u|^(2b)`.
#[inline(always)]
fn bell<L: Lane>(cx: L::Context, x: L, center: f64, width: f64, power: impl Fn(L) -> L) -> L {
    let u = (x - L::splat(cx, center)) / L::splat(cx, width);
    let one = L::splat(cx, 1.0);
    one / (one + power(u))
}

/// `base^exponent` by repeated squaring (exponentiation by squaring), no `powf`.
#[inline(always)]
pub(crate) fn integer_power<L: Lane>(cx: L::Context, mut base: L, mut exponent: u32) -> L {
    let mut result = L::splat(cx, 1.0);
    while exponent > 0 {
        if exponent & 1 == 1 {
            result = result * base;
        }
        base = base * base;
        exponent >>= 1;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MembershipFn;

    #[test]
    fn integer_slopes_are_compiled_without_powf() {
        let compile = |b: f64| MembershipFn::bell(1.0, b, 0.0).compile().unwrap();
        assert!(matches!(compile(1.0), CompiledMf::BellSquare { .. }));
        assert!(matches!(compile(2.0), CompiledMf::BellQuartic { .. }));
        assert!(matches!(
            compile(1.5),
            CompiledMf::BellInteger { exponent: 3, .. }
        ));
        assert!(matches!(
            compile(32.0),
            CompiledMf::BellInteger { exponent: 64, .. }
        ));
        assert!(matches!(compile(32.5), CompiledMf::BellReal { .. }));
        assert!(matches!(compile(0.3), CompiledMf::BellReal { .. }));
        // Exponentiation by squaring is exact for powers of two and small integers.
        assert_eq!(integer_power((), 1.5, 0), 1.0);
        assert_eq!(integer_power((), 1.5, 5), 7.59375);
        assert_eq!(integer_power((), 2.0, 64), 2f64.powi(64));
    }
}
