//! The spatial arm: gradients against finite differences, plans checked by sampling surfaces.

use backbone_kin::{BasePose, SpatialModalMap, spatial_joint_positions};
use clearance::{ClearanceData, ClearanceModel, Obstacle, distances};
use shape_plan::{Arm, ArmScratch, PlanOptions, Planner, SpatialArm};

fn obstacles() -> Vec<Obstacle> {
    vec![
        Obstacle::sphere([0.45, 0.2, 0.1], 0.05).unwrap(),
        Obstacle::capsule([0.2, -0.3, 0.3], [0.3, 0.3, 0.35], 0.03).unwrap(),
        Obstacle::cuboid([0.7, -0.1, -0.2], [0.05, 0.1, 0.08], [0.3, -0.2, 0.5]).unwrap(),
    ]
}

fn base() -> BasePose {
    BasePose {
        xyz: [0.01, -0.02, 0.03],
        rpy: [0.1, -0.2, 0.3],
    }
}

#[test]
fn spatial_gradients_match_finite_differences() {
    let arm = SpatialArm::new(&[0.1; 8], 2, base()).unwrap();
    let model = ClearanceModel::new(8, 0.01, obstacles()).unwrap();
    let m = arm.n_coords();
    let mut data = ClearanceData::new(&model, m).unwrap();
    let mut scratch = ArmScratch::new(&arm);
    let pairs = model.pairs().len();
    let (mut gradients, mut tip_jacobian) = (vec![0.0; pairs * m], vec![0.0; 3 * m]);
    let a = [0.7, -0.4, 0.3, 0.2, -0.5, 0.6, 0.1, -0.3];
    arm.place(&model, &mut data, &mut scratch, &a).unwrap();
    distances(&model, &mut data);
    let base_distances = data.distances().to_vec();
    arm.gradients(
        &model,
        &mut data,
        &mut scratch,
        &mut gradients,
        &mut tip_jacobian,
    )
    .unwrap();
    // The tip by backbone-kin's own walk.
    let map = SpatialModalMap::new(&[0.1; 8], 2).unwrap();
    let tip_of = |a: &[f64]| {
        let mut theta = vec![0.0; 16];
        map.joint_angles(a, &mut theta).unwrap();
        let mut p = vec![[0.0; 3]; 9];
        spatial_joint_positions(&[0.1; 8], &base(), &theta, &mut p).unwrap();
        p[8]
    };
    assert!((0..3).all(|d| (tip_of(&a)[d] - scratch.points[8][d]).abs() < 1e-15));
    let h = 1e-6;
    let mut checked = 0;
    for l in 0..m {
        let (mut plus, mut minus) = (a, a);
        plus[l] += h;
        minus[l] -= h;
        let (tp, tm) = (tip_of(&plus), tip_of(&minus));
        for d in 0..3 {
            let fd = (tp[d] - tm[d]) / (2.0 * h);
            assert!((fd - tip_jacobian[d * m + l]).abs() < 1e-8, "tip {d}, a{l}");
        }
        arm.place(&model, &mut data, &mut scratch, &plus).unwrap();
        distances(&model, &mut data);
        let up = data.distances().to_vec();
        arm.place(&model, &mut data, &mut scratch, &minus).unwrap();
        distances(&model, &mut data);
        let down = data.distances().to_vec();
        for k in 0..pairs {
            // Skip pairs whose closest points jump (a kink of the distance) within the step.
            let fd = (up[k] - down[k]) / (2.0 * h);
            let one_sided = (up[k] - base_distances[k]) / h;
            if (fd - one_sided).abs() > 1e-4 {
                continue;
            }
            checked += 1;
            assert!(
                (fd - gradients[k * m + l]).abs() < 1e-6,
                "pair {k}, a{l}: {fd} vs {}",
                gradients[k * m + l]
            );
        }
    }
    assert!(checked > pairs * m * 9 / 10, "{checked}");
}

