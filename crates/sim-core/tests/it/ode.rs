//! The integrators against closed-form solutions: measured order of convergence, tolerance
//! control, exact landing on interval ends, and every error path.

use proptest::prelude::*;
use sim_core::ode::{DormandPrince, OdeError, OdeSystem, Rk4, Tolerances};
use std::convert::Infallible;

/// `x'' = -w^2 x`: exact solution `x = x0 cos(w t) + v0/w sin(w t)`.
struct Oscillator {
    w: f64,
}

impl OdeSystem for Oscillator {
    type Error = Infallible;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        dy[0] = y[1];
        dy[1] = -self.w * self.w * y[0];
        Ok(())
    }
}

/// `y' = -lambda y + sin(w t)`: non-autonomous, with a closed form.
struct Forced {
    lambda: f64,
    w: f64,
}

impl Forced {
    /// The exact solution from `y(0) = y0`.
    fn exact(&self, y0: f64, t: f64) -> f64 {
        let (l, w) = (self.lambda, self.w);
        let d = l * l + w * w;
        let particular = |t: f64| (l * (w * t).sin() - w * (w * t).cos()) / d;
        (y0 - particular(0.0)) * (-l * t).exp() + particular(t)
    }
}

impl OdeSystem for Forced {
    type Error = Infallible;
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        dy[0] = -self.lambda * y[0] + (self.w * t).sin();
        Ok(())
    }
}

/// Fails once `t` passes `fail_after`.
struct Failing {
    fail_after: f64,
}

impl OdeSystem for Failing {
    type Error = String;
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), String> {
        if t > self.fail_after {
            return Err(format!("refused at {t}"));
        }
        dy[0] = -y[0];
        Ok(())
    }
}

/// `y' = y^2` from `y(0) = 1` blows up at `t = 1`.
struct BlowUp;

impl OdeSystem for BlowUp {
    type Error = Infallible;
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Infallible> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}

/// DP5 forced to take steps of exactly `h`: an error test that always accepts.
fn fixed_step_dp5(dim: usize, h: f64) -> DormandPrince {
    DormandPrince::new(
        dim,
        Tolerances {
            rtol: 1e300,
            atol: 1e300,
            h_init: Some(h),
            h_max: h,
            ..Tolerances::default()
        },
    )
}

fn oscillator_error_rk4(h: f64) -> f64 {
    let mut y = [1.0, 0.0];
    let t1 = 10.0;
    Rk4::new(2)
        .integrate(&mut Oscillator { w: 1.0 }, 0.0, t1, &mut y, h)
        .unwrap();
    (y[0] - t1.cos()).hypot(y[1] + t1.sin())
}

#[test]
fn rk4_converges_with_order_four() {
    let errors: Vec<f64> = [0.1, 0.05, 0.025, 0.0125]
        .iter()
        .map(|&h| oscillator_error_rk4(h))
        .collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            (order - 4.0).abs() < 0.1,
            "RK4 order {order}, errors {errors:?}"
        );
    }
}

#[test]
fn dormand_prince_converges_with_order_five() {
    let t1 = 10.0;
    let error = |steps: usize| {
        let mut y = [1.0, 0.0];
        let stats = fixed_step_dp5(2, t1 / steps as f64)
            .integrate(&mut Oscillator { w: 1.0 }, 0.0, t1, &mut y)
            .unwrap();
        assert_eq!(stats.accepted, steps);
        (y[0] - t1.cos()).hypot(y[1] + t1.sin())
    };
    let errors: Vec<f64> = [50, 100, 200, 400].iter().map(|&n| error(n)).collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            (order - 5.0).abs() < 0.1,
            "DP5 order {order}, errors {errors:?}"
        );
    }
    // One step: local error O(h^6).
    let local = |h: f64| {
        let mut y = [1.0, 0.0];
        fixed_step_dp5(2, h)
            .integrate(&mut Oscillator { w: 1.0 }, 0.0, h, &mut y)
            .unwrap();
        (y[0] - h.cos()).hypot(y[1] + h.sin())
    };
    let order = (local(0.4) / local(0.2)).log2();
    assert!((order - 6.0).abs() < 0.15, "DP5 local order {order}");
}

#[test]
fn dormand_prince_respects_its_tolerance() {
    let system = Forced {
        lambda: 1.0,
        w: 2.0,
    };
    let mut previous_error = f64::INFINITY;
    let mut steps = Vec::new();
    for tol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
        let mut solver = DormandPrince::new(
            1,
            Tolerances {
                rtol: tol,
                atol: tol,
                ..Tolerances::default()
            },
        );
        let mut y = [1.0];
        let mut sys = Forced { ..system };
        let stats = solver.integrate(&mut sys, 0.0, 10.0, &mut y).unwrap();
        let error = (y[0] - system.exact(1.0, 10.0)).abs();
        assert!(error < 10.0 * tol, "tol {tol}: error {error}");
        assert!(error < previous_error, "tighter tolerance, larger error");
        previous_error = error;
        steps.push(stats.accepted as f64);
    }
    // Local error ~ h^5 per unit tolerance: steps grow like tol^(-1/5), x10 per 1e-5.
    let growth = steps[4] / steps[1];
    assert!((5.0..20.0).contains(&growth), "steps {steps:?}");
}

