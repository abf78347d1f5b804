//! The rows MPC plans within ([`MpcLimits`], [`MpcConstraints`]): the clearance rows against
//! finite differences of the signed distance along the plan's dynamics, and plans of
//! [`MpcController`] that keep the joint torque and joint angle limits at every node where the
//! plan without them does not.

use backbone_kin::{BaseAngle, ModalMap};
use clearance::{ClearanceData, ClearanceModel, Obstacle};
use manip_dyn::ChainModel;
use modal_reduce::spatial::SpatialReducedModel;
use modal_reduce::{Plant, PlantData, PlantDerivatives, ReducedModel};
use optimal_ctl::{DiscreteDynamics, MpcSettings, ReducedEuler, StepConstraints};
use sim_core::controller::{
    CLEARANCE_APPROACH_S, ControlContext, Controller, ModalState, MpcConstraints, MpcController,
    MpcLimits,
};
use sim_core::reference::{ReferenceSample, Step};

/// The paper's 10-link arm with two harmonics, `alpha0 = pi/2` fixed (`m = 4`).
fn arm() -> ReducedModel {
    let lengths = [0.1; 10];
    ReducedModel::new(
        ChainModel::uniform(10, 0.1, 0.1, 9.81).unwrap(),
        ModalMap::new(&lengths, 2, BaseAngle::Fixed(std::f64::consts::FRAC_PI_2)).unwrap(),
    )
    .unwrap()
}

/// The chain's `n + 1` points at the coordinates `a` of either family, through the loop's own
/// forward kinematics.
fn chain_points(plant: Plant<'_>, a: &[f64]) -> Vec<[f64; 3]> {
    match plant {
        Plant::Planar(arm) => {
            let n = arm.n_links();
            let lengths: Vec<f64> = arm.chain().link_lengths().collect();
            let mut theta = vec![0.0; n];
            arm.map().joint_angles(a, &mut theta).unwrap();
            let mut points = vec![[0.0; 2]; n + 1];
            backbone_kin::joint_positions(&lengths, &theta, &mut points).unwrap();
            points.iter().map(|p| [p[0], p[1], 0.0]).collect()
        }
        Plant::Spatial(arm) => {
            let map = arm.map();
            let mut theta = vec![0.0; map.n_joints()];
            map.joint_angles(a, &mut theta).unwrap();
            let mut points = vec![[0.0; 3]; map.n_links() + 1];
            backbone_kin::spatial_joint_positions(
                map.link_lengths(),
                arm.base(),
                &theta,
                &mut points,
            )
            .unwrap();
            points
        }
    }
}

/// The clearance of every pair of `model` at the coordinates `a`.
fn clearances(plant: Plant<'_>, model: &ClearanceModel, a: &[f64]) -> Vec<f64> {
    let mut data = ClearanceData::new(model, 0).unwrap();
    let points = chain_points(plant, a);
    let axes = vec![[0.0, 0.0, 1.0]; points.len() - 1];
    clearance::place(model, &mut data, &points, &axes).unwrap();
    clearance::distances(model, &mut data);
    data.distances().to_vec()
}

/// One semi-implicit Euler step of the plan's dynamics: the next state `(a_{k+1}, a_dot_{k+1})`.
fn next_state(plant: Plant<'_>, x: &[f64], u: &[f64], h: f64) -> Vec<f64> {
    let (mut data, mut derivatives) = (PlantData::new(plant), PlantDerivatives::new(plant));
    let mut euler = ReducedEuler::new(plant, &mut data, &mut derivatives, h).unwrap();
    let mut next = vec![0.0; x.len()];
    euler.step(x, u, &mut next).unwrap();
    next
}

