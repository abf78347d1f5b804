//! The premise side of ANFIS: derivatives of every membership function with respect to its
//! parameters (layer 1 of Jang 1993, the `d O / d alpha` of eq 12), and the repair that keeps a
//! function valid after a gradient step.

use crate::compiled_mf::{s_shape, sigmoid, trapezoid_sides, z_shape};
use crate::membership::MembershipFn;

/// Writes `d mu / d p` at `x` into `grad`, for the parameters `p` in MATLAB's order; `mu` is the
/// degree at `x`. Where a function has a kink (triangle corners, the shoulders of `gauss2mf`),
/// the derivative of the piece MATLAB's formula evaluates is used. A constant degree has no
/// trainable parameter (its gradient is zero).
pub(crate) fn gradient(mf: &MembershipFn, x: f64, mu: f64, grad: &mut [f64; 4]) {
    *grad = [0.0; 4];
    match *mf {
        MembershipFn::Bell {
            width,
            slope,
            center,
        } => {
            // mu = 1 / (1 + t), t = |u|^(2b), u = (x - c) / a; d mu / d t = -mu^2 and
            // mu^2 t = mu (1 - mu), which stays finite where t overflows.
            let u = (x - center) / width;
            if u == 0.0 {
                return;
            }
            let g = mu * (1.0 - mu);
            grad[0] = g * 2.0 * slope / width;
            grad[1] = -g * 2.0 * u.abs().ln();
            grad[2] = g * 2.0 * slope / (u * width);
        }
        MembershipFn::Gaussian { sigma, center } => {
            let d = x - center;
            grad[0] = mu * d * d / (sigma * sigma * sigma);
            grad[1] = mu * d / (sigma * sigma);
        }
        MembershipFn::Gaussian2 {
            sigma1,
            center1,
            sigma2,
            center2,
        } => {
            let side = |x: f64, s: f64, c: f64| {
                let d = x - c;
                let g = (-d * d / (2.0 * s * s)).exp();
                (g, g * d * d / (s * s * s), g * d / (s * s))
            };
            let (left, dl_ds, dl_dc) = if x <= center1 {
                side(x, sigma1, center1)
            } else {
                (1.0, 0.0, 0.0)
            };
            let (right, dr_ds, dr_dc) = if x >= center2 {
                side(x, sigma2, center2)
            } else {
                (1.0, 0.0, 0.0)
            };
            *grad = [dl_ds * right, dl_dc * right, left * dr_ds, left * dr_dc];
        }
        MembershipFn::Triangle { left, peak, right } => {
            if x > left && x < peak {
                let w = peak - left;
                grad[0] = (x - peak) / (w * w);
                grad[1] = -(x - left) / (w * w);
            } else if x > peak && x < right {
                let w = right - peak;
                grad[1] = (right - x) / (w * w);
                grad[2] = (x - peak) / (w * w);
            }
        }
        MembershipFn::Trapezoid {
            left_foot: a,
            left_shoulder: b,
            right_shoulder: c,
            right_foot: d,
        } => {
            // mu = min(rising, falling): the smaller side carries the derivative.
            let (rising, falling) = trapezoid_sides(x, a, b, c, d);
            if rising <= falling && x >= a && x < b {
                let w = b - a;
                grad[0] = (x - b) / (w * w);
                grad[1] = -(x - a) / (w * w);
            } else if falling < rising && x > c && x <= d {
                let w = d - c;
                grad[2] = (d - x) / (w * w);
                grad[3] = (x - c) / (w * w);
            }
        }
        MembershipFn::Sigmoid { slope, center } => {
            let (ds_da, ds_dc) = sigmoid_gradient(x, slope, center);
            grad[0] = ds_da;
            grad[1] = ds_dc;
        }
        MembershipFn::SigmoidDifference {
            slope1,
            center1,
            slope2,
            center2,
        } => {
            let (s1, s2) = (sigmoid(x, slope1, center1), sigmoid(x, slope2, center2));
            let sign = if s1 >= s2 { 1.0 } else { -1.0 };
            let (d1a, d1c) = sigmoid_gradient(x, slope1, center1);
            let (d2a, d2c) = sigmoid_gradient(x, slope2, center2);
            *grad = [sign * d1a, sign * d1c, -sign * d2a, -sign * d2c];
        }
        MembershipFn::SigmoidProduct {
            slope1,
            center1,
            slope2,
            center2,
        } => {
            let (s1, s2) = (sigmoid(x, slope1, center1), sigmoid(x, slope2, center2));
            let (d1a, d1c) = sigmoid_gradient(x, slope1, center1);
            let (d2a, d2c) = sigmoid_gradient(x, slope2, center2);
            *grad = [d1a * s2, d1c * s2, s1 * d2a, s1 * d2c];
        }
        MembershipFn::SShape { start, end } => {
            let (da, db) = s_shape_gradient(x, start, end);
            grad[0] = da;
            grad[1] = db;
        }
        MembershipFn::ZShape { start, end } => {
            // zmf = 1 - smf where a < b; both are constant steps otherwise.
            let (da, db) = s_shape_gradient(x, start, end);
            grad[0] = -da;
            grad[1] = -db;
        }
        MembershipFn::PiShape {
            left_foot: a,
            left_shoulder: b,
            right_shoulder: c,
            right_foot: d,
        } => {
            // pimf = smf(a, b) zmf(c, d).
            let (rising, falling) = (s_shape(x, a, b), z_shape(x, c, d));
            let (da, db) = s_shape_gradient(x, a, b);
            let (dc, dd) = s_shape_gradient(x, c, d);
            *grad = [da * falling, db * falling, -dc * rising, -dd * rising];
        }
        MembershipFn::Constant { .. } => {}
    }
}

