//! The main job (`hrm` with no arguments) and `hrm simulate`: closed-loop runs of the shipped
//! scenarios (section 5 of the paper), a comparison table, and per-run output files.

use crate::output_dir::OutputDir;
use crate::spatial_figures::{self, CoordinateSeries};
use crate::{console, deploy_simulate, figures, progress, report};
use lane_math::Compact;
use serde_json::json;
use sim_core::Run;
use sim_study::imitation::{self, ImitationOptions};
use sim_study::study::{self, ComparisonRun, run_one_with, run_prepared};
use sim_study::{ArmKind, ControllerKind, DeployFailure, ReferenceSpec, Scenario, Workspace};
use std::fmt::Write as _;
use std::path::Path;

/// A warning when the arm entered an obstacle or itself (a negative smallest clearance over the
/// controller samples, `min_clearance_m` and `min_self_clearance_m`), which a run reports rather
/// than refuses: a planned motion tracked too loosely, or a controller that keeps no margin.
pub fn collision_warning(summary: &sim_core::Summary) -> Option<String> {
    let depth = |clearance: Option<f64>| clearance.filter(|c| *c < 0.0).map(|c| -1e3 * c);
    let obstacles = depth(summary.min_clearance_m)
        .map(|mm| format!("the arm reaches {mm:.2} mm into an obstacle"));
    let itself = depth(summary.min_self_clearance_m)
        .map(|mm| format!("links of the arm that share no joint overlap by {mm:.2} mm"));
    let what = match (obstacles, itself) {
        (Some(obstacles), Some(itself)) => format!("{obstacles}; {itself}"),
        (obstacles, itself) => obstacles.or(itself)?,
    };
    Some(format!(
        "{what} (smallest clearances over the controller samples, summary.json): the tracking \
         leaves the planned margin (a slower motion, a shorter controller period or a \
         controller that keeps clearance, mpc with controller.clearance_m, tracks closer)"
    ))
}

/// Runs `scenario` with `controller` (or the scenario's own) and writes its files into `out`.
/// A scenario that cannot be built is refused before anything is written; a run that stops
/// (diverges) writes its data up to the stop, then fails with the reason, and one that stops
/// before its first recorded sample writes nothing (as a URDF arm's or a deployment's).
pub fn simulate(name_or_path: &str, controller: Option<&str>, out: &Path) -> Result<(), String> {
    let mut scenario = Scenario::resolve(name_or_path).map_err(|e| e.to_string())?;
    refuse_scenario_inputs_inside(out, name_or_path, &scenario)?;
    if let Some(kind) = controller {
        scenario.controller.kind = kind
            .parse()
            .map_err(|e: sim_core::SimError| e.to_string())?;
    }
    // A controller the URDF or deployment loop refuses is the option's, when it gave it.
    let named = |error: String| match (controller, error.strip_prefix("controller.kind ")) {
        (Some(_), Some(problem)) => format!("--controller {problem}"),
        _ => error,
    };
    if scenario.arm.urdf.is_some() {
        return crate::chain_simulate::simulate(&scenario, out).map_err(named);
    }
    if scenario.deploy.is_some() {
        return deploy_simulate::simulate(&scenario, out).map_err(named);
    }
    let samples = scenario
        .build()
        .map_err(|e| e.to_string())?
        .settings()
        .controller_samples();
    let staging = OutputDir::create(out, "simulate")?;
    let mut progress = progress::SampleProgress::new(samples as u64);
    let outcome = run_one_with(&scenario, scenario.controller.kind, &mut progress);
    progress.finish();
    if let Err(stopped) = &outcome.result
        && stopped
            .partial
            .as_ref()
            .is_none_or(|run| run.record.is_empty())
    {
        return Err(stopped.error.to_string());
    }
    write_outcome(&outcome, &scenario, staging.path()).map_err(|e| staging.named(e))?;
    staging.commit()?;
    let run = match &outcome.result {
        Ok(run) => Some(run),
        Err(stopped) => stopped.partial.as_deref(),
    };
    if let Some(warning) = run.and_then(|run| collision_warning(&run.summary)) {
        console::to_stderr(&format!("warning: {warning}"));
    }
    console::print(&table(&table_rows(
        std::slice::from_ref(&outcome),
        std::slice::from_ref(&scenario),
    )))?;
    console::print(&format!("wrote {}\n", console::shown(out)))?;
    outcome
        .result
        .map(|_| ())
        .map_err(|stopped| stopped.error.to_string())
}

/// Refuses an output folder `out` that holds the files of the scenario `name_or_path`: the
/// scenario file itself, its `controller.fis` and its `arm.urdf`.
pub fn refuse_scenario_inputs_inside(
    out: &Path,
    name_or_path: &str,
    scenario: &Scenario,
) -> Result<(), String> {
    let mut inputs = vec![("scenario file", Path::new(name_or_path))];
    if let Some(fis) = &scenario.controller.fis {
        inputs.push(("controller.fis file", fis));
    }
    if let Some(urdf) = &scenario.arm.urdf {
        inputs.push(("arm.urdf file", urdf));
    }
    crate::output_dir::refuse_inputs_inside(out, &inputs)
}

