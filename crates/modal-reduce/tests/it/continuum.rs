//! The continuum limit of the modal model: with the arm's total length and mass fixed, the
//! reduced dynamics of `n` links converge, as `n` grows, to those of an inextensible rod whose
//! inclination is the backbone curve's `alpha(s)`, computed here independently by quadrature
//! along the rod. The observed order of convergence is 2 (the links sample the curve at their
//! midpoints, and each link's own rotational inertia is `O(1/n^2)` of the whole): the error falls
//! 4-fold each time `n` doubles. `docs/theory.md` states the rate.

use backbone_kin::{ModalMap, harmonic_basis};
use manip_dyn::ChainModel;
use modal_reduce::{ReducedData, ReducedModel, forward_dynamics};

/// The rod: length `L`, mass `MASS` (uniform), gravity `G` along `-y`.
const L: f64 = 1.0;
const MASS: f64 = 1.0;
const G: f64 = 9.81;

/// The state: the paper's coordinates `(a1, a2, alpha0)`, their rates and `tau*`.
const A: [f64; 3] = [0.8, -0.5, 0.7];
const A_DOT: [f64; 3] = [1.2, -0.7, 0.4];
const TAU_STAR: [f64; 3] = [0.3, -0.2, 0.1];

/// `d alpha / d a_j` at arc length `s`: `(sin(2 pi s / l), 1 - cos(2 pi s / l), 1)`.
fn basis(s: f64) -> [f64; 3] {
    let (sin_term, one_minus_cos) = harmonic_basis(1, s, L);
    [sin_term, one_minus_cos, 1.0]
}

/// `alpha(s)` at the state.
fn inclination(s: f64) -> f64 {
    let psi = basis(s);
    (0..3).map(|j| psi[j] * A[j]).sum()
}

/// Cumulative trapezoid integrals of `f` (values at `cells + 1` equally spaced nodes on
/// `[0, L]`): entry `i` approximates the integral over `[0, s_i]`.
fn cumulative(f: &[[f64; 2]], cells: usize) -> Vec<[f64; 2]> {
    let h = L / cells as f64;
    let mut out = vec![[0.0; 2]; cells + 1];
    for i in 1..=cells {
        for c in 0..2 {
            out[i][c] = out[i - 1][c] + 0.5 * h * (f[i - 1][c] + f[i][c]);
        }
    }
    out
}

/// Trapezoid integral over `[0, L]` of values at `cells + 1` nodes.
fn integral(f: impl Fn(usize) -> f64, cells: usize) -> f64 {
    let h = L / cells as f64;
    let inner: f64 = (1..cells).map(&f).sum();
    h * (inner + 0.5 * (f(0) + f(cells)))
}

/// `(M*, C*, G*)` of the rod on a grid of `cells` cells:
/// `R_j(s) = dr(s)/da_j = int_0^s w psi_j`, `Q(s) = -int_0^s u alpha_dot^2` (the acceleration at
/// `a_ddot = 0`), `M*_jk = rho int R_j . R_k`, `C*_j = rho int R_j . Q`, `G*_j = g rho int R_j,y`,
/// with `u = (cos alpha, sin alpha)`, `w = (-sin alpha, cos alpha)`.
fn rod_terms(cells: usize) -> ([[f64; 3]; 3], [f64; 3], [f64; 3]) {
    let rho = MASS / L;
    let nodes: Vec<f64> = (0..=cells).map(|i| L * i as f64 / cells as f64).collect();
    let r: Vec<Vec<[f64; 2]>> = (0..3)
        .map(|j| {
            let f: Vec<[f64; 2]> = nodes
                .iter()
                .map(|&s| {
                    let (sin, cos) = inclination(s).sin_cos();
                    let psi = basis(s)[j];
                    [-sin * psi, cos * psi]
                })
                .collect();
            cumulative(&f, cells)
        })
        .collect();
    let f: Vec<[f64; 2]> = nodes
        .iter()
        .map(|&s| {
            let (sin, cos) = inclination(s).sin_cos();
            let psi = basis(s);
            let rate: f64 = (0..3).map(|j| psi[j] * A_DOT[j]).sum();
            [-cos * rate * rate, -sin * rate * rate]
        })
        .collect();
    let q = cumulative(&f, cells);
    let dot = |x: [f64; 2], y: [f64; 2]| x[0] * y[0] + x[1] * y[1];
    let mass = std::array::from_fn(|j| {
        std::array::from_fn(|k| rho * integral(|i| dot(r[j][i], r[k][i]), cells))
    });
    let coriolis = std::array::from_fn(|j| rho * integral(|i| dot(r[j][i], q[i]), cells));
    let gravity = std::array::from_fn(|j| G * rho * integral(|i| r[j][i][1], cells));
    (mass, coriolis, gravity)
}

