//! The joint-space chain as a discrete system ([`ChainEuler`]) and its MPC ([`ChainMpc`]).

use manip_dyn::ChainModel;
use manip_dyn::spatial::{
    SpatialData, SpatialDerivativeData, SpatialJoint, SpatialLink, SpatialModel, Transform,
};
use optimal_ctl::{ChainEuler, ChainMpc, DiscreteDynamics, MpcSettings};

/// A four-link planar arm behind a massless carriage on a prismatic axis along `(0.6, 0.8)`
/// (the deployment's chain, `sim_study::Scenario::deploy_model`).
fn deploying_arm() -> SpatialModel {
    let planar = SpatialModel::from_planar(&ChainModel::uniform(4, 0.1, 0.1, 9.81).unwrap());
    let mut joints = vec![SpatialJoint::prismatic(
        [0.6, 0.8, 0.0],
        Transform::translation([0.1, -0.2, 0.0]),
    )];
    joints.extend_from_slice(planar.joints());
    let mut links = vec![SpatialLink {
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    }];
    links.extend_from_slice(planar.links());
    SpatialModel::new(joints, links, planar.gravity()).unwrap()
}

#[test]
fn the_jacobians_of_the_chain_euler_map_match_finite_differences() {
    let model = deploying_arm();
    let n = model.n_links();
    let (mut data, mut derivatives) =
        (SpatialData::new(&model), SpatialDerivativeData::new(&model));
    let h = 2e-3;
    let mut map = ChainEuler::new(&model, &mut data, &mut derivatives, h).unwrap();
    assert_eq!((map.state_dim(), map.control_dim()), (2 * n, n));
    let x: Vec<f64> = (0..2 * n).map(|i| 0.3 * (1.3 * i as f64).sin()).collect();
    let u: Vec<f64> = (0..n).map(|i| 0.2 + 0.1 * (0.7 * i as f64).cos()).collect();
    let (mut next, mut a, mut b) = (vec![0.0; 2 * n], vec![0.0; 4 * n * n], vec![0.0; 2 * n * n]);
    map.linearise(&x, &u, &mut next, &mut a, &mut b).unwrap();
    let mut plain = vec![0.0; 2 * n];
    map.step(&x, &u, &mut plain).unwrap();
    // linearise's accelerations come from the base-frame ABA of `aba_derivatives`, step's from
    // `aba`: the same F(x, u) to rounding.
    for (l, s) in next.iter().zip(&plain) {
        assert!(
            (l - s).abs() <= 1e-12 * (1.0 + s.abs()),
            "linearise's next state is step's: {l} vs {s}"
        );
    }
    let eps = 1e-6;
    let (mut up, mut down) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
    let mut worst: f64 = 0.0;
    for j in 0..2 * n {
        let (mut xp, mut xm) = (x.clone(), x.clone());
        xp[j] += eps;
        xm[j] -= eps;
        map.step(&xp, &u, &mut up).unwrap();
        map.step(&xm, &u, &mut down).unwrap();
        for i in 0..2 * n {
            let fd = (up[i] - down[i]) / (2.0 * eps);
            worst = worst.max((fd - a[i * 2 * n + j]).abs() / (1.0 + fd.abs()));
        }
    }
    for j in 0..n {
        let (mut upu, mut downu) = (u.clone(), u.clone());
        upu[j] += eps;
        downu[j] -= eps;
        map.step(&x, &upu, &mut up).unwrap();
        map.step(&x, &downu, &mut down).unwrap();
        for i in 0..2 * n {
            let fd = (up[i] - down[i]) / (2.0 * eps);
            worst = worst.max((fd - b[i * n + j]).abs() / (1.0 + fd.abs()));
        }
    }
    assert!(worst < 1e-7, "largest relative mismatch {worst:e}");
}

#[test]
fn chain_mpc_brings_the_deploying_arm_to_a_pose_within_its_box() {
    let model = deploying_arm();
    let n = model.n_links();
    let mut settings = MpcSettings::uniform(n);
    settings.horizon = 40;
    settings.step = 0.002;
    settings.effort_weight = vec![1.0; n];
    settings.tau_star_limits = Some(vec![10.0; n]);
    let mut mpc = ChainMpc::new(&model, &settings).unwrap();
    let target = [0.15, 1.0, 0.2, -0.1, 0.3];
    let zero = vec![0.0; n];
    for k in 0..=mpc.horizon() {
        mpc.set_reference(&model, k, &target, &zero, &zero).unwrap();
    }
    // The plant: the same Euler map at a finer step, re-planned every model step.
    let mut data = SpatialData::new(&model);
    let mut derivatives = SpatialDerivativeData::new(&model);
    let mut x = vec![0.0; 2 * n];
    x[1] = 1.2;
    let start_error: f64 = (0..n).map(|i| (x[i] - target[i]).abs()).fold(0.0, f64::max);
    let (mut tau, mut next) = (vec![0.0; n], vec![0.0; 2 * n]);
    let fine = settings.step / 5.0;
    for _ in 0..500 {
        let (q, v) = x.split_at(n);
        mpc.solve(&model, q, v).unwrap();
        for s in 0..5 {
            let (q, v) = x.split_at(n);
            mpc.control(s as f64 * fine, q, v, &mut tau).unwrap();
            assert!(tau.iter().all(|t| t.abs() <= 10.0), "{tau:?}");
            let mut plant = ChainEuler::new(&model, &mut data, &mut derivatives, fine).unwrap();
            plant.step(&x, &tau, &mut next).unwrap();
            x.copy_from_slice(&next);
        }
        mpc.shift(1);
    }
    let error: f64 = (0..n).map(|i| (x[i] - target[i]).abs()).fold(0.0, f64::max);
    assert!(error < 1e-3 * start_error, "{error:e} from {start_error}");
}

#[test]
fn chain_mpc_refuses_a_wrong_size_by_name() {
    let model = deploying_arm();
    let mut settings = MpcSettings::uniform(3);
    let e = ChainMpc::new(&model, &settings).unwrap_err();
    assert!(
        e.to_string().starts_with("position_weight has 3 entries"),
        "{e}"
    );
    settings = MpcSettings::uniform(5);
    settings.tau_star_limits = Some(vec![-1.0; 5]);
    let e = ChainMpc::new(&model, &settings).unwrap_err();
    assert!(
        e.to_string().contains("tau_star_limits must be positive"),
        "{e}"
    );
}

#[test]
fn chain_mpc_control_names_a_wrong_length_and_refuses_before_a_plan() {
    let model = deploying_arm();
    let n = model.n_links();
    let mut mpc = ChainMpc::new(&model, &MpcSettings::uniform(n)).unwrap();
    let (q, v) = (vec![0.0; n], vec![0.0; n]);
    let mut tau = vec![0.0; n];
    for (name, e) in [
        ("q", mpc.control(0.0, &q[1..], &v, &mut tau).unwrap_err()),
        ("v", mpc.control(0.0, &q, &[0.0; 2], &mut tau).unwrap_err()),
        ("tau", mpc.control(0.0, &q, &v, &mut [0.0; 1]).unwrap_err()),
    ] {
        assert!(e.to_string().starts_with(&format!("{name} has ")), "{e}");
    }
    let e = mpc.control(0.0, &q, &v, &mut tau).unwrap_err();
    assert!(e.to_string().contains("plan"), "{e}");
    mpc.solve(&model, &q, &v).unwrap();
    mpc.control(0.0, &q, &v, &mut tau).unwrap();
    assert!(tau.iter().all(|t| t.is_finite()), "{tau:?}");
}