/// The main job: every shipped scenario with every controller (see [`experiments`]), each cut
/// at `duration` seconds when given (finite, positive), rounded down to a whole number of the
/// scenario's controller periods ([`cut_to_whole_periods`]).
pub fn main_job(out: &Path, duration: Option<f64>) -> Result<(), String> {
    let mut scenarios = study::builtin_scenarios().map_err(|e| e.to_string())?;
    if let Some(cut) = duration {
        if !(cut.is_finite() && cut > 0.0) {
            return Err(format!(
                "--duration: {cut}, expected a finite positive number of seconds"
            ));
        }
        for scenario in &mut scenarios {
            let period = scenario.controller_period().map_err(|e| e.to_string())?;
            if cut < scenario.duration {
                scenario.duration = cut_to_whole_periods(cut, period).ok_or_else(|| {
                    format!(
                        "--duration: {} s is shorter than one controller period ({} s) of \
                         '{}'",
                        Compact(cut),
                        Compact(period),
                        scenario.name
                    )
                })?;
            }
        }
    }
    experiments(out, &scenarios)
}

/// `cut` as a run's duration with controller period `period`: `cut` itself when it is a whole
/// number of periods (within rounding), otherwise the whole periods below it; `None` below one
/// period.
fn cut_to_whole_periods(cut: f64, period: f64) -> Option<f64> {
    let ratio = cut / period;
    let whole = ratio.round();
    if whole >= 1.0 && (ratio - whole).abs() <= 1e-9 * whole {
        Some(cut)
    } else {
        let below = ratio.floor();
        (below >= 1.0).then_some(below * period)
    }
}

/// Runs `scenarios` with every controller, in parallel (results in a fixed order), then writes
/// the per-run files, the comparison table, the figures and `report.html` into `out`. A
/// scenario with a `[deploy]` runs computed torque in joint space on its insertion axis
/// ([`deploy_runs`]).
fn experiments(out: &Path, all: &[Scenario]) -> Result<(), String> {
    let staging = OutputDir::create(out, "run")?;
    staging.claim("figures")?;
    for scenario in all {
        staging.claim(&scenario.name)?;
    }
    let (deploys, scenarios): (Vec<Scenario>, Vec<Scenario>) =
        all.iter().cloned().partition(|s| s.deploy.is_some());
    let scenarios = &scenarios[..];
    let dir = staging.path();
    let runs = scenarios.len() * ControllerKind::ALL.len();
    let bar = progress::bar(runs as u64, "runs");
    let outcomes = study::compare(scenarios, |outcome| {
        let kind = outcome.controller;
        let scenario = scenario_of(scenarios, outcome)?;
        write_outcome(
            outcome,
            scenario,
            &dir.join(&outcome.scenario).join(kind.name()),
        )?;
        bar.set_message(format!("{} with {kind}", outcome.scenario));
        bar.inc(1);
        Ok::<(), String>(())
    });
    bar.finish_and_clear();
    let outcomes = outcomes?;
    let learned = learned_runs(dir, scenarios)?;
    let (deploy_summaries, deploy_figures) = deploy_runs(dir, &deploys)?;
    let mut summaries: Vec<_> = outcomes.iter().map(outcome_json).collect();
    summaries.extend(deploy_summaries);
    summaries.extend(learned.iter().map(|o| {
        let mut summary = outcome_json(o);
        summary["controller"] = json!(LEARNED);
        summary
    }));
    write(&dir.join("summary.json"), &pretty(&json!(summaries))?)?;
    let mut rows = table_rows(&outcomes, scenarios);
    rows.extend(table_rows(&learned, scenarios).into_iter().map(|mut row| {
        row.cells[1] = LEARNED.to_owned();
        row
    }));
    let text = table(&rows);
    write(&dir.join("comparison.txt"), &text)?;
    let mut sections = figures(dir, scenarios, &outcomes)?;
    if !deploy_figures.is_empty() {
        sections.insert(
            sections.len() - 1,
            report::Section {
                title: "Follow-the-leader deployment".into(),
                text: "The arm on a prismatic insertion axis advances into a channel, its body on the path its tip traced: the kinematic plan (shape-plan's follow_the_leader) tracked on the whole chain in joint space by computed torque and by MPC (iLQR over the chain's joint-space dynamics, insertion included, within a box on the joint efforts).".into(),
                figures: deploy_figures,
            },
        );
    }
    let groups = groups(scenarios, &outcomes, &learned, &rows)?;
    let intro = format!(
        "Every scenario ({}) run with every controller ({}; a follow-the-leader deployment with computed torque and MPC): a table and an animation per scenario in modal coordinates (the deployment, in joint space, is in the figures), then figures in the spirit of the paper's section 5. The {LEARNED} row of {LEARNED_ON} is a fuzzy controller learned by imitation of computed torque on the step and sine responses about a grid of operating points, never on the path ({LEARNED}.fis next to this page). Per-run time series and metrics are in <scenario>/<controller>/timeseries.csv and summary.json next to this page.",
        all.iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
        ControllerKind::ALL.map(ControllerKind::name).join(", ")
    );
    report::write(
        &dir.join("report.html"),
        "hrm: the paper's experiments",
        &intro,
        &groups,
        &sections,
        run_view::REPORT_SAMPLES,
    )?;
    staging.commit()?;
    console::print(&text)?;
    console::print(&format!(
        "wrote {} (summary.json, comparison.txt, figures/, learned.fis, one folder per run)\nreport: {}\n",
        console::shown(out),
        console::shown(&out.join("report.html"))
    ))
}

