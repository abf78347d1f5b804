//! Control-limited iLQR and model-predictive control: the box QP against brute force, iLQR
//! against the finite-horizon Riccati solution on a linear system, the cost gradient against
//! finite differences, the KKT conditions, monotone cost and respected limits on the reduced
//! model of every family, the reference preview, and MPC in the closed loop (tracking under
//! limits, better than clamped computed torque, allocation-free).

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::{ChainModel, Link};
use modal_reduce::{PlantData, PlantDerivatives, ReducedData, ReducedModel};
use optimal_ctl::{
    BoxQp, BoxQpSettings, DiscreteDynamics, Ilqr, IlqrSettings, MpcSettings, OptimalError,
    ReducedEuler, TrackingCost,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sim_core::controller::{
    ComputedTorque, ControlContext, Controller, ControllerError, ModalState, MpcController,
};
use sim_core::reference::{Reference, ReferencePreview, ReferenceSample, Sinusoid, Step};
use sim_core::{Integrator, LoopSettings, Simulation};
use sim_study::{ControllerKind, Scenario};
use test_support::alloc::{allocations, is_counting};

/// The 10-link arm with unequal links and masses, reduced to the family of `harmonics` and
/// `base` (m = 2, 3, 4, 5 for (1, fixed), (1, free), (2, fixed), (2, free)).
fn model(harmonics: usize, base: BaseAngle) -> ReducedModel {
    let lengths: Vec<f64> = (0..10).map(|i| 0.08 + 0.005 * i as f64).collect();
    let masses: Vec<f64> = (0..10).map(|i| 0.12 - 0.004 * i as f64).collect();
    let links = lengths
        .iter()
        .zip(&masses)
        .map(|(&l, &m)| Link::new(l, m, 0.45 * l, m * l * l / 10.0).unwrap())
        .collect();
    let chain = ChainModel::new(links, 9.81).unwrap();
    let map = ModalMap::new(&lengths, harmonics, base).unwrap();
    ReducedModel::new(chain, map).unwrap()
}

fn families() -> Vec<ReducedModel> {
    [
        (1, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)),
        (2, BaseAngle::Free),
    ]
    .into_iter()
    .map(|(k, base)| model(k, base))
    .collect()
}

/// A configuration of `m` coordinates near the paper's working range (alpha0 last when free).
fn configuration(m: usize, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut a: Vec<f64> = (0..m).map(|_| rng.random_range(-0.6..0.6)).collect();
    a[0] += 1.0;
    if m % 2 == 1 {
        a[m - 1] = 1.4 + rng.random_range(-0.2..0.2);
    }
    a
}

/// `G*(a)`: the torques holding `a` at rest.
fn holding(model: &ReducedModel, a: &[f64]) -> Vec<f64> {
    let mut data = ReducedData::new(model);
    modal_reduce::reduced_terms(model, &mut data, a, &vec![0.0; a.len()]).unwrap();
    data.gravity().to_vec()
}

// ---------------------------------------------------------------------------------------------
// Box QP.

/// Solves the `n x n` system `a x = b` by Gaussian elimination with partial pivoting.
fn solve_dense(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut m = a.to_vec();
    let mut x = b.to_vec();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| m[i * n + col].abs().total_cmp(&m[j * n + col].abs()))
            .unwrap();
        for k in 0..n {
            m.swap(col * n + k, pivot * n + k);
        }
        x.swap(col, pivot);
        for row in col + 1..n {
            let f = m[row * n + col] / m[col * n + col];
            for k in col..n {
                m[row * n + k] -= f * m[col * n + k];
            }
            x[row] -= f * x[col];
        }
    }
    for row in (0..n).rev() {
        let mut s = x[row];
        for k in row + 1..n {
            s -= m[row * n + k] * x[k];
        }
        x[row] = s / m[row * n + row];
    }
    x
}

fn qp_value(h: &[f64], g: &[f64], x: &[f64]) -> f64 {
    let n = x.len();
    (0..n)
        .map(|i| x[i] * (g[i] + 0.5 * (0..n).map(|j| h[i * n + j] * x[j]).sum::<f64>()))
        .sum()
}

