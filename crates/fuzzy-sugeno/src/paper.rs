//! The paper's controller (section 5, eqs 22-24, Table 1 as corrected in the project's model
//! notes): zero-order Sugeno, product inference, centre-average defuzzifier, four inputs
//! `[da1, da2, a1_dot, a2_dot]` with two bell sets each (N, P), two outputs `[tau1*, tau2*]`.
//!
//! The inputs are measured minus desired (`da = a - a_ref`), the only sign that makes Table 1
//! stabilising. Each output depends on one error/rate pair: `tau1* = f(da1, a1_dot)`,
//! `tau2* = f(da2, a2_dot)`, with (N,N) -> VP, (N,P) -> P, (P,N) -> N, (P,P) -> VN.

use crate::error::FuzzyError;
use crate::membership::MembershipFn;
use crate::system::{FuzzySystem, OutputFn};

/// The paper's controller with its free parameters exposed. The paper gives the ranges and
/// constants (eqs 22-24) but no bell parameters; the defaults are the documented choice
/// `a = r` (half-range), `b = 2`, `c = -r` (N) and `+r` (P).
///
/// ```
/// use fuzzy_sugeno::{PaperController, Evaluator};
/// // Wider bells, a softer controller: override only what you need.
/// let soft = PaperController { width_fraction: 1.5, ..PaperController::default() }.build()?;
/// let mut evaluator = Evaluator::new(soft);
/// let mut tau = [0.0; 2];
/// evaluator.eval(&[0.1, 0.0, 0.0, 0.0], &mut tau)?;
/// assert!(tau[0] < 0.0); // above the reference: push back
/// # Ok::<(), fuzzy_sugeno::FuzzyError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperController {
    /// Half-range `r` of the angle errors `da1`, `da2`: range `[-r, r]` rad (eq 22: 0.3).
    pub error_half_range: f64,
    /// Half-range `r` of the rates `a1_dot`, `a2_dot`: range `[-r, r]` rad/s (eq 22: 1).
    pub rate_half_range: f64,
    /// Bell width `a` as a fraction of the half-range (default 1).
    pub width_fraction: f64,
    /// Bell slope `b` (default 2).
    pub slope: f64,
    /// Bell centres `c = ±centre_fraction * r` (default 1).
    pub centre_fraction: f64,
    /// `tau1*` constants VN, N, P, VP in N m (eq 23: -100, -80, 80, 100).
    pub tau1: [f64; 4],
    /// `tau2*` constants VN, N, P, VP in N m (eq 24: -50, -40, 40, 50).
    pub tau2: [f64; 4],
}

impl Default for PaperController {
    fn default() -> Self {
        Self {
            error_half_range: 0.3,
            rate_half_range: 1.0,
            width_fraction: 1.0,
            slope: 2.0,
            centre_fraction: 1.0,
            tau1: [-100.0, -80.0, 80.0, 100.0],
            tau2: [-50.0, -40.0, 40.0, 50.0],
        }
    }
}

impl PaperController {
    /// Builds the 16-rule system of Table 1; fails if a parameter is invalid (for example a
    /// non-positive width or slope).
    pub fn build(&self) -> Result<FuzzySystem, FuzzyError> {
        let sets = |r: f64| {
            let (a, c) = (self.width_fraction * r, self.centre_fraction * r);
            [
                ("N", MembershipFn::bell(a, self.slope, -c)),
                ("P", MembershipFn::bell(a, self.slope, c)),
            ]
        };
        let terms = |t: [f64; 4]| {
            let [vn, n, p, vp] = t.map(OutputFn::Constant);
            [("VN", vn), ("N", n), ("P", p), ("VP", vp)]
        };
        let range = |t: [f64; 4]| {
            [
                t.iter().copied().fold(f64::INFINITY, f64::min),
                t.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ]
        };
        let (e, v) = (self.error_half_range, self.rate_half_range);
        FuzzySystem::builder("paper")
            .input("da1", [-e, e], sets(e))
            .input("da2", [-e, e], sets(e))
            .input("a1_dot", [-v, v], sets(v))
            .input("a2_dot", [-v, v], sets(v))
            .output("tau1", range(self.tau1), terms(self.tau1))
            .output("tau2", range(self.tau2), terms(self.tau2))
            // Table 1, column by column:  da1   da2   a1_dot a2_dot      tau1  tau2
            .rule(["N", "N", "N", "N"], ["VP", "VP"])
            .rule(["N", "N", "N", "P"], ["VP", "P"])
            .rule(["N", "P", "N", "N"], ["VP", "N"])
            .rule(["N", "P", "N", "P"], ["VP", "VN"])
            .rule(["N", "N", "P", "N"], ["P", "VP"])
            .rule(["N", "N", "P", "P"], ["P", "P"])
            .rule(["N", "P", "P", "N"], ["P", "N"])
            .rule(["N", "P", "P", "P"], ["P", "VN"])
            .rule(["P", "N", "N", "N"], ["N", "VP"])
            .rule(["P", "N", "N", "P"], ["N", "P"])
            .rule(["P", "P", "N", "N"], ["N", "N"])
            .rule(["P", "P", "N", "P"], ["N", "VN"])
            .rule(["P", "N", "P", "N"], ["VN", "VP"])
            .rule(["P", "N", "P", "P"], ["VN", "P"])
            .rule(["P", "P", "P", "N"], ["VN", "N"])
            .rule(["P", "P", "P", "P"], ["VN", "VN"])
            .build()
    }
}

