//! Quadrature rules with a-priori error bounds for entire integrands.
//!
//! The integrands of this crate (`cos alpha(s)`, `sin alpha(s)` and their derivatives along the
//! modal coordinates) are entire functions of the arc length whose growth in a horizontal strip
//! `|Im s| <= sigma` is known in closed form, `|f| <= M(sigma)`. Two rules use that bound:
//!
//! - Composite Gauss-Legendre, for any interval: on a panel of width `h` the `p`-point rule errs
//!   by at most `(h / 2) (64 / 15) M rho^(-2p) / (rho^2 - 1)` when `f` is bounded by `M` in the
//!   Bernstein ellipse `E_rho` of the panel (Trefethen, *Approximation Theory and Approximation
//!   Practice*, Thm 19.3), and that ellipse fits in the strip when `(h / 4)(rho - 1 / rho) <=
//!   sigma`. Summed over panels of total width `S`: `error <= (32 / 15) S M rho^(-2p)` whenever
//!   `rho >= sqrt(2)`.
//! - The trapezoid rule over a full period `l` (the whole curve: every harmonic is
//!   `l`-periodic): `N` equally spaced nodes err by at most `2 l M / (exp(2 pi sigma N / l) - 1)`
//!   (Trefethen and Weideman, *The exponentially convergent trapezoidal rule*, SIAM Review 2014,
//!   Thm 3.2). It needs several times fewer nodes than Gauss-Legendre for the same bound.
//!
//! [`resolution`] picks, for a tolerance, the widest Gauss-Legendre panel and the fewest
//! trapezoid nodes, optimising each over `sigma`.

/// Number of Gauss-Legendre points per panel.
pub(crate) const ORDER: usize = 10;

/// The non-negative nodes of the 10-point Gauss-Legendre rule on `[-1, 1]` (roots of `P_10`).
const NODES: [f64; ORDER / 2] = [
    0.148_874_338_981_631_22,
    0.433_395_394_129_247_2,
    0.679_409_568_299_024_4,
    0.865_063_366_688_984_5,
    0.973_906_528_517_171_7,
];

/// The weights `2 / ((1 - x^2) P_10'(x)^2)` matching [`NODES`].
const WEIGHTS: [f64; ORDER / 2] = [
    0.295_524_224_714_752_87,
    0.269_266_719_309_996_35,
    0.219_086_362_515_982_04,
    0.149_451_349_150_580_6,
    0.066_671_344_308_688_14,
];

/// Calls `visit(s, w)` for every node `s` and weight `w` of the composite rule on `[start, end]`
/// with equal panels no wider than `max_width`, so that `sum w f(s)` approximates the integral
/// of `f`. Allocation-free.
pub(crate) fn for_each_node(start: f64, end: f64, max_width: f64, mut visit: impl FnMut(f64, f64)) {
    let span = end - start;
    if span <= 0.0 {
        return;
    }
    // `max_width` is positive and `span / max_width` is bounded by the caller's panel budget.
    let panels = (span / max_width).ceil().max(1.0) as usize;
    let width = span / panels as f64;
    let half = 0.5 * width;
    for panel in 0..panels {
        let centre = start + (panel as f64 + 0.5) * width;
        for (&x, &w) in NODES.iter().zip(&WEIGHTS) {
            visit(centre - half * x, half * w);
            visit(centre + half * x, half * w);
        }
    }
}

/// Calls `visit(s, w)` for the `nodes` equally spaced nodes `s = i l / nodes` of the trapezoid
/// rule over one period `[0, l)`, all with weight `w = l / nodes`. Allocation-free.
pub(crate) fn for_each_periodic_node(period: f64, nodes: usize, mut visit: impl FnMut(f64, f64)) {
    let weight = period / nodes as f64;
    for i in 0..nodes {
        visit(i as f64 * weight, weight);
    }
}

/// How finely to sample an integrand for a given absolute tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Resolution {
    /// Widest Gauss-Legendre panel (see [`for_each_node`]) that meets the tolerance over any
    /// interval of length at most the period; 0 if no strip gives a finite bound.
    pub(crate) panel_width: f64,
    /// Fewest trapezoid nodes (see [`for_each_periodic_node`]) that meet the tolerance over one
    /// period; infinite if no strip gives a finite bound.
    pub(crate) periodic_nodes: f64,
}