/// The minimiser by enumerating every assignment of each coordinate to its lower bound, its
/// upper bound or free, solving the free ones exactly, and keeping the best feasible point.
fn brute_force(h: &[f64], g: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    let n = g.len();
    let mut best: Option<(f64, Vec<f64>)> = None;
    for code in 0..3usize.pow(n as u32) {
        let mut x = vec![0.0; n];
        let mut free = Vec::new();
        let mut c = code;
        let mut possible = true;
        for i in 0..n {
            match c % 3 {
                0 => free.push(i),
                1 => x[i] = lower[i],
                _ => x[i] = upper[i],
            }
            possible &= x[i].is_finite();
            c /= 3;
        }
        if !possible {
            continue;
        }
        if !free.is_empty() {
            let k = free.len();
            let mut hf = vec![0.0; k * k];
            let mut rhs = vec![0.0; k];
            for (a, &i) in free.iter().enumerate() {
                for (b, &j) in free.iter().enumerate() {
                    hf[a * k + b] = h[i * n + j];
                }
                rhs[a] = -g[i]
                    - (0..n)
                        .filter(|j| !free.contains(j))
                        .map(|j| h[i * n + j] * x[j])
                        .sum::<f64>();
            }
            let xf = solve_dense(&hf, &rhs, k);
            for (a, &i) in free.iter().enumerate() {
                x[i] = xf[a];
            }
        }
        let feasible = (0..n).all(|i| x[i] >= lower[i] - 1e-12 && x[i] <= upper[i] + 1e-12);
        if feasible {
            let value = qp_value(h, g, &x);
            if best.as_ref().is_none_or(|(v, _)| value < *v) {
                best = Some((value, x));
            }
        }
    }
    best.unwrap().1
}

#[test]
fn box_qp_matches_brute_force_on_random_problems() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut clamped_seen = 0;
    for trial in 0..400 {
        let n = 1 + trial % 5;
        // H = L L^T + 0.1 I with a random L: symmetric positive definite, often ill-conditioned.
        let l: Vec<f64> = (0..n * n).map(|_| rng.random_range(-2.0..2.0)).collect();
        let mut h = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                h[i * n + j] = (0..n).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>()
                    + if i == j { 0.1 } else { 0.0 };
            }
        }
        let g: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
        let mut lower = vec![0.0; n];
        let mut upper = vec![0.0; n];
        for i in 0..n {
            let centre = rng.random_range(-1.0..1.0);
            let width = rng.random_range(0.0..2.0);
            lower[i] = if rng.random_bool(0.15) {
                f64::NEG_INFINITY
            } else {
                centre - width
            };
            upper[i] = if rng.random_bool(0.15) {
                f64::INFINITY
            } else {
                centre + width
            };
        }
        let expected = brute_force(&h, &g, &lower, &upper);
        let mut qp = BoxQp::new(n);
        let mut x: Vec<f64> = (0..n).map(|_| rng.random_range(-3.0..3.0)).collect();
        let report = qp
            .solve(&h, &g, &lower, &upper, &mut x, &BoxQpSettings::default())
            .unwrap();
        assert!(report.converged, "trial {trial}: {report:?}");
        let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            assert!(
                (x[i] - expected[i]).abs() <= 1e-7 * scale,
                "trial {trial}: x = {x:?}, brute force {expected:?}"
            );
            assert!(x[i] >= lower[i] && x[i] <= upper[i]);
        }
        clamped_seen += qp.free().iter().filter(|f| !**f).count();
    }
    assert!(clamped_seen > 100, "the problems hardly touch their bounds");
}

#[test]
fn box_qp_refuses_bad_input() {
    let mut qp = BoxQp::new(2);
    let h = [2.0, 0.0, 0.0, 2.0];
    let settings = BoxQpSettings::default();
    let mut x = [0.0; 2];
    let err = qp
        .solve(&h, &[1.0, 1.0], &[1.0, 0.0], &[0.0, 1.0], &mut x, &settings)
        .unwrap_err();
    assert!(err.to_string().contains("lower <= upper"), "{err}");
    let err = qp
        .solve(&h, &[1.0], &[0.0; 2], &[1.0; 2], &mut x, &settings)
        .unwrap_err();
    assert!(
        matches!(err, OptimalError::Dimension { name: "g", .. }),
        "{err}"
    );
    let indefinite = [1.0, 0.0, 0.0, -1.0];
    let err = qp
        .solve(
            &indefinite,
            &[1.0, 1.0],
            &[-1.0; 2],
            &[1.0; 2],
            &mut x,
            &settings,
        )
        .unwrap_err();
    assert!(matches!(err, OptimalError::NotPositiveDefinite(_)), "{err}");
}

// ---------------------------------------------------------------------------------------------
// iLQR on a linear system against the Riccati recursion.

/// `x' = A x + B u`.
struct Linear {
    nx: usize,
    nu: usize,
    a: Vec<f64>,
    b: Vec<f64>,
}