/// `(d mu / d a, d mu / d b)` of MATLAB's `smf(x, [a b])`: on the rising half
/// `mu = 2 t^2`, `t = (x - a) / (b - a)`; on the upper half `mu = 1 - 2 s^2`,
/// `s = (b - x) / (b - a)`; zero outside `(a, b]` and for the step `a >= b`. At the middle
/// `(a + b) / 2` the rising half is the piece MATLAB evaluates.
fn s_shape_gradient(x: f64, a: f64, b: f64) -> (f64, f64) {
    if a >= b || x <= a || x > b {
        return (0.0, 0.0);
    }
    let w = b - a;
    if x <= 0.5 * (a + b) {
        let t = (x - a) / w;
        (4.0 * t * (x - b) / (w * w), -4.0 * t * (x - a) / (w * w))
    } else {
        let s = (b - x) / w;
        (-4.0 * s * (b - x) / (w * w), -4.0 * s * (x - a) / (w * w))
    }
}

/// `(d s / d a, d s / d c)` of `s = 1 / (1 + exp(-a (x - c)))`.
fn sigmoid_gradient(x: f64, slope: f64, center: f64) -> (f64, f64) {
    let s = sigmoid(x, slope, center);
    let ds = s * (1.0 - s);
    (ds * (x - center), -ds * slope)
}

/// The smallest width, sigma or foot-to-foot distance a step may leave, as a fraction of the
/// input's range.
const MIN_WIDTH_FRACTION: f64 = 1e-6;
/// The smallest bell slope `b` a step may leave.
const MIN_BELL_SLOPE: f64 = 1e-3;

