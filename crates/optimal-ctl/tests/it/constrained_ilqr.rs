//! iLQR under general linear control constraints (`Ilqr::solve_constrained`) against the same
//! problem written as one QP over all the controls (the dynamics condensed,
//! `x_k = Phi_k x_0 + Gamma_k U`) and solved by `LinearQp`, itself checked against enumeration
//! of active sets (`qp`): on random linear systems with random quadratic costs and random
//! polytopes of controls, the two optima agree.

use optimal_ctl::{
    DiscreteDynamics, Ilqr, IlqrSettings, LinearQp, OptimalError, StepConstraints, TrackingCost,
};
use proptest::prelude::*;

/// `x' = A x + B u`.
struct Linear {
    a: Vec<f64>,
    b: Vec<f64>,
    nx: usize,
    nu: usize,
}

impl DiscreteDynamics for Linear {
    fn state_dim(&self) -> usize {
        self.nx
    }

    fn control_dim(&self) -> usize {
        self.nu
    }

    fn step(&mut self, x: &[f64], u: &[f64], next: &mut [f64]) -> Result<(), OptimalError> {
        for (i, out) in next.iter_mut().enumerate().take(self.nx) {
            *out = (0..self.nx)
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
        a.copy_from_slice(&self.a);
        b.copy_from_slice(&self.b);
        self.step(x, u, next)
    }
}

/// The same rows `G u <= g` at every step.
struct Fixed {
    rows: Vec<f64>,
    bounds: Vec<f64>,
}

impl StepConstraints for Fixed {
    fn max_rows(&self) -> usize {
        self.bounds.len()
    }