impl DiscreteDynamics for Linear {
    fn state_dim(&self) -> usize {
        self.nx
    }
    fn control_dim(&self) -> usize {
        self.nu
    }
    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError> {
        for (i, next) in next.iter_mut().enumerate().take(self.nx) {
            *next = (0..self.nx)
                .map(|j| self.a[i * self.nx + j] * x[j])
                .sum::<f64>()
                + (0..self.nu)
                    .map(|j| self.b[i * self.nu + j] * u[j])
                    .sum::<f64>();
        }
        Ok(())
    }
    fn linearise(
        &mut self,
        x: &[f64],
        u: &[f64],
        next: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<(), OptimalError> {
        self.step(x, u, next)?;
        a.copy_from_slice(&self.a);
        b.copy_from_slice(&self.b);
        Ok(())
    }
}

fn mat_mul(a: &[f64], b: &[f64], r: usize, k: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for l in 0..k {
            for j in 0..c {
                out[i * c + j] += a[i * k + l] * b[l * c + j];
            }
        }
    }
    out
}

fn transpose(a: &[f64], r: usize, c: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * c];
    for i in 0..r {
        for j in 0..c {
            out[j * r + i] = a[i * c + j];
        }
    }
    out
}

/// The finite-horizon LQR gains `K_k` (`u_k = -K_k x_k`) by the backward Riccati recursion
/// `P_N = Q_f`, `K = (R + B^T P B)^-1 B^T P A`, `P = Q + A^T P (A - B K)`.
fn riccati_gains(sys: &Linear, q: &[f64], r: &[f64], qf: &[f64], horizon: usize) -> Vec<Vec<f64>> {
    let (nx, nu) = (sys.nx, sys.nu);
    let diag = |d: &[f64]| {
        let n = d.len();
        let mut out = vec![0.0; n * n];
        for i in 0..n {
            out[i * n + i] = d[i];
        }
        out
    };
    let mut p = diag(qf);
    let (at, bt) = (transpose(&sys.a, nx, nx), transpose(&sys.b, nx, nu));
    let mut gains = vec![Vec::new(); horizon];
    for k in (0..horizon).rev() {
        let pb = mat_mul(&p, &sys.b, nx, nx, nu);
        let mut s = mat_mul(&bt, &pb, nu, nx, nu);
        for j in 0..nu {
            s[j * nu + j] += r[j];
        }
        let bpa = mat_mul(&bt, &mat_mul(&p, &sys.a, nx, nx, nx), nu, nx, nx);
        // K = S^-1 (B^T P A), column by column.
        let mut gain = vec![0.0; nu * nx];
        for col in 0..nx {
            let rhs: Vec<f64> = (0..nu).map(|j| bpa[j * nx + col]).collect();
            let sol = solve_dense(&s, &rhs, nu);
            for j in 0..nu {
                gain[j * nx + col] = sol[j];
            }
        }
        let closed: Vec<f64> = sys
            .a
            .iter()
            .zip(mat_mul(&sys.b, &gain, nx, nu, nx))
            .map(|(a, bk)| a - bk)
            .collect();
        let mut next = mat_mul(&at, &mat_mul(&p, &closed, nx, nx, nx), nx, nx, nx);
        for i in 0..nx {
            next[i * nx + i] += q[i];
        }
        p = next;
        gains[k] = gain;
    }
    gains
}

