//! `hrm view` of a sweep's output folder (`hrm sweep`, `hrm sweep merge`). A sweep keeps only
//! each run's metrics, so the viewer lists its runs from `runs.json` and runs the chosen ones
//! again from the configuration stored there (scenario, controller, noise level and seed), with
//! their time series: the same runs, which give the metrics the sweep stored (checked; a
//! difference is reported).

use crate::console;
use run_view::Scene;
use sim_study::study::{self, RunId, ShardReader, StoredOutcome, SweepConfig};
use std::fmt::Write as _;
use std::path::Path;

/// Most runs one `hrm view` of a sweep runs again (two noise levels of every controller).
pub const MAX_RERUNS: usize = 12;

/// Whether `dir` is a sweep's output folder: it holds `runs.json`.
pub fn is_sweep(dir: &Path) -> bool {
    dir.join("runs.json").is_file()
}

/// The sweep stored in `dir/runs.json` (its header, checked as a merge checks it).
fn open(dir: &Path) -> Result<ShardReader<study::ShardInput>, String> {
    ShardReader::open(&dir.join("runs.json")).map_err(|e| e.to_string())
}

/// Prints the runs of the sweep in `dir`, one a line: index, noise level, controller, seed
/// number (1 to `seeds`; `runs.json` holds the seed itself), and the tip error RMS or why the run stopped; streamed, as a sweep may hold millions.
pub fn list(dir: &Path) -> Result<(), String> {
    let mut reader = open(dir)?;
    let config = reader.header().config.clone();
    let mut text = format!(
        "sweep of {} ({} runs); `hrm view {} --runs I,J,...` shows up to {MAX_RERUNS} of them\n\
         {:>8}  {:>10}  {:<16} {:>8}  outcome\n",
        console::escape_field(&config.scenario.name),
        config.runs().unwrap_or(0),
        dir.display(),
        "run",
        "L (rad)",
        "controller",
        "seed no.",
    );
    while let Some(run) = reader.next_run().map_err(|e| e.to_string())? {
        let outcome = match &run.outcome {
            StoredOutcome::Completed(m) => format!(
                "tip error RMS {} mm",
                crate::report::plain(m.tip_error_rms_m * 1e3, 4)
            ),
            StoredOutcome::Failed { error, .. } => format!("stopped: {error}"),
        };
        let _ = writeln!(
            text,
            "{:>8}  {:>10}  {:<16} {:>8}  {}",
            run.index,
            lane_math::Compact(run.noise_level).to_string(),
            run.controller.name(),
            run.seed_index + 1,
            console::escape_field(&outcome)
        );
        if text.len() > 1 << 16 {
            console::print(&text)?;
            text.clear();
        }
    }
    console::print(&text)
}

/// The runs shown when none are chosen: the first noise realisation of every controller at the
/// lowest and at the highest noise level.
fn default_runs(config: &SweepConfig) -> Vec<usize> {
    let s = &config.settings;
    let cell = |level: usize, c: usize| (level * s.controllers.len() + c) * s.seeds;
    let mut levels = vec![0];
    if s.noise_levels.len() > 1 {
        levels.push(s.noise_levels.len() - 1);
    }
    levels
        .into_iter()
        .flat_map(|l| (0..s.controllers.len()).map(move |c| cell(l, c)))
        .collect()
}

/// Checks the chosen run indices against the sweep's `runs`: at least one, at most
/// [`MAX_RERUNS`], each an index of the sweep and none twice. Returns them ascending.
fn check_selection(chosen: &[usize], runs: usize) -> Result<Vec<usize>, String> {
    if chosen.is_empty() {
        return Err("--runs: name at least one run".into());
    }
    if chosen.len() > MAX_RERUNS {
        return Err(format!(
            "--runs lists {} runs, more than the {MAX_RERUNS} `hrm view` runs again: choose fewer",
            chosen.len()
        ));
    }
    if let Some(bad) = chosen.iter().find(|&&i| i >= runs) {
        return Err(format!(
            "--runs {bad}: the sweep has {runs} runs, numbered 0 to {} (`hrm view DIR --list` \
             lists them)",
            runs.saturating_sub(1)
        ));
    }
    let mut sorted = chosen.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("--runs lists run {} twice", w[0]));
    }
    Ok(sorted)
}

