//! `hrm view DIR`: the viewer page (`run-view`) of an `hrm simulate` output folder, of a
//! main job's output folder (one animation per scenario, every controller), or of a sweep's
//! (chosen runs run again, [`crate::view_sweep`]), and with `--gif FILE` an animated GIF of one
//! run. The files are written whole or not at all, and a
//! file hrm did not write is never replaced.

use crate::output_dir;
use run_view::{GifOptions, RunView, Scene};
use sim_core::Record;
use sim_study::{ControllerKind, MAX_INPUT_FILE_BYTES, Scenario, read_text_file};
use std::path::{Path, PathBuf};

/// Largest `timeseries.csv` read (256 MiB: a 10-link run of an hour at the recording rate of
/// the shipped scenarios is about a tenth of it).
const MAX_TIMESERIES_BYTES: u64 = 256 << 20;

/// The command line of `hrm view`.
#[derive(clap::Args)]
pub struct ViewArgs {
    /// An `hrm simulate` output folder, the main job's (`hrm run`) output folder, or a sweep's
    /// (`hrm sweep`, `hrm sweep merge`).
    dir: PathBuf,
    /// The page to write (default: DIR/view.html).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Also write an animated GIF of the run (of a main job's folder: of `--run`).
    #[arg(long)]
    gif: Option<PathBuf>,
    /// The run of a main job's folder the GIF shows, as SCENARIO/CONTROLLER (default
    /// `paper-tracking/fuzzy`).
    #[arg(long)]
    run: Option<String>,
    /// A sweep's runs to show (their numbers in `--list`), at most 12; they are run again from
    /// the sweep's configuration. Default: the first seed of every controller at the lowest and
    /// the highest noise level. The GIF shows the first.
    #[arg(long, value_delimiter = ',', action = clap::ArgAction::Set, value_name = "I,J,...")]
    runs: Option<Vec<usize>>,
    /// List a sweep's runs (number, noise level, controller, seed number, outcome) and write
    /// nothing (so not with `--out`, `--gif` or `--runs`).
    #[arg(long, conflicts_with_all = ["out", "gif", "runs"])]
    list: bool,
    /// GIF width (pixels); with `--gif` only, as the height, rate and speed.
    #[arg(long, default_value_t = 480, requires = "gif")]
    width: u32,
    /// GIF height (pixels).
    #[arg(long, default_value_t = 360, requires = "gif")]
    height: u32,
    /// GIF frames a second.
    #[arg(long, default_value_t = 20, requires = "gif")]
    fps: u32,
    /// Seconds of the run a second of the GIF shows (1 is real time).
    #[arg(long, default_value_t = 1.0, requires = "gif")]
    speed: f64,
}