/// Moves the parameters of `mf` back to valid values after a gradient step: positive widths,
/// sigmas and bell slopes, triangle and trapezoid corners in order with the feet apart. `span`
/// is the width of the input's range. `before` is the function before the step: a spline of
/// `smf`, `zmf` or either side of `pimf` that was one (`a < b`) stays one, with its ends at
/// least the floor apart, rather than turning into the step `a >= b` (whose gradient is zero,
/// so it would never move again); a step stays a step, since its parameters never move.
pub(crate) fn repair(mf: &mut MembershipFn, before: &MembershipFn, span: f64) {
    let floor = span * MIN_WIDTH_FRACTION;
    // Keeps `(a, b)` a spline with `b - a >= floor` if `was_spline`.
    let spline = |a: &mut f64, b: &mut f64, was_spline: bool| {
        if was_spline {
            if *a > *b {
                std::mem::swap(a, b);
            }
            *b = b.max(*a + floor);
        }
    };
    match (mf, *before) {
        (
            MembershipFn::SShape { start, end } | MembershipFn::ZShape { start, end },
            MembershipFn::SShape {
                start: was_start,
                end: was_end,
            }
            | MembershipFn::ZShape {
                start: was_start,
                end: was_end,
            },
        ) => spline(start, end, was_start < was_end),
        (
            MembershipFn::PiShape {
                left_foot,
                left_shoulder,
                right_shoulder,
                right_foot,
            },
            MembershipFn::PiShape {
                left_foot: a,
                left_shoulder: b,
                right_shoulder: c,
                right_foot: d,
            },
        ) => {
            spline(left_foot, left_shoulder, a < b);
            spline(right_shoulder, right_foot, c < d);
        }
        (mf, _) => repair_shape(mf, floor),
    }
}