    fn rows(
        &mut self,
        _k: usize,
        _x: &[f64],
        _u: &[f64],
        _b: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        rows[..self.rows.len()].copy_from_slice(&self.rows);
        bounds[..self.bounds.len()].copy_from_slice(&self.bounds);
        Ok(self.bounds.len())
    }
}

/// The optimal controls of the whole horizon as one QP, `min 1/2 U^T H U + q^T U` subject to
/// `G u_k <= g` for every `k`.
#[allow(clippy::too_many_arguments)]
fn condensed(
    sys: &Linear,
    cost: &TrackingCost,
    horizon: usize,
    x0: &[f64],
    x_ref: &[f64],
    constraints: &Fixed,
) -> Vec<f64> {
    let (nx, nu, n) = (sys.nx, sys.nu, horizon);
    let dim = n * nu;
    // x_k = phi_k + Gamma_k U, built forward.
    let mut phi = x0.to_vec();
    let mut gamma = vec![0.0; nx * dim];
    let mut h = vec![0.0; dim * dim];
    let mut q = vec![0.0; dim];
    for k in 0..=n {
        let weights = if k == n { &cost.terminal } else { &cost.state };
        for i in 0..nx {
            let e = phi[i] - x_ref[k * nx + i];
            for c in 0..dim {
                q[c] += weights[i] * e * gamma[i * dim + c];
                for d in 0..dim {
                    h[c * dim + d] += weights[i] * gamma[i * dim + c] * gamma[i * dim + d];
                }
            }
        }
        if k == n {
            break;
        }
        for j in 0..nu {
            h[(k * nu + j) * dim + k * nu + j] += cost.control[j];
        }
        let mut next_phi = vec![0.0; nx];
        let mut next_gamma = vec![0.0; nx * dim];
        for i in 0..nx {
            for l in 0..nx {
                next_phi[i] += sys.a[i * nx + l] * phi[l];
                for c in 0..dim {
                    next_gamma[i * dim + c] += sys.a[i * nx + l] * gamma[l * dim + c];
                }
            }
            for j in 0..nu {
                next_gamma[i * dim + k * nu + j] += sys.b[i * nu + j];
            }
        }
        phi = next_phi;
        gamma = next_gamma;
    }
    let per = constraints.bounds.len();
    let mut rows = vec![0.0; n * per * dim];
    let mut bounds = vec![0.0; n * per];
    for k in 0..n {
        for r in 0..per {
            for j in 0..nu {
                rows[(k * per + r) * dim + k * nu + j] = constraints.rows[r * nu + j];
            }
            bounds[k * per + r] = constraints.bounds[r];
        }
    }
    let mut qp = LinearQp::new(dim, n * per);
    let mut u = vec![0.0; dim];
    qp.solve(&h, &q, &rows, &bounds, &mut u).unwrap();
    u
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn constrained_ilqr_matches_the_condensed_qp(
        a in prop::collection::vec(-0.6..0.6f64, 4),
        b in prop::collection::vec(-1.0..1.0f64, 4),
        weights in prop::collection::vec(0.5..3.0f64, 6),
        x0 in prop::collection::vec(-2.0..2.0f64, 2),
        x_ref in prop::collection::vec(-2.0..2.0f64, 14),
        seed_rows in prop::collection::vec(-1.0..1.0f64, 6),
        slack in prop::collection::vec(0.05..0.5f64, 3),
    ) {
        let (nx, nu, horizon) = (2, 2, 6);
        // A = I + small, B random: a controllable-ish discrete system.
        let a = vec![1.0 + a[0], a[1], a[2], 1.0 + a[3]];
        let mut sys = Linear { a, b, nx, nu };
        let cost = TrackingCost {
            state: weights[..2].to_vec(),
            control: weights[2..4].to_vec(),
            terminal: weights[4..6].to_vec(),
        };
        // Three rows that u = 0 satisfies with some slack: the polytope is never empty.
        let constraints = Fixed { rows: seed_rows, bounds: slack };
        let expected = condensed(&sys, &cost, horizon, &x0, &x_ref, &constraints);
        let mut ilqr = Ilqr::new(nx, nu, horizon, &cost).unwrap();
        ilqr.reserve_constraints(3).unwrap();
        ilqr.state_references_mut().copy_from_slice(&x_ref);
        let settings = IlqrSettings {
            max_iterations: 200,
            tolerance: 1e-14,
            gradient_tolerance: 1e-12,
            ..IlqrSettings::default()
        };
        // Only problems whose free optimum breaks a row: the constraints matter.
        ilqr.solve(&mut sys, &x0, &settings).unwrap();
        let breaks = ilqr.controls().chunks_exact(nu).any(|u| {
            constraints.rows.chunks_exact(nu).zip(&constraints.bounds)
                .any(|(row, g)| row[0] * u[0] + row[1] * u[1] > g + 1e-6)
        });
        prop_assume!(breaks);
        ilqr.controls_mut().fill(0.0);
        let mut fixed = Fixed { rows: constraints.rows.clone(), bounds: constraints.bounds.clone() };
        ilqr.solve_constrained(&mut sys, &mut fixed, &x0, &settings).unwrap();
        let scale = 1.0 + expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (got, want) in ilqr.controls().iter().zip(&expected) {
            prop_assert!(
                (got - want).abs() < 1e-5 * scale,
                "iLQR {:?}\nQP   {:?}", ilqr.controls(), expected
            );
        }
        // Every planned control is within the rows.
        for u in ilqr.controls().chunks_exact(nu) {
            for (row, g) in constraints.rows.chunks_exact(nu).zip(&constraints.bounds) {
                prop_assert!(row[0] * u[0] + row[1] * u[1] <= g + 1e-9);
            }
        }
    }
}

/// Without reserved rows a constrained solve is refused; a step whose rows admit no control is
/// planned within the box alone (here every step: the plan of the unconstrained solve) and
/// counted.
#[test]
fn constrained_solves_need_their_rows_reserved_and_plan_empty_steps_within_the_box() {
    let cost = TrackingCost {
        state: vec![1.0; 2],
        control: vec![1.0; 2],
        terminal: vec![1.0; 2],
    };
    let mut sys = Linear {
        a: vec![1.0, 0.1, 0.0, 1.0],
        b: vec![0.0, 0.0, 0.1, 0.1],
        nx: 2,
        nu: 2,
    };
    let mut ilqr = Ilqr::new(2, 2, 4, &cost).unwrap();
    // u_1 <= -1 and -u_1 <= -1: no control.
    let mut empty = Fixed {
        rows: vec![1.0, 0.0, -1.0, 0.0],
        bounds: vec![-1.0, -1.0],
    };
    let settings = IlqrSettings::default();
    let refused = ilqr.solve_constrained(&mut sys, &mut empty, &[1.0, 0.0], &settings);
    assert!(
        matches!(refused, Err(OptimalError::InvalidSetting { .. })),
        "{refused:?}"
    );
    ilqr.reserve_constraints(2).unwrap();
    let report = ilqr
        .solve_constrained(&mut sys, &mut empty, &[1.0, 0.0], &settings)
        .unwrap();
    assert_eq!(report.relaxed_nodes, 4);
    let mut free = Ilqr::new(2, 2, 4, &cost).unwrap();
    free.solve(&mut sys, &[1.0, 0.0], &settings).unwrap();
    for (got, want) in ilqr.controls().iter().zip(free.controls()) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

/// The paper's arm with `alpha0 = pi/2` fixed.
fn paper_arm() -> modal_reduce::ReducedModel {
    modal_reduce::ReducedModel::new(
        manip_dyn::ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        backbone_kin::ModalMap::paper_fixed_alpha0(10, std::f64::consts::FRAC_PI_2).unwrap(),
    )
    .unwrap()
}

/// The joint torques of `tau_star` at `(a, a_dot)` by RNEA on the full chain (eq 12) with the
/// joint accelerations `J a_ddot` of the reduced forward dynamics (eq 15).
fn rnea_torques(
    model: &modal_reduce::ReducedModel,
    a: &[f64],
    a_dot: &[f64],
    u: &[f64],
) -> Vec<f64> {
    let mut data = modal_reduce::ReducedData::new(model);
    let mut a_ddot = [0.0; 2];
    modal_reduce::forward_dynamics(model, &mut data, a, a_dot, u, &mut a_ddot).unwrap();
    let (mut q, mut v, mut qdd, mut tau) = ([0.0; 10], [0.0; 10], [0.0; 10], vec![0.0; 10]);
    let map = model.map();
    map.joint_angles(a, &mut q).unwrap();
    map.joint_rates(a_dot, &mut v).unwrap();
    map.joint_rates(&a_ddot, &mut qdd).unwrap();
    let mut chain = manip_dyn::ChainData::new(model.chain());
    manip_dyn::rnea(model.chain(), &mut chain, &q, &v, &qdd, &mut tau).unwrap();
    tau
}

#[test]
fn the_joint_torque_rows_are_the_chain_s_torques() {
    let model = paper_arm();
    let mut rows = optimal_ctl::JointTorqueRows::new(&model, &[2.0; 10]).unwrap();
    let (mut g, mut bounds) = (vec![0.0; 40], vec![0.0; 20]);
    let x = [0.4, -0.3, 1.5, -0.7];
    assert_eq!(
        rows.rows(0, &x, &[0.0; 2], &[], &mut g, &mut bounds)
            .unwrap(),
        20
    );
    for u in [[0.0, 0.0], [1.3, -0.4], [-2.0, 3.0]] {
        let tau = rnea_torques(&model, &x[..2], &x[2..], &u);
        for j in 0..10 {
            // Row 2j is A_j u <= limit - b_j: A_j u + b_j = tau_j.
            let affine = g[2 * j * 2] * u[0] + g[2 * j * 2 + 1] * u[1] + (2.0 - bounds[2 * j]);
            assert!(
                (affine - tau[j]).abs() < 1e-10,
                "joint {j}: {affine} vs {}",
                tau[j]
            );
            assert_eq!(g[(2 * j + 1) * 2], -g[2 * j * 2]);
            assert!((bounds[2 * j + 1] - (2.0 + (2.0 - bounds[2 * j]))).abs() < 1e-12);
        }
    }
}

/// The rows `|A tau* + b| <= limits` by the second algorithm of the definition: `b` the joint
/// torques (eq 13) of the forward dynamics (eq 15) under zero modal torque, `A`'s column `i`
/// those under the unit torque `e_i` less `b` (`m + 1` forward-dynamics solves).
fn rows_by_unit_torques(plant: modal_reduce::Plant<'_>, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (n, m) = (plant.n_joints(), plant.n_coords());
    let mut data = modal_reduce::PlantData::new(plant);
    let (a, a_dot) = (&x[..m], &x[m..]);
    let torques = |data: &mut modal_reduce::PlantData, unit: Option<usize>| {
        let mut tau_star = vec![0.0; m];
        if let Some(i) = unit {
            tau_star[i] = 1.0;
        }
        let (mut a_ddot, mut tau) = (vec![0.0; m], vec![0.0; n]);
        plant
            .forward_dynamics(data, a, a_dot, &tau_star, &mut a_ddot)
            .unwrap();
        plant
            .joint_torques(data, a, a_dot, &a_ddot, &mut tau)
            .unwrap();
        tau
    };
    let bias = torques(&mut data, None);
    let mut columns = vec![0.0; n * m];
    for i in 0..m {
        for (j, tau) in torques(&mut data, Some(i)).iter().enumerate() {
            columns[j * m + i] = tau - bias[j];
        }
    }
    (columns, bias)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// `JointTorqueLimits::rows` (one `M*`, `C*`, `G*` and a Cholesky solve) writes the rows of
    /// the unit-torque construction to 1e-12 of their scale, planar (the paper's arm with and
    /// without a free base angle) and spatial, at random states.
    #[test]
    fn the_joint_torque_rows_match_the_unit_torque_construction(
        x in proptest::collection::vec(-2.0f64..2.0, 12),
        family in 0usize..3,
    ) {
        let planar_free = modal_reduce::ReducedModel::new(
            manip_dyn::ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
            backbone_kin::ModalMap::paper(10).unwrap(),
        )
        .unwrap();
        let (planar, spatial) = (
            paper_arm(),
            modal_reduce::spatial::SpatialReducedModel::uniform_rods(6, 1, 0.1, 0.1, [0.0, -9.81, 0.0])
                .unwrap(),
        );
        let plant: modal_reduce::Plant<'_> = match family {
            0 => (&planar).into(),
            1 => (&planar_free).into(),
            _ => (&spatial).into(),
        };
        let (n, m) = (plant.n_joints(), plant.n_coords());
        let x = &x[..2 * m];
        let limits: Vec<f64> = (0..n).map(|j| 1.0 + 0.1 * j as f64).collect();
        let mut rows = optimal_ctl::JointTorqueLimits::new(plant, &limits).unwrap();
        let (mut g, mut bounds) = (vec![0.0; 2 * n * m], vec![0.0; 2 * n]);
        prop_assert_eq!(rows.rows(plant, x, &mut g, &mut bounds).unwrap(), 2 * n);
        let (columns, bias) = rows_by_unit_torques(plant, x);
        let scale = columns.iter().chain(&bias).fold(1.0f64, |s, v| s.max(v.abs()));
        for j in 0..n {
            for i in 0..m {
                prop_assert!((g[2 * j * m + i] - columns[j * m + i]).abs() <= 1e-12 * scale);
                prop_assert_eq!(g[(2 * j + 1) * m + i], -g[2 * j * m + i]);
            }
            prop_assert!((bounds[2 * j] - (limits[j] - bias[j])).abs() <= 1e-12 * scale);
            prop_assert!((bounds[2 * j + 1] - (limits[j] + bias[j])).abs() <= 1e-12 * scale);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// `JointTorqueLimits::state_jacobian` (closed form) matches central differences of the
    /// rows' residuals `G(x) u - g(x)` at a fixed modal torque `u` to 1e-6 of their scale on
    /// the paper's arm with and without a free base angle, at random states and torques; on a
    /// spatial arm it declines (`false`, the solve takes forward differences).
    #[test]
    fn the_joint_torque_rows_state_jacobian_matches_finite_differences(
        x in proptest::collection::vec(-1.5f64..1.5, 6),
        u in proptest::collection::vec(-2.0f64..2.0, 3),
        free in any::<bool>(),
    ) {
        let planar_free = modal_reduce::ReducedModel::new(
            manip_dyn::ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
            backbone_kin::ModalMap::paper(10).unwrap(),
        )
        .unwrap();
        let planar = paper_arm();
        let plant: modal_reduce::Plant<'_> =
            if free { (&planar_free).into() } else { (&planar).into() };
        let (n, m) = (plant.n_joints(), plant.n_coords());
        let (x, u, nx) = (&x[..2 * m], &u[..m], 2 * m);
        let limits: Vec<f64> = (0..n).map(|j| 1.0 + 0.1 * j as f64).collect();
        let mut limits = optimal_ctl::JointTorqueLimits::new(plant, &limits).unwrap();
        let mut jacobian = vec![0.0; 2 * n * nx];
        prop_assert!(limits.state_jacobian(plant, x, u, &mut jacobian).unwrap());
        let (mut g, mut bounds) = (vec![0.0; 2 * n * m], vec![0.0; 2 * n]);
        let mut residuals = |x: &[f64]| -> Vec<f64> {
            limits.rows(plant, x, &mut g, &mut bounds).unwrap();
            (0..2 * n)
                .map(|r| (0..m).map(|i| g[r * m + i] * u[i]).sum::<f64>() - bounds[r])
                .collect()
        };
        let step = 1e-6;
        let mut differences = vec![0.0; 2 * n * nx];
        for c in 0..nx {
            let (mut plus, mut minus) = (x.to_vec(), x.to_vec());
            plus[c] += step;
            minus[c] -= step;
            let (up, down) = (residuals(&plus), residuals(&minus));
            for r in 0..2 * n {
                differences[r * nx + c] = (up[r] - down[r]) / (2.0 * step);
            }
        }
        let scale = differences.iter().fold(1.0f64, |s, d| s.max(d.abs()));
        for (analytic, difference) in jacobian.iter().zip(&differences) {
            prop_assert!(
                (analytic - difference).abs() <= 1e-6 * scale,
                "{analytic} against {difference} (scale {scale})"
            );
        }
        let spatial =
            modal_reduce::spatial::SpatialReducedModel::uniform_rods(6, 1, 0.1, 0.1, [0.0, -9.81, 0.0])
                .unwrap();
        let plant: modal_reduce::Plant<'_> = (&spatial).into();
        let (n, m) = (plant.n_joints(), plant.n_coords());
        let mut limits = optimal_ctl::JointTorqueLimits::new(plant, &vec![1.0; n]).unwrap();
        let mut jacobian = vec![7.0; 4 * n * m];
        prop_assert!(!limits.state_jacobian(plant, &vec![0.1; 2 * m], &vec![0.0; m], &mut jacobian).unwrap());
        prop_assert!(jacobian.iter().all(|&d| d == 7.0));
    }
}

/// MPC on the paper's arm towards a bent shape: the unconstrained plan asks for joint torques
/// beyond 3 N m; the plan within the joint-torque polytope keeps every node's joint torques
/// (by RNEA, at the planned states) within them.
#[test]
fn mpc_plans_within_the_joint_torque_limits() {
    let model = paper_arm();
    let mut settings = optimal_ctl::MpcSettings::uniform(2);
    settings.horizon = 30;
    let limit = 3.0;
    let target = ([0.6, -0.4], [0.0; 2], [0.0; 2]);
    let plan = |constrained: bool| {
        let mut mpc = optimal_ctl::Mpc::new(&model, &settings).unwrap();
        for k in 0..=mpc.horizon() {
            mpc.set_reference(&model, k, &target.0, &target.1, &target.2)
                .unwrap();
        }
        let mut rows = optimal_ctl::JointTorqueRows::new(&model, &[limit; 10]).unwrap();
        for _ in 0..4 {
            if constrained {
                mpc.solve_constrained(&model, &[0.0; 2], &[0.0; 2], &mut rows)
                    .unwrap();
            } else {
                mpc.solve(&model, &[0.0; 2], &[0.0; 2]).unwrap();
            }
        }
        let ilqr = mpc.ilqr();
        let peak = (0..ilqr.horizon())
            .map(|k| {
                let x = &ilqr.states()[k * 4..(k + 1) * 4];
                let u = &ilqr.controls()[k * 2..(k + 1) * 2];
                rnea_torques(&model, &x[..2], &x[2..], u)
                    .iter()
                    .fold(0.0f64, |m, t| m.max(t.abs()))
            })
            .fold(0.0f64, f64::max);
        (peak, ilqr.states()[ilqr.horizon() * 4])
    };
    let (free_peak, _) = plan(false);
    assert!(free_peak > 1.5 * limit, "{free_peak}");
    let (peak, a1_end) = plan(true);
    assert!(peak <= limit * (1.0 + 1e-9), "{peak}");
    // ... and still moves towards the target.
    assert!(a1_end > 0.1, "{a1_end}");
}

/// The gain keeps the active joint-torque rows active as the state moves, the rows' own state
/// dependence included (`A K = -D` for the active rows `A u <= g(x)`, `D = d(A u - g)/dx`): at
/// every node of a converged plan within binding limits where one or two rows are active, a
/// state step `dx` with the control `u + K dx` changes those rows' residuals by under 1% of
/// `|dx|` (second order, and `D`'s forward differences). A gain blind to `D` changes them by
/// `D dx` (58% of `|dx|` here), which the forward pass's projection then undoes, and its
/// line searches fail.
#[test]
fn the_gain_keeps_the_active_joint_torque_rows_active_as_the_state_moves() {
    let model = paper_arm();
    let mut settings = optimal_ctl::MpcSettings::uniform(2);
    settings.horizon = 30;
    settings.solver.max_iterations = 60;
    settings.solver.tolerance = 1e-9;
    let limit = 3.0;
    let mut mpc = optimal_ctl::Mpc::new(&model, &settings).unwrap();
    for k in 0..=mpc.horizon() {
        mpc.set_reference(&model, k, &[0.6, -0.4], &[0.0; 2], &[0.0; 2])
            .unwrap();
    }
    let mut rows = optimal_ctl::JointTorqueRows::new(&model, &[limit; 10]).unwrap();
    mpc.reserve_constraints(rows.max_rows()).unwrap();
    let report = mpc
        .solve_constrained(&model, &[0.0; 2], &[0.0; 2], &mut rows)
        .unwrap();
    assert!(report.converged, "{report:?}");
    let ilqr = mpc.ilqr();
    let (mut g, mut bounds) = (vec![0.0; 40], vec![0.0; 20]);
    let (mut g_step, mut bounds_step) = (vec![0.0; 40], vec![0.0; 20]);
    let residual = |g: &[f64], bounds: &[f64], r: usize, u: &[f64]| {
        g[2 * r] * u[0] + g[2 * r + 1] * u[1] - bounds[r]
    };
    let mut checked = 0;
    for k in 0..ilqr.horizon() {
        let x = &ilqr.states()[k * 4..(k + 1) * 4];
        let u = &ilqr.controls()[k * 2..(k + 1) * 2];
        let gain = &ilqr.gains()[k * 8..(k + 1) * 8];
        rows.rows(k, x, u, &[], &mut g, &mut bounds).unwrap();
        let active: Vec<usize> = (0..20)
            .filter(|&r| residual(&g, &bounds, r, u).abs() <= 1e-7 * (1.0 + bounds[r].abs()))
            .collect();
        if active.is_empty() || active.len() > 2 {
            continue;
        }
        for direction in [[1.0, -0.5, 0.3, 0.8], [-0.2, 0.7, -1.0, 0.4]] {
            let eps = 1e-5;
            let dx = direction.map(|d| eps * d);
            let moved: Vec<f64> = x.iter().zip(&dx).map(|(x, d)| x + d).collect();
            let controlled: Vec<f64> = (0..2)
                .map(|j| u[j] + (0..4).map(|i| gain[j * 4 + i] * dx[i]).sum::<f64>())
                .collect();
            rows.rows(k, &moved, &controlled, &[], &mut g_step, &mut bounds_step)
                .unwrap();
            for &r in &active {
                let change =
                    residual(&g_step, &bounds_step, r, &controlled) - residual(&g, &bounds, r, u);
                assert!(
                    change.abs() <= 1e-2 * eps,
                    "node {k}, row {r}: the residual moved by {change:e} for |dx| ~ {eps:e}"
                );
            }
        }
        checked += 1;
    }
    assert!(checked >= 3, "{checked} nodes with active rows");
}

/// A receding-horizon warm start follows the previous plan's feedback: on `x' = 2 x + u` over
/// 1100 steps from a state off the previous plan, where the shifted controls open loop overflow,
/// the warm start costs the optimum of the scalar Riccati recursion (the plan's gains are the
/// regulator's) and the solve ends there; controls set by hand are rolled out open loop and
/// refused.
#[test]
fn a_warm_start_that_diverges_open_loop_follows_the_previous_plan() {
    let (a, b, horizon) = (2.0, 1.0, 1100);
    let cost = TrackingCost {
        state: vec![1.0],
        control: vec![1.0],
        terminal: vec![1.0],
    };
    let mut sys = Linear {
        a: vec![a],
        b: vec![b],
        nx: 1,
        nu: 1,
    };
    let settings = IlqrSettings::default();
    let mut ilqr = Ilqr::new(1, 1, horizon, &cost).unwrap();
    // The plan at the reference: zero controls with the regulator's gains.
    ilqr.solve(&mut sys, &[0.0], &settings).unwrap();
    ilqr.shift(1);
    // 2^1100 overflows: open loop, the shifted zero controls give an infinite cost.
    let report = ilqr.solve(&mut sys, &[1.0], &settings).unwrap();
    // The optimum 1/2 P_0 x_0^2 from P_N = Q_f, P = Q + a^2 P - (a b P)^2 / (R + b^2 P).
    let mut p = 1.0;
    for _ in 0..horizon {
        p = 1.0 + a * a * p - (a * b * p).powi(2) / (1.0 + b * b * p);
    }
    let optimum = 0.5 * p;
    assert!(report.converged, "{report:?}");
    assert!(
        (report.initial_cost - optimum).abs() < 1e-9 * optimum,
        "{} vs {optimum}",
        report.initial_cost
    );
    assert!(
        (report.cost - optimum).abs() < 1e-9 * optimum,
        "{} vs {optimum}",
        report.cost
    );
    // Controls set by hand are rolled out open loop: refused as before.
    ilqr.controls_mut().fill(0.0);
    let error = ilqr.solve(&mut sys, &[1.0], &settings).unwrap_err();
    assert!(
        matches!(
            error,
            OptimalError::InvalidSetting {
                name: "warm start",
                ..
            }
        ),
        "{error}"
    );
}

/// Rows `G u <= g + s x_1` whose bounds move with the state, counting their evaluations; said
/// to be of `(k, x, u)` alone from `reuse` 1 on and of `(k, x)` alone at 2, with a state
/// Jacobian when `jacobian` says so.
struct Moving {
    fixed: Fixed,
    slope: f64,
    reuse: u8,
    jacobian: bool,
    calls: usize,
}

impl StepConstraints for Moving {
    fn max_rows(&self) -> usize {
        self.fixed.max_rows()
    }

    fn rows(
        &mut self,
        k: usize,
        x: &[f64],
        u: &[f64],
        b: &[f64],
        rows: &mut [f64],
        bounds: &mut [f64],
    ) -> Result<usize, OptimalError> {
        self.calls += 1;
        let count = self.fixed.rows(k, x, u, b, rows, bounds)?;
        for bound in &mut bounds[..count] {
            *bound += self.slope * x[0];
        }
        Ok(count)
    }

    fn state_jacobian(&self) -> bool {
        self.jacobian
    }

    fn rows_of_state_and_control(&self) -> bool {
        self.reuse >= 1
    }

    fn rows_of_state(&self) -> bool {
        self.reuse >= 2
    }
}

/// Rows of `(k, x, u)` alone that a forward pass wrote at the state and control an accepted
/// pass keeps are reused, not evaluated again (nor their QP, where the projection found them
/// empty), and rows of `(k, x)` alone at the state it keeps: the same plan and relaxed nodes
/// to the bit, with fewer evaluations, with and without the rows' state Jacobian (by forward
/// differences), for rows active at many steps and for rows that admit no control while
/// `x_1 < 0.1`.
#[test]
fn rows_of_the_accepted_forward_pass_are_reused_to_the_bit() {
    let cost = TrackingCost {
        state: vec![2.0, 1.0],
        control: vec![0.5, 0.5],
        terminal: vec![4.0, 2.0],
    };
    let x_ref: Vec<f64> = (0..=8).flat_map(|k| [1.5 - 0.1 * k as f64, 0.3]).collect();
    let settings = IlqrSettings {
        max_iterations: 30,
        tolerance: 1e-14,
        ..IlqrSettings::default()
    };
    let cases = [
        // u_1 + u_2 <= 0.4 + x_1 and -u_1 <= 0.3 + x_1: active at many steps.
        (vec![1.0, 1.0, -1.0, 0.0], vec![0.4, 0.3], false),
        // u_1 <= 0.1 + x_1 and u_1 >= 0.3 - x_1: empty while x_1 < 0.1.
        (vec![1.0, 0.0, -1.0, 0.0], vec![0.1, -0.3], true),
    ];
    for ((g, bounds, empty), jacobian) in
        cases.iter().flat_map(|case| [(case, false), (case, true)])
    {
        let plan = |reuse: u8| {
            let mut sys = Linear {
                a: vec![1.0, 0.1, -0.05, 0.98],
                b: vec![0.0, 0.05, 0.1, 0.02],
                nx: 2,
                nu: 2,
            };
            let mut rows = Moving {
                fixed: Fixed {
                    rows: g.clone(),
                    bounds: bounds.clone(),
                },
                slope: 1.0,
                reuse,
                jacobian,
                calls: 0,
            };
            let mut ilqr = Ilqr::new(2, 2, 8, &cost).unwrap();
            ilqr.reserve_constraints(2).unwrap();
            ilqr.state_references_mut().copy_from_slice(&x_ref);
            let report = ilqr
                .solve_constrained(&mut sys, &mut rows, &[0.0, 0.0], &settings)
                .unwrap();
            assert!(report.iterations > 1, "{report:?}");
            assert_eq!(report.relaxed_nodes > 0, *empty, "{report:?}");
            let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            (
                bits(ilqr.controls()),
                bits(ilqr.states()),
                rows.calls,
                report.relaxed_nodes,
            )
        };
        let fresh = plan(0);
        let mut calls = vec![fresh.2];
        for reuse in [1, 2] {
            let reused = plan(reuse);
            assert_eq!(
                fresh.0, reused.0,
                "controls (reuse {reuse}, jacobian {jacobian})"
            );
            assert_eq!(
                fresh.1, reused.1,
                "states (reuse {reuse}, jacobian {jacobian})"
            );
            assert_eq!(
                fresh.3, reused.3,
                "relaxed (reuse {reuse}, jacobian {jacobian})"
            );
            calls.push(reused.2);
        }
        // With the state Jacobian the gain moves the controls along the rows and the forward
        // pass's projection moves some of them: only rows of `(k, x)` alone are reused there.
        let fewer = if jacobian {
            calls[2] < calls[1]
        } else {
            calls[2] <= calls[1]
        };
        assert!(
            fewer && calls[1] < calls[0],
            "evaluations {calls:?} (jacobian {jacobian})"
        );
    }
}

/// A constrained solve allocates nothing, on a clone of a solver too (a clone's working memory
/// is sized as the original's, whatever the projections' active sets held before).
#[test]
fn a_constrained_solve_allocates_nothing_on_a_clone_too() {
    assert!(test_support::alloc::is_counting());
    let cost = TrackingCost {
        state: vec![2.0, 1.0],
        control: vec![0.5, 0.5],
        terminal: vec![4.0, 2.0],
    };
    let mut sys = Linear {
        a: vec![1.0, 0.1, -0.05, 0.98],
        b: vec![0.0, 0.05, 0.1, 0.02],
        nx: 2,
        nu: 2,
    };
    // Four rows, two of them active together at the early steps.
    let mut rows = Fixed {
        rows: vec![1.0, 1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0],
        bounds: vec![0.4, 0.3, 0.5, 0.35],
    };
    // The original plans at rest within the rows (no projection has an active set), the clone
    // towards a reference that needs them.
    let mut ilqr = Ilqr::new(2, 2, 8, &cost).unwrap();
    ilqr.reserve_constraints(4).unwrap();
    let settings = IlqrSettings::default();
    ilqr.solve_constrained(&mut sys, &mut rows, &[0.0, 0.0], &settings)
        .unwrap();
    let mut clone = ilqr.clone();
    clone.state_references_mut().fill(2.0);
    let count = test_support::alloc::allocations_during(|| {
        clone
            .solve_constrained(&mut sys, &mut rows, &[0.1, 0.0], &settings)
            .unwrap();
    });
    assert_eq!(count, 0);
    let active = clone
        .controls()
        .chunks_exact(2)
        .filter(|u| (u[0] + u[1] - 0.4).abs() < 1e-9 || (u[1] - 0.35).abs() < 1e-9)
        .count();
    assert!(active > 1, "{:?}", clone.controls());
}