/// Runs `hrm view`.
pub fn run(args: ViewArgs) -> Result<(), String> {
    let options = GifOptions {
        width: args.width,
        height: args.height,
        fps: args.fps,
        speed: args.speed,
    };
    if args.gif.is_some() {
        options.check().map_err(|e| e.to_string())?;
    }
    let dir = &args.dir;
    if !dir.is_dir() {
        let problem = if dir.exists() {
            "not a folder"
        } else {
            "no such folder"
        };
        return Err(format!("{}: {problem}", dir.display()));
    }
    let out = args.out.clone().unwrap_or_else(|| dir.join("view.html"));
    if let Some(gif) = &args.gif {
        output_dir::refuse_shared_outputs(&[("--out", &out), ("--gif", gif)])?;
    }
    let is_sweep = crate::view_sweep::is_sweep(dir);
    if (args.list || args.runs.is_some()) && !is_sweep {
        return Err(format!(
            "{}: --list and --runs take a sweep's output folder (with runs.json)",
            dir.display()
        ));
    }
    if args.list {
        return crate::view_sweep::list(dir);
    }
    let is_run = dir.join("timeseries.csv").is_file();
    if let Some(run) = &args.run
        && (is_sweep || is_run)
    {
        return Err(format!(
            "--run {run}: takes a main job's output folder (hrm run); {} is {}",
            dir.display(),
            if is_sweep {
                "a sweep's (choose its runs with --runs)"
            } else {
                "one run's"
            }
        ));
    }
    let (title, scenes, gif_run) = if is_sweep {
        let scenes = crate::view_sweep::load(dir, args.runs.as_deref())?;
        let gif_run = scenes[0].runs[0].clone();
        let title = format!("hrm: runs of the sweep in {}", dir.display());
        (title, scenes, gif_run)
    } else if is_run {
        let (scenario, run) = load_run(dir, None)?;
        let title = format!("{} with {}", scenario.name, run.label);
        let scene = Scene {
            title: title.clone(),
            caption: scenario.description.clone(),
            runs: vec![run.clone()],
        };
        (title, vec![scene], run)
    } else {
        let scenes = load_main_job(dir)?;
        let chosen = args.run.as_deref().unwrap_or("paper-tracking/fuzzy");
        let (name, controller) = chosen
            .split_once('/')
            .ok_or_else(|| format!("--run {chosen}: expected SCENARIO/CONTROLLER"))?;
        let gif_run = scenes
            .iter()
            .filter(|s| s.title == name)
            .flat_map(|s| &s.runs)
            .find(|r| r.label == controller)
            .cloned();
        let gif_run = match (gif_run, &args.gif) {
            (Some(run), _) => run,
            (None, None) => scenes[0].runs[0].clone(),
            (None, Some(_)) => {
                // A run folder that exists but is not animated says why.
                let folder = dir.join(name).join(controller);
                if folder.join("timeseries.csv").is_file() {
                    load_run(&folder, None)?;
                }
                return Err(format!(
                    "--run {chosen}: no such run in {} (its folders are SCENARIO/CONTROLLER)",
                    dir.display()
                ));
            }
        };
        ("hrm: every run of the main job".to_owned(), scenes, gif_run)
    };
    let page = run_view::page(
        &title,
        "The arm link by link (links coloured by joint torque), the reference path and the tip's trace, in sync with the time series. Space plays and pauses, the arrows step, drag pans (or orbits a spatial arm), the wheel zooms.",
        &scenes,
        if scenes.len() > 1 {
            run_view::REPORT_SAMPLES
        } else {
            run_view::PAGE_SAMPLES
        },
    )
    .map_err(|e| e.to_string())?;
    output_dir::refuse_foreign_file(&out, run_view::SIGNATURE_WITHIN, run_view::written_by_hrm)?;
    let mut files = vec![(out.clone(), page.into_bytes())];
    if let Some(gif) = &args.gif {
        output_dir::refuse_foreign_file(gif, run_view::SIGNATURE_WITHIN, run_view::written_by_hrm)?;
        let mut bytes = Vec::new();
        run_view::write_gif(&gif_run, &options, &mut bytes).map_err(|e| e.to_string())?;
        files.push((gif.clone(), bytes));
    }
    // The page and the GIF: both or neither.
    output_dir::write_files(&files, "view")?;
    crate::console::print(&format!("wrote {}\n", crate::console::shown(&out)))?;
    if let Some(gif) = &args.gif {
        crate::console::print(&format!("wrote {}\n", crate::console::shown(gif)))?;
    }
    Ok(())
}

