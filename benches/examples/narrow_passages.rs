//! The narrow-passage benchmark set (issue 30): `PROBLEMS` seeded problems of
//! `shape_plan::narrow_passage` (the paper's arm, two harmonics, six circles each leaving 5 mm
//! beyond a 1 cm margin around a random witness shape), planned one after the other. Prints, as
//! `<id> <value> <unit>` lines: the success rate, the smallest goal clearance and smallest
//! checked path clearance over the solved problems, and the median and largest planning time.
//!
//! `cargo run --release -p hrm-benches --example narrow_passages`

use shape_plan::{PassageSpec, PlanOptions, Planner, narrow_passage};
use std::time::Instant;

const PROBLEMS: u64 = 200;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut solved, mut goal, mut path) = (0, f64::INFINITY, f64::INFINITY);
    let mut times = Vec::new();
    for seed in 0..PROBLEMS {
        let problem = narrow_passage(&PassageSpec {
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
        })?;
        let options = PlanOptions {
            clearance: 0.01,
            check_slack: 0.002,
            seed,
            ..PlanOptions::default()
        };
        let mut planner = Planner::new(problem.arm, problem.clearance_model, options)?;
        let start = Instant::now();
        let outcome = planner.plan(&problem.initial, &problem.target);
        times.push(start.elapsed().as_secs_f64());
        if let Ok(plan) = outcome {
            solved += 1;
            goal = goal.min(plan.goal_clearance);
            path = path.min(plan.path_clearance);
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "passages/success_rate {} ratio",
        f64::from(solved) / PROBLEMS as f64
    );
    println!("passages/goal_clearance_m {goal} m");
    println!("passages/path_clearance_m {path} m");
    println!("passages/median_plan_s {} s", times[times.len() / 2]);
    println!("passages/max_plan_s {} s", times[times.len() - 1]);
    Ok(())
}
