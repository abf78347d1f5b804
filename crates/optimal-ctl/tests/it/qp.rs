//! The polytope projection (least-distance programming by NNLS) and the linearly constrained QP
//! against a general solver: enumeration of every active set's KKT system on random problems,
//! feasible by construction.

use optimal_ctl::{LinearQp, LinearQpFailure, PolytopeProjection, ProjectionFailure};
use proptest::prelude::*;

/// Solves the dense system `a x = b` (`n x n`, row-major) by Gaussian elimination with partial
/// pivoting; `None` when singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    for c in 0..n {
        let pivot = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))?;
        if a[pivot * n + c].abs() < 1e-10 {
            return None;
        }
        for k in 0..n {
            a.swap(c * n + k, pivot * n + k);
        }
        b.swap(c, pivot);
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] -= f * a[c * n + k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for c in (0..n).rev() {
        x[c] = (b[c] - (c + 1..n).map(|k| a[c * n + k] * x[k]).sum::<f64>()) / a[c * n + c];
    }
    Some(x)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The minimiser of `1/2 x^T H x + q^T x` subject to `G x <= g` by enumeration: for every set
/// `S` of at most `m` constraints, the stationary point of the KKT system with `G_S x = g_S`;
/// the feasible candidate of least objective is the optimum (the optimum is the minimiser over
/// the affine hull of its own active face, and every feasible candidate bounds it from above).
fn brute_force(h: &[f64], q: &[f64], rows: &[Vec<f64>], g: &[f64]) -> Option<Vec<f64>> {
    let (p, m) = (rows.len(), q.len());
    let feasible = |x: &[f64]| rows.iter().zip(g).all(|(r, gi)| dot(r, x) <= gi + 1e-9);
    let objective = |x: &[f64]| {
        let quadratic: f64 = (0..m).map(|i| x[i] * dot(&h[i * m..(i + 1) * m], x)).sum();
        0.5 * quadratic + dot(q, x)
    };
    let mut best: Option<(f64, Vec<f64>)> = None;
    for mask in 0u32..(1 << p) {
        let set: Vec<usize> = (0..p).filter(|i| mask & (1 << i) != 0).collect();
        if set.len() > m {
            continue;
        }
        let n = m + set.len();
        let mut kkt = vec![0.0; n * n];
        let mut rhs = vec![0.0; n];
        for i in 0..m {
            kkt[i * n..i * n + m].copy_from_slice(&h[i * m..(i + 1) * m]);
            rhs[i] = -q[i];
        }
        for (s, &c) in set.iter().enumerate() {
            for i in 0..m {
                kkt[i * n + m + s] = rows[c][i];
                kkt[(m + s) * n + i] = rows[c][i];
            }
            rhs[m + s] = g[c];
        }
        let Some(solution) = solve(kkt, rhs, n) else {
            continue;
        };
        let x = &solution[..m];
        if feasible(x) {
            let value = objective(x);
            if best.as_ref().is_none_or(|(b, _)| value < *b) {
                best = Some((value, x.to_vec()));
            }
        }
    }
    best.map(|(_, x)| x)
}

/// Rows of `m` columns and bounds that `inside` satisfies with the given slack.
fn polytope(
    seed_rows: &[Vec<f64>],
    m: usize,
    slack: &[f64],
    inside: &[f64],
) -> (Vec<Vec<f64>>, Vec<f64>) {
    let rows: Vec<Vec<f64>> = seed_rows.iter().map(|r| r[..m].to_vec()).collect();
    let g = rows
        .iter()
        .zip(slack)
        .map(|(r, s)| dot(r, &inside[..m]) + s)
        .collect();
    (rows, g)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn projection_matches_enumeration(
        m in 1usize..5,
        seed_rows in prop::collection::vec(prop::collection::vec(-1.0..1.0f64, 4), 2..11),
        slack in prop::collection::vec(0.0..0.5f64, 11),
        inside in prop::collection::vec(-1.0..1.0f64, 4),
        x0 in prop::collection::vec(-3.0..3.0f64, 4),
    ) {
        let (rows, g) = polytope(&seed_rows, m, &slack, &inside);
        let flat: Vec<f64> = rows.iter().flatten().copied().collect();
        let mut projection = PolytopeProjection::new(m, rows.len());
        let mut x = vec![0.0; m];
        let moved = projection.project(&flat, &g, &x0[..m], &mut x).unwrap();
        let mut identity = vec![0.0; m * m];
        for i in 0..m {
            identity[i * m + i] = 1.0;
        }
        let q: Vec<f64> = x0[..m].iter().map(|v| -v).collect();
        let reference = brute_force(&identity, &q, &rows, &g).unwrap();
        for (a, b) in x.iter().zip(&reference) {
            prop_assert!((a - b).abs() < 1e-7, "{:?} vs {:?}", x, reference);
        }
        let inside_already = rows.iter().zip(&g).all(|(r, gi)| dot(r, &x0[..m]) <= *gi);
        prop_assert_eq!(moved, !inside_already);
    }

    #[test]
    fn a_far_away_constraint_changes_no_projection(
        m in 1usize..5,
        seed_rows in prop::collection::vec(prop::collection::vec(-1.0..1.0f64, 4), 2..11),
        slack in prop::collection::vec(0.0..0.5f64, 11),
        inside in prop::collection::vec(-1.0..1.0f64, 4),
        x0 in prop::collection::vec(-3.0..3.0f64, 4),
        far in prop::collection::vec(-1.0..1.0f64, 4),
        distance in prop::sample::select(vec![1e6, 1e12, 1e100, 1e300]),
    ) {
        // A constraint that holds a long way beyond the polytope (a distant obstacle, a joint
        // left practically unlimited) leaves the closest point where it was, to the rounding.
        let (mut rows, mut g) = polytope(&seed_rows, m, &slack, &inside);
        let flat: Vec<f64> = rows.iter().flatten().copied().collect();
        let mut x = vec![0.0; m];
        PolytopeProjection::new(m, rows.len())
            .project(&flat, &g, &x0[..m], &mut x)
            .unwrap();
        let row = far[..m].to_vec();
        g.push(dot(&row, &x0[..m]).abs() + 10.0 + distance);
        rows.push(row);
        let flat: Vec<f64> = rows.iter().flatten().copied().collect();
        let mut with_far = vec![0.0; m];
        PolytopeProjection::new(m, rows.len())
            .project(&flat, &g, &x0[..m], &mut with_far)
            .unwrap();
        for (a, b) in with_far.iter().zip(&x) {
            prop_assert!((a - b).abs() < 1e-9, "{:?} vs {:?}", with_far, x);
        }
    }

    #[test]
    fn linear_qp_matches_enumeration(
        m in 1usize..5,
        factor in prop::collection::vec(-1.0..1.0f64, 16),
        q in prop::collection::vec(-3.0..3.0f64, 4),
        seed_rows in prop::collection::vec(prop::collection::vec(-1.0..1.0f64, 4), 1..10),
        slack in prop::collection::vec(0.0..0.5f64, 10),
        inside in prop::collection::vec(-1.0..1.0f64, 4),
    ) {
        // H = F F^T + 0.1 I: symmetric positive definite, conditioned up to a few hundred.
        let mut h = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                h[i * m + j] = (0..m).map(|k| factor[i * 4 + k] * factor[j * 4 + k]).sum::<f64>()
                    + if i == j { 0.1 } else { 0.0 };
            }
        }
        let (rows, g) = polytope(&seed_rows, m, &slack, &inside);
        let flat: Vec<f64> = rows.iter().flatten().copied().collect();
        let mut qp = LinearQp::new(m, rows.len());
        let mut x = vec![0.0; m];
        qp.solve(&h, &q[..m], &flat, &g, &mut x).unwrap();
        let reference = brute_force(&h, &q[..m], &rows, &g).unwrap();
        for (a, b) in x.iter().zip(&reference) {
            prop_assert!((a - b).abs() < 1e-6, "{:?} vs {:?}", x, reference);
        }
    }
}

