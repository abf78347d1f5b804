//! The premise side of ANFIS: derivatives of every membership function with respect to its
//! parameters (layer 1 of Jang 1993, the `d O / d alpha` of eq 12), and the repair that keeps a
//! function valid after a gradient step.

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
        MembershipFn::Constant { .. } => {}
    }
}

fn sigmoid(x: f64, slope: f64, center: f64) -> f64 {
    1.0 / (1.0 + (-slope * (x - center)).exp())
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
/// is the width of the input's range.
pub(crate) fn repair(mf: &mut MembershipFn, span: f64) {
    let floor = span * MIN_WIDTH_FRACTION;
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
        | MembershipFn::Constant { .. } => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every type with random valid parameters, away from its kinks.
    fn arbitrary_mf() -> impl Strategy<Value = MembershipFn> {
        (0usize..8, prop::array::uniform4(-1.0f64..1.0)).prop_map(|(kind, p)| {
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
                _ => MembershipFn::SigmoidProduct {
                    slope1: 4.0 * p[0],
                    center1: p[1],
                    slope2: 4.0 * p[2],
                    center2: p[3],
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
                    let moved = MembershipFn::from_matlab_unchecked(mf.matlab_name(), &p[..count]);
                    moved.degree(x)
                };
                let (Ok(up), Ok(down)) = (degree_at(h), degree_at(-h)) else { continue };
                // Skip points near a kink, where one side uses the other piece: a corner or
                // shoulder at a parameter, or where dsigmf's |s1 - s2| crosses zero.
                let kinked = params[..count].iter().any(|&q| (x - q).abs() < 1e-4)
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
            let mut moved = MembershipFn::from_matlab_unchecked(mf.matlab_name(), &params[..count]);
            repair(&mut moved, 2.0);
            prop_assert!(moved.validate().is_ok(), "{moved:?}");
        }
    }
}