/// The deployment scenarios' runs (computed torque, then MPC, in joint space,
/// [`Scenario::run_deploy`]): each run's files into `out/<scenario>/<controller>` and its
/// figures into `out/figures`;
/// returns their entries of the main `summary.json` (a run that fails: its `error`, and the
/// summary up to the stop of one that stopped after its first recorded sample, whose figures
/// are not drawn) and the report's figures.
fn deploy_runs(
    out: &Path,
    scenarios: &[Scenario],
) -> Result<(Vec<serde_json::Value>, Vec<report::Figure>), String> {
    let (mut summaries, mut figures) = (Vec::new(), Vec::new());
    let figures_dir = out.join("figures");
    std::fs::create_dir_all(&figures_dir)
        .map_err(|e| format!("cannot create {}: {e}", figures_dir.display()))?;
    for (base, kind) in scenarios.iter().flat_map(|s| {
        [
            (s, ControllerKind::ComputedTorque),
            (s, ControllerKind::Mpc),
        ]
    }) {
        let mut scenario = base.clone();
        scenario.controller.kind = kind;
        let scenario = &scenario;
        let controller = kind.name();
        let dir = out.join(&scenario.name).join(controller);
        match scenario.run_deploy() {
            Ok(run) => {
                deploy_simulate::write_run(&dir, scenario, &run, None)?;
                figures.extend(deploy_simulate::figures(&figures_dir, scenario, &run)?);
                let summary = deploy_simulate::summary(scenario, &run, None);
                summaries.push(json!({"scenario": scenario.name, "controller": controller, "summary": summary}));
            }
            Err(DeployFailure {
                error,
                partial: Some(run),
            }) => {
                deploy_simulate::write_run(&dir, scenario, &run, Some(&error))?;
                let summary = deploy_simulate::summary(scenario, &run, Some(&error));
                summaries.push(json!({"scenario": scenario.name, "controller": controller, "error": error.to_string(), "summary": summary}));
            }
            Err(DeployFailure { error: e, .. }) => {
                std::fs::create_dir_all(&dir)
                    .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
                write(&dir.join("scenario.toml"), &scenario.to_toml())?;
                let error = json!({"error": e.to_string()});
                write(&dir.join("summary.json"), &pretty(&error)?)?;
                summaries.push(json!({"scenario": scenario.name, "controller": controller, "error": e.to_string()}));
            }
        }
    }
    Ok((summaries, figures))
}

/// The name of the learned controller's rows, folders and file (`learned.fis`).
const LEARNED: &str = "learned";
/// The scenario the learned controller is compared on; it is trained on
/// [`PAPER_TRAINING_SCENARIOS`](imitation::PAPER_TRAINING_SCENARIOS), never on it.
const LEARNED_ON: &str = "paper-tracking";

/// The learned controller's runs: if `scenarios` holds [`LEARNED_ON`], a fuzzy controller learned
/// by imitation of computed torque on the shipped step and sine responses about a grid of
/// operating points ([`paper_demonstrations`](imitation::paper_demonstrations), default
/// [`ImitationOptions`]) is written to `out/learned.fis` and run, from memory, on it; its files
/// go to `out/<scenario>/learned`.
fn learned_runs(out: &Path, scenarios: &[Scenario]) -> Result<Vec<ComparisonRun>, String> {
    let targets: Vec<&Scenario> = scenarios.iter().filter(|s| s.name == LEARNED_ON).collect();
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let learned = imitation::paper_demonstrations()
        .and_then(|training| imitation::imitate(&training, &ImitationOptions::default(), |_, _| {}))
        .map_err(|e| format!("learning the {LEARNED} controller: {e}"))?;
    let file = out.join(format!("{LEARNED}.fis"));
    write(&file, &learned.system.to_fis())?;
    let mut runs = Vec::with_capacity(targets.len());
    for target in targets {
        let mut scenario = target.clone();
        scenario.controller.kind = ControllerKind::Fuzzy;
        scenario.controller.fis = Some(file.clone());
        // The learned system as learned, not read back from its file (the same numbers: a
        // `.fis` file holds every number in its shortest exact form).
        let outcome = run_prepared(&scenario, scenario.prepare_with_system(&learned.system));
        // The run's scenario.toml names the learned system relative to itself.
        let mut written = scenario.clone();
        written.controller.fis = Some(Path::new("../..").join(format!("{LEARNED}.fis")));
        write_outcome(&outcome, &written, &out.join(&scenario.name).join(LEARNED))?;
        runs.push(outcome);
    }
    Ok(runs)
}

