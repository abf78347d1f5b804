//! The narrow-passage benchmark set (issue 30): `PROBLEMS` seeded planar problems of
//! `shape_plan::narrow_passage` (the paper's arm, two harmonics) and as many spatial ones of
//! `spatial_narrow_passage` (ten universal joints, one harmonic a plane), six obstacles of 3 cm
//! each leaving 5 mm beyond a 1 cm margin around a random witness shape, planned one after the
//! other. Prints, as `<id> <value> <unit>` lines for `passages/planar` and `passages/spatial`:
//! the success rate, the smallest goal clearance and smallest checked path clearance over the
//! solved problems, and the median and largest planning time.
//!
//! `cargo run --release -p hrm-benches --example narrow_passages`

use shape_plan::{
    Arm, NarrowPassage, PassageSpec, PlanError, PlanOptions, Planner, narrow_passage,
    spatial_narrow_passage,
};
use std::time::Instant;

const PROBLEMS: u64 = 200;

fn spec(harmonics: usize, seed: u64) -> PassageSpec {
    PassageSpec {
        link_lengths: vec![0.1; 10],
        harmonics,
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

fn run<A: Arm>(
    name: &str,
    generate: impl Fn(u64) -> Result<NarrowPassage<A>, PlanError>,
) -> Result<(), Box<dyn std::error::Error>> {
    let (mut solved, mut goal, mut path) = (0, f64::INFINITY, f64::INFINITY);
    let mut times = Vec::new();
    for seed in 0..PROBLEMS {
        let problem = generate(seed)?;
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
    let rate = f64::from(solved) / PROBLEMS as f64;
    println!("passages/{name}/success_rate {rate} ratio");
    println!("passages/{name}/goal_clearance_m {goal} m");
    println!("passages/{name}/path_clearance_m {path} m");
    println!("passages/{name}/median_plan_s {} s", times[times.len() / 2]);
    println!("passages/{name}/max_plan_s {} s", times[times.len() - 1]);
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    run("planar", |seed| narrow_passage(&spec(2, seed)))?;
    run("spatial", |seed| spatial_narrow_passage(&spec(1, seed)))
}