/// Checks the clearance rows of `plant` at `(x, u)` among spheres set 5 mm (clearance) beside
/// links 4 and 8 and one far away, with a 1 cm margin: every row is the first-order expansion
/// in `u'` of its pair's barrier after one step of the dynamics,
/// `psi(u') = d(a_{k+1}(u')) + T g . a_dot_{k+1}(u')` (`T` = `CLEARANCE_APPROACH_S`, `g` the
/// clearance's modal gradient at `a_{k+1}(u)`, by central differences here): its coefficients
/// are the central finite differences of the true `psi`, its value at `u` the true `psi` less
/// the floor `min(d(a), margin)`.
fn check_clearance_rows(plant: Plant<'_>, x: &[f64], u: &[f64]) {
    let (h, m) = (0.005, plant.n_coords());
    let a = &x[..m];
    let points = chain_points(plant, a);
    let (radius, link_radius, margin) = (0.03, 0.01, 0.01);
    let beside = |link: usize, side: f64| {
        let (p, q) = (points[link], points[link + 1]);
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        // A direction across the link: d x z, or d x x for a link along z.
        let across = if d[0].hypot(d[1]) > 1e-3 {
            [d[1], -d[0], 0.0]
        } else {
            [0.0, d[2], -d[1]]
        };
        let length = (across[0].powi(2) + across[1].powi(2) + across[2].powi(2)).sqrt();
        let offset = side * (radius + link_radius + 0.005) / length;
        let centre: [f64; 3] = std::array::from_fn(|i| 0.5 * (p[i] + q[i]) + offset * across[i]);
        Obstacle::sphere(centre, radius).unwrap()
    };
    let obstacles = vec![
        beside(4, 1.0),
        beside(8, -1.0),
        Obstacle::sphere([5.0, 5.0, 5.0], 0.1).unwrap(),
    ];
    let model = ClearanceModel::new(10, link_radius, obstacles).unwrap();
    let limits = MpcLimits {
        clearance: Some(model.clone()),
        clearance_margin_m: margin,
        ..MpcLimits::default()
    };
    let mut constraints = MpcConstraints::new(plant, &limits, h).unwrap().unwrap();
    // B = dF/du of the plan's step.
    let (mut data, mut derivatives) = (PlantData::new(plant), PlantDerivatives::new(plant));
    let mut euler = ReducedEuler::new(plant, &mut data, &mut derivatives, h).unwrap();
    let (mut next, mut a_mat, mut b_mat) =
        (vec![0.0; 2 * m], vec![0.0; 4 * m * m], vec![0.0; 2 * m * m]);
    euler
        .linearise(x, u, &mut next, &mut a_mat, &mut b_mat)
        .unwrap();
    let max = constraints.max_rows();
    let (mut rows, mut bounds) = (vec![0.0; max * m], vec![0.0; max]);
    let count = constraints
        .bind(plant)
        .rows(0, x, u, &b_mat, &mut rows, &mut bounds)
        .unwrap();
    let pairs = constraints.clearance_pairs().to_vec();
    assert_eq!(pairs.len(), count);
    // Links 4 and 8 against their spheres (pairs link * 3 + obstacle); the far sphere is out of
    // reach of the activation distance.
    for pair in [4 * 3, 8 * 3 + 1] {
        assert!(pairs.contains(&pair), "{pairs:?}");
    }
    assert!(pairs.iter().all(|&p| p >= 30 || p % 3 != 2), "{pairs:?}");
    let now = clearances(plant, &model, a);
    let next = next_state(plant, x, u, h);
    for (r, &pair) in pairs.iter().enumerate() {
        let row = &rows[r * m..(r + 1) * m];
        // The clearance's modal gradient at the predicted coordinates.
        let gradient: Vec<f64> = (0..m)
            .map(|i| {
                let eps = 1e-6;
                let (mut up, mut down) = (next[..m].to_vec(), next[..m].to_vec());
                up[i] += eps;
                down[i] -= eps;
                let (d_up, d_down) = (
                    clearances(plant, &model, &up),
                    clearances(plant, &model, &down),
                );
                (d_up[pair] - d_down[pair]) / (2.0 * eps)
            })
            .collect();
        let psi = |state: &[f64]| {
            let rate: f64 = gradient.iter().zip(&state[m..]).map(|(g, v)| g * v).sum();
            clearances(plant, &model, &state[..m])[pair] + CLEARANCE_APPROACH_S * rate
        };
        // The row is -c . u' <= psi(u) - floor - c . u: its value at u is the barrier after the
        // step less the floor (d(a) to first order: the step is a few mrad).
        let cu: f64 = row.iter().zip(u).map(|(g, u)| g * u).sum();
        let value = bounds[r] - cu;
        let expected = psi(&next) - now[pair].min(margin);
        assert!(
            (value - expected).abs() < 1e-5,
            "pair {pair}: {value} vs {expected}"
        );
        for i in 0..m {
            let eps = 1e-4;
            let (mut up, mut down) = (u.to_vec(), u.to_vec());
            up[i] += eps;
            down[i] -= eps;
            let fd = (psi(&next_state(plant, x, &up, h)) - psi(&next_state(plant, x, &down, h)))
                / (2.0 * eps);
            assert!(
                (-row[i] - fd).abs() < 1e-6 * fd.abs().max(1e-6),
                "pair {pair}, u{i}: {} vs {fd}",
                -row[i]
            );
        }
    }
}