/// The scenario `outcome` ran.
fn scenario_of<'a>(
    scenarios: &'a [Scenario],
    outcome: &ComparisonRun,
) -> Result<&'a Scenario, String> {
    scenarios
        .iter()
        .find(|s| s.name == outcome.scenario)
        .ok_or_else(|| format!("no scenario named {}", outcome.scenario))
}

/// The run `outcome` of `scenario` as the viewer draws it (up to the stop for a run that
/// stopped), named `label`; `None` for a run that recorded nothing.
pub fn run_view_of(
    scenario: &Scenario,
    label: &str,
    outcome: &ComparisonRun,
) -> Result<Option<run_view::RunView>, String> {
    let (run, stopped) = match &outcome.result {
        Ok(run) => (Some(run), None),
        Err(stopped) => (stopped.partial.as_deref(), Some(stopped.error.to_string())),
    };
    match run {
        Some(run) if !run.record.is_empty() => {
            run_view::from_record(scenario, label, &run.record, stopped.as_deref())
                .map(Some)
                .map_err(|e| e.to_string())
        }
        _ => Ok(None),
    }
}

/// The report's groups: per scenario, its rows of the comparison (without the scenario
/// column) and the animation of its runs, the learned controller's included.
fn groups(
    scenarios: &[Scenario],
    outcomes: &[ComparisonRun],
    learned: &[ComparisonRun],
    rows: &[report::Row],
) -> Result<Vec<report::Group>, String> {
    scenarios
        .iter()
        .map(|scenario| {
            let mut runs = Vec::new();
            for outcome in outcomes.iter().chain(learned) {
                if outcome.scenario != scenario.name {
                    continue;
                }
                let label = if learned.iter().any(|l| std::ptr::eq(l, outcome)) {
                    LEARNED
                } else {
                    outcome.controller.name()
                };
                runs.extend(run_view_of(scenario, label, outcome)?);
            }
            let rows = rows
                .iter()
                .filter(|r| r.cells[0] == scenario.name)
                .map(|r| report::Row {
                    cells: r.cells[1..].to_vec(),
                    error: r.error.clone(),
                })
                .collect();
            Ok(report::Group {
                title: scenario.name.clone(),
                text: scenario.description.clone(),
                table: report::Table {
                    headers: HEADERS[1..].iter().map(|h| h.to_string()).collect(),
                    rows,
                },
                names: 1,
                scene: (!runs.is_empty()).then(|| run_view::Scene {
                    title: format!("{}: every controller, animated", scenario.name),
                    caption: "The arm link by link (links coloured by joint torque), the reference (red) and the tip's trace (green), in sync with the time series; pick a second controller to compare side by side or overlaid.".into(),
                    runs,
                }),
            })
        })
        .collect()
}

/// Interval between the drawn arm configurations of Figure 10 (s).
const CONFIGURATION_INTERVAL_S: f64 = 0.5;
/// Samples per axis of the fuzzy control surfaces.
const SURFACE_RESOLUTION: usize = 61;

