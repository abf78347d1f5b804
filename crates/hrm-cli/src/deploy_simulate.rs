//! Runs of a scenario with a `[deploy]` (follow-the-leader deployment on an insertion axis,
//! [`Scenario::run_deploy`]): `hrm simulate` and the main job write `scenario.toml`,
//! `summary.json` (the joint-space run's fields and the deployment metrics), `timeseries.csv`
//! (`t`, then `q_i`, `q_ref_i`, `tau_i` per joint, the insertion first) and `links.csv`; the main
//! job also draws the arm in the channel and its clearance to the walls over time.

use crate::chain_simulate::{chain_timeseries, write};
use crate::output_dir::OutputDir;
use crate::plot::{self, Labels, Series, Style};
use crate::{console, report};
use lane_math::Compact;
use sim_core::SimError;
use sim_study::{ControllerKind, DeployFailure, DeployRun, Scenario};
use std::fmt::Write as _;
use std::path::Path;

/// Interval between the drawn arm shapes (s).
const SHAPE_INTERVAL_S: f64 = 0.5;

/// Runs `scenario` (with a `[deploy]`) and writes its files into `out`; a run that stops writes
/// them up to the stop (`summary.json` with its `error` and `stopped_at_s`) and fails with its
/// error, one that fails before its first recorded sample writes nothing.
pub fn simulate(scenario: &Scenario, out: &Path) -> Result<(), String> {
    let (run, stop) = DeployFailure::split(scenario.run_deploy()).map_err(|e| e.to_string())?;
    let staging = OutputDir::create(out, "simulate")?;
    write_run(staging.path(), scenario, &run, stop.as_ref()).map_err(|e| staging.named(e))?;
    staging.commit()?;
    if let Some(warning) = wall_warning(&run) {
        console::to_stderr(&format!("warning: {warning}"));
    }
    let stopped = match &stop {
        Some(error) => format!("stopped: {error}\n"),
        None => String::new(),
    };
    console::print(&format!(
        "{}\n{stopped}wrote {}\n",
        headline(scenario, &run),
        console::shown(out)
    ))?;
    stop.map_or(Ok(()), |error| Err(error.to_string()))
}

/// A warning when the arm's capsules reach the channel's walls or beyond (a negative smallest
/// wall clearance over the run), which the run reports rather than refuses: a bend sharper than
/// its links follow (the plan reaches the walls too), or a tracking error that the plan does not
/// have; and when its links that share no joint overlap (the plan refuses shapes that do, so
/// only the tracking can).
pub fn wall_warning(run: &DeployRun) -> Option<String> {
    let clearance = run.metrics.min_wall_clearance;
    let walls = (clearance < 0.0).then(|| {
        format!(
            "the arm reaches {:.2} mm into the channel's walls (smallest wall clearance; the \
             plan's {:.2} mm): {}",
            -1e3 * clearance,
            1e3 * run.plan.min_wall_clearance,
            if run.plan.min_wall_clearance < 0.0 {
                "the centreline's bends leave it no room"
            } else {
                "the plan keeps within them at its frames, the run does not: the reference \
                 between the frames or the tracking leaves the channel (compare q and q_ref in \
                 timeseries.csv; a shorter controller period or computed torque tracks closer)"
            }
        )
    });
    let folded = run.metrics.min_self_clearance;
    let itself = (folded < 0.0).then(|| {
        format!(
            "links of the arm that share no joint overlap by {:.2} mm (smallest self clearance; \
             the plan keeps {:.2} mm): the tracking folds the body onto itself",
            -1e3 * folded,
            1e3 * run.plan.min_self_clearance,
        )
    });
    match (walls, itself) {
        (Some(walls), Some(itself)) => Some(format!("{walls}; {itself}")),
        (walls, itself) => walls.or(itself),
    }
}

/// One line on the run: the deployment metrics.
pub fn headline(scenario: &Scenario, run: &DeployRun) -> String {
    let m = &run.metrics;
    format!(
        "{}: {} deploying the arm on its insertion axis: tip error {:.3} mm, \
         shape deviation {:.2}% of the deployed length, smallest wall clearance {:.2} mm, \
         smallest self clearance {}, final |q - q_ref| {:.3e}",
        scenario.name,
        scenario.controller.kind.name(),
        1e3 * m.tip_error,
        m.shape_deviation_percent,
        1e3 * m.min_wall_clearance,
        if m.min_self_clearance.is_finite() {
            format!("{:.2} mm", 1e3 * m.min_self_clearance)
        } else {
            "none (no two links without a shared joint)".to_string()
        },
        run.run.summary.final_error
    )
}