#[test]
fn dormand_prince_uses_first_same_as_last() {
    let mut solver = DormandPrince::new(2, Tolerances::default());
    let mut y = [1.0, 0.0];
    let stats = solver
        .integrate(&mut Oscillator { w: 2.0 }, 0.0, 7.0, &mut y)
        .unwrap();
    // One evaluation for stage 1, one for the starting-step estimate, then six per attempt.
    let attempts = stats.accepted + stats.rejected;
    assert_eq!(stats.evaluations, 2 + 6 * attempts);
    assert!(stats.accepted > 10);
}

#[test]
fn integrators_land_exactly_on_sample_times() {
    let exact = |t: f64| [t.cos(), -t.sin()];
    let mut rk4 = Rk4::new(2);
    let mut dp5 = DormandPrince::new(
        2,
        Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
            ..Tolerances::default()
        },
    );
    let (mut y_rk4, mut y_dp5) = ([1.0, 0.0], [1.0, 0.0]);
    let period = 0.013;
    for k in 0..300 {
        let (t0, t1) = (k as f64 * period, (k + 1) as f64 * period);
        let s = rk4
            .integrate(&mut Oscillator { w: 1.0 }, t0, t1, &mut y_rk4, 0.005)
            .unwrap();
        assert_eq!(s.accepted, 3);
        dp5.integrate(&mut Oscillator { w: 1.0 }, t0, t1, &mut y_dp5)
            .unwrap();
    }
    let e = exact(300.0 * period);
    assert!((y_rk4[0] - e[0]).abs() < 1e-9 && (y_rk4[1] - e[1]).abs() < 1e-9);
    assert!((y_dp5[0] - e[0]).abs() < 1e-10 && (y_dp5[1] - e[1]).abs() < 1e-10);
    // A span that is a whole number of steps up to rounding takes exactly that many steps.
    let mut y = [1.0, 0.0];
    let s = rk4
        .integrate(&mut Oscillator { w: 1.0 }, 0.3, 0.3 + 1e-4, &mut y, 1e-4)
        .unwrap();
    assert_eq!(s.accepted, 1);
}

#[test]
fn start_derivative_is_the_right_hand_side_at_the_start() {
    let mut rk4 = Rk4::new(2);
    let mut dp5 = DormandPrince::new(2, Tolerances::default());
    let mut y = [0.5, -0.25];
    rk4.integrate(&mut Oscillator { w: 2.0 }, 0.0, 1.0, &mut y.clone(), 0.1)
        .unwrap();
    dp5.integrate(&mut Oscillator { w: 2.0 }, 0.0, 1.0, &mut y)
        .unwrap();
    assert_eq!(rk4.start_derivative(), &[-0.25, -2.0]);
    assert_eq!(dp5.start_derivative(), &[-0.25, -2.0]);
}

#[test]
fn right_hand_side_errors_propagate_with_their_time() {
    let mut y = [1.0];
    let err = Rk4::new(1)
        .integrate(&mut Failing { fail_after: 0.5 }, 0.0, 1.0, &mut y, 0.1)
        .unwrap_err();
    match err {
        OdeError::Rhs { t, source } => {
            assert!(t > 0.5 && t <= 0.6 + 1e-12, "t = {t}");
            assert!(source.starts_with("refused at"));
        }
        other => panic!("unexpected {other:?}"),
    }
    let mut y = [1.0];
    let err = DormandPrince::new(1, Tolerances::default())
        .integrate(&mut Failing { fail_after: 0.5 }, 0.0, 1.0, &mut y)
        .unwrap_err();
    assert!(matches!(err, OdeError::Rhs { t, .. } if t > 0.5));
    assert!(err.to_string().contains("right-hand side failed"));
}

#[test]
fn blow_up_is_reported_not_returned_as_garbage() {
    let mut y = [1.0];
    let err = Rk4::new(1)
        .integrate(&mut BlowUp, 0.0, 2.0, &mut y, 0.01)
        .unwrap_err();
    assert!(
        matches!(err, OdeError::NonFinite { t } if t > 0.9),
        "{err:?}"
    );
    let mut y = [1.0];
    let err = DormandPrince::new(1, Tolerances::default())
        .integrate(&mut BlowUp, 0.0, 2.0, &mut y)
        .unwrap_err();
    match err {
        OdeError::StepTooSmall { t, .. } => assert!((t - 1.0).abs() < 1e-3, "t = {t}"),
        OdeError::MaxSteps { t, .. } => assert!((t - 1.0).abs() < 1e-3, "t = {t}"),
        other => panic!("unexpected {other:?}"),
    }
    // The state is left at the last accepted point, finite.
    assert!(y[0].is_finite() && y[0] > 1e3);
}