/// Writes every figure into `out/figures` and returns the report's sections: Figure 9 for each
/// scenario with a modal reference, Figures 10 and 11 for each path-tracking scenario (only
/// runs that finished are drawn), then the fuzzy controller.
fn figures(
    out: &Path,
    scenarios: &[Scenario],
    outcomes: &[ComparisonRun],
) -> Result<Vec<report::Section>, String> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let figure = |file: String, caption: String| report::Figure {
        file: format!("figures/{file}"),
        caption,
    };
    let finished = |name: &str| -> Vec<(ControllerKind, &Run)> {
        outcomes
            .iter()
            .filter(|o| o.scenario == name)
            .filter_map(|o| o.result.as_ref().ok().map(|run| (o.controller, run)))
            .collect()
    };
    let (mut responses, mut backbones, mut residuals) = (Vec::new(), Vec::new(), Vec::new());
    let mut spatial = Vec::new();
    for scenario in scenarios {
        let runs = finished(&scenario.name);
        if runs.is_empty() {
            continue;
        }
        let name = &scenario.name;
        if scenario.arm.kind == ArmKind::Spatial {
            spatial_figures(&dir, scenario, &runs, &mut spatial)?;
            let file = format!("fig11_{name}.svg");
            figures::tracking_residual(&dir.join(&file), name, &runs)?;
            residuals.push(figure(
                file,
                format!("{name}: distance in space from the tip to its reference (mm) for every controller; lower is better."),
            ));
            continue;
        }
        if !matches!(scenario.reference, ReferenceSpec::Path { .. }) {
            let file = format!("fig9_{name}.svg");
            let names = scenario.coordinate_names();
            figures::modal_responses(&dir.join(&file), name, &names, &runs)?;
            responses.push(figure(
                file,
                format!("{name}: {}(t) of every controller against the reference; look at overshoot and settling (paper Figure 9).", names.join("(t), ")),
            ));
            continue;
        }
        for &(kind, run) in &runs {
            let file = format!("fig10_{name}_{}.svg", kind.name());
            figures::backbone_over_path(
                &dir.join(&file),
                scenario,
                kind,
                run,
                CONFIGURATION_INTERVAL_S,
            )?;
            backbones.push(figure(
                file,
                format!("{name} with {kind}: the arm every {CONFIGURATION_INTERVAL_S} s, light to dark; the tip (green) should stay on the red path (paper Figure 10)."),
            ));
        }
        let file = format!("fig11_{name}.svg");
        figures::tracking_residual(&dir.join(&file), name, &runs)?;
        residuals.push(figure(
            file,
            format!("{name}: distance from the tip to its reference (mm) for every controller; lower is better (paper Figure 11)."),
        ));
    }
    let fuzzy = figures::fuzzy_controller(&dir.join("fuzzy"), SURFACE_RESOLUTION)?
        .into_iter()
        .map(|path| {
            let file = path
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            let caption = if file.starts_with("mf_") {
                format!(
                    "Membership functions (generalised bells N and P) of input {} (eq 22).",
                    &file[3..file.len() - 4]
                )
            } else {
                format!(
                    "Control surface {} (Table 1, eqs 21, 23-24), other inputs at zero.",
                    &file[8..file.len() - 4]
                )
            };
            figure(format!("fuzzy/{file}"), caption)
        })
        .collect();
    let section = |title: &str, text: &str, figures: Vec<report::Figure>| report::Section {
        title: title.into(),
        text: text.into(),
        figures,
    };
    Ok(vec![
        section(
            "Responses (Figure 9)",
            "The modal coordinates (a1, a2) of the backbone curve following step, sinusoidal and noisy references.",
            responses,
        ),
        section(
            "Backbone on the tracking path (Figure 10)",
            "The tip follows y = 0.4 sin(5x) + 0.2 (eq 25) for 0.08 <= x <= 0.4 m.",
            backbones,
        ),
        section(
            "Tracking residual (Figure 11)",
            "Tip error along the path.",
            residuals,
        ),
        section(
            "Spatial arms",
            "Universal-joint arms held as horizontal cantilevers under gravity (along -z), two bending planes of K harmonics each (az: in the x-y plane, ay: out of it); the tip follows a circle about the x axis, out of the arm's plane, or (spatial-clutter) reaches a target among obstacles on a planned motion.",
            spatial,
        ),
        section(
            "The fuzzy controller (section 4)",
            "Four inputs (modal errors da1, da2 and rates a1_dot, a2_dot), two bell sets each, 16 rules, constant (zero-order Sugeno) outputs.",
            fuzzy,
        ),
    ])
}

/// The figures of a spatial scenario's finished `runs` into `dir`, their captions appended to
/// `figures`: the backbone in space (three views, with the obstacles) of each controller, the
/// clearance over time among obstacles, the tip's coordinates against the reference, and the
/// per-coordinate modal errors and forces.
fn spatial_figures(
    dir: &Path,
    scenario: &Scenario,
    runs: &[(ControllerKind, &Run)],
    figures: &mut Vec<report::Figure>,
) -> Result<(), String> {
    let name = &scenario.name;
    let mut add = |file: String, caption: String| {
        figures.push(report::Figure {
            file: format!("figures/{file}"),
            caption,
        })
    };
    for &(kind, run) in runs {
        let file = format!("backbone3d_{name}_{}.svg", kind.name());
        spatial_figures::backbone_in_space(
            &dir.join(&file),
            scenario,
            kind,
            run,
            CONFIGURATION_INTERVAL_S,
        )?;
        add(
            file,
            format!(
                "{name} with {kind}: the arm every {CONFIGURATION_INTERVAL_S} s, light to dark, from above, from the side and obliquely, with the obstacles (grey) if any; the tip (green) should stay on the red path."
            ),
        );
    }
    if !scenario.obstacles.is_empty() {
        let file = format!("clearance_{name}.svg");
        spatial_figures::clearance_over_time(&dir.join(&file), scenario, runs)?;
        add(
            file,
            format!(
                "{name}: the smallest clearance of the links to the obstacles and between links (mm) of every controller, against the task's margin; above zero is collision-free."
            ),
        );
    }
    let file = format!("tip_{name}.svg");
    spatial_figures::tip_paths(&dir.join(&file), name, runs)?;
    add(
        file,
        format!("{name}: the tip's x, y and z of every controller against the reference."),
    );
    let names = scenario.coordinate_names();
    for (what, tag, caption) in [
        (
            CoordinateSeries::Error,
            "errors",
            "the error of every modal coordinate (mrad)",
        ),
        (
            CoordinateSeries::Effort,
            "efforts",
            "the modal force tau* of every coordinate (N m)",
        ),
    ] {
        let file = format!("{tag}_{name}.svg");
        spatial_figures::per_coordinate(&dir.join(&file), name, &names, runs, what)?;
        add(file, format!("{name}: {caption}, every controller."));
    }
    Ok(())
}