#[test]
fn an_empty_polytope_is_reported() {
    // x <= -1 and x >= 1.
    let mut projection = PolytopeProjection::new(1, 2);
    let mut x = [0.0];
    let result = projection.project(&[1.0, -1.0], &[-1.0, -1.0], &[0.0], &mut x);
    assert_eq!(result, Err(ProjectionFailure::Empty));
    let mut qp = LinearQp::new(1, 2);
    let result = qp.solve(&[2.0], &[0.0], &[1.0, -1.0], &[-1.0, -1.0], &mut x);
    assert_eq!(
        result,
        Err(LinearQpFailure::Projection(ProjectionFailure::Empty))
    );
    // A NaN in the linear term is not a solution: it returned Ok with a NaN point.
    let result = qp.solve(&[2.0], &[f64::NAN], &[1.0, -1.0], &[1.0, 1.0], &mut x);
    assert_eq!(
        result,
        Err(LinearQpFailure::Projection(ProjectionFailure::NonFinite))
    );
}

#[test]
fn a_polytope_empty_by_a_hair_is_reported_not_left_with_a_point_outside() {
    // The box |x_j| <= 1 and 0.7312 x_0 + 0.9992 x_1 <= -1.73046, whose least value over the
    // box is -1.73043: empty by 3e-5, which the dual's residual alone does not show.
    let mut rows = vec![0.7312032087903603, 0.9992311263456333];
    let mut bounds = vec![-1.7304630812143225];
    for j in 0..2 {
        for sign in [1.0, -1.0] {
            let mut row = [0.0; 2];
            row[j] = sign;
            rows.extend_from_slice(&row);
            bounds.push(1.0);
        }
    }
    let mut projection = PolytopeProjection::new(2, bounds.len());
    let mut x = [0.0; 2];
    let result = projection.project(&rows, &bounds, &[0.0; 2], &mut x);
    assert_eq!(result, Err(ProjectionFailure::Empty), "{x:?}");
    // Loosened by 1e-4 it holds points, all near the corner (-1, -1): the projection finds one.
    bounds[0] += 1e-4;
    assert_eq!(
        projection.project(&rows, &bounds, &[0.0; 2], &mut x),
        Ok(true)
    );
    for (row, bound) in rows.chunks_exact(2).zip(&bounds) {
        assert!(row[0] * x[0] + row[1] * x[1] <= bound + 1e-12, "{x:?}");
    }
    assert!(
        (x[0] + 1.0).abs() < 1e-3 && (x[1] + 1.0).abs() < 1e-3,
        "{x:?}"
    );
}

