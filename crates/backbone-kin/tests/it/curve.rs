//! The backbone curve against independent algorithms: the closed-form end point (eqs 3-4), the
//! Jacobi-Anger (Bessel series) expansion of every point of the two-mode curve, a periodic
//! trapezoid rule and composite Simpson for `K` harmonics, finite differences for eqs 1-2.

use backbone_kin::{BackboneCurve, QUADRATURE_TOLERANCE, end_point};
use proptest::prelude::*;
use std::f64::consts::{PI, TAU};
use test_support::config::expensive;

/// `J_n(x)` for any integer `n`, with `J_{-n} = (-1)^n J_n`.
fn bessel(n: i32, x: f64) -> f64 {
    let value = libm::jn(n.abs(), x);
    if n < 0 && n % 2 != 0 { -value } else { value }
}

/// The point at `s` of the two-mode curve from the Jacobi-Anger expansion, independent of any
/// quadrature. With `theta = 2 pi s / l`, `alpha = alpha0 + a2 + A sin(theta - beta)`
/// (`cos beta = a1 / A`, `sin beta = a2 / A`) and `exp(i A sin t) = sum_n J_n(A) exp(i n t)`:
/// `x + i y = exp(i (alpha0 + a2)) [J0(A) s + sum_{n != 0} J_n(A) exp(-i n beta) l (exp(i n theta) - 1) / (2 pi i n)]`.
fn bessel_series_point(length: f64, a1: f64, a2: f64, alpha0: f64, s: f64) -> [f64; 2] {
    let amplitude = a1.hypot(a2);
    let beta = a2.atan2(a1);
    let theta = TAU * s / length;
    let (mut re, mut im) = (bessel(0, amplitude) * s, 0.0);
    for n in (-60..=60).filter(|&n| n != 0) {
        let nf = f64::from(n);
        let c = bessel(n, amplitude) * length / (TAU * nf);
        // c exp(-i n beta) (exp(i n theta) - 1) / i
        let (u_re, u_im) = (
            (nf * (theta - beta)).cos() - (nf * beta).cos(),
            (nf * (theta - beta)).sin() + (nf * beta).sin(),
        );
        re += c * u_im;
        im -= c * u_re;
    }
    let (sin, cos) = (alpha0 + a2).sin_cos();
    [cos * re - sin * im, sin * re + cos * im]
}

fn close(p: [f64; 2], q: [f64; 2], tolerance: f64) -> bool {
    (p[0] - q[0]).abs() <= tolerance && (p[1] - q[1]).abs() <= tolerance
}

#[test]
fn bessel_series_reference_is_itself_right() {
    // Straight curve: the series collapses to s (cos alpha0, sin alpha0).
    let p = bessel_series_point(2.0, 0.0, 0.0, 0.4, 1.5);
    assert!(close(p, [1.5 * 0.4f64.cos(), 1.5 * 0.4f64.sin()], 1e-15));
    // At s = l it reproduces eqs 3-4.
    let p = bessel_series_point(1.0, 0.7, -0.9, 0.2, 1.0);
    assert!(close(p, end_point(1.0, [0.7, -0.9], 0.2).unwrap(), 1e-15));
}

#[test]
fn paper_numbers_closed_form_vs_quadrature() {
    for &(a1, a2, alpha0) in &[
        (0.0, 0.0, 0.0),
        (1.0, 0.5, PI / 2.0),
        (-2.0, 1.0, -1.0),
        (0.3, -2.3, 3.0),
    ] {
        let curve = BackboneCurve::paper(1.0, a1, a2, alpha0).unwrap();
        let quad = curve.point(1.0).unwrap();
        let closed = end_point(1.0, [a1, a2], alpha0).unwrap();
        assert!(
            close(quad, closed, 1e-15),
            "{a1} {a2} {alpha0}: {quad:?} vs {closed:?}"
        );
        assert_eq!(curve.end_point(), closed);
    }
}