fn outcome_json(outcome: &ComparisonRun) -> serde_json::Value {
    match &outcome.result {
        Ok(run) => {
            json!({"scenario": outcome.scenario, "controller": outcome.controller.name(), "summary": run.summary})
        }
        Err(e) => {
            json!({"scenario": outcome.scenario, "controller": outcome.controller.name(), "error": e.error.to_string()})
        }
    }
}

/// Writes `summary.json`, `timeseries.csv`, `links.csv` and `scenario.toml` (what `hrm view` draws the arm
/// from) of one run of `scenario` into `dir`. A run that stopped has its time series up to the
/// stop, and a summary of the metrics up to it with the `error` and the time it `stopped_at_s`.
fn write_outcome(outcome: &ComparisonRun, scenario: &Scenario, dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut ran = scenario.clone();
    ran.controller.kind = outcome.controller;
    write(&dir.join("scenario.toml"), &ran.to_toml())?;
    let summary = sim_study::summary_json::run(&outcome.result);
    let run = match &outcome.result {
        Ok(run) => Some(run),
        Err(stopped) => stopped.partial.as_deref(),
    };
    write(&dir.join("summary.json"), &pretty(&summary)?)?;
    if let Some(run) = run {
        let r = &run.record;
        let names = &outcome.coordinates;
        let mut header = vec!["t".to_string()];
        header.extend(names.iter().cloned());
        header.extend(names.iter().map(|n| format!("{n}_dot")));
        header.extend(names.iter().map(|n| format!("{n}_ref")));
        header.extend((1..=names.len()).map(|i| format!("tau{i}")));
        let spatial = scenario.arm.kind == ArmKind::Spatial;
        if spatial {
            header.extend(
                [
                    "tip_x",
                    "tip_y",
                    "tip_z",
                    "tip_ref_x",
                    "tip_ref_y",
                    "tip_ref_z",
                ]
                .map(String::from),
            );
        } else {
            header.extend(["tip_x", "tip_y", "tip_ref_x", "tip_ref_y"].map(String::from));
        }
        header.extend((1..=names.len()).map(|i| format!("clamped{i}")));
        header.extend((1..=r.n_joints).map(|j| format!("joint_tau{j}")));
        let mut csv = header.join(",") + "\n";
        for k in 0..r.len() {
            let row = std::iter::once(r.t[k])
                .chain(r.a_at(k).iter().copied())
                .chain(r.a_dot_at(k).iter().copied())
                .chain(r.a_ref_at(k).iter().copied())
                .chain(r.tau_star_at(k).iter().copied())
                .chain(r.tip[k])
                .chain(spatial.then_some(r.tip_z[k]))
                .chain(r.tip_ref[k])
                .chain(spatial.then_some(r.tip_ref_z[k]))
                .chain(r.clamped_at(k).iter().map(|&c| f64::from(u8::from(c))))
                .chain(r.joint_torques_at(k).iter().copied());
            let line: Vec<String> = row.map(|v| Compact(v).to_string()).collect();
            let _ = writeln!(csv, "{}", line.join(","));
        }
        write(&dir.join("timeseries.csv"), &csv)?;
        write(&dir.join("links.csv"), &links_csv(r, scenario.workspace()))?;
    }
    Ok(())
}

/// `links.csv`: the time, then the base point and every link's end point (`t, x0, y0, x1, y1,
/// ...`, with `z0, z1, ...` interleaved for a spatial arm) at each recorded sample, exactly the
/// points the loop measured the clearance from.
fn links_csv(r: &sim_core::Record, workspace: Workspace) -> String {
    let axes: &[&str] = match workspace {
        Workspace::Planar => &["x", "y"],
        Workspace::Spatial => &["x", "y", "z"],
    };
    let mut header = vec!["t".to_string()];
    for j in 0..r.n_points {
        header.extend(axes.iter().map(|axis| format!("{axis}{j}")));
    }
    let mut csv = header.join(",") + "\n";
    for k in 0..r.len() {
        let points = r.joint_points_at(k).iter();
        let coordinates = points.flat_map(|p| p.iter().take(axes.len()).copied());
        let row = std::iter::once(r.t[k]).chain(coordinates);
        let line: Vec<String> = row.map(|v| Compact(v).to_string()).collect();
        let _ = writeln!(csv, "{}", line.join(","));
    }
    csv
}

