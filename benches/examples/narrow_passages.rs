//! The narrow-passage benchmark set (issue 30): `PROBLEMS` seeded planar problems of
//! `shape_plan::narrow_passage` (the paper's arm, two harmonics) and as many spatial ones of
//! `spatial_narrow_passage` (ten universal joints, one harmonic a plane), six obstacles of 3 cm
//! each leaving 5 mm beyond a 1 cm margin around a random witness shape, planned one after the
//! other. Prints, as `<id> <value> <unit>` lines for `passages/planar` and `passages/spatial`:
//! the success rate, the smallest goal clearance and smallest checked path clearance over the
//! solved problems, and the median and largest planning time. Then `CHANNELS` seeded bent
//! channels for follow-the-leader deployment ([`channel`]: straight, a bend, straight, solvable
//! by construction), the paper's arm with `K = 5` deployed to each end by
//! `shape_plan::follow_the_leader`: for `passages/deploy`, the success rate (tip within 1 mm of
//! the centreline and the body inside the walls all along), the median and largest shape
//! deviation (% of the deployed length), the largest tip error, the smallest wall clearance and
//! the median and largest planning time.
//!
//! `cargo run --release -p hrm-benches --example narrow_passages`

use shape_plan::{
    Arm, Channel, NarrowPassage, PassageSpec, PlanError, PlanOptions, Planner, follow_the_leader,
    narrow_passage, spatial_narrow_passage,
};
use std::time::Instant;

const PROBLEMS: u64 = 200;
/// Generated channels of the deployment set.
const CHANNELS: u64 = 50;
/// Steps of tip progress of each deployment.
const DEPLOY_STEPS: usize = 200;

/// A uniform number in `[0, 1)` from `state` (splitmix64).
fn uniform(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// The seeded channel `seed` for the paper's arm (ten links of 0.1 m, 1 cm thick): radius 3 cm,
/// entering along a random direction, straight for 0.1-0.3 m, a circular bend of radius
/// 0.25-0.5 m (at most what leaves 5 cm after it) turning 30-100 degrees either way (60 segments), then straight to a total length
/// of 0.9 m. Solvable by construction: the exact follow-the-leader chain lies on the
/// centreline but for its links' chords in the bend, whose sagitta `L^2 / 8R <= 5 mm` stays
/// inside the 2 cm left between the links' capsules and the walls.
fn channel(seed: u64) -> Result<Channel, PlanError> {
    let mut state = seed;
    let heading = std::f64::consts::TAU * uniform(&mut state);
    let first = 0.1 + 0.2 * uniform(&mut state);
    let turn = (30.0 + 70.0 * uniform(&mut state)).to_radians();
    // At most what leaves 5 cm of straight after the bend (at least 0.315 m: above 0.25 m).
    let radius = (0.25 + 0.25 * uniform(&mut state)).min((0.85 - first) / turn);
    let sign = if uniform(&mut state) < 0.5 { 1.0 } else { -1.0 };
    let bend = radius * turn;
    let last = 0.9 - first - bend;
    let mut points = vec![[0.0, 0.0], [first * heading.cos(), first * heading.sin()]];
    // The bend's centre, to the left (sign 1) or right of the direction of travel.
    let centre = [
        points[1][0] - sign * radius * heading.sin(),
        points[1][1] + sign * radius * heading.cos(),
    ];
    for k in 1..=60 {
        let angle = heading + sign * turn * f64::from(k) / 60.0;
        points.push([
            centre[0] + sign * radius * angle.sin(),
            centre[1] - sign * radius * angle.cos(),
        ]);
    }
    if last > 1e-3 {
        let angle = heading + sign * turn;
        let end = points[points.len() - 1];
        points.push([end[0] + last * angle.cos(), end[1] + last * angle.sin()]);
    }
    Channel::new(&points, 0.03)
}

/// The deployment set: [`CHANNELS`] generated channels, each deployed to its end.
fn deploy() -> Result<(), Box<dyn std::error::Error>> {
    let (mut solved, mut tip, mut clearance) = (0, 0.0f64, f64::INFINITY);
    let (mut deviations, mut times) = (Vec::new(), Vec::new());
    for seed in 0..CHANNELS {
        let channel = channel(seed)?;
        let start = Instant::now();
        let deployment = follow_the_leader(
            &channel,
            &[0.1; 10],
            0.01,
            5,
            channel.length(),
            DEPLOY_STEPS,
        )?;
        times.push(start.elapsed().as_secs_f64());
        let m = deployment.metrics;
        if m.tip_error < 1e-3 && m.min_wall_clearance > 0.0 {
            solved += 1;
        }
        tip = tip.max(m.tip_error);
        clearance = clearance.min(m.min_wall_clearance);
        deviations.push(m.shape_deviation_percent);
    }
    deviations.sort_by(f64::total_cmp);
    times.sort_by(f64::total_cmp);
    let rate = f64::from(solved) / CHANNELS as f64;
    let median = |v: &[f64]| v[v.len() / 2];
    println!("passages/deploy/success_rate {rate} ratio");
    println!(
        "passages/deploy/median_shape_deviation_pct {} %",
        median(&deviations)
    );
    println!(
        "passages/deploy/max_shape_deviation_pct {} %",
        deviations[deviations.len() - 1]
    );
    println!("passages/deploy/max_tip_error_m {tip} m");
    println!("passages/deploy/min_wall_clearance_m {clearance} m");
    println!("passages/deploy/median_plan_s {} s", median(&times));
    println!("passages/deploy/max_plan_s {} s", times[times.len() - 1]);
    Ok(())
}

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
    run("spatial", |seed| spatial_narrow_passage(&spec(1, seed)))?;
    deploy()
}