/// [`repair`] for the shapes whose validity does not depend on the function before the step.
fn repair_shape(mf: &mut MembershipFn, floor: f64) {
    match mf {
        MembershipFn::Bell { width, slope, .. } => {
            *width = width.max(floor);
            *slope = slope.max(MIN_BELL_SLOPE);
        }
        MembershipFn::Gaussian { sigma, .. } => *sigma = sigma.max(floor),
        MembershipFn::Gaussian2 { sigma1, sigma2, .. } => {
            *sigma1 = sigma1.max(floor);
            *sigma2 = sigma2.max(floor);
        }
        MembershipFn::Triangle { left, peak, right } => {
            let mut p = [*left, *peak, *right];
            p.sort_by(f64::total_cmp);
            p[2] = p[2].max(p[0] + floor);
            [*left, *peak, *right] = p;
        }
        MembershipFn::Trapezoid {
            left_foot,
            left_shoulder,
            right_shoulder,
            right_foot,
        } => {
            let mut p = [*left_foot, *left_shoulder, *right_shoulder, *right_foot];
            p.sort_by(f64::total_cmp);
            p[3] = p[3].max(p[0] + floor);
            [*left_foot, *left_shoulder, *right_shoulder, *right_foot] = p;
        }
        MembershipFn::Sigmoid { .. }
        | MembershipFn::SigmoidDifference { .. }
        | MembershipFn::SigmoidProduct { .. }
        | MembershipFn::SShape { .. }
        | MembershipFn::ZShape { .. }
        | MembershipFn::PiShape { .. }
        | MembershipFn::Constant { .. } => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every type with random valid parameters, away from its kinks.
    fn arbitrary_mf() -> impl Strategy<Value = MembershipFn> {
        (0usize..11, prop::array::uniform4(-1.0f64..1.0)).prop_map(|(kind, p)| {
            let mut s = p;
            s.sort_by(f64::total_cmp);
            let spread = |k: usize| s[0] + 0.5 * k as f64 + (s[k] - s[0]) * 0.1;
            match kind {
                0 => MembershipFn::bell(0.2 + p[0].abs(), 0.5 + 2.0 * p[1].abs(), p[2]),
                1 => MembershipFn::gaussian(0.2 + p[0].abs(), p[1]),
                2 => MembershipFn::Gaussian2 {
                    sigma1: 0.2 + p[0].abs(),
                    center1: p[1],
                    sigma2: 0.2 + p[2].abs(),
                    center2: p[3],
                },
                3 => MembershipFn::triangle(spread(0), spread(1), spread(2)),
                4 => MembershipFn::trapezoid(spread(0), spread(1), spread(2), spread(3)),
                5 => MembershipFn::sigmoid(4.0 * p[0], p[1]),
                6 => MembershipFn::SigmoidDifference {
                    slope1: 4.0 * p[0],
                    center1: p[1],
                    slope2: 4.0 * p[2],
                    center2: p[3],
                },
                7 => MembershipFn::SigmoidProduct {
                    slope1: 4.0 * p[0],
                    center1: p[1],
                    slope2: 4.0 * p[2],
                    center2: p[3],
                },
                // A spline, or the step a >= b when p[3] > 0.6.
                8 | 9 => {
                    let (a, b) = (spread(0), spread(1));
                    let (start, end) = if p[3] > 0.6 { (b, a) } else { (a, b) };
                    if kind == 8 {
                        MembershipFn::SShape { start, end }
                    } else {
                        MembershipFn::ZShape { start, end }
                    }
                }
                _ => MembershipFn::PiShape {
                    left_foot: spread(0),
                    left_shoulder: spread(1),
                    right_shoulder: spread(2),
                    right_foot: spread(3),
                },
            }
        })
    }

    proptest! {
        /// Central differences of the evaluator's own degree (the compiled form every system
        /// uses) agree with the analytic gradient, away from kinks.
        #[test]
        fn gradient_matches_finite_differences(mf in arbitrary_mf(), x in -1.5f64..1.5) {
            let (params, count) = mf.param_array();
            let mu = mf.degree(x).unwrap();
            let mut grad = [0.0; 4];
            gradient(&mf, x, mu, &mut grad);
            for k in 0..count {
                let h = 1e-6;
                let degree_at = |delta: f64| {
                    let mut p = params;
                    p[k] += delta;
                    let moved = mf.with_params(&p[..count]);
                    moved.degree(x)
                };
                let (Ok(up), Ok(down)) = (degree_at(h), degree_at(-h)) else { continue };
                // Skip points near a kink, where one side uses the other piece: a corner or
                // shoulder at a parameter, or where dsigmf's |s1 - s2| crosses zero.
                // For smf, zmf and pimf the middle of each spline, and the step, are kinks too.
                let middles = match mf {
                    MembershipFn::SShape { start, end } | MembershipFn::ZShape { start, end } => {
                        [0.5 * (start + end); 2]
                    }
                    MembershipFn::PiShape { left_foot, left_shoulder, right_shoulder, right_foot } => {
                        [0.5 * (left_foot + left_shoulder), 0.5 * (right_shoulder + right_foot)]
                    }
                    _ => [f64::NAN; 2],
                };
                let kinked = params[..count].iter().chain(&middles).any(|&q| (x - q).abs() < 1e-4)
                    || (matches!(mf, MembershipFn::SigmoidDifference { .. }) && mu < 1e-4);
                prop_assume!(!kinked);
                let numeric = (up - down) / (2.0 * h);
                prop_assert!(
                    (numeric - grad[k]).abs() < 1e-6 * (1.0 + numeric.abs()),
                    "{mf:?} at {x}: d/dp{k} numeric {numeric}, analytic {}", grad[k]
                );
            }
        }

        /// Whatever a step does to the parameters, the repaired function validates.
        #[test]
        fn repair_restores_validity(mf in arbitrary_mf(), step in prop::array::uniform4(-3.0f64..3.0)) {
            let (mut params, count) = mf.param_array();
            for (p, s) in params.iter_mut().zip(step) {
                *p += s;
            }
            let mut moved = mf.with_params(&params[..count]);
            repair(&mut moved, &mf, 2.0);
            prop_assert!(moved.validate().is_ok(), "{moved:?}");
            // A spline of smf, zmf or pimf stays a spline.
            let pairs = |f: &MembershipFn| -> Vec<(f64, f64)> {
                let (p, _) = f.param_array();
                match f {
                    MembershipFn::SShape { .. } | MembershipFn::ZShape { .. } => vec![(p[0], p[1])],
                    MembershipFn::PiShape { .. } => vec![(p[0], p[1]), (p[2], p[3])],
                    _ => vec![],
                }
            };
            for ((a0, b0), (a1, b1)) in pairs(&mf).into_iter().zip(pairs(&moved)) {
                if a0 < b0 {
                    prop_assert!(b1 - a1 >= 2.0 * MIN_WIDTH_FRACTION * (1.0 - 1e-9), "{moved:?}");
                }
            }
        }
    }
}