/// The comparison table's columns.
const HEADERS: [&str; 9] = [
    "scenario",
    "controller",
    "tip error RMS (mm)",
    "tip error max (mm)",
    "modal error RMS (mrad)",
    "peak |tau*| (N m)",
    "peak |joint torque| (N m)",
    "effort (N^2 m^2 s)",
    "tau* clamped (%)",
];

/// The comparison table's rows in plain notation ([`report::plain`]): tip error RMS and
/// maximum (mm), modal error RMS (mrad), peak torques (N m), effort, and the percentage of controller samples whose `tau_i*` the actuator limits clamped
/// (`-` for a scenario without limits); a failed run has only its scenario and controller, and its error.
fn table_rows(outcomes: &[ComparisonRun], scenarios: &[Scenario]) -> Vec<report::Row> {
    outcomes
        .iter()
        .map(|o| {
            let limited = scenarios
                .iter()
                .any(|s| s.name == o.scenario && s.limits.tau_star.is_some());
            // The scenario's name is the user's text: a newline or U+202E in it must not break
            // or reverse the table.
            let mut cells = vec![
                console::escape_field(&o.scenario),
                o.controller.name().to_owned(),
            ];
            match &o.result {
                Ok(run) => {
                    let m = &run.summary;
                    cells.extend([
                        report::plain(m.tip_error_rms_m * 1e3, 3),
                        report::plain(m.tip_error_max_m * 1e3, 3),
                        list(&m.modal_error_rms_rad, |v| report::plain(v * 1e3, 3)),
                        list(&m.peak_modal_torques_nm, |v| report::plain(v, 3)),
                        report::plain(m.peak_joint_torque_nm, 3),
                        report::plain(m.control_effort_n2m2s, 4),
                        if limited {
                            list(&m.tau_star_clamped_fraction, |v| {
                                format!("{:.1}", 100.0 * v)
                            })
                        } else {
                            "-".to_owned()
                        },
                    ]);
                    report::Row { cells, error: None }
                }
                Err(e) => report::Row {
                    cells,
                    error: Some(e.error.to_string()),
                },
            }
        })
        .collect()
}

