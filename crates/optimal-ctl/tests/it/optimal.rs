//! The optimal-control building blocks on the paper's arm: the linearisation (of planar and
//! spatial arms) against the nonlinear flow (finite differences of an RK4 integration about an equilibrium), the LQR's
//! Riccati residual and closed-loop stability, and the regulator driving the nonlinear model
//! back to its reference.

use backbone_kin::{BaseAngle, ModalMap};
use manip_dyn::ChainModel;
use modal_reduce::spatial::SpatialReducedModel;
use modal_reduce::{Plant, PlantData, ReducedModel};
use optimal_ctl::{Linearisation, Lqr, LqrSettings, OptimalError};

fn model(harmonics: usize, base: BaseAngle) -> ReducedModel {
    let map = ModalMap::new(&[0.1; 10], harmonics, base).unwrap();
    ReducedModel::new(ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(), map).unwrap()
}

/// The generalised forces holding `a` at rest: `G*(a)`.
fn holding(model: Plant<'_>, a: &[f64]) -> Vec<f64> {
    let m = model.n_coords();
    let mut data = PlantData::new(model);
    let mut out = vec![0.0; m];
    model
        .forward_dynamics(&mut data, a, &vec![0.0; m], &vec![0.0; m], &mut out)
        .unwrap();
    data.gravity().to_vec()
}