/// The clearance rows against finite differences of the clearance along the plan's dynamics,
/// on the planar arm and on a spatial one (its links bent out of the plane).
#[test]
fn clearance_rows_match_finite_differences_of_the_clearance_along_the_dynamics() {
    let arm = arm();
    check_clearance_rows(
        Plant::from(&arm),
        &[0.4, -0.2, 0.15, 0.05, 0.1, -0.05, 0.05, 0.0],
        &[0.8, -0.3, 0.1, 0.05],
    );
    let spatial = SpatialReducedModel::uniform_rods(10, 1, 0.1, 0.1, [0.0, 0.0, -9.81]).unwrap();
    check_clearance_rows(
        Plant::from(&spatial),
        &[0.4, -0.2, 0.3, 0.1, 0.1, -0.05, 0.05, 0.02],
        &[0.2, -0.1, 0.3, 0.05],
    );
}

/// The largest joint torque (by eq 13 at the planned states) and the largest angle of a joint
/// past the base over the nodes of `mpc`'s last plan.
fn plan_peaks(arm: &ReducedModel, mpc: &MpcController) -> (f64, f64) {
    let plant = Plant::from(arm);
    let mut data = PlantData::new(plant);
    let ilqr = mpc.mpc().ilqr();
    let (mut a_ddot, mut tau, mut theta) = ([0.0; 4], [0.0; 10], [0.0; 10]);
    let (mut torque, mut angle) = (0.0f64, 0.0f64);
    for k in 0..=ilqr.horizon() {
        let x = &ilqr.states()[k * 8..(k + 1) * 8];
        arm.map().joint_angles(&x[..4], &mut theta).unwrap();
        angle = theta[1..].iter().fold(angle, |m, t| m.max(t.abs()));
        if k < ilqr.horizon() {
            let u = &ilqr.controls()[k * 4..(k + 1) * 4];
            plant
                .forward_dynamics(&mut data, &x[..4], &x[4..], u, &mut a_ddot)
                .unwrap();
            plant
                .joint_torques(&mut data, &x[..4], &x[4..], &a_ddot, &mut tau)
                .unwrap();
            torque = tau.iter().fold(torque, |m, t| m.max(t.abs()));
        }
    }
    (torque, angle)
}