/// `values` formatted by `format`, comma-separated.
fn list(values: &[f64], format: impl Fn(f64) -> String) -> String {
    values
        .iter()
        .map(|&v| format(v))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The comparison table as text: the two name columns left-aligned, numbers right-aligned
/// (padded by characters, so that a name of any length, `std::fmt`'s widths stopping at
/// 65,535, lines up).
fn table(rows: &[report::Row]) -> String {
    let mut widths = HEADERS.map(|header| header.chars().count());
    for row in rows {
        for (width, cell) in widths.iter_mut().zip(&row.cells) {
            *width = (*width).max(cell.chars().count());
        }
    }
    let line = |cells: &[String], error: Option<&String>| {
        let mut s = String::new();
        for (k, (cell, width)) in cells.iter().zip(widths).enumerate() {
            let padding = " ".repeat(width - cell.chars().count());
            if k < 2 {
                s += &format!("{cell}{padding}  ");
            } else {
                s += &format!("{padding}{cell}  ");
            }
        }
        if let Some(e) = error {
            let _ = write!(s, "stopped: {e}");
        }
        s.trim_end().to_owned() + "\n"
    };
    let mut s = line(&HEADERS.map(String::from), None);
    for row in rows {
        s += &line(&row.cells, row.error.as_ref());
    }
    s
}

fn pretty(value: &serde_json::Value) -> Result<String, String> {
    serde_json::to_string_pretty(value)
        .map(|s| s + "\n")
        .map_err(|e| e.to_string())
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fuzzy_sugeno::FuzzySystem;

    #[test]
    fn a_duration_cut_is_whole_controller_periods_or_refused_up_front() {
        assert_eq!(cut_to_whole_periods(0.15, 1e-3), Some(0.15));
        assert_eq!(cut_to_whole_periods(0.0015, 1e-3), Some(1e-3));
        assert_eq!(cut_to_whole_periods(5e-4, 1e-3), None);
        // Below every scenario's period: refused before anything is written (it made a report
        // of 67 runs each "stopped" by a settings error).
        let dir = std::env::temp_dir().join(format!("hrm-main-job-cut-{}", std::process::id()));
        let err = main_job(&dir, Some(1e-5)).unwrap_err();
        assert!(
            err.starts_with("--duration: 1e-5 s is shorter than one controller period ("),
            "{err}"
        );
        assert!(!dir.exists());
    }

    #[test]
    fn simulate_writes_the_summary_keys_and_a_time_series() {
        let dir = std::env::temp_dir().join(format!("hrm-simulate-test-{}", std::process::id()));
        let mut scenario = Scenario::builtin("paper-responses-step").unwrap();
        scenario.duration = 0.2;
        let outcome = study::run_one(&scenario, ControllerKind::ComputedTorque);
        write_outcome(&outcome, &scenario, &dir).unwrap();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        for key in [
            "tip_error_rms_m",
            "tip_error_max_m",
            "modal_error_rms_rad",
            "peak_modal_torques_nm",
            "peak_joint_torque_nm",
            "steps",
        ] {
            assert!(
                summary.get(key).is_some(),
                "summary.json lacks {key}: {summary}"
            );
        }
        let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
        assert_eq!(
            csv.lines().count(),
            outcome.result.as_ref().unwrap().record.len() + 1
        );
        let mut outcome = outcome;
        assert!(
            table(&table_rows(std::slice::from_ref(&outcome), &[scenario]))
                .contains("computed-torque")
        );
        // A scenario name with a newline and a right-to-left override stays on its row, escaped.
        outcome.scenario = "step\nlimit \u{202e}".into();
        let text = table(&table_rows(std::slice::from_ref(&outcome), &[]));
        assert_eq!(text.lines().count(), 2, "{text}");
        assert!(text.contains("step\\nlimit \\u{202e}"), "{text}");
        // A name beyond `std::fmt`'s widths (65,535) lines up too, and non-ASCII names by
        // characters: the header pads to the name's 70,000 characters.
        outcome.scenario = "é".repeat(70_000);
        let text = table(&table_rows(&[outcome], &[]));
        let (header, row) = text.split_once('\n').unwrap();
        assert_eq!(header.find("controller"), Some(70_002));
        assert_eq!(row.chars().position(|c| c != 'é'), Some(70_000));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_report_has_a_row_per_run_and_every_figure_it_shows() {
        let dir = std::env::temp_dir().join(format!("hrm-main-job-test-{}", std::process::id()));
        let mut scenarios: Vec<Scenario> = ["paper-tracking", "paper-responses-step"]
            .into_iter()
            .map(|name| Scenario::builtin(name).unwrap())
            .collect();
        for scenario in &mut scenarios {
            scenario.duration = 0.15;
        }
        // A runaway bound so tight that every step run stops: a failed row.
        scenarios[1].limits.max_modal_error = 1e-6;
        experiments(&dir, &scenarios).unwrap();
        let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
        // Every scenario with every controller, and the learned controller on paper-tracking.
        let runs = scenarios.len() * ControllerKind::ALL.len() + 1;
        // One table per scenario, and its animation.
        assert_eq!(page.matches("<table>").count(), scenarios.len());
        assert_eq!(page.matches("<tr>").count(), scenarios.len() + runs);
        assert!(page.contains("<td>learned</td><td class=\"num"));
        assert!(page.matches("class=\"hrm-view\"").count() >= 1);
        assert!(!page.contains("http://") && !page.contains("https://"));
        // Numbers in plain notation: no exponent in any cell.
        for cell in page.split("<td class=\"num").skip(1) {
            let text = &cell[cell.find('>').unwrap() + 1..cell.find("</td>").unwrap()];
            assert!(!text.contains('e'), "{text}");
        }
        // Each run's folder holds the scenario it ran, the learned one naming its system.
        let ran = Scenario::load(&dir.join("paper-tracking/learned/scenario.toml")).unwrap();
        assert_eq!(
            ran.controller.fis.unwrap(),
            std::fs::canonicalize(dir.join("learned.fis")).unwrap()
        );
        let learned =
            FuzzySystem::from_fis(&std::fs::read_to_string(dir.join("learned.fis")).unwrap());
        assert_eq!(learned.unwrap().inputs().len(), 8);
        assert!(dir.join("paper-tracking/learned/timeseries.csv").is_file());
        assert_eq!(
            page.matches("<td class=\"error\"").count(),
            ControllerKind::ALL.len(),
            "{page}"
        );
        let mut images = 0;
        for piece in page.split("<img src=\"").skip(1) {
            let file = &piece[..piece.find('"').unwrap()];
            assert!(dir.join(file).is_file(), "{file} is missing");
            images += 1;
        }
        // Figures 10 (one per controller) and 11, four membership plots and two surfaces; no
        // Figure 9 as every step run failed.
        assert_eq!(images, ControllerKind::ALL.len() + 1 + 4 + 2);
        for name in ["summary.json", "comparison.txt"] {
            assert!(dir.join(name).is_file());
        }
        std::fs::remove_dir_all(&dir).unwrap();
        // An output folder that cannot be created is an error naming it.
        let blocked = dir.with_extension("file");
        std::fs::write(&blocked, "").unwrap();
        let err = experiments(&blocked.join("out"), &scenarios[..1]).unwrap_err();
        assert!(err.contains(&*blocked.to_string_lossy()), "{err}");
        std::fs::remove_file(&blocked).unwrap();
    }

    #[test]
    fn unknown_scenario_and_controller_are_refused() {
        let dir = std::env::temp_dir();
        assert!(simulate("no-such-scenario", None, &dir).is_err());
        let err = simulate("paper-responses-step", Some("bang-bang"), &dir).unwrap_err();
        assert!(err.contains(&ControllerKind::names(", ")), "{err}");
    }
}