/// The smallest clearance of sampled capsule surfaces (radius 0.01) to the spheres.
fn sampled_sphere_clearance(points: &[[f64; 3]], spheres: &[([f64; 3], f64)]) -> f64 {
    let mut smallest = f64::INFINITY;
    for pair in points.windows(2) {
        for s in 0..=40 {
            let t = f64::from(s) / 40.0;
            let c: Vec<f64> = (0..3)
                .map(|d| pair[0][d] + t * (pair[1][d] - pair[0][d]))
                .collect();
            // Fibonacci directions on the sphere.
            for k in 0..64 {
                let z = 1.0 - 2.0 * (f64::from(k) + 0.5) / 64.0;
                let r = (1.0 - z * z).sqrt();
                let phi = 2.399_963_229_728_653 * f64::from(k);
                let x = [
                    c[0] + 0.01 * r * phi.cos(),
                    c[1] + 0.01 * r * phi.sin(),
                    c[2] + 0.01 * z,
                ];
                for (center, radius) in spheres {
                    let dist = (0..3)
                        .map(|d| (x[d] - center[d]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    smallest = smallest.min(dist - radius);
                }
            }
        }
    }
    smallest
}

#[test]
fn a_spatial_plan_reaches_around_spheres_and_keeps_the_margin() {
    let lengths = [0.1; 10];
    let target = [0.45, 0.35, 0.45];
    // Spheres on the bodies of the free-space solutions the planner starts from.
    let free = SpatialArm::new(&lengths, 2, BasePose::default()).unwrap();
    let starts = free.free_space_starts(target, &[0.0; 8]);
    assert!(!starts.is_empty());
    let mut spheres = Vec::new();
    let mut scratch = ArmScratch::new(&free);
    let empty = ClearanceModel::new(10, 0.01, vec![]).unwrap();
    let mut data = ClearanceData::new(&empty, 8).unwrap();
    for start in &starts {
        free.place(&empty, &mut data, &mut scratch, start).unwrap();
        spheres.push((scratch.points[5], 0.03));
    }
    let model = ClearanceModel::new(
        10,
        0.01,
        spheres
            .iter()
            .map(|(c, r)| Obstacle::sphere(*c, *r).unwrap())
            .collect(),
    )
    .unwrap();
    let options = PlanOptions {
        clearance: 0.01,
        ..PlanOptions::default()
    };
    let mut planner = Planner::new(free.clone(), model, options).unwrap();
    let initial = [0.0; 8];
    let plan = planner.plan(&initial, &target).unwrap();
    let map = SpatialModalMap::new(&lengths, 2).unwrap();
    let points_of = |a: &[f64]| {
        let mut theta = vec![0.0; 20];
        map.joint_angles(a, &mut theta).unwrap();
        let mut p = vec![[0.0; 3]; 11];
        spatial_joint_positions(&lengths, &BasePose::default(), &theta, &mut p).unwrap();
        p
    };
    let goal = points_of(&plan.goal);
    let tip_error = (0..3)
        .map(|d| (goal[10][d] - target[d]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(tip_error <= options.tip_tolerance, "{tip_error}");
    for pair in plan.path.windows(2) {
        for s in 0..=50 {
            let t = f64::from(s) / 50.0;
            let a: Vec<f64> = pair[0]
                .iter()
                .zip(&pair[1])
                .map(|(x, y)| x + t * (y - x))
                .collect();
            let sampled = sampled_sphere_clearance(&points_of(&a), &spheres);
            assert!(sampled >= options.clearance, "{sampled}");
        }
    }
}

#[test]
fn the_spatial_lipschitz_bound_holds_on_random_pairs_of_shapes() {
    use rand::{RngExt, SeedableRng};
    let lengths: Vec<f64> = (0..9).map(|i| 0.12 - 0.01 * f64::from(i)).collect();
    let arm = SpatialArm::new(&lengths, 2, base()).unwrap();
    let map = SpatialModalMap::new(&lengths, 2).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut worst: f64 = 0.0;
    for _ in 0..400 {
        let a: Vec<f64> = (0..8).map(|_| rng.random_range(-2.0..2.0)).collect();
        let b: Vec<f64> = a
            .iter()
            .map(|x| x + rng.random_range(-0.05..0.05))
            .collect();
        let points = |a: &[f64]| {
            let mut theta = vec![0.0; 18];
            map.joint_angles(a, &mut theta).unwrap();
            let mut p = vec![[0.0; 3]; 10];
            spatial_joint_positions(&lengths, &base(), &theta, &mut p).unwrap();
            p
        };
        let (pa, pb) = (points(&a), points(&b));
        let step = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt();
        for i in 0..9 {
            for s in 0..=10 {
                let t = f64::from(s) / 10.0;
                let at = |p: &[[f64; 3]]| -> Vec<f64> {
                    (0..3)
                        .map(|d| p[i][d] + t * (p[i + 1][d] - p[i][d]))
                        .collect()
                };
                let (x, y) = (at(&pa), at(&pb));
                let moved = (0..3).map(|d| (x[d] - y[d]).powi(2)).sum::<f64>().sqrt();
                worst = worst.max(moved / step);
            }
        }
    }
    assert!(worst <= arm.lipschitz(), "{worst} > {}", arm.lipschitz());
    assert!(
        worst > 0.05 * arm.lipschitz(),
        "{worst} vs {}",
        arm.lipschitz()
    );
}