/// The runs of a main job's output folder: one scene per scenario folder, its controllers in
/// the order of the comparison (the learned controller last).
fn load_main_job(dir: &Path) -> Result<Vec<Scene>, String> {
    let folders = |path: &Path| -> Result<Vec<PathBuf>, String> {
        let mut list: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        list.sort();
        Ok(list)
    };
    let rank = |path: &Path| {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        ControllerKind::ALL
            .iter()
            .position(|k| Some(k.name()) == name.as_deref())
            .unwrap_or(ControllerKind::ALL.len())
    };
    let mut scenes = Vec::new();
    for scenario_dir in folders(dir)? {
        let mut runs: Vec<PathBuf> = folders(&scenario_dir)?
            .into_iter()
            .filter(|p| p.join("timeseries.csv").is_file() && !is_deployment(p))
            .collect();
        runs.sort_by_key(|p| rank(p));
        let mut views = Vec::with_capacity(runs.len());
        let mut description = String::new();
        for run in &runs {
            let label = run.file_name().map(|n| n.to_string_lossy().into_owned());
            let (scenario, view) = load_run(run, label.as_deref())?;
            description = scenario.description;
            views.push(view);
        }
        if let (false, Some(name)) = (views.is_empty(), scenario_dir.file_name()) {
            scenes.push(Scene {
                title: name.to_string_lossy().into_owned(),
                caption: description,
                runs: views,
            });
        }
    }
    let csv = dir.join("timeseries.csv");
    if scenes.is_empty() && csv.exists() && !csv.is_file() {
        return Err(format!("{}: not a regular file", csv.display()));
    }
    if scenes.is_empty() {
        return Err(format!(
            "{}: neither an `hrm simulate` output (no timeseries.csv) nor a main job's (no SCENARIO/CONTROLLER/timeseries.csv)",
            dir.display()
        ));
    }
    Ok(scenes)
}

/// Whether the run folder `dir` holds a deployment (its scenario has a `[deploy]`): a joint-space
/// run the main job draws as figures, not an animation.
fn is_deployment(dir: &Path) -> bool {
    Scenario::load(&dir.join("scenario.toml")).is_ok_and(|s| s.deploy.is_some())
}

/// One run folder (`scenario.toml`, `timeseries.csv`, `summary.json`) as a [`RunView`] named
/// `label` (default: its controller).
fn load_run(dir: &Path, label: Option<&str>) -> Result<(Scenario, RunView), String> {
    let toml = dir.join("scenario.toml");
    if !toml.is_file() {
        return Err(format!(
            "{}: no scenario.toml (written by hrm simulate and hrm run since `hrm view` exists); run it again",
            dir.display()
        ));
    }
    let scenario = Scenario::load(&toml).map_err(|e| format!("{}: {e}", toml.display()))?;
    let joint_space = if scenario.deploy.is_some() {
        Some("a deployment on an insertion axis ([deploy]), which the main job draws as figures")
    } else if scenario.arm.urdf.is_some() {
        Some("a URDF arm's run in joint space (arm.urdf)")
    } else {
        None
    };
    if let Some(what) = joint_space {
        return Err(format!(
            "{}: {what}: `hrm view` animates the runs in modal coordinates of `hrm simulate` \
             and the main job, not this one",
            dir.display()
        ));
    }
    // The arm the scenario describes (refused there, e.g. too many links).
    let n_joints = scenario
        .plant()
        .map_err(|e| format!("{}: {e}", toml.display()))?
        .plant()
        .n_joints();
    let summary = dir.join("summary.json");
    let stopped = match read_text_file(&summary, MAX_INPUT_FILE_BYTES) {
        Ok(text) => serde_json::from_str::<serde_json::Value>(&text)
            .map_err(|e| format!("{}: {e}", summary.display()))?
            .get("error")
            .and_then(|e| e.as_str().map(str::to_owned)),
        Err(_) => None,
    };
    let csv = dir.join("timeseries.csv");
    let text = read_text_file(&csv, MAX_TIMESERIES_BYTES)
        .map_err(|e| format!("{}: {e}", csv.display()))?;
    // A byte-order mark (an editor's) before the header is not part of the column `t`.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let record = parse_timeseries(text, &scenario, n_joints)
        .map_err(|e| format!("{}: {e}", csv.display()))?;
    let label = label.unwrap_or(scenario.controller.kind.name());
    let view = run_view::from_record(&scenario, label, &record, stopped.as_deref())
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok((scenario, view))
}