proptest! {
    /// Eqs 3-4 (corrected) against quadrature of eq 2, over any amplitude (also past j01).
    #[test]
    fn closed_form_matches_quadrature(
        length in 0.1f64..10.0,
        a1 in -4.0f64..4.0,
        a2 in -4.0f64..4.0,
        alpha0 in -PI..PI,
    ) {
        let curve = BackboneCurve::paper(length, a1, a2, alpha0).unwrap();
        let quad = curve.point(length).unwrap();
        let closed = end_point(length, [a1, a2], alpha0).unwrap();
        prop_assert!(close(quad, closed, 1e-13 * length), "{quad:?} vs {closed:?}");
        prop_assert!(close(quad, closed, 2e-15 * length), "{quad:?} vs {closed:?}");
    }

    /// Every point of the two-mode curve against the Bessel series: the documented accuracy
    /// `QUADRATURE_TOLERANCE * l`, plus rounding.
    #[test]
    fn quadrature_matches_bessel_series_everywhere(
        length in 0.1f64..10.0,
        a1 in -3.0f64..3.0,
        a2 in -3.0f64..3.0,
        alpha0 in -PI..PI,
        fraction in 0.0f64..=1.0,
    ) {
        let curve = BackboneCurve::paper(length, a1, a2, alpha0).unwrap();
        let s = fraction * length;
        let quad = curve.point(s).unwrap();
        let series = bessel_series_point(length, a1, a2, alpha0, s);
        prop_assert!(close(quad, series, QUADRATURE_TOLERANCE * length + 2e-15 * length), "s = {s}: {quad:?} vs {series:?}");
    }

    /// `alpha(0) = alpha0`, `alpha(l) = alpha0` (every harmonic closes), and
    /// `d alpha / ds = kappa` (eq 2 is the integral of eq 1) by central differences.
    #[test]
    fn inclination_is_the_integral_of_curvature(
        length in 0.5f64..5.0,
        modes in prop::collection::vec(-2.0f64..2.0, 1..=4).prop_map(|v| v.iter().flat_map(|&x| [x, 0.7 * x - 0.3]).collect::<Vec<_>>()),
        alpha0 in -PI..PI,
        fraction in 0.01f64..0.99,
    ) {
        let curve = BackboneCurve::new(length, &modes, alpha0).unwrap();
        prop_assert!((curve.inclination(0.0).unwrap() - alpha0).abs() <= 1e-15);
        prop_assert!((curve.inclination(length).unwrap() - alpha0).abs() <= 1e-12);
        let s = fraction * length;
        let h = 1e-5 * length;
        let slope = (curve.inclination(s + h).unwrap() - curve.inclination(s - h).unwrap()) / (2.0 * h);
        let kappa = curve.curvature(s).unwrap();
        prop_assert!((slope - kappa).abs() <= 1e-6 * (1.0 + kappa.abs()), "{slope} vs {kappa}");
    }
}

/// End point of a `K`-harmonic curve by the periodic trapezoid rule: every integrand is
/// `l`-periodic, so `n` equal steps are exact up to harmonics of order `n` (negligible here);
/// compensated (Neumaier) sums keep the rounding at the last bit.
fn trapezoid_end_point(curve: &BackboneCurve, steps: usize) -> [f64; 2] {
    let l = curve.length();
    let mut sum = [(0.0f64, 0.0f64); 2];
    for i in 0..steps {
        let (sin, cos) = curve
            .inclination(l * i as f64 / steps as f64)
            .unwrap()
            .sin_cos();
        for ((total, carry), term) in sum.iter_mut().zip([cos, sin]) {
            let next = *total + term;
            *carry += if total.abs() >= term.abs() {
                (*total - next) + term
            } else {
                (term - next) + *total
            };
            *total = next;
        }
    }
    sum.map(|(total, carry)| (total + carry) * l / steps as f64)
}