/// The page's scenes of the sweep in `dir`: the runs `chosen` (default [`default_runs`]) run
/// again, one scene per noise level and seed holding its controllers. A re-run whose metrics
/// differ from those the sweep stored is reported on standard error and in the scene's caption.
pub fn load(dir: &Path, chosen: Option<&[usize]>) -> Result<Vec<Scene>, String> {
    let mut reader = open(dir)?;
    let config = reader.header().config.clone();
    let runs = config.runs().unwrap_or(0);
    let indices = match chosen {
        Some(chosen) => check_selection(chosen, runs)?,
        None => check_selection(&default_runs(&config), runs)?,
    };
    // The files the scenario references must be those the sweep ran with.
    let now = study::input_digests(&config.scenario)
        .map_err(|e| format!("{}: cannot run the sweep's runs again: {e}", dir.display()))?;
    if let Some((input, _)) = study::first_changed(&config.inputs, &now) {
        return Err(format!(
            "{}: {} changed since the sweep ran, so its runs cannot be run again as they were",
            dir.display(),
            input.describe()
        ));
    }
    // What the sweep stored of each chosen run, read in one pass.
    let mut stored = Vec::with_capacity(indices.len());
    while stored.len() < indices.len() {
        match reader.next_run().map_err(|e| e.to_string())? {
            Some(run) if indices.contains(&run.index) => stored.push(run.outcome),
            Some(_) => {}
            None => return Err(format!("{}: runs.json ends early", dir.display())),
        }
    }
    let ids: Vec<RunId> = indices.iter().map(|&i| config.run_at(i)).collect();
    let outcomes: Vec<_> = {
        use rayon::prelude::*;
        ids.par_iter()
            .map(|id| {
                let scenario = config.scenario_for(id);
                (scenario.clone(), study::run_one(&scenario, id.controller))
            })
            .collect()
    };
    // One scene per (noise level, seed): its runs, and the runs' numbers for the caption.
    let mut scenes: Vec<((usize, usize), Vec<String>, Scene)> = Vec::new();
    for ((id, (scenario, outcome)), stored) in ids.iter().zip(outcomes).zip(stored) {
        let label = id.controller.name();
        let view = crate::experiment::run_view_of(&scenario, label, &outcome)?
            .ok_or_else(|| format!("run {}: stopped before it recorded anything", id.index))?;
        let mut named = format!("{} ({label})", id.index);
        if StoredOutcome::of(outcome.result) != stored {
            let warning = format!(
                "run {} ({label}) of {} did not give the metrics the sweep stored (hrm {} ran \
                 the sweep, this is hrm {})",
                id.index,
                dir.display(),
                config.hrm_version,
                study::VERSION
            );
            console::to_stderr(&format!(
                "warning: {}",
                lane_math::escape_controls(&warning, &[])
            ));
            named.push_str(", which did not give the metrics the sweep stored");
        }
        let key = (id.level_index, id.seed_index);
        match scenes.iter_mut().find(|(k, _, _)| *k == key) {
            Some((_, names, scene)) => {
                names.push(named);
                scene.runs.push(view);
            }
            None => scenes.push((
                key,
                vec![named],
                Scene {
                    title: format!(
                        "{} at noise level L = {} rad, seed {}",
                        config.scenario.name,
                        lane_math::Compact(id.noise_level),
                        id.seed_index + 1
                    ),
                    caption: String::new(),
                    runs: vec![view],
                },
            )),
        }
    }
    let s = &config.settings;
    Ok(scenes
        .into_iter()
        .map(|(_, names, mut scene)| {
            let (runs, compare) = match names.len() {
                1 => ("Run", ""),
                _ => ("Runs", "; pick a second controller to compare"),
            };
            scene.caption = format!(
                "{runs} {} of the sweep, run again from its configuration (sensor noise std L \
                 on the modal coordinates, {} L on their rates, {} L on the reference){compare}.",
                names.join(", "),
                lane_math::Compact(s.rate_noise_ratio),
                lane_math::Compact(s.reference_noise_ratio)
            );
            scene
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selections_are_bounded_and_checked() {
        assert_eq!(check_selection(&[5, 0, 3], 6), Ok(vec![0, 3, 5]));
        assert!(
            check_selection(&[], 6)
                .unwrap_err()
                .contains("at least one")
        );
        let many: Vec<usize> = (0..=MAX_RERUNS).collect();
        assert!(
            check_selection(&many, 100)
                .unwrap_err()
                .contains("more than the 12")
        );
        assert_eq!(
            check_selection(&[6], 6).unwrap_err(),
            "--runs 6: the sweep has 6 runs, numbered 0 to 5 (`hrm view DIR --list` lists them)"
        );
        assert_eq!(
            check_selection(&[2, 1, 2], 6).unwrap_err(),
            "--runs lists run 2 twice"
        );
    }

    #[test]
    fn the_default_runs_are_the_first_seed_at_the_extreme_levels() {
        let mut scenario = sim_study::Scenario::builtin("paper-responses-step").unwrap();
        scenario.duration = 0.01;
        let settings = study::SweepSettings {
            controllers: vec![
                sim_study::ControllerKind::Fuzzy,
                sim_study::ControllerKind::Pd,
            ],
            noise_levels: vec![0.0, 0.01, 0.02],
            seeds: 3,
            ..study::SweepSettings::default()
        };
        let config = SweepConfig::new(scenario, settings).unwrap();
        let runs = default_runs(&config);
        assert_eq!(runs, vec![0, 3, 12, 15]);
        for (i, (level, controller)) in runs.iter().zip([
            (0, sim_study::ControllerKind::Fuzzy),
            (0, sim_study::ControllerKind::Pd),
            (2, sim_study::ControllerKind::Fuzzy),
            (2, sim_study::ControllerKind::Pd),
        ]) {
            let id = config.run_at(*i);
            assert_eq!(
                (id.level_index, id.controller, id.seed_index),
                (level, controller, 0)
            );
        }
    }
}