/// The run's `summary.json` ([`sim_study::summary_json::deploy`]), of a run that stopped with
/// `stop` if given ([`sim_study::summary_json::stopped`]).
pub fn summary(scenario: &Scenario, run: &DeployRun, stop: Option<&SimError>) -> serde_json::Value {
    let summary = sim_study::summary_json::deploy(scenario, run);
    match stop {
        Some(error) => sim_study::summary_json::stopped(summary, error, &run.run),
        None => summary,
    }
}

/// Writes `scenario.toml`, `summary.json`, `timeseries.csv` and `links.csv` of `run` (one that
/// stopped with `stop`, if given) into `dir` (created if needed).
pub fn write_run(
    dir: &Path,
    scenario: &Scenario,
    run: &DeployRun,
    stop: Option<&SimError>,
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let text =
        serde_json::to_string_pretty(&summary(scenario, run, stop)).map_err(|e| e.to_string())?;
    write(&dir.join("summary.json"), &(text + "\n"))?;
    write(&dir.join("scenario.toml"), &scenario.to_toml())?;
    write(&dir.join("timeseries.csv"), &chain_timeseries(&run.run))?;
    write(&dir.join("links.csv"), &links_csv(run))
}

/// `t, x0, y0, x1, y1, ...`: the base and every link's end at each recorded sample.
fn links_csv(run: &DeployRun) -> String {
    let t = &run.run.record.t;
    let points = run.points.len() / t.len().max(1);
    let mut csv = String::from("t");
    for j in 0..points {
        let _ = write!(csv, ",x{j},y{j}");
    }
    csv.push('\n');
    for (k, time) in t.iter().enumerate() {
        let _ = write!(csv, "{}", Compact(*time));
        for p in run.points_at(k) {
            let _ = write!(csv, ",{},{}", Compact(p[0]), Compact(p[1]));
        }
        csv.push('\n');
    }
    csv
}

/// The channel's two walls (the centreline offset by its radius on either side, the guide
/// behind the entry included, `behind` metres long) as drawable curves.
fn walls(run: &DeployRun, behind: f64) -> [Vec<(f64, f64)>; 2] {
    let channel = &run.channel;
    let length = channel.length();
    let samples = 400;
    let mut sides = [Vec::new(), Vec::new()];
    for k in 0..=samples {
        let sigma = -behind + (length + behind) * k as f64 / samples as f64;
        let step = 1e-4 * (length + behind);
        let (a, b) = (
            channel.point_at((sigma - step).max(-behind)),
            channel.point_at((sigma + step).min(length)),
        );
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let norm = dx.hypot(dy);
        let normal = [-dy / norm, dx / norm];
        let p = channel.point_at(sigma);
        for (side, sign) in sides.iter_mut().zip([1.0, -1.0]) {
            side.push((
                p[0] + sign * channel.radius() * normal[0],
                p[1] + sign * channel.radius() * normal[1],
            ));
        }
    }
    sides
}