#[test]
fn sizes_that_disagree_and_indefinite_h_are_refused() {
    let mut projection = PolytopeProjection::new(2, 1);
    let mut x = [0.0; 2];
    let result = projection.project(&[1.0, 0.0, 1.0, 0.0], &[1.0, 1.0], &[0.0; 2], &mut x);
    assert_eq!(result, Err(ProjectionFailure::Dimension));
    // A NaN is not an empty polytope; an infinite bound is a row that never binds.
    for (row, bound, x0) in [
        ([1.0, 0.0], f64::NAN, [0.0; 2]),
        ([f64::NAN, 0.0], 1.0, [0.0; 2]),
        ([f64::INFINITY, 0.0], 1.0, [0.0; 2]),
        ([1.0, 0.0], 1.0, [f64::NAN, 0.0]),
    ] {
        let result = projection.project(&row, &[bound], &x0, &mut x);
        assert_eq!(
            result,
            Err(ProjectionFailure::NonFinite),
            "{row:?} {bound} {x0:?}"
        );
    }
    assert_eq!(
        projection.project(&[1.0, 0.0], &[f64::INFINITY], &[5.0, 0.0], &mut x),
        Ok(false)
    );
    assert_eq!(x, [5.0, 0.0]);
    let mut qp = LinearQp::new(2, 1);
    let result = qp.solve(
        &[1.0, 0.0, 0.0, -1.0],
        &[0.0; 2],
        &[1.0, 0.0],
        &[1.0],
        &mut x,
    );
    assert_eq!(result, Err(LinearQpFailure::NotPositiveDefinite));
    // The box QP refuses a NaN gradient: it returned Ok with a NaN value at the warm start.
    let mut box_qp = optimal_ctl::BoxQp::new(2);
    let settings = optimal_ctl::BoxQpSettings::default();
    let mut u = [0.0; 2];
    let h = [1.0, 0.0, 0.0, 1.0];
    let (lower, upper) = ([-1.0; 2], [1.0; 2]);
    let error = box_qp
        .solve(&h, &[f64::NAN, 1.0], &lower, &upper, &mut u, &settings)
        .unwrap_err();
    assert!(
        error
            .to_string()
            .starts_with("box QP gradient g must be finite"),
        "{error}"
    );
    let report = box_qp
        .solve(&h, &[2.0, 0.0], &lower, &upper, &mut u, &settings)
        .unwrap();
    assert!(report.value.is_finite());
    assert_eq!(u, [-1.0, 0.0]);
}