/// Composite Simpson's rule on `[0, s]` with `2 m` intervals.
fn simpson_point(curve: &BackboneCurve, s: f64, m: usize) -> [f64; 2] {
    let h = s / (2 * m) as f64;
    let mut sum = [0.0; 2];
    for i in 0..=2 * m {
        let weight = if i == 0 || i == 2 * m {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let (sin, cos) = curve.inclination(i as f64 * h).unwrap().sin_cos();
        sum[0] += weight * cos;
        sum[1] += weight * sin;
    }
    [sum[0] * h / 3.0, sum[1] * h / 3.0]
}

proptest! {
    #![proptest_config(expensive())]

    /// `K` harmonics: the Gauss-Legendre end point against the periodic trapezoid rule, and an
    /// interior point against composite Simpson.
    #[test]
    fn harmonic_curve_matches_independent_rules(
        length in 0.5f64..5.0,
        modes in prop::collection::vec(-1.5f64..1.5, 2..=8).prop_filter("pairs", |v| v.len() % 2 == 0),
        alpha0 in -PI..PI,
        fraction in 0.0f64..1.0,
    ) {
        let curve = BackboneCurve::new(length, &modes, alpha0).unwrap();
        let end = curve.end_point();
        // The same rule summed two ways: equal to the rounding of sums over many panels (a
        // curve of 8 harmonics and 3.5 m differed by 3.8e-15 m, 17 eps * length).
        let at_length = curve.point(length).unwrap();
        prop_assert!(close(end, at_length, 4e-15 * length), "{end:?} vs {at_length:?}");
        let trapezoid = trapezoid_end_point(&curve, 512);
        prop_assert!(close(end, trapezoid, 3e-15 * length), "{end:?} vs {trapezoid:?}");
        let s = fraction * length;
        let simpson = simpson_point(&curve, s, 20_000);
        let quad = curve.point(s).unwrap();
        prop_assert!(close(quad, simpson, 1e-11 * length), "{quad:?} vs {simpson:?}");
    }

    /// The analytic end-point Jacobian against central differences of the end point.
    #[test]
    fn end_point_jacobian_matches_finite_differences(
        length in 0.5f64..5.0,
        modes in prop::collection::vec(-1.5f64..1.5, 2..=6).prop_filter("pairs", |v| v.len() % 2 == 0),
        alpha0 in -PI..PI,
    ) {
        let m = modes.len();
        let curve = BackboneCurve::new(length, &modes, alpha0).unwrap();
        let mut jacobian = vec![0.0; 2 * m];
        let point = curve.end_point_jacobian(&mut jacobian).unwrap();
        prop_assert!(close(point, curve.end_point(), 2e-15 * length));
        let h = 1e-5;
        for j in 0..m {
            let shifted = |delta: f64| {
                let mut c = modes.clone();
                c[j] += delta;
                BackboneCurve::new(length, &c, alpha0).unwrap().end_point()
            };
            let (plus, minus) = (shifted(h), shifted(-h));
            for row in 0..2 {
                let fd = (plus[row] - minus[row]) / (2.0 * h);
                let analytic = jacobian[row * m + j];
                prop_assert!((fd - analytic).abs() <= 1e-8 * length, "d{row}/da{j}: {fd} vs {analytic}");
            }
        }
    }
}

#[test]
fn set_modes_is_the_same_as_a_new_curve() {
    let mut curve = BackboneCurve::new(2.0, &[0.1, 0.2, 0.3, 0.4], 0.5).unwrap();
    curve.set_modes(&[-1.0, 0.5, 0.25, 2.0]).unwrap();
    let fresh = BackboneCurve::new(2.0, &[-1.0, 0.5, 0.25, 2.0], 0.5).unwrap();
    assert_eq!(curve, fresh);
    assert_eq!(
        (curve.harmonics(), curve.length(), curve.alpha0()),
        (2, 2.0, 0.5)
    );
}

#[test]
fn first_harmonic_in_a_larger_family_is_the_paper_curve() {
    // Padding with zero higher harmonics changes nothing: the quadrature end point of the K = 3
    // curve equals the closed form of the K = 1 curve.
    let padded = BackboneCurve::new(1.0, &[1.2, -0.7, 0.0, 0.0, 0.0, 0.0], 0.3).unwrap();
    let paper = end_point(1.0, [1.2, -0.7], 0.3).unwrap();
    assert!(close(padded.end_point(), paper, 1e-15));
    assert!(
        (padded.curvature(0.3).unwrap()
            - BackboneCurve::paper(1.0, 1.2, -0.7, 0.3)
                .unwrap()
                .curvature(0.3)
                .unwrap())
        .abs()
            < 1e-15
    );
}

#[test]
fn curvature_is_eq_1() {
    let (l, a1, a2) = (2.0, 0.8, -0.3);
    let curve = BackboneCurve::paper(l, a1, a2, 0.1).unwrap();
    for s in [0.0, 0.3, 1.0, 1.7, 2.0] {
        let eq1 = TAU / l * (a1 * (TAU * s / l).cos() + a2 * (TAU * s / l).sin());
        assert!((curve.curvature(s).unwrap() - eq1).abs() < 1e-14);
    }
}