/// Draws the run into `dir`: `deploy_<name>.svg` (the walls, the arm every
/// [`SHAPE_INTERVAL_S`] light to dark over the tip's path) and `deploy_clearance_<name>.svg` (the
/// smallest wall clearance and the tip's distance from the centreline over time, mm); returns
/// the report's figures.
pub fn figures(
    dir: &Path,
    scenario: &Scenario,
    run: &DeployRun,
) -> Result<Vec<report::Figure>, String> {
    let name = &scenario.name;
    let kind = scenario.controller.kind;
    let controller = kind.name();
    // Computed torque's figures keep the scenario's name alone; another controller's add its.
    let suffix = if kind == ControllerKind::ComputedTorque {
        String::new()
    } else {
        format!("_{controller}")
    };
    let t = &run.run.record.t;
    let arm_length: f64 = {
        let shape = run.points_at(0);
        shape
            .windows(2)
            .map(|p| (p[1][0] - p[0][0]).hypot(p[1][1] - p[0][1]))
            .sum()
    };
    let mut curves = Vec::new();
    for (side, label) in walls(run, arm_length)
        .into_iter()
        .zip(["channel walls", ""])
    {
        curves.push((
            Series {
                label: label.into(),
                points: side,
            },
            Style {
                colour: (90, 90, 90),
                width: 2,
                dots: false,
            },
        ));
    }
    // The tip's path under the arms, as a wide band: a body that follows it lies inside.
    curves.push((
        Series {
            label: "tip's path".into(),
            points: (0..t.len())
                .map(|k| {
                    let tip = run.points_at(k).last().copied().unwrap_or_default();
                    (tip[0], tip[1])
                })
                .collect(),
        },
        Style {
            colour: (150, 220, 160),
            width: 8,
            dots: false,
        },
    ));
    let every =
        ((SHAPE_INTERVAL_S / (t[1.min(t.len() - 1)] - t[0]).max(1e-12)).round() as usize).max(1);
    let shown: Vec<usize> = (0..t.len()).step_by(every).chain([t.len() - 1]).collect();
    let last = shown.len().saturating_sub(1).max(1) as f64;
    for (i, &k) in shown.iter().enumerate() {
        let shade = |light: f64, dark: f64| (light + (dark - light) * i as f64 / last) as u8;
        curves.push((
            Series {
                label: if i == 0 || i + 1 == shown.len() {
                    format!("arm at t = {:.1} s", t[k])
                } else {
                    String::new()
                },
                points: run.points_at(k).iter().map(|p| (p[0], p[1])).collect(),
            },
            Style {
                colour: (shade(170.0, 10.0), shade(200.0, 40.0), shade(240.0, 140.0)),
                width: 2,
                dots: true,
            },
        ));
    }
    let shapes = format!("deploy_{name}{suffix}.svg");
    let title = format!("{name}: the arm every {SHAPE_INTERVAL_S} s in the channel ({controller})");
    plot::xy_chart(
        &dir.join(&shapes),
        &Labels {
            title: &title,
            x: "x (m)",
            y: "y (m)",
        },
        &curves,
    )?;
    let clearance = format!("deploy_clearance_{name}{suffix}.svg");
    let series = [
        Series {
            label: "wall clearance".into(),
            points: t
                .iter()
                .zip(&run.samples)
                .map(|(t, s)| (*t, 1e3 * s.wall_clearance))
                .collect(),
        },
        Series {
            label: "tip error".into(),
            points: t
                .iter()
                .zip(&run.samples)
                .map(|(t, s)| (*t, 1e3 * s.tip_error))
                .collect(),
        },
    ];
    let title = format!("{name}: wall clearance and tip error ({controller})");
    plot::line_chart(
        &dir.join(&clearance),
        &Labels {
            title: &title,
            x: "t (s)",
            y: "mm",
        },
        &series,
        None,
    )?;
    let m = &run.metrics;
    Ok(vec![
        report::Figure {
            file: format!("figures/{shapes}"),
            caption: format!(
                "{name} with {controller}: the arm every {SHAPE_INTERVAL_S} s, light to dark, advancing on its insertion axis into the channel (grey walls), its body on the path its tip (green) traced; shape deviation {:.2}% of the deployed length at most.",
                m.shape_deviation_percent
            ),
        },
        report::Figure {
            file: format!("figures/{clearance}"),
            caption: format!(
                "{name} with {controller}: the body's smallest clearance to the walls (link capsules of the arm's radius; above zero: inside) and the tip's distance from the centreline (mm) over time; at least {:.2} mm and at most {:.3} mm.",
                1e3 * m.min_wall_clearance,
                1e3 * m.tip_error
            ),
        },
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pipe_deploy_writes_its_metrics_and_links() {
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.duration = 1.0;
        let dir = std::env::temp_dir().join(format!("hrm-deploy-simulate-{}", std::process::id()));
        simulate(&scenario, &dir).unwrap();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["joints"], 11);
        assert_eq!(summary["arm"], "deploy");
        for key in [
            "deploy_tip_error_m",
            "deploy_shape_deviation_pct",
            "deploy_min_wall_clearance_m",
            "deploy_min_self_clearance_m",
            "deploy_length_m",
        ] {
            assert!(
                summary[key].is_number() && summary["plan"][key].is_number(),
                "{key}"
            );
        }
        assert!(summary["deploy_min_wall_clearance_m"].as_f64().unwrap() > 0.0);
        assert_eq!(wall_warning(&scenario.run_deploy().unwrap()), None);
        let links = std::fs::read_to_string(dir.join("links.csv")).unwrap();
        assert_eq!(links.lines().count(), 1 + 101);
        assert_eq!(links.lines().next().unwrap().split(',').count(), 1 + 22);
        let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
        assert_eq!(csv.lines().next().unwrap().split(',').count(), 1 + 33);
        // The main job's figures.
        let run = scenario.run_deploy().unwrap();
        let figures = figures(&dir, &scenario, &run).unwrap();
        assert_eq!(figures.len(), 2);
        let svg = std::fs::read_to_string(dir.join("deploy_pipe-deploy.svg")).unwrap();
        assert!(svg.contains("channel walls"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_channel_narrower_than_the_arm_is_refused() {
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.duration = 0.2;
        let deploy = scenario.deploy.as_mut().unwrap();
        deploy.radius = 0.5 * scenario.arm.radius.unwrap();
        let error = scenario.run_deploy().unwrap_err().error.to_string();
        assert!(
            error.contains("deploy radius (the arm must fit in the channel)"),
            "{error}"
        );
    }

    #[test]
    fn links_that_overlap_in_the_run_are_warned_of() {
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.duration = 0.2;
        let mut run = scenario.run_deploy().unwrap();
        assert!(run.metrics.min_self_clearance > 0.05 && run.plan.min_self_clearance > 0.05);
        assert_eq!(wall_warning(&run), None);
        run.metrics.min_self_clearance = -0.003;
        let warning = wall_warning(&run).unwrap();
        assert!(
            warning.starts_with("links of the arm that share no joint overlap by 3.00 mm"),
            "{warning}"
        );
    }

    #[test]
    fn a_run_that_strays_from_a_clear_plan_is_warned_of_as_tracking() {
        // The deployment MPC hurried through the bend: the plan keeps 25 mm from the walls,
        // the tracking does not.
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.controller.kind = ControllerKind::Mpc;
        scenario.reference = sim_study::ReferenceSpec::Planned { travel_time: 0.4 };
        scenario.duration = 0.6;
        let run = scenario.run_deploy().unwrap();
        assert!(run.plan.min_wall_clearance > 0.0);
        let warning = wall_warning(&run).unwrap();
        assert!(
            warning.contains("the plan keeps within them at its frames, the run does not"),
            "{warning}"
        );
    }

    #[test]
    fn a_deployment_that_stops_writes_its_files_up_to_the_stop() {
        // The MPC hurrying through the bend strays past a joint bound of 5 cm (or rad).
        let mut scenario = Scenario::builtin("pipe-deploy").unwrap();
        scenario.controller.kind = ControllerKind::Mpc;
        scenario.reference = sim_study::ReferenceSpec::Planned { travel_time: 0.4 };
        scenario.duration = 0.6;
        scenario.limits.max_modal_error = 0.05;
        let failure = scenario.run_deploy().unwrap_err();
        let run = failure.partial.as_deref().expect("samples before the stop");
        let stop = run.run.record.t.last().copied().unwrap();
        assert!(stop > 0.0 && stop < 0.6, "{stop}");
        assert!(
            failure.error.to_string().contains("runaway"),
            "{}",
            failure.error
        );
        let dir = std::env::temp_dir().join(format!("hrm-deploy-stopped-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let error = simulate(&scenario, &dir).unwrap_err();
        assert_eq!(error, failure.error.to_string());
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["error"], error.as_str());
        assert_eq!(summary["stopped_at_s"], stop);
        assert_eq!(summary["deploy_tip_error_m"], run.metrics.tip_error);
        let links = std::fs::read_to_string(dir.join("links.csv")).unwrap();
        assert_eq!(links.lines().count(), 1 + run.run.record.t.len());
        assert!(dir.join("timeseries.csv").is_file() && dir.join("scenario.toml").is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