/// The paper's controller with the default bell parameters of [`PaperController`].
pub fn paper_controller() -> FuzzySystem {
    // A test builds the defaults, so this cannot fail.
    PaperController::default()
        .build()
        .expect("the paper's default parameters are valid")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Evaluator, OutOfRange};
    use proptest::prelude::*;

    fn eval(x: [f64; 4]) -> [f64; 2] {
        let mut out = [0.0; 2];
        Evaluator::new(paper_controller())
            .eval(&x, &mut out)
            .unwrap();
        out
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    #[test]
    fn defaults_build() {
        let system = PaperController::default().build().unwrap();
        assert_eq!(system.rules().len(), 16);
        assert_eq!(
            system.inputs()[2].sets[1].membership,
            MembershipFn::bell(1.0, 2.0, 1.0)
        );
        assert_eq!(system.outputs()[1].range, [-50.0, 50.0]);
    }

    // Hand calculations. The rule base is the full grid and the AND is a product, so in eq 21
    // the memberships of the two inputs an output does not depend on factor out:
    //   tau1 = [muN (VP mN + P mP) + muP (N mN + VN mP)] / [(muN + muP)(mN + mP)]
    // with mu the da1 memberships and m the a1_dot memberships (likewise tau2 with da2, a2_dot).

    #[test]
    fn origin_gives_zero() {
        // All memberships are 1/2, and the four constants of each output sum to zero.
        assert_eq!(eval([0.0; 4]), [0.0, 0.0]);
    }

    #[test]
    fn edge_of_the_error_range_by_hand() {
        // da1 = 0.3: muN = 1 / (1 + (0.6 / 0.3)^4) = 1/17, muP = 1. a1_dot = 0: mN = mP = 1/2.
        // tau1 = 90 (muN - muP) / (muN + muP) = 90 (1/17 - 1) / (18/17) = -80.
        let [tau1, tau2] = eval([0.3, 0.0, 0.0, 0.0]);
        assert!(close(tau1, -80.0), "{tau1}");
        assert_eq!(tau2, 0.0);
    }

    #[test]
    fn interior_point_by_hand() {
        // da1 = 0.15: muN = 1 / (1 + 1.5^4) = 16/97, muP = 1 / (1 + 0.5^4) = 16/17.
        // a1_dot = -0.5: mN = 16/17, mP = 16/97.
        // tau1 = [16/97 (100 * 16/17 + 80 * 16/97) - 16/17 (80 * 16/17 + 100 * 16/97)]
        //        / [(16/97 + 16/17)(16/17 + 16/97)] = -3200/57.
        // da2 = -0.1: muN = 1 / (1 + (2/3)^4) = 81/97, muP = 1 / (1 + (4/3)^4) = 81/337.
        // a2_dot = 0.2: mN = 1 / (1 + 1.2^4) = 625/1921, mP = 1 / (1 + 0.8^4) = 625/881.
        // tau2 = [81/97 (50 mN + 40 mP) - 81/337 (40 mN + 50 mP)] / [(81/97 + 81/337)(mN + mP)]
        //      = 7001200/304017.
        let [tau1, tau2] = eval([0.15, -0.1, -0.5, 0.2]);
        assert!(close(tau1, -3200.0 / 57.0), "{tau1}");
        assert!(close(tau2, 7_001_200.0 / 304_017.0), "{tau2}");
    }

    #[test]
    fn each_output_ignores_the_other_pair() {
        let a = eval([0.12, -0.2, 0.4, 0.9]);
        let b = eval([0.12, 0.25, 0.4, -0.6]);
        assert!(close(a[0], b[0]));
        let c = eval([-0.05, -0.2, 0.7, 0.9]);
        assert!(close(a[1], c[1]));
    }

    #[test]
    fn the_table_is_stabilising() {
        // Above the reference and moving away (P, P): the strongest push back.
        let [tau1, tau2] = eval([0.3, 0.3, 1.0, 1.0]);
        assert!(tau1 < -80.0 && tau2 < -40.0);
        let [tau1, tau2] = eval([-0.3, -0.3, -1.0, -1.0]);
        assert!(tau1 > 80.0 && tau2 > 40.0);
    }

    /// The direct formula of eq 21 for one output pair: bells of half-width `r` (error) and
    /// `rv` (rate), slope 2, centred at the range ends; `z` the constants of (N,N), (N,P),
    /// (P,N), (P,P).
    fn by_formula(e: f64, v: f64, r: f64, rv: f64, z: [f64; 4]) -> f64 {
        let bell = |x: f64, c: f64, a: f64| 1.0 / (1.0 + ((x - c) / a).powi(4));
        let (n, p) = (bell(e, -r, r), bell(e, r, r));
        let (vn, vp) = (bell(v, -rv, rv), bell(v, rv, rv));
        (n * vn * z[0] + n * vp * z[1] + p * vn * z[2] + p * vp * z[3]) / ((n + p) * (vn + vp))
    }

    #[test]
    fn out_of_range_inputs_are_evaluated_as_given_by_default_as_matlab_does() {
        // MATLAB's evalfis (and Simulink's Fuzzy Logic Controller block) evaluate an input
        // outside its range as given, with a warning: here da1 = -0.414, outside [-0.3, 0.3].
        let x = [-0.414, -0.263, 0.904, 0.246];
        let tau1 = by_formula(x[0], x[2], 0.3, 1.0, [100.0, 80.0, -80.0, -100.0]);
        let tau2 = by_formula(x[1], x[3], 0.3, 1.0, [50.0, 40.0, -40.0, -50.0]);
        let got = eval(x);
        assert!(close(got[0], tau1) && close(got[1], tau2), "{got:?}");
        assert!((tau1 - 75.933).abs() < 1e-3, "{tau1}");
        // Clamped (the explicit choice), da1 acts like the edge of its range.
        let options = crate::EvalOptions {
            out_of_range: OutOfRange::Clamp,
            ..Default::default()
        };
        let mut clamped = Evaluator::with_options(paper_controller(), options).unwrap();
        let mut out = [0.0; 2];
        clamped.eval(&x, &mut out).unwrap();
        let tau1 = by_formula(-0.3, x[2], 0.3, 1.0, [100.0, 80.0, -80.0, -100.0]);
        assert!(close(out[0], tau1), "{}", out[0]);
        assert!((tau1 - 71.321).abs() < 1e-3, "{tau1}");
        // Far out, clamping saturates the action while the bells evaluated as given fade.
        clamped.eval(&[5.0, 0.0, 0.0, 0.0], &mut out).unwrap();
        assert_eq!(out, eval([0.3, 0.0, 0.0, 0.0]));
        let [far, _] = eval([5.0, 0.0, 0.0, 0.0]);
        assert!(far > -80.0 && far < 0.0, "{far}");
    }

    #[test]
    fn invalid_overrides_are_refused() {
        let error = PaperController {
            slope: 0.0,
            ..PaperController::default()
        }
        .build()
        .unwrap_err();
        assert_eq!(
            error.to_string(),
            "input 'da1' set 'N': gbellmf: slope b must be positive, got 0"
        );
        // A flat table gives a point output range, which MATLAB accepts too (its juggler
        // example has one): tau1 is then 1 everywhere. A non-finite torque is refused.
        let flat = PaperController {
            tau1: [1.0; 4],
            ..PaperController::default()
        }
        .build()
        .unwrap();
        assert_eq!(flat.outputs()[0].range, [1.0, 1.0]);
        let infinite = PaperController {
            tau1: [1.0, 2.0, 3.0, f64::INFINITY],
            ..PaperController::default()
        }
        .build()
        .unwrap_err();
        assert!(
            infinite
                .to_string()
                .starts_with("output 'tau1': range must be finite with min <= max"),
            "{infinite}"
        );
    }

    proptest! {
        #[test]
        fn the_control_surface_is_odd(x in prop::array::uniform4(-2.0f64..2.0)) {
            // N and P are mirror images and Table 1 is antisymmetric, so f(-x) = -f(x), also
            // outside the ranges (clamping is symmetric too).
            let plus = eval(x);
            let minus = eval(x.map(|v| -v));
            for o in 0..2 {
                prop_assert!((plus[o] + minus[o]).abs() <= 1e-12 * 100.0, "{plus:?} vs {minus:?}");
            }
        }
    }
}