/// The rod's `a_ddot`: its terms on two grids, Richardson-extrapolated (the trapezoid errors of
/// these smooth integrands go as `h^2`), then `M*^-1 (tau* - C* - G*)` by Cramer's rule.
fn rod_acceleration() -> [f64; 3] {
    let (coarse, fine) = (rod_terms(1 << 12), rod_terms(1 << 13));
    let extrapolate = |c: f64, f: f64| (4.0 * f - c) / 3.0;
    let m: [[f64; 3]; 3] =
        std::array::from_fn(|j| std::array::from_fn(|k| extrapolate(coarse.0[j][k], fine.0[j][k])));
    let rhs: [f64; 3] = std::array::from_fn(|j| {
        TAU_STAR[j] - extrapolate(coarse.1[j], fine.1[j]) - extrapolate(coarse.2[j], fine.2[j])
    });
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    std::array::from_fn(|c| {
        let mut replaced = m;
        for (row, value) in replaced.iter_mut().zip(rhs) {
            row[c] = value;
        }
        det(replaced) / d
    })
}

/// The modal accelerations of the `n`-link arm of the same length and mass.
fn chain_acceleration(n: usize) -> [f64; 3] {
    let link = L / n as f64;
    let model = ReducedModel::new(
        ChainModel::uniform(n, link, MASS / n as f64, G).unwrap(),
        ModalMap::paper(n).unwrap(),
    )
    .unwrap();
    let mut a_ddot = [0.0; 3];
    forward_dynamics(
        &model,
        &mut ReducedData::new(&model),
        &A,
        &A_DOT,
        &TAU_STAR,
        &mut a_ddot,
    )
    .unwrap();
    a_ddot
}

#[test]
fn the_reduced_dynamics_converge_to_the_rod_at_second_order() {
    let rod = rod_acceleration();
    let error = |n| {
        let chain = chain_acceleration(n);
        (0..3)
            .map(|j| (chain[j] - rod[j]).abs())
            .fold(0.0, f64::max)
    };
    let sizes = [16, 32, 64, 128, 256, 512, 1024];
    let errors: Vec<f64> = sizes.iter().map(|&n| error(n)).collect();
    for (pair, n) in errors.windows(2).zip(&sizes) {
        let order = (pair[0] / pair[1]).log2();
        println!(
            "n = {n} -> {}: error {:.3e} -> {:.3e}, order {order:.3}",
            2 * n,
            pair[0],
            pair[1]
        );
        assert!(
            (1.9..2.1).contains(&order),
            "order {order} from {n} to {} links",
            2 * n
        );
    }
    // n^2 times the error settles to a constant (the leading coefficient).
    let scaled: Vec<f64> = sizes
        .iter()
        .zip(&errors)
        .map(|(&n, e)| e * (n * n) as f64)
        .collect();
    println!("n^2 x error: {scaled:.4?}");
    let last = scaled[scaled.len() - 1];
    assert!((scaled[scaled.len() - 2] - last).abs() < 0.02 * last);
}