/// The nonlinear state after `period` s with `u` held, by RK4 with `steps` steps.
fn flow(model: Plant<'_>, x: &[f64], u: &[f64], period: f64, steps: usize) -> Vec<f64> {
    let m = model.n_coords();
    let mut data = PlantData::new(model);
    let mut rhs = |x: &[f64]| -> Vec<f64> {
        let mut a_ddot = vec![0.0; m];
        model
            .forward_dynamics(&mut data, &x[..m], &x[m..], u, &mut a_ddot)
            .unwrap();
        [&x[m..], &a_ddot[..]].concat()
    };
    let h = period / steps as f64;
    let mut x = x.to_vec();
    for _ in 0..steps {
        let shifted = |x: &[f64], k: &[f64], s: f64| -> Vec<f64> {
            x.iter().zip(k).map(|(a, b)| a + s * b).collect()
        };
        let k1 = rhs(&x);
        let k2 = rhs(&shifted(&x, &k1, h / 2.0));
        let k3 = rhs(&shifted(&x, &k2, h / 2.0));
        let k4 = rhs(&shifted(&x, &k3, h));
        for i in 0..x.len() {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    x
}

#[test]
fn discrete_linearisation_is_the_jacobian_of_the_flow_at_an_equilibrium() {
    let planar: Vec<ReducedModel> = [
        (1, BaseAngle::Fixed(1.4)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Fixed(1.4)),
    ]
    .into_iter()
    .map(|(harmonics, base)| model(harmonics, base))
    .collect();
    // A spatial arm, a cantilever under gravity along -z (m = 4 and 8).
    let spatial: Vec<SpatialReducedModel> = [1, 2]
        .into_iter()
        .map(|k| SpatialReducedModel::uniform_rods(10, k, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap())
        .collect();
    let plants = planar
        .iter()
        .map(Plant::from)
        .chain(spatial.iter().map(Plant::from));
    for model in plants {
        let m = model.n_coords();
        let a: Vec<f64> = [0.4, -0.3, 0.2, 0.1, 1.2, -0.2, 0.3, 0.1][..m].to_vec();
        let u = holding(model, &a);
        let period = 0.01;
        let mut lin = Linearisation::new(model);
        lin.linearise(model, &a, &vec![0.0; m], &u, period).unwrap();
        assert!(
            lin.drift().iter().all(|x| x.abs() < 1e-12),
            "not an equilibrium"
        );
        let x: Vec<f64> = [a.clone(), vec![0.0; m]].concat();
        let eps = 1e-6;
        for k in 0..3 * m {
            let (mut xp, mut xm, mut up, mut um) = (x.clone(), x.clone(), u.clone(), u.clone());
            if k < 2 * m {
                xp[k] += eps;
                xm[k] -= eps;
            } else {
                up[k - 2 * m] += eps;
                um[k - 2 * m] -= eps;
            }
            let plus = flow(model, &xp, &up, period, 50);
            let minus = flow(model, &xm, &um, period, 50);
            for i in 0..2 * m {
                let fd = (plus[i] - minus[i]) / (2.0 * eps);
                let analytic = if k < 2 * m {
                    lin.discrete_a()[(i, k)]
                } else {
                    lin.discrete_b()[(i, k - 2 * m)]
                };
                assert!(
                    (fd - analytic).abs() < 1e-6 * (1.0 + fd.abs()),
                    "m = {m}, [{i}][{k}]: exp {analytic} vs flow {fd}"
                );
            }
        }
        // The continuous pair: [[0, I], [d_a, d_a_dot]] and [[0], [M*^-1]].
        for i in 0..m {
            for j in 0..2 * m {
                let expected = if j == m + i { 1.0 } else { 0.0 };
                assert_eq!(lin.continuous_a()[(i, j)], expected);
            }
            for j in 0..m {
                assert_eq!(lin.continuous_b()[(i, j)], 0.0);
            }
        }
    }
}

/// Weights: unit on positions, 0.1 on rates; `r` on the controls.
fn weights(m: usize, r: f64) -> (Vec<f64>, Vec<f64>) {
    let n = 2 * m;
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        q[i * n + i] = if i < m { 1.0 } else { 0.1 };
    }
    let mut rm = vec![0.0; m * m];
    for i in 0..m {
        rm[i * m + i] = r;
    }
    (q, rm)
}

fn row_major(mat: faer::MatRef<'_, f64>) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 0..mat.nrows() {
        for j in 0..mat.ncols() {
            out.push(mat[(i, j)]);
        }
    }
    out
}

fn mul(a: &[f64], b: &[f64], r: usize, k: usize, c: usize) -> Vec<f64> {
    (0..r * c)
        .map(|x| (0..k).map(|l| a[(x / c) * k + l] * b[l * c + x % c]).sum())
        .collect()
}

fn transpose(a: &[f64], r: usize, c: usize) -> Vec<f64> {
    (0..r * c).map(|x| a[(x % r) * c + x / r]).collect()
}

#[test]
fn lqr_solves_the_riccati_equation_and_stabilises_the_loop() {
    for (harmonics, base) in [
        (1, BaseAngle::Fixed(1.4)),
        (1, BaseAngle::Free),
        (2, BaseAngle::Fixed(1.4)),
    ] {
        let model = model(harmonics, base);
        let (m, n) = (model.n_coords(), 2 * model.n_coords());
        let a: Vec<f64> = [0.4, -0.3, 0.2, 0.1, 1.2][..m].to_vec();
        let u = holding((&model).into(), &a);
        let mut lin = Linearisation::new(&model);
        lin.linearise(&model, &a, &vec![0.0; m], &u, 0.01).unwrap();
        let (q, r) = weights(m, 1e-2);
        let mut lqr = Lqr::new(m, &q, &r).unwrap();
        let steps = lqr.solve(&lin, &LqrSettings::default()).unwrap();
        // Doubling: a few tens of steps stand for 2^steps steps of the recursion.
        assert!(steps <= 30, "m = {m}: {steps} doubling steps");
        let (ad, bd) = (row_major(lin.discrete_a()), row_major(lin.discrete_b()));
        let p = row_major(lqr.cost_to_go());
        let k = row_major(lqr.gain());
        // Residual of P = Q + A'PA - A'PB (R + B'PB)^-1 B'PA, with K = (R + B'PB)^-1 B'PA.
        let at = transpose(&ad, n, n);
        let apa = mul(&at, &mul(&p, &ad, n, n, n), n, n, n);
        let apb = mul(&at, &mul(&p, &bd, n, n, m), n, n, m);
        let correction = mul(&apb, &k, n, m, n);
        let scale = p.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        for i in 0..n * n {
            let residual = q[i] + apa[i] - correction[i] - p[i];
            assert!(
                residual.abs() < 1e-9 * scale,
                "m = {m}: residual {residual} (scale {scale})"
            );
        }
        // The gain is K itself: (R + B'PB) K = B'PA.
        let s: Vec<f64> = mul(&transpose(&bd, n, m), &mul(&p, &bd, n, n, m), m, n, m)
            .iter()
            .zip(&r)
            .map(|(x, y)| x + y)
            .collect();
        let lhs = mul(&s, &k, m, m, n);
        let rhs = transpose(&apb, n, m);
        for i in 0..m * n {
            assert!((lhs[i] - rhs[i]).abs() < 1e-9 * scale);
        }
        // Closed loop A - B K: its powers decay (spectral radius below one), while the open loop
        // (an arm hanging off a held pose is not stable in every mode) need not.
        let closed: Vec<f64> = ad
            .iter()
            .zip(mul(&bd, &k, n, m, n))
            .map(|(a, bk)| a - bk)
            .collect();
        let mut power = closed.clone();
        for _ in 0..11 {
            power = mul(&power, &power, n, n, n); // closed^(2^12)
        }
        let norm = power.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        assert!(norm < 1e-6, "m = {m}: ||(A - BK)^4096|| = {norm}");
    }
}

#[test]
fn lqr_brings_the_nonlinear_arm_back_to_its_reference() {
    let model = model(1, BaseAngle::Fixed(1.4));
    let m = model.n_coords();
    let a_ref = vec![0.4, -0.3];
    let u_ref = holding((&model).into(), &a_ref);
    let period = 0.01;
    let mut lin = Linearisation::new(&model);
    lin.linearise(&model, &a_ref, &[0.0, 0.0], &u_ref, period)
        .unwrap();
    let (q, r) = weights(m, 1e-2);
    let mut lqr = Lqr::new(m, &q, &r).unwrap();
    lqr.solve(&lin, &LqrSettings::default()).unwrap();
    let x_ref = [a_ref.clone(), vec![0.0; m]].concat();
    let mut x = vec![0.55, -0.15, 0.5, -0.5];
    let mut u = vec![0.0; m];
    for _ in 0..300 {
        lqr.control(&u_ref, &x, &x_ref, &mut u).unwrap();
        x = flow((&model).into(), &x, &u, period, 10);
    }
    for (xi, ri) in x.iter().zip(&x_ref) {
        assert!((xi - ri).abs() < 1e-4, "{x:?} vs {x_ref:?}");
    }
}

#[test]
fn bad_settings_are_refused() {
    let model = model(1, BaseAngle::Free);
    let m = model.n_coords();
    let (q, r) = weights(m, 1e-2);
    let mut lin = Linearisation::new(&model);
    let error = lin
        .linearise(&model, &[0.0; 3], &[0.0; 3], &[0.0; 3], -0.1)
        .unwrap_err();
    assert!(
        matches!(error, OptimalError::InvalidSetting { name: "period", .. }),
        "{error}"
    );
    let error = lin
        .linearise(&model, &[0.0; 2], &[0.0; 3], &[0.0; 3], 0.1)
        .unwrap_err();
    assert!(matches!(error, OptimalError::Dynamics(_)), "{error}");
    let not_pd = vec![0.0; m * m];
    assert!(matches!(
        Lqr::new(m, &q, &not_pd),
        Err(OptimalError::NotPositiveDefinite("R"))
    ));
    assert!(matches!(
        Lqr::new(m, &q[1..], &r),
        Err(OptimalError::Dimension { name: "Q", .. })
    ));
    // A size whose entry count wraps around (2^32 squared is 0 in 64 bits) is refused by name.
    for huge in [1 << 32, usize::MAX] {
        assert!(matches!(
            Lqr::new(huge, &[], &[]),
            Err(OptimalError::Dimension { name: "Q", .. })
        ));
    }
    let mut lqr = Lqr::new(m, &q, &r).unwrap();
    lin.linearise(&model, &[0.1, 0.2, 1.0], &[0.0; 3], &[0.0; 3], 0.01)
        .unwrap();
    let settings = LqrSettings {
        max_iterations: 0,
        ..LqrSettings::default()
    };
    assert!(matches!(
        lqr.solve(&lin, &settings),
        Err(OptimalError::InvalidSetting { .. })
    ));
    let mut u = [0.0; 3];
    assert!(
        lqr.control(&[0.0; 3], &[0.0; 5], &[0.0; 6], &mut u)
            .is_err()
    );
}

#[test]
fn mpc_max_coords_is_the_largest_plan_the_workspace_holds() {
    use optimal_ctl::{Ilqr, MpcSettings, TrackingCost};
    let cost = |m: usize| TrackingCost {
        state: vec![1.0; 2 * m],
        control: vec![1.0; m],
        terminal: vec![1.0; 2 * m],
    };
    for horizon in [60, 1000] {
        let mut settings = MpcSettings::uniform(1);
        settings.horizon = horizon;
        let m = settings.max_coords();
        // 60 steps: 60 * 14 m^2 <= 2^25 up to m = 199.
        if horizon == 60 {
            assert_eq!(m, 199);
        }
        assert!(Ilqr::new(2 * m, m, horizon, &cost(m)).is_ok(), "{horizon}");
        let err = Ilqr::new(2 * (m + 1), m + 1, horizon, &cost(m + 1)).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("horizon * (2 n_x^2 + 3 n_x n_u) (the workspace's numbers) must be"),
            "{err}"
        );
    }
    // A state too large for any horizon is named with the workspace it needs, not the horizon.
    let err = Ilqr::new(usize::MAX, 1, 1, &cost(1)).unwrap_err();
    assert!(err.to_string().contains("workspace"), "{err}");
}

#[test]
fn mpc_weights_and_steps_that_vanish_are_refused_by_name() {
    use optimal_ctl::{Mpc, MpcSettings};
    let model = model(1, BaseAngle::Free);
    let mut settings = MpcSettings::uniform(3);
    settings.effort_weight = vec![5e-324; 3];
    let err = Mpc::new(&model, &settings).unwrap_err().to_string();
    assert!(
        err.starts_with("effort_weight must be large enough"),
        "{err}"
    );
    let mut settings = MpcSettings::uniform(3);
    settings.step = 5e-324;
    let err = Mpc::new(&model, &settings).unwrap_err().to_string();
    assert!(
        err.starts_with("step must be between 1e-9 s and 10 s"),
        "{err}"
    );
}