/// The [`Resolution`] for an `period`-periodic integrand bounded by `exp(log_bound(sigma))` in the
/// strip `|Im s| <= sigma`, to within `tolerance` (absolute). `log_bound` must be convex and
/// non-decreasing in `sigma` (as `sum_k A_k sinh(2 pi k sigma / l)` is).
///
/// `sigma` is searched on a geometric grid `scale * 2^(j/2) / 16`, `j = 1..=24`; `scale` should be
/// the integrand's shortest length scale (the period of its fastest harmonic divided by `2 pi`).
pub(crate) fn resolution(
    period: f64,
    scale: f64,
    tolerance: f64,
    log_bound: impl Fn(f64) -> f64,
) -> Resolution {
    // Gauss: rho^(2p) >= (32 / 15) S M / tolerance with S <= period, and rho >= sqrt(2).
    let log_gauss = (32.0 / 15.0 * period / tolerance).ln();
    // Trapezoid: exp(2 pi sigma N / l) >= 1 + 2 l M / tolerance, implied by >= 4 l M / tolerance.
    let log_periodic = (4.0 * period / tolerance).ln();
    let (mut best_width, mut best_nodes) = (0.0f64, f64::INFINITY);
    let mut sigma = scale / 16.0;
    for _ in 0..24 {
        sigma *= std::f64::consts::SQRT_2;
        let log_m = log_bound(sigma);
        if !log_m.is_finite() {
            break; // no usable bound in this or any wider strip (overflow, or NaN from inf * 0)
        }
        let log_rho = ((log_gauss + log_m) / (2 * ORDER) as f64).max(std::f64::consts::LN_2 / 2.0);
        // Ellipse half-height (h / 4)(rho - 1 / rho) must not exceed sigma.
        let rho = log_rho.exp();
        let width = 4.0 * sigma / (rho - rho.recip());
        let nodes = (log_periodic + log_m) * period / (std::f64::consts::TAU * sigma);
        // Both criteria are unimodal in sigma (log_bound is convex and non-decreasing): once
        // neither improves, wider strips only get worse.
        if width <= best_width && nodes >= best_nodes {
            break;
        }
        best_width = best_width.max(width);
        best_nodes = best_nodes.min(nodes);
    }
    Resolution {
        panel_width: best_width,
        periodic_nodes: best_nodes.ceil().max(1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `P_10(x)` and `P_10'(x)` by the three-term recurrence.
    fn legendre_10(x: f64) -> (f64, f64) {
        let (mut p0, mut p1) = (1.0, x);
        for k in 1..ORDER {
            let k = k as f64;
            let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
            p0 = p1;
            p1 = p2;
        }
        let n = ORDER as f64;
        (p1, n * (x * p1 - p0) / (x * x - 1.0))
    }

    #[test]
    fn nodes_are_roots_of_p10_and_weights_match() {
        for (&x, &w) in NODES.iter().zip(&WEIGHTS) {
            let (p, dp) = legendre_10(x);
            // The Newton correction to the node is below rounding: x is the root to the last ulp.
            assert!((p / dp).abs() <= f64::EPSILON * x, "P_10({x}) = {p}");
            let exact = 2.0 / ((1.0 - x * x) * dp * dp);
            assert!((w - exact).abs() < 1e-15, "weight at {x}: {w} vs {exact}");
        }
    }

    #[test]
    fn integrates_polynomials_up_to_degree_19_exactly() {
        for degree in 0..2 * ORDER as i32 {
            let mut sum = 0.0;
            for_each_node(0.0, 1.0, 1.0, |s, w| sum += w * s.powi(degree));
            let exact = 1.0 / f64::from(degree + 1);
            assert!(
                (sum - exact).abs() < 2e-16,
                "degree {degree}: {sum} vs {exact}"
            );
        }
        // Degree 20 is not exact: the rule really has order 10.
        let mut sum = 0.0;
        for_each_node(0.0, 1.0, 1.0, |s, w| sum += w * s.powi(20));
        assert!((sum - 1.0 / 21.0).abs() > 1e-12);
    }

    #[test]
    fn composite_rule_splits_into_equal_panels() {
        let mut count = 0;
        let mut total = 0.0;
        for_each_node(1.0, 3.5, 1.0, |s, w| {
            assert!((1.0..=3.5).contains(&s));
            count += 1;
            total += w;
        });
        assert_eq!(count, 3 * ORDER);
        assert!((total - 2.5).abs() < 1e-15);
        for_each_node(2.0, 2.0, 1.0, |_, _| panic!("empty interval has no nodes"));
    }

    #[test]
    fn bounds_hold_for_a_periodic_entire_integrand() {
        // f(s) = exp(c cos(2 pi s)) on [0, 1], |f| <= exp(c cosh(2 pi sigma)) in the strip, and
        // int_0^1 f = I0(c); int_0^t f for t < 1 checked against a fine Gauss-Legendre sum.
        let bessel_i0 = |c: f64| {
            (0..60)
                .map(|k| (0.5 * c).powi(2 * k) / (1..=k).map(f64::from).product::<f64>().powi(2))
                .sum::<f64>()
        };
        for c in [0.5, 3.0, 12.0] {
            let f = |s: f64| (c * (std::f64::consts::TAU * s).cos()).exp();
            let scale = 1.0 / std::f64::consts::TAU;
            for tolerance in [1e-3, 1e-6, 1e-10] {
                let bound = |sigma: f64| c * (std::f64::consts::TAU * sigma).cosh();
                let res = resolution(1.0, scale, tolerance, bound);
                assert!(res.panel_width > 0.0 && res.periodic_nodes.is_finite());
                let mut periodic = 0.0;
                for_each_periodic_node(1.0, res.periodic_nodes as usize, |s, w| {
                    periodic += w * f(s)
                });
                let error = (periodic - bessel_i0(c)).abs();
                assert!(
                    error <= tolerance,
                    "c = {c}, tol {tolerance}: trapezoid error {error}"
                );
                let (mut gauss, mut fine) = (0.0, 0.0);
                for_each_node(0.0, 0.7, res.panel_width, |s, w| gauss += w * f(s));
                for_each_node(0.0, 0.7, 1e-3, |s, w| fine += w * f(s));
                let error = (gauss - fine).abs();
                assert!(
                    error <= tolerance,
                    "c = {c}, tol {tolerance}: Gauss error {error}"
                );
            }
        }
    }

    #[test]
    fn periodic_nodes_are_equally_spaced() {
        let mut nodes = Vec::new();
        for_each_periodic_node(2.0, 4, |s, w| nodes.push((s, w)));
        assert_eq!(nodes, [(0.0, 0.5), (0.5, 0.5), (1.0, 0.5), (1.5, 0.5)]);
    }
}