#[test]
fn unconstrained_ilqr_on_a_linear_system_is_the_finite_horizon_lqr() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for trial in 0..20 {
        let (nx, nu, horizon) = (2 + trial % 5, 1 + trial % 3, 10 + trial);
        // A random, possibly unstable A near the identity; a random B.
        let a: Vec<f64> = (0..nx * nx)
            .map(|i| (if i % (nx + 1) == 0 { 1.0 } else { 0.0 }) + rng.random_range(-0.2..0.2))
            .collect();
        let b: Vec<f64> = (0..nx * nu).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut sys = Linear { nx, nu, a, b };
        let cost = TrackingCost {
            state: (0..nx).map(|_| rng.random_range(0.0..2.0)).collect(),
            control: (0..nu).map(|_| rng.random_range(0.1..1.0)).collect(),
            terminal: (0..nx).map(|_| rng.random_range(0.0..5.0)).collect(),
        };
        let x0: Vec<f64> = (0..nx).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut ilqr = Ilqr::new(nx, nu, horizon, &cost).unwrap();
        // A poor warm start: random controls.
        for u in ilqr.controls_mut() {
            *u = rng.random_range(-3.0..3.0);
        }
        let report = ilqr.solve(&mut sys, &x0, &IlqrSettings::default()).unwrap();
        assert!(report.converged, "trial {trial}: {report:?}");
        // One Newton step solves a linear-quadratic problem; the second confirms it.
        assert!(report.iterations <= 2, "trial {trial}: {report:?}");
        let gains = riccati_gains(&sys, &cost.state, &cost.control, &cost.terminal, horizon);
        let mut x = x0.clone();
        for (k, gain) in gains.iter().enumerate() {
            let u: Vec<f64> = (0..nu)
                .map(|j| -(0..nx).map(|i| gain[j * nx + i] * x[i]).sum::<f64>())
                .collect();
            for j in 0..nu {
                let got = ilqr.controls()[k * nu + j];
                assert!(
                    (got - u[j]).abs() <= 1e-9 * (1.0 + u[j].abs()),
                    "trial {trial}, step {k}: iLQR {got}, LQR {}",
                    u[j]
                );
                for i in 0..nx {
                    let (got, lqr) = (ilqr.gains()[(k * nu + j) * nx + i], -gain[j * nx + i]);
                    assert!(
                        (got - lqr).abs() <= 1e-9 * (1.0 + lqr.abs()),
                        "trial {trial}, step {k}: gain {got} vs {lqr}"
                    );
                }
            }
            let mut next = vec![0.0; nx];
            sys.step(&x, &u, &mut next).unwrap();
            x = next;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// iLQR on the reduced model.

/// A tracking problem on `model`: from a random state towards a random configuration held by
/// its gravity torques, with limits `limit` times below what the reference needs.
fn reduced_problem(
    model: &ReducedModel,
    horizon: usize,
    rng: &mut ChaCha8Rng,
    limit_fraction: f64,
) -> (Ilqr, Vec<f64>) {
    let m = model.n_coords();
    let target = configuration(m, rng);
    let start = configuration(m, rng);
    let g_target = holding(model, &target);
    let cost = TrackingCost {
        state: [vec![100.0; m], vec![1.0; m]].concat(),
        control: vec![1e-2; m],
        terminal: [vec![1000.0; m], vec![10.0; m]].concat(),
    };
    let mut ilqr = Ilqr::new(2 * m, m, horizon, &cost).unwrap();
    for k in 0..=horizon {
        ilqr.state_references_mut()[k * 2 * m..k * 2 * m + m].copy_from_slice(&target);
    }
    for k in 0..horizon {
        ilqr.control_references_mut()[k * m..(k + 1) * m].copy_from_slice(&g_target);
    }
    let limit: Vec<f64> = g_target
        .iter()
        .map(|g| (g.abs() * limit_fraction).max(0.05))
        .collect();
    let lower: Vec<f64> = limit.iter().map(|l| -l).collect();
    ilqr.set_bounds(&lower, &limit).unwrap();
    let x0 = [start, (0..m).map(|_| rng.random_range(-0.5..0.5)).collect()].concat();
    (ilqr, x0)
}

#[test]
fn limits_hold_and_the_cost_decreases_monotonically_for_every_family() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for model in families() {
        let m = model.n_coords();
        let (mut data, mut derivatives) = (
            PlantData::new((&model).into()),
            PlantDerivatives::new((&model).into()),
        );
        for _ in 0..3 {
            let (ilqr, x0) = reduced_problem(&model, 30, &mut rng, 0.7);
            let mut previous = f64::INFINITY;
            let mut clamped = 0;
            for iterations in 0..8 {
                let mut run = ilqr.clone();
                let mut dynamics =
                    ReducedEuler::new(&model, &mut data, &mut derivatives, 0.01).unwrap();
                let settings = IlqrSettings {
                    max_iterations: iterations,
                    tolerance: 0.0,
                    gradient_tolerance: 0.0,
                    ..IlqrSettings::default()
                };
                let report = run.solve(&mut dynamics, &x0, &settings).unwrap();
                assert!(
                    report.cost <= previous,
                    "m = {m}: {iterations} iterations cost {} after {previous}",
                    report.cost
                );
                assert!(report.cost <= report.initial_cost);
                previous = report.cost;
                let (lower, upper) = run.bounds();
                for u in run.controls().chunks_exact(m) {
                    for j in 0..m {
                        assert!(u[j] >= lower[j] && u[j] <= upper[j], "m = {m}: {u:?}");
                        clamped += usize::from(u[j] == lower[j] || u[j] == upper[j]);
                    }
                }
            }
            assert!(clamped > 0, "m = {m}: the limits never bind");
            assert!(previous.is_finite());
        }
    }
}

#[test]
fn cost_gradient_matches_central_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for model in families() {
        let m = model.n_coords();
        let (mut data, mut derivatives) = (
            PlantData::new((&model).into()),
            PlantDerivatives::new((&model).into()),
        );
        let horizon = 12;
        let (mut ilqr, x0) = reduced_problem(&model, horizon, &mut rng, 1e6);
        let g_ref = ilqr.control_references_mut().to_vec();
        let controls: Vec<f64> = g_ref
            .iter()
            .map(|g| g + rng.random_range(-0.3..0.3))
            .collect();
        let cost_of = |ilqr: &mut Ilqr,
                       data: &mut PlantData,
                       derivatives: &mut PlantDerivatives,
                       u: &[f64]| {
            ilqr.controls_mut().copy_from_slice(u);
            let mut dynamics = ReducedEuler::new(&model, data, derivatives, 0.02).unwrap();
            let settings = IlqrSettings {
                max_iterations: 0,
                ..IlqrSettings::default()
            };
            ilqr.solve(&mut dynamics, &x0, &settings).unwrap().cost
        };
        let cost = cost_of(&mut ilqr, &mut data, &mut derivatives, &controls);
        let mut gradient = vec![0.0; horizon * m];
        let mut dynamics = ReducedEuler::new(&model, &mut data, &mut derivatives, 0.02).unwrap();
        let adjoint_cost = ilqr.gradient(&mut dynamics, &mut gradient).unwrap();
        assert!((adjoint_cost - cost).abs() <= 1e-12 * cost);
        let scale = gradient.iter().fold(0.0f64, |s, g| s.max(g.abs()));
        for index in 0..horizon * m {
            // Step-size control: the central difference at two steps must agree before it is
            // trusted.
            let fd =
                |eps: f64, ilqr: &mut Ilqr, data: &mut PlantData, der: &mut PlantDerivatives| {
                    let mut plus = controls.clone();
                    plus[index] += eps;
                    let mut minus = controls.clone();
                    minus[index] -= eps;
                    (cost_of(ilqr, data, der, &plus) - cost_of(ilqr, data, der, &minus))
                        / (2.0 * eps)
                };
            let coarse = fd(1e-4, &mut ilqr, &mut data, &mut derivatives);
            let fine = fd(5e-5, &mut ilqr, &mut data, &mut derivatives);
            assert!(
                (coarse - fine).abs() <= 1e-6 * scale,
                "m = {m}: unstable difference"
            );
            assert!(
                (gradient[index] - fine).abs() <= 1e-6 * scale,
                "m = {m}, control {index}: adjoint {} vs finite difference {fine}",
                gradient[index]
            );
        }
    }
}

