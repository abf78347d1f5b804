//! Generated narrow passages: solvable by construction, solved by the planner.

use clearance::distances;
use shape_plan::{Arm, PassageSpec, PlanData, PlanOptions, Planner, check_segment, narrow_passage};

fn spec(seed: u64) -> PassageSpec {
    PassageSpec {
        link_lengths: vec![0.1; 10],
        harmonics: 2,
        alpha0: std::f64::consts::FRAC_PI_2,
        radius: 0.01,
        clearance: 0.01,
        gap: 0.005,
        obstacles: 6,
        obstacle_radius: 0.03,
        amplitude: 1.5,
        seed,
    }
}

#[test]
fn generated_passages_are_solvable_and_solved() {
    let mut solved = 0;
    let problems = 12;
    for seed in 0..problems {
        let problem = narrow_passage(&spec(seed)).unwrap();
        let model = &problem.clearance_model;
        assert!(
            model.obstacles().len() >= 3,
            "seed {seed}: {}",
            model.obstacles().len()
        );
        let options = PlanOptions {
            clearance: 0.01,
            check_slack: 0.002,
            seed,
            ..PlanOptions::default()
        };
        // The witness reaches the target and its straight motion keeps the margin.
        let mut data = PlanData::new(&problem.arm, model).unwrap();
        let check = check_segment(
            &problem.arm,
            model,
            &options,
            &mut data,
            &problem.initial,
            &problem.witness,
        )
        .unwrap();
        assert!(check.clear, "seed {seed}");
        let mut scratch = shape_plan::ArmScratch::new(&problem.arm);
        let mut cd = clearance::ClearanceData::new(model, 4).unwrap();
        problem
            .arm
            .place(model, &mut cd, &mut scratch, &problem.witness)
            .unwrap();
        let (near, itself) = distances(model, &mut cd);
        let tip = cd.points()[10];
        assert!(
            (tip[0] - problem.target[0]).abs() < 1e-15
                && (tip[1] - problem.target[1]).abs() < 1e-15
        );
        assert!(
            near.min(itself) < 0.01 + 0.005 + 1e-9,
            "seed {seed}: the passage is narrow"
        );
        let mut planner = Planner::new(problem.arm.clone(), model.clone(), options).unwrap();
        match planner.plan(&problem.initial, &problem.target) {
            Ok(plan) => {
                solved += 1;
                assert!(plan.goal_clearance >= options.needed());
            }
            Err(e) => eprintln!("seed {seed}: {e}"),
        }
    }
    eprintln!("solved {solved} of {problems}");
    assert!(solved >= problems - 1, "{solved}");
}

#[test]
fn generated_spatial_passages_are_solved() {
    let mut solved = 0;
    let problems = 8;
    for seed in 0..problems {
        let problem = shape_plan::spatial_narrow_passage(&PassageSpec {
            harmonics: 1,
            ..spec(seed)
        })
        .unwrap();
        let model = &problem.clearance_model;
        assert!(model.obstacles().len() >= 3, "seed {seed}");
        assert_eq!(problem.target.len(), 3);
        let options = PlanOptions {
            clearance: 0.01,
            check_slack: 0.002,
            seed,
            ..PlanOptions::default()
        };
        let mut data = PlanData::new(&problem.arm, model).unwrap();
        let witness = check_segment(
            &problem.arm,
            model,
            &options,
            &mut data,
            &problem.initial,
            &problem.witness,
        )
        .unwrap();
        assert!(witness.clear, "seed {seed}");
        let mut planner = Planner::new(problem.arm.clone(), model.clone(), options).unwrap();
        match planner.plan(&problem.initial, &problem.target) {
            Ok(plan) => {
                solved += 1;
                assert!(plan.goal_clearance >= options.needed());
            }
            Err(e) => eprintln!("seed {seed}: {e}"),
        }
    }
    eprintln!("solved {solved} of {problems}");
    assert!(solved >= problems - 1, "{solved}");
}