/// The columns of `timeseries.csv` the viewer needs, back into a [`Record`]: `t`, the
/// coordinates and their `_ref`, `tau1..m`, the tips, and `joint_tau1..n_joints` when present.
fn parse_timeseries(text: &str, scenario: &Scenario, n_joints: usize) -> Result<Record, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("no column {name}"))
    };
    let names = scenario.coordinate_names();
    let m = names.len();
    let a: Vec<usize> = names.iter().map(|n| column(n)).collect::<Result<_, _>>()?;
    let a_ref: Vec<usize> = names
        .iter()
        .map(|n| column(&format!("{n}_ref")))
        .collect::<Result<_, _>>()?;
    let tau: Vec<usize> = (1..=m)
        .map(|i| column(&format!("tau{i}")))
        .collect::<Result<_, _>>()?;
    let [t, tip_x, tip_y, ref_x, ref_y] =
        ["t", "tip_x", "tip_y", "tip_ref_x", "tip_ref_y"].map(column);
    let (t, tip_x, tip_y, ref_x, ref_y) = (t?, tip_x?, tip_y?, ref_x?, ref_y?);
    // A spatial run's tip has z columns too; a planar run's z is zero.
    let [tip_z, ref_z] = ["tip_z", "tip_ref_z"].map(|name| column(name).ok());
    let joint: Vec<usize> = (1..=n_joints)
        .map_while(|j| column(&format!("joint_tau{j}")).ok())
        .collect();
    // Torque columns for another arm: the folder's scenario.toml was not the run's.
    let written = header.iter().filter(|h| h.starts_with("joint_tau")).count();
    if written > 0 && (joint.len() != n_joints || written != n_joints) {
        return Err(format!(
            "{written} joint torque columns (joint_tau1, ...) but the arm of scenario.toml has \
             {n_joints} joints: the folder's scenario.toml is not the one this run wrote"
        ));
    }
    let mut record = Record {
        n_joints,
        n_coords: m,
        ..Record::default()
    };
    let mut row = Vec::with_capacity(header.len());
    for (line, text) in lines.enumerate() {
        row.clear();
        for (k, cell) in text.split(',').enumerate() {
            let Some(name) = header.get(k) else {
                return Err(format!(
                    "line {}: more values than the {} columns",
                    line + 2,
                    header.len()
                ));
            };
            let value: f64 = cell.parse().map_err(|_| {
                format!("line {}: column {name}: {cell:?} is not a number", line + 2)
            })?;
            // hrm writes no time, coordinate or rate beyond its runaway bounds (a hand-edited
            // 1e308 would make the drawn distances overflow); torques grow with the arm's masses
            // and are only rounded.
            let max = if name.starts_with("tau") || name.starts_with("joint_tau") {
                run_view::MAX_VALUE
            } else {
                run_view::MAX_MAGNITUDE
            };
            if value.is_nan() {
                return Err(format!(
                    "line {}: column {name}: NaN is not a value a run writes",
                    line + 2
                ));
            }
            if value.abs() > max {
                return Err(format!(
                    "line {}: column {name}: {} is beyond the {} a run writes",
                    line + 2,
                    lane_math::Compact(value),
                    lane_math::Compact(max)
                ));
            }
            row.push(value);
        }
        if row.len() != header.len() {
            return Err(format!(
                "line {}: {} values for {} columns",
                line + 2,
                row.len(),
                header.len()
            ));
        }
        record.t.push(row[t]);
        record.a.extend(a.iter().map(|&c| row[c]));
        record.a_ref.extend(a_ref.iter().map(|&c| row[c]));
        record.tau_star.extend(tau.iter().map(|&c| row[c]));
        record.tip.push([row[tip_x], row[tip_y]]);
        record.tip_ref.push([row[ref_x], row[ref_y]]);
        record.tip_z.push(tip_z.map_or(0.0, |c| row[c]));
        record.tip_ref_z.push(ref_z.map_or(0.0, |c| row[c]));
        if joint.len() == n_joints {
            record.joint_torques.extend(joint.iter().map(|&c| row[c]));
        }
    }
    if record.is_empty() {
        return Err("no samples".into());
    }
    Ok(record)
}