/// MPC from the straight arm towards a bent shape, `tau*` free: the plan within the box alone
/// asks for joint torques well beyond twice those that hold the arm in the goal shape, and bends
/// its joints as far as the goal does; planned within joint torque limits of twice the holding
/// torques and joint angle limits (past the base) of 80% of the goal's largest bend, every node
/// keeps both, and the plan still moves towards the goal.
#[test]
fn mpc_plans_keep_the_joint_torque_and_angle_limits_at_every_node() {
    let arm = arm();
    let plant = Plant::from(&arm);
    let target = [0.6, -0.3, 0.2, 0.0];
    let plan = |limits: &MpcLimits| {
        let settings = MpcSettings::uniform(4);
        let reference = Step::constant(&target).unwrap();
        let mut mpc = MpcController::new(&arm, &settings, Box::new(reference))
            .unwrap()
            .with_limits(&arm, limits)
            .unwrap();
        let measured = ModalState::zeros(4);
        let mut sample = ReferenceSample::zeros(4);
        sample.a.copy_from_slice(&target);
        let ctx = ControlContext {
            t: 0.0,
            measured: &measured,
            reference: &sample,
            model: plant,
            tau_star_limits: None,
        };
        let mut tau = [0.0; 4];
        mpc.control(&ctx, &mut tau).unwrap();
        assert_eq!(mpc.relaxed_nodes(), 0);
        let a_end = mpc.mpc().ilqr().states()[60 * 8];
        (plan_peaks(&arm, &mpc), a_end)
    };
    // The goal shape: its holding joint torques (at rest, G* alone) and its largest bend.
    let mut data = PlantData::new(plant);
    plant.terms(&mut data, &target, &[0.0; 4]).unwrap();
    let holding = data.gravity().to_vec();
    let mut tau = [0.0; 10];
    plant
        .joint_torques(&mut data, &target, &[0.0; 4], &[0.0; 4], &mut tau)
        .unwrap();
    let hold = tau.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    assert!(holding.iter().any(|g| g.abs() > 0.1), "{holding:?}");
    let mut theta = [0.0; 10];
    arm.map().joint_angles(&target, &mut theta).unwrap();
    // The base joint's angle is alpha0 = pi/2 plus the bend: bound the others.
    let goal_bend = theta[1..].iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let ((free_torque, free_angle), _) = plan(&MpcLimits::default());
    let torque_limit = 2.0 * hold;
    let angle_limit = 0.8 * goal_bend;
    assert!(
        free_torque > 1.5 * torque_limit,
        "{free_torque} vs {torque_limit}"
    );
    assert!(free_angle > goal_bend, "{free_angle} vs {goal_bend}");
    let mut angles = vec![angle_limit; 10];
    angles[0] = 4.0;
    // Each limit alone (together, this tight, some nodes of the first plan admit no torque).
    let torque_only = MpcLimits {
        joint_torque_limits: Some(vec![torque_limit; 10]),
        ..MpcLimits::default()
    };
    let ((torque, _), a1_end) = plan(&torque_only);
    assert!(torque <= torque_limit * (1.0 + 1e-9), "{torque}");
    assert!(a1_end > 0.1, "{a1_end}");
    let angle_only = MpcLimits {
        joint_angle_limits: Some(angles),
        joint_angle_approach_s: sim_core::JOINT_ANGLE_APPROACH_S,
        ..MpcLimits::default()
    };
    let ((_, angle), a1_end) = plan(&angle_only);
    assert!(angle <= angle_limit * (1.0 + 1e-9), "{angle}");
    assert!(a1_end > 0.1, "{a1_end}");
}

/// Limits out of their domain are refused by the field they come from; empty limits make no
/// rows.
#[test]
fn mpc_limits_out_of_their_domain_are_refused_by_name() {
    let arm = arm();
    let plant = Plant::from(&arm);
    assert!(
        MpcConstraints::new(plant, &MpcLimits::default(), 0.005)
            .unwrap()
            .is_none()
    );
    let model = ClearanceModel::new(10, 0.01, vec![]).unwrap();
    let cases: [(MpcLimits, &str); 6] = [
        (
            MpcLimits {
                joint_torque_limits: Some(vec![1.0; 9]),
                ..MpcLimits::default()
            },
            "limits.joint_torque_nm",
        ),
        (
            MpcLimits {
                joint_torque_limits: Some(vec![f64::NAN; 10]),
                ..MpcLimits::default()
            },
            "limits.joint_torque_nm",
        ),
        (
            MpcLimits {
                joint_angle_limits: Some(vec![-1.0; 10]),
                joint_angle_approach_s: 0.02,
                ..MpcLimits::default()
            },
            "limits.joint_angle_rad",
        ),
        (
            MpcLimits {
                joint_angle_limits: Some(vec![1.0; 10]),
                joint_angle_approach_s: 0.0,
                ..MpcLimits::default()
            },
            "joint_angle_approach_s",
        ),
        (
            MpcLimits {
                clearance: Some(model.clone()),
                clearance_margin_m: -0.01,
                ..MpcLimits::default()
            },
            "controller.clearance_m",
        ),
        (
            MpcLimits {
                clearance: Some(ClearanceModel::new(9, 0.01, vec![]).unwrap()),
                ..MpcLimits::default()
            },
            "obstacles",
        ),
    ];
    for (limits, field) in cases {
        let e = MpcConstraints::new(plant, &limits, 0.005)
            .err()
            .unwrap()
            .to_string();
        assert!(e.starts_with(field), "{field}: {e}");
    }
}