#[test]
fn step_limits_are_enforced() {
    let mut y = [1.0, 0.0];
    let tol = Tolerances {
        max_steps: 5,
        rtol: 1e-10,
        atol: 1e-10,
        ..Tolerances::default()
    };
    let err = DormandPrince::new(2, tol)
        .integrate(&mut Oscillator { w: 1.0 }, 0.0, 100.0, &mut y)
        .unwrap_err();
    assert!(matches!(err, OdeError::MaxSteps { max_steps: 5, .. }));
    let tol = Tolerances {
        h_min: 0.5,
        h_init: Some(0.5),
        rtol: 1e-12,
        atol: 1e-12,
        ..Tolerances::default()
    };
    let err = DormandPrince::new(2, tol)
        .integrate(&mut Oscillator { w: 1.0 }, 0.0, 10.0, &mut y)
        .unwrap_err();
    assert!(
        matches!(err, OdeError::StepTooSmall { h_min: 0.5, .. }),
        "{err:?}"
    );
}

#[test]
fn bad_calls_are_refused() {
    let mut osc = Oscillator { w: 1.0 };
    let mut rk4 = Rk4::new(2);
    let mut dp5 = DormandPrince::new(2, Tolerances::default());
    let mut short = [1.0];
    assert!(matches!(
        rk4.integrate(&mut osc, 0.0, 1.0, &mut short, 0.1),
        Err(OdeError::Dimension {
            expected: 2,
            found: 1
        })
    ));
    assert!(matches!(
        dp5.integrate(&mut osc, 0.0, 1.0, &mut short),
        Err(OdeError::Dimension {
            expected: 2,
            found: 1
        })
    ));
    let mut y = [1.0, 0.0];
    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            rk4.integrate(&mut osc, 0.0, 1.0, &mut y, h),
            Err(OdeError::InvalidSetting(_))
        ));
    }
    assert!(matches!(
        rk4.integrate(&mut osc, 1.0, 0.0, &mut y, 0.1),
        Err(OdeError::InvalidSetting(_))
    ));
    // A step that would take more than MAX_RK4_STEPS steps (hours of work) is refused at once.
    let refused = rk4
        .integrate(&mut osc, 0.0, 1.0, &mut y, 1e-12)
        .unwrap_err();
    assert!(refused.to_string().contains("MAX_RK4_STEPS"), "{refused}");
    assert_eq!(y, [1.0, 0.0]);
    assert!(matches!(
        dp5.integrate(&mut osc, 0.0, f64::NAN, &mut y),
        Err(OdeError::InvalidSetting(_))
    ));
    let mut nan = [f64::NAN, 0.0];
    assert!(matches!(
        dp5.integrate(&mut osc, 0.0, 1.0, &mut nan),
        Err(OdeError::NonFinite { t: 0.0 })
    ));
    for tol in [
        Tolerances {
            rtol: 0.0,
            ..Tolerances::default()
        },
        Tolerances {
            atol: -1.0,
            ..Tolerances::default()
        },
        Tolerances {
            h_max: 0.0,
            ..Tolerances::default()
        },
        Tolerances {
            h_min: 1.0,
            h_max: 0.5,
            ..Tolerances::default()
        },
        Tolerances {
            h_init: Some(0.0),
            ..Tolerances::default()
        },
        Tolerances {
            max_steps: 0,
            ..Tolerances::default()
        },
    ] {
        let err = DormandPrince::new(2, tol)
            .integrate(&mut osc, 0.0, 1.0, &mut y)
            .unwrap_err();
        assert!(matches!(err, OdeError::InvalidTolerance { .. }), "{tol:?}");
    }
    // An empty interval is no work, not an error.
    let stats = dp5.integrate(&mut osc, 2.0, 2.0, &mut y).unwrap();
    assert_eq!(stats.evaluations, 0);
    assert_eq!(y, [1.0, 0.0]);
}

proptest! {
    #[test]
    fn dormand_prince_matches_closed_form(
        lambda in 0.05f64..20.0,
        w in 0.1f64..10.0,
        y0 in -5.0f64..5.0,
        t1 in 0.1f64..20.0,
    ) {
        let system = Forced { lambda, w };
        let mut sys = Forced { lambda, w };
        let mut y = [y0];
        let tol = Tolerances { rtol: 1e-10, atol: 1e-10, ..Tolerances::default() };
        DormandPrince::new(1, tol).integrate(&mut sys, 0.0, t1, &mut y).unwrap();
        let exact = system.exact(y0, t1);
        prop_assert!((y[0] - exact).abs() < 1e-8 * (1.0 + exact.abs()), "{} vs {}", y[0], exact);
    }

    #[test]
    fn rk4_matches_closed_form(w in 0.1f64..5.0, x0 in -2.0f64..2.0, v0 in -2.0f64..2.0) {
        let mut y = [x0, v0];
        let t1 = 3.0;
        Rk4::new(2).integrate(&mut Oscillator { w }, 0.0, t1, &mut y, 1e-3).unwrap();
        let exact = x0 * (w * t1).cos() + v0 / w * (w * t1).sin();
        // Global error ~ t1 (w h)^4 / 120 per unit amplitude, far below 1e-9 here.
        prop_assert!((y[0] - exact).abs() < 1e-9 * (1.0 + x0.abs() + v0.abs() / w));
    }
}