#[test]
fn the_solution_satisfies_the_kkt_conditions_of_the_box() {
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for model in families() {
        let m = model.n_coords();
        let (mut data, mut derivatives) = (
            PlantData::new((&model).into()),
            PlantDerivatives::new((&model).into()),
        );
        for _ in 0..2 {
            let horizon = 25;
            let (mut ilqr, x0) = reduced_problem(&model, horizon, &mut rng, 0.8);
            let mut gradient = vec![0.0; horizon * m];
            ilqr.warm_start_from_control_references();
            let mut dynamics =
                ReducedEuler::new(&model, &mut data, &mut derivatives, 0.01).unwrap();
            let settings = IlqrSettings {
                max_iterations: 0,
                ..IlqrSettings::default()
            };
            ilqr.solve(&mut dynamics, &x0, &settings).unwrap();
            ilqr.gradient(&mut dynamics, &mut gradient).unwrap();
            let initial = gradient.iter().fold(0.0f64, |s, g| s.max(g.abs()));
            let settings = IlqrSettings {
                max_iterations: 500,
                tolerance: 1e-14,
                gradient_tolerance: 1e-12,
                ..IlqrSettings::default()
            };
            let report = ilqr.solve(&mut dynamics, &x0, &settings).unwrap();
            assert!(report.cost < report.initial_cost);
            ilqr.gradient(&mut dynamics, &mut gradient).unwrap();
            let (lower, upper) = (ilqr.bounds().0.to_vec(), ilqr.bounds().1.to_vec());
            let tolerance = 1e-5 * initial;
            let mut at_bound = 0;
            for (k, (u, g)) in ilqr
                .controls()
                .chunks_exact(m)
                .zip(gradient.chunks_exact(m))
                .enumerate()
            {
                for j in 0..m {
                    // Stationary inside the box; at a bound, the gradient points out of it.
                    let ok = if u[j] <= lower[j] {
                        at_bound += 1;
                        g[j] >= -tolerance
                    } else if u[j] >= upper[j] {
                        at_bound += 1;
                        g[j] <= tolerance
                    } else {
                        g[j].abs() <= tolerance
                    };
                    assert!(
                        ok,
                        "m = {m}, step {k}, control {j}: u = {} in [{}, {}], dJ/du = {} \
                         (initial {initial}), {report:?}",
                        u[j], lower[j], upper[j], g[j]
                    );
                }
            }
            assert!(at_bound > 0, "m = {m}: no limit is active");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The reference preview and MPC.

#[test]
fn the_preview_equals_direct_sampling_after_any_move() {
    let sine = Sinusoid::new(&[0.1, 0.0], &[0.2, 0.3], &[0.7, 1.3], &[0.0, 1.0]).unwrap();
    let mut direct = sine.clone();
    let mut preview = ReferencePreview::new(Box::new(sine), 21, 0.01).unwrap();
    let mut sample = ReferenceSample::zeros(2);
    for t in [0.0, 0.01, 0.03, 0.035, 0.035, 0.245, 1.0, 0.2] {
        let samples = preview.advance(t).unwrap().to_vec();
        for (k, s) in samples.iter().enumerate() {
            direct.sample(t + k as f64 * 0.01, &mut sample).unwrap();
            for i in 0..2 {
                assert!((s.a[i] - sample.a[i]).abs() < 1e-12, "t = {t}, node {k}");
                assert!((s.a_ddot[i] - sample.a_ddot[i]).abs() < 1e-10);
            }
        }
    }
    let err =
        ReferencePreview::new(Box::new(Step::constant(&[0.0]).unwrap()), 0, 0.01).unwrap_err();
    assert!(err.to_string().contains("preview"), "{err}");
    let err =
        ReferencePreview::new(Box::new(Step::constant(&[0.0]).unwrap()), 5, f64::NAN).unwrap_err();
    assert!(err.to_string().contains("spacing"), "{err}");
}

#[test]
fn bad_mpc_settings_are_refused_with_the_field_named() {
    let model = model(1, BaseAngle::Free);
    let reference = || Box::new(Step::constant(&[1.0, 0.0, 1.4]).unwrap());
    type Change = Box<dyn Fn(&mut MpcSettings)>;
    let cases: Vec<(Change, &str)> = vec![
        (Box::new(|s| s.horizon = 0), "horizon"),
        (Box::new(|s| s.horizon = 1_000_000), "horizon"),
        (Box::new(|s| s.step = -0.01), "step"),
        (Box::new(|s| s.step = f64::NAN), "step"),
        (
            Box::new(|s| s.position_weight[1] = f64::NAN),
            "position_weight",
        ),
        (Box::new(|s| s.rate_weight = vec![1.0; 2]), "rate_weight"),
        (Box::new(|s| s.effort_weight[0] = 0.0), "effort_weight"),
        (Box::new(|s| s.rate_weight[2] = -1.0), "rate_weight"),
        (Box::new(|s| s.terminal_seconds = -1.0), "terminal_seconds"),
        (
            Box::new(|s| s.tau_star_limits = Some(vec![1.0, 0.0, 1.0])),
            "tau_star_limits",
        ),
        (
            Box::new(|s| s.tau_star_limits = Some(vec![1.0])),
            "tau_star_limits",
        ),
        (
            Box::new(|s| s.solver.line_search_steps = 0),
            "line_search_steps",
        ),
    ];
    for (change, field) in cases {
        let mut settings = MpcSettings::uniform(3);
        change(&mut settings);
        let err = match MpcController::new(&model, &settings, reference()) {
            Ok(mut controller) => {
                // Solver settings are checked at the first solve.
                let measured = ModalState::new(&[1.0, 0.0, 1.4], &[0.0; 3]).unwrap();
                let mut target = ReferenceSample::zeros(3);
                target.a.copy_from_slice(&[1.0, 0.0, 1.4]);
                let ctx = ControlContext {
                    t: 0.0,
                    measured: &measured,
                    reference: &target,
                    model: (&model).into(),
                    tau_star_limits: None,
                };
                controller
                    .control(&ctx, &mut [0.0; 3])
                    .unwrap_err()
                    .to_string()
            }
            Err(err) => err.to_string(),
        };
        assert!(err.contains(field), "{field}: {err}");
        assert!(!err.contains('\n'), "{err}");
    }
    let err = MpcController::new(
        &model,
        &MpcSettings::uniform(3),
        Box::new(Step::constant(&[1.0, 0.0]).unwrap()),
    )
    .unwrap_err();
    assert!(
        err.to_string().contains("previews a reference of 2"),
        "{err}"
    );
}

/// Computed torque clamped to `limits`: the baseline MPC must beat.
struct Clamped(ComputedTorque, Vec<f64>);

impl Controller for Clamped {
    fn control(
        &mut self,
        ctx: &ControlContext<'_>,
        tau_star: &mut [f64],
    ) -> Result<(), ControllerError> {
        self.0.control(ctx, tau_star)?;
        for (t, l) in tau_star.iter_mut().zip(&self.1) {
            *t = t.clamp(-l, *l);
        }
        Ok(())
    }
}

/// A cosine reference at `frequency` Hz about a configuration of the arm (a1 = 1 rad, alpha0 =
/// 1.4 rad when free), starting at rest.
fn sine_reference(m: usize, frequency: f64) -> Sinusoid {
    let mut offset = vec![0.0; m];
    offset[0] = 1.0;
    if m % 2 == 1 {
        offset[m - 1] = 1.4;
    }
    let amplitude: Vec<f64> = (0..m).map(|i| if i == 0 { 0.3 } else { 0.1 }).collect();
    let phase = vec![std::f64::consts::FRAC_PI_2; m];
    Sinusoid::new(&offset, &amplitude, &vec![frequency; m], &phase).unwrap()
}

/// The RMS modal error of a run and the largest `|tau*_i| / limit_i`.
fn run(model: &ReducedModel, controller: Box<dyn Controller>, limits: &[f64]) -> (f64, f64) {
    let m = model.n_coords();
    let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 1.0);
    let mut sim = Simulation::new(
        model.clone(),
        Box::new(sine_reference(m, 2.0)),
        controller,
        settings,
        None,
    )
    .unwrap();
    let run = sim.run().unwrap();
    let rms = run
        .summary
        .modal_error_rms_rad
        .iter()
        .map(|e| e * e)
        .sum::<f64>()
        .sqrt();
    let mut ratio = 0.0f64;
    for k in 0..run.record.len() {
        for (t, l) in run.record.tau_star_at(k).iter().zip(limits) {
            ratio = ratio.max(t.abs() / l);
        }
    }
    (rms, ratio)
}

#[test]
fn mpc_respects_the_limits_and_beats_clamped_computed_torque() {
    for model in [
        model(1, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)),
        model(1, BaseAngle::Free),
    ] {
        let m = model.n_coords();
        // Limits at 60% of the peak computed torque of the unclamped run.
        let ct = ComputedTorque::new(&model, &vec![2500.0; m], &vec![100.0; m]).unwrap();
        let (free_rms, _) = run(&model, Box::new(ct.clone()), &vec![f64::INFINITY; m]);
        let settings = LoopSettings::new(Integrator::Rk4 { dt: 1e-3 }, 1e-3, 1.0);
        let peak = {
            let mut sim = Simulation::new(
                model.clone(),
                Box::new(sine_reference(m, 2.0)),
                Box::new(ct.clone()),
                settings,
                None,
            )
            .unwrap();
            let run = sim.run().unwrap();
            let mut peak = vec![0.0f64; m];
            for k in 0..run.record.len() {
                for (p, t) in peak.iter_mut().zip(run.record.tau_star_at(k)) {
                    *p = p.max(t.abs());
                }
            }
            peak
        };
        let limits: Vec<f64> = peak.iter().map(|p| 0.6 * p).collect();
        let (clamped_rms, clamped_ratio) =
            run(&model, Box::new(Clamped(ct, limits.clone())), &limits);
        assert!(clamped_ratio <= 1.0 + 1e-12);
        assert!(
            clamped_rms > 10.0 * free_rms,
            "the limits do not hurt computed torque"
        );
        let mut mpc_settings = MpcSettings::uniform(m);
        mpc_settings.tau_star_limits = Some(limits.clone());
        let reference = Box::new(sine_reference(m, 2.0));
        let mpc = MpcController::new(&model, &mpc_settings, reference).unwrap();
        let (mpc_rms, mpc_ratio) = run(&model, Box::new(mpc), &limits);
        assert!(
            mpc_ratio <= 1.0 + 1e-12,
            "m = {m}: |tau*| / limit = {mpc_ratio}"
        );
        assert!(
            mpc_rms < 0.5 * clamped_rms,
            "m = {m}: MPC {mpc_rms} rad RMS vs clamped computed torque {clamped_rms} \
             (unclamped {free_rms})"
        );
    }
}

#[test]
fn mpc_control_calls_allocate_nothing() {
    assert!(is_counting(), "the test binary must count allocations");
    for model in families() {
        let m = model.n_coords();
        let mut settings = MpcSettings::uniform(m);
        settings.tau_star_limits = Some(vec![5.0; m]);
        let reference = sine_reference(m, 0.5);
        let mut loop_reference = reference.clone();
        let mut controller = MpcController::new(&model, &settings, Box::new(reference)).unwrap();
        let mut measured = ModalState::zeros(m);
        let mut target = ReferenceSample::zeros(m);
        let mut tau = vec![0.0; m];
        // The loop's actuator limits, which replace the settings' at every plan.
        let loop_limits = vec![4.0; m];
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut count = |t: f64, controller: &mut MpcController| {
            loop_reference.sample(t, &mut target).unwrap();
            for i in 0..m {
                measured.a[i] = target.a[i] + rng.random_range(-0.05..0.05);
                measured.a_dot[i] = rng.random_range(-0.2..0.2);
            }
            let ctx = ControlContext {
                t,
                measured: &measured,
                reference: &target,
                model: (&model).into(),
                tau_star_limits: Some(&loop_limits),
            };
            let before = allocations();
            controller
                .control(&ctx, &mut tau)
                .unwrap_or_else(|e| panic!("m = {m}, t = {t}: {e}"));
            let made = allocations() - before;
            assert!(tau.iter().all(|t| t.abs() <= 5.0));
            made
        };
        // The first plan, re-plans every 10 ms, feedback in between, and a restart.
        for t in [0.0, 0.001, 0.01, 0.015, 0.02, 0.05, 0.0505, 0.0] {
            assert_eq!(count(t, &mut controller), 0, "m = {m}, t = {t}");
        }
    }
}

#[test]
fn scenarios_run_mpc_by_name() {
    let kind: ControllerKind = "mpc".parse().unwrap();
    assert_eq!(kind.name(), "mpc");
    for name in ["paper-tracking", "free-base-tracking"] {
        let mut scenario = Scenario::builtin(name).unwrap();
        scenario.controller.kind = kind;
        scenario.duration = 0.2;
        let run = scenario.build().unwrap().run().unwrap();
        assert!(
            run.summary.tip_error_rms_m < 5e-3,
            "{name}: tip RMS {} m",
            run.summary.tip_error_rms_m
        );
    }
}

/// The loop's actuator limits (`ControlContext::tau_star_limits`) replace the settings' limits:
/// an MPC configured without limits plans within the loop's, which bind on a large error.
#[test]
fn mpc_plans_within_the_loop_s_limits() {
    for model in families() {
        let m = model.n_coords();
        let settings = MpcSettings::uniform(m);
        let reference = sine_reference(m, 0.5);
        let mut controller = MpcController::new(&model, &settings, Box::new(reference)).unwrap();
        // Far from the reference: unlimited, the plan would ask for large torques.
        let measured = ModalState::new(&vec![0.8; m], &vec![0.0; m]).unwrap();
        let mut target = ReferenceSample::zeros(m);
        sine_reference(m, 0.5).sample(0.0, &mut target).unwrap();
        let limits = vec![0.05; m];
        let ctx = ControlContext {
            t: 0.0,
            measured: &measured,
            reference: &target,
            model: (&model).into(),
            tau_star_limits: Some(&limits),
        };
        let mut tau = vec![0.0; m];
        controller.control(&ctx, &mut tau).unwrap();
        assert!(
            tau.iter().all(|t| t.abs() <= 0.05 + 1e-12),
            "m = {m}: {tau:?}"
        );
        assert!(
            tau.iter().any(|t| t.abs() >= 0.05 - 1e-9),
            "m = {m}: the limits should bind: {tau:?}"
        );
    }
}

/// Issue 13's target on `paper-tracking-fast` (the paper's path in 1 s under `tau*` limits): MPC,
/// planning within the limits, at least halves the tip error RMS of computed torque clamped by
/// them (2.93 mm against 5.94 mm when written).
#[test]
fn mpc_at_least_halves_clamped_computed_torque_on_the_fast_path() {
    let mut scenario = Scenario::builtin("paper-tracking-fast").unwrap();
    let mut tip_rms = |kind| {
        scenario.controller.kind = kind;
        let run = scenario.build().unwrap().run().unwrap();
        run.summary.tip_error_rms_m
    };
    let clamped = tip_rms(ControllerKind::ComputedTorque);
    let mpc = tip_rms(ControllerKind::Mpc);
    assert!(
        mpc <= 0.5 * clamped,
        "MPC {:.4} mm against clamped computed torque {:.4} mm",
        mpc * 1e3,
        clamped * 1e3
    );
}

/// A model of more coordinates than MPC's workspace plans over its horizon is refused by the
/// scenario key that set them, before any run.
#[test]
fn mpc_on_too_many_coordinates_names_the_harmonics() {
    let mut scenario = Scenario::builtin("paper-tracking").unwrap();
    scenario.arm.links = Some(400);
    scenario.modal.harmonics = 100;
    scenario.duration = 1e-4;
    scenario.reference = sim_study::ReferenceSpec::Step {
        initial: None,
        target: vec![0.0; 200],
        time: 0.0,
    };
    scenario.controller.kind = ControllerKind::Mpc;
    let Err(error) = scenario.build() else {
        panic!("built")
    };
    let message = error.to_string();
    assert!(
        message.contains("modal.harmonics")
            && message.contains("gives 200 modal coordinates, more than the 199"),
        "{message}"
    );
    // One harmonic fewer fits the workspace; its solves are then counted in the run's work.
    scenario.modal.harmonics = 99;
    scenario.reference = sim_study::ReferenceSpec::Step {
        initial: None,
        target: vec![0.0; 198],
        time: 0.0,
    };
    let Err(error) = scenario.build() else {
        panic!("built")
    };
    let message = error.to_string();
    assert!(
        message.contains("of the controller's own") && message.contains("another kind than"),
        "{message}"
    );
}
